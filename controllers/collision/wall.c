// collision.wall: the local force model of a flat wall, for trying haptics
// without a deformable body. The wall fills y < height; a tool point below
// the plane is pushed up by stiffness x depth. Published as the model the
// haptics controller renders: F0 at the tool position x0, and K = -k n n^T
// while in contact, so that between two publishes the force follows the hand.
#include "wall.h"

#include <stdlib.h>
#include <string.h>

typedef struct wall {
  double stiffness; // N/m
  double height;    // m, the plane y = height
  tx_port pose;     // the tool pose read
  tx_port model;    // the force model written
} wall;

static const tx_param_def params[] = {
    {"stiffness", TX_PARAM_NUM, "N/m", 0, 1e6, 300, NULL, "the wall's spring: F = stiffness x depth"},
    {"height_m", TX_PARAM_NUM, "m", -10, 10, 0, NULL, "the plane y = height_m; the wall fills y below it"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the tool pose read (f64 1 x 7)"},
    {"force_model", TX_PARAM_STR, NULL, 0, 0, 0, "tool0.force_model", "the force model written (f64 1 x 15)"},
};

static int configure(tx_setup* s, void** self) {
  wall* w = calloc(1, sizeof *w);
  if (!w) return -1;
  *self = w;
  w->stiffness = tx_table_num(s, "stiffness");
  w->height = tx_table_num(s, "height_m");
  const char* pose = tx_table_str(s, "pose");
  const char* model = tx_table_str(s, "force_model");
  if (!pose || !model) return -1;
  w->pose = tx_setup_read_as(s, pose, TX_F64, 7); // x y z, qw qx qy qz
  w->model = tx_setup_write(s, &(tx_component_def){model, TX_F64, 1, 15, "N, m, N/m"});
  return 0;
}

static void step(tx_ctx* c, void* self) {
  wall* w = self;
  const double* x = tx_read(c, w->pose).data; // x y z, then the orientation
  double depth = w->height - x[1];
  double* m = tx_write(c, w->model); // f0 (3), x0 (3), K (9)
  memset(m, 0, 15 * sizeof *m);
  memcpy(m + 3, x, 3 * sizeof *m);
  if (depth > 0) {
    m[1] = w->stiffness * depth; // up, out of the wall
    m[6 + 4] = -w->stiffness;    // K_yy: deeper is stronger
  }
}

static void fini(void* self) { free(self); }

const tx_controller_class tx_collision_wall = {
    .type = "collision.wall",
    .summary = "force model of the flat wall y < height_m: F0 = k depth up, K = -k n n^T",
    .configure = configure,
    .step = step,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
