// Internal: the force a haptics tick renders from the published force model.
#ifndef TX_CONTROLLERS_HAPTICS_RENDER_H
#define TX_CONTROLLERS_HAPTICS_RENDER_H

#include <tactus/haptics.h>

typedef enum tx_render_mode {
  TX_RENDER_LOCAL_MODEL = 1, // F = F0 + K (x - x0), every tick: follows the hand between physics frames
  TX_RENDER_SAMPLE_HOLD,     // F = F0, held until the next model: the suturing papers' 60 Hz hold
} tx_render_mode;

// the force at device position x (m), N
void tx_render_force(const tx_force_model* m, tx_render_mode mode, const double x[3], double f[3]);

// a spring-damper between the device and the simulated tool (virtual coupling):
// F = kc (tool_x - x) + bc (tool_v - v), N
void tx_render_coupling(double kc, double bc, const double tool_x[3], const double tool_v[3], const double x[3],
                        const double v[3], double f[3]);

#endif
