// collision.wall: the local force model of a flat wall, for trying haptics
// without a deformable body. The wall fills y < height; a tool point below
// the plane is pushed up by stiffness x depth. Published as the model the
// haptics controller renders: F0 at the tool position x0, and K = -k n n^T
// while in contact, so that between two publishes the force follows the hand.
#include "wall.h"

#include <tactus/components.h>

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
  w->pose = TX_READ_OF(s, pose, tx_pose);
  w->model = tx_setup_write(s, &TX_COMPONENT_OF(model, tx_force_model, 1));
  return 0;
}

static void step(tx_ctx* c, void* self) {
  wall* w = self;
  const tx_pose* x = tx_read(c, w->pose).data;
  double depth = w->height - x->pos[1];
  tx_force_model* m = tx_write(c, w->model);
  memset(m, 0, sizeof *m);
  memcpy(m->x0, x->pos, sizeof m->x0);
  if (depth > 0) {
    m->f0[1] = w->stiffness * depth; // up, out of the wall
    m->k[3 * 1 + 1] = -w->stiffness; // K_yy (row-major): deeper is stronger
  }
}

// both numbers may change during a run: the next step uses them
static void tune(tx_ctx* c, void* self, const char* key, double value) {
  (void)c;
  wall* w = self;
  if (strcmp(key, "stiffness") == 0) w->stiffness = value;
  else w->height = value;
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
    .live = (const char* const[]){"stiffness", "height_m", NULL},
    .tune = tune,
};
