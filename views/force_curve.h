// Internal: the "view.force_curve" controller class, a view of one tool's
// force against its position. Each step it reads the pose (F64 1x7) and the
// force (F64 1x3, default device0.force: what the device was sent), and
// optionally the HIP state (hip0.state) and the skin's torn-link count
// (skin.torn); it writes nothing. When the run ends it leaves, in the run's
// folder, NAME.csv (t_s, x y z m, fx fy fz N, contacts, pierced, torn,
// skin_t_s: the time of the skin publish the force was computed on) and
// NAME.png, the force along `axis` against the position along it in mm, the
// length unit of every plot (the suturing papers' plots, which use cm).
// Parameters: pose, force, state ("" for none), torn ("" for none), axis (x, y
// or z), file (default force_displacement), max_samples (the recording stops,
// with a warning, when it is full), png (false: the CSV only; the PNG goes
// through PLplot and cairo, whose font threads ThreadSanitizer cannot see
// into).
#ifndef TX_VIEWS_FORCE_CURVE_H
#define TX_VIEWS_FORCE_CURVE_H

#include <tactus/controller.h>

extern const tx_controller_class tx_view_force_curve;

#endif
