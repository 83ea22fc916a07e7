// lagb.probe: a scripted laparoscopic probe for the LAGB organs. The
// waypoints are over the committed phantom (assets/lagb; y anterior, up for
// a supine patient): the liver's anterior surface lies at y = 55 mm at
// x = z = 60 mm and 51 mm at x = 30 mm; the stomach's at y = 37 mm at
// (x, z) = (-40, -35) mm and 36 mm at (-20, -45) mm. With the 5 mm tool
// sphere the probe goes about 1 cm into each and slides 3 cm along it.
#include "lagb_probe.h"

#include <tactus/components.h>

#include <stdlib.h>
#include <string.h>

static const double waypoints[][4] = {
    // t s, x, y, z m
    {0.0, 0.060, 0.080, 0.060},    // above the liver
    {1.0, 0.060, 0.050, 0.060},    // pressed 1 cm into it
    {2.5, 0.030, 0.046, 0.060},    // slid 3 cm along it
    {3.0, 0.030, 0.080, 0.060},    // lifted
    {3.5, -0.040, 0.060, -0.035},  // above the stomach
    {4.5, -0.040, 0.032, -0.035},  // pressed 1 cm into it
    {6.0, -0.020, 0.031, -0.045},  // slid along it
    {6.5, -0.020, 0.060, -0.045},  // lifted
};
enum { WAYPOINTS = sizeof waypoints / sizeof waypoints[0] };

void tx_lagb_probe_at(double t, double pose[7]) {
  memset(pose, 0, 7 * sizeof *pose);
  pose[3] = 1;
  int i = 0;
  while (i + 1 < WAYPOINTS && waypoints[i + 1][0] <= t) i++;
  double u = 0;
  if (i + 1 < WAYPOINTS && t > waypoints[i][0]) u = (t - waypoints[i][0]) / (waypoints[i + 1][0] - waypoints[i][0]);
  const double* b = waypoints[i + 1 < WAYPOINTS ? i + 1 : i];
  for (int a = 0; a < 3; a++) pose[a] = waypoints[i][a + 1] + u * (b[a + 1] - waypoints[i][a + 1]);
}

static const tx_param_def params[] = {
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the pose it writes (tx_pose)"},
};

static int configure(tx_setup* s, void** self) {
  tx_port* p = malloc(sizeof *p);
  if (!p) return -1;
  *self = p;
  const char* name = tx_table_str(s, "pose");
  if (!name) return -1;
  *p = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_pose, 1));
  return 0;
}

static int init(tx_ctx* c, void* self) {
  tx_lagb_probe_at(0, tx_write(c, *(tx_port*)self));
  return 0;
}

static void step(tx_ctx* c, void* self) { tx_lagb_probe_at((double)tx_sim_ns(c) * 1e-9, tx_write(c, *(tx_port*)self)); }

static void fini(void* self) { free(self); }

const tx_controller_class tx_lagb_probe = {
    .type = "lagb.probe",
    .summary = "scripted probe of lagb-organs: presses and slides on the liver, then the stomach; writes a tx_pose",
    .configure = configure,
    .init = init,
    .step = step,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
