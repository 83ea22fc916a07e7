// test.suture_feed: the scripted stand-in of suture_feed.h.
#include "suture_feed.h"

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NODES 41

typedef struct feed {
  tx_port ievents, tevents, punctures, nodes, tension, loads, holder, hand0, hand1;
  double scale; // simulation seconds per script second
  int through;  // the punctures the thread runs through once pulled (3 s)
  double step;  // script seconds per step
  double last;  // script time of the last step, -1 before the first
} feed;

static const double entry[3] = {0, 0, 0.004};
// the punctures: time, z (the wound runs along x at z = 0), side
static const double script[4][3] = {{1.0, 0.004, +1}, {1.2, 0.0005, -1}, {1.6, -0.0005, +1}, {2.0, -0.0025, -1}};

static int feed_configure(tx_setup* s, void** self) {
  feed* f = calloc(1, sizeof *f);
  if (!f) return -1;
  *self = f;
  f->scale = tx_table_num(s, "time_scale");
  f->through = tx_table_int(s, "through");
  f->step = 1 / (tx_setup_rate(s) * f->scale);
  f->ievents = tx_setup_emit(s, "instruments.events", 64);
  f->tevents = tx_setup_emit(s, "thread.events", 64);
  f->punctures = tx_setup_write(s, &TX_COMPONENT_OF("needle.punctures", tx_puncture, 8));
  f->nodes = tx_setup_write(s, &TX_COMPONENT_OF("thread.nodes", tx_thread_node, NODES));
  f->tension = tx_setup_write(s, &TX_COMPONENT_OF("thread.force_model", tx_force_model, 1));
  f->loads = tx_setup_write(s, &TX_COMPONENT_OF("thread.puncture_loads", tx_puncture_load, 9));
  f->holder = tx_setup_write(s, &TX_COMPONENT_OF("instrument0.pose", tx_instrument_pose, 1));
  f->hand0 = tx_setup_write(s, &TX_COMPONENT_OF("device0.pose", tx_pose, 1));
  f->hand1 = tx_setup_write(s, &TX_COMPONENT_OF("device1.pose", tx_pose, 1));
  return 0;
}

// a run (and a reset) starts before the script's first event
static int feed_init(tx_ctx* c, void* self) {
  (void)c;
  ((feed*)self)->last = -1;
  return 0;
}

// the first step at or after script time `when`: in real time a late tick
// may be skipped, and the event must not go with it
static bool at(const feed* f, double t, double when) { return t >= when - 1e-9 && f->last < when - 1e-9; }

static void feed_step(tx_ctx* c, void* self) {
  feed* f = self;
  double t = (double)tx_sim_ns(c) * 1e-9 / f->scale;
  // punctures: the event and the row in the same step
  tx_puncture* p = tx_write(c, f->punctures);
  for (int i = 0; i < 8; i++) p[i] = (tx_puncture){{-1, 0, 0}, {0, 0, 0}, 0};
  for (int i = 0; i < 4; i++) {
    if (t < script[i][0] - 1e-9) continue;
    p[i] = (tx_puncture){{0, 1, 2}, {1, 0, 0}, script[i][2]};
    if (at(f, t, script[i][0])) {
      tx_event e = {.kind = TX_EVENT_PUNCTURE, .source = 7};
      e.puncture.point[0] = 0.002, e.puncture.point[1] = 0, e.puncture.point[2] = script[i][1];
      tx_emit(c, f->ievents, &e);
    }
  }
  // grasps and releases of hand 0 and hand 1
  const struct { double t; uint32_t kind, hand; } jaws[] = {
      {0.5, TX_EVENT_GRASP, 0}, {0.7, TX_EVENT_GRASP, 1}, {8.0, TX_EVENT_RELEASE, 1}, {8.5, TX_EVENT_RELEASE, 0}};
  for (int i = 0; i < 4; i++)
    if (at(f, t, jaws[i].t)) tx_emit(c, f->ievents, &(tx_event){.kind = jaws[i].kind, .source = jaws[i].hand});
  // the thread: straight along +x through the entry, from node j on; pulled
  // through (a 2 cm tail) at 3 s; from 4 s 1.5 turns around the holder's jaws
  tx_thread_node* n = tx_write(c, f->nodes);
  int j = t < 3 ? 0 : 30;
  for (int i = 0; i < NODES; i++) n[i] = (tx_thread_node){{entry[0] + (i - j) * 0.002, entry[1], entry[2]}, 0.00025};
  if (t >= 4 && t < 7)
    for (int i = 0; i < 20; i++) {
      double a = 3 * M_PI * i / 19.0;
      n[5 + i] = (tx_thread_node){{0.055 + 0.001 * i, 0.02 + 0.003 * cos(a), 0.003 * sin(a)}, 0.00025};
    }
  tx_puncture_load* ld = tx_write(c, f->loads); // the punctures the thread runs through
  for (int i = 0; i < 9; i++) ld[i] = (tx_puncture_load){{i < f->through && t >= 3 ? 0 : -1, 1, 2}, {1, 0, 0}, {0, 0, 0}, 0};
  tx_force_model* m = tx_write(c, f->tension);
  memset(m, 0, sizeof *m);
  m->f0[1] = t < 5 ? 0.5 * t : 0; // a tension of up to 2.5 N, along y
  tx_instrument_pose* h = tx_write(c, f->holder);
  *h = (tx_instrument_pose){{0.05, 0.02, 0}, {1, 0, 0, 0}, 0};
  tx_pose* h0 = tx_write(c, f->hand0);
  *h0 = (tx_pose){{0.1 * fmin(t, 8) / 8, 0.05, 0}, {1, 0, 0, 0}};
  tx_pose* h1 = tx_write(c, f->hand1);
  *h1 = (tx_pose){{-0.05, 0.05, 0}, {1, 0, 0, 0}};
  // the thread's events: a knot, fixed, a second knot, a cut
  const struct { double t; uint32_t kind, source; double fixed; } thread[] = {
      {5.0, TX_EVENT_KNOT, 1, 0}, {5.5, TX_EVENT_KNOT, 1, 1}, {6.5, TX_EVENT_KNOT, 2, 0}, {7.5, TX_EVENT_CUT, 20, 0}};
  for (int i = 0; i < 4; i++)
    if (at(f, t, thread[i].t)) {
      tx_event e = {.kind = thread[i].kind, .source = thread[i].source};
      e.value[2] = thread[i].fixed;
      tx_emit(c, f->tevents, &e);
    }
  f->last = t;
}

static void feed_fini(void* self) { free(self); }

static const tx_param_def params[] = {
    {"time_scale", TX_PARAM_NUM, "1", 0.05, 10, 1, NULL, "simulation seconds per second of the script"},
    {"through", TX_PARAM_INT, "1", 0, 4, 4, NULL, "punctures the thread runs through once pulled through (3 s), in the needle's order"},
};

const tx_controller_class tx_test_suture_feed = {.type = "test.suture_feed",
                                                 .summary = "scripted instruments and thread of a suture",
                                                 .configure = feed_configure,
                                                 .init = feed_init,
                                                 .step = feed_step,
                                                 .fini = feed_fini,
                                                 .params = params,
                                                 .nparams = TX_PARAMS_COUNT(params)};

#ifdef TX_SUTURE_FEED_PLUGIN
__attribute__((visibility("default"))) int TX_PLUGIN_ENTRY(int api_version) {
  if (api_version != TX_API_VERSION) return -1;
  return tx_register_controller(&tx_test_suture_feed);
}
#endif

