// Test controllers shared by the controller tests: a counter that writes its
// step count and a recorder that logs the order of steps.
#ifndef TX_TESTS_CONTROLLERS_SUPPORT_H
#define TX_TESTS_CONTROLLERS_SUPPORT_H

#include <tactus/controller.h>
#include <tactus/events.h>

#include <stdlib.h>
#include <string.h>

typedef struct counter {
  tx_port out, in;
  double gain;
  double seen; // last value read from "in"
  int64_t stop_at; // step index at which to stop the run (tx_stop_run), -1: never
} counter;

static const tx_param_def counter_params[] = {
    {"gain", TX_PARAM_NUM, "1", -1e6, 1e6, 1, NULL, "value written per step"},
    {"stop_at", TX_PARAM_INT, "1", -1, 1000000000, -1, NULL, "step index at which to stop the run; -1: never"},
    {"write", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "the component written (f64 1 x 2); none by default"},
    {"read", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "a component read; none by default"},
};

static int counter_configure(tx_setup* s, void** self) {
  counter* c = calloc(1, sizeof *c);
  *self = c;
  c->gain = tx_table_num(s, "gain");
  c->stop_at = tx_table_int(s, "stop_at");
  const char* out = tx_table_str(s, "write");
  const char* in = tx_table_str(s, "read");
  if (out) c->out = tx_setup_write(s, &(tx_component_def){out, TX_F64, 1, 2, "1"});
  if (in) c->in = tx_setup_read(s, in);
  return 0;
}

static void counter_step(tx_ctx* x, void* self) {
  counter* c = self;
  if (c->stop_at >= 0 && tx_step_index(x) == (uint64_t)c->stop_at) tx_stop_run(x, "disk full");
  if (c->in.id) {
    tx_snapshot s = tx_read(x, c->in);
    c->seen = ((const double*)s.data)[0];
  }
  if (c->out.id) {
    double* v = tx_write(x, c->out);
    v[0] = c->gain * (double)(tx_step_index(x) + 1) + 0.5 * c->seen;
    v[1] = (double)tx_sim_ns(x) * 1e-9;
  }
}

static void counter_fini(void* self) { free(self); }

static const tx_controller_class test_counter = {.type = "test.counter", .summary = "counts steps",
                                                 .configure = counter_configure, .step = counter_step,
                                                 .fini = counter_fini, .params = counter_params,
                                                 .nparams = TX_PARAMS_COUNT(counter_params)};

// event streams: params "emit" (stream), "capacity", "per_step" (events sent
// each step), "listen" (stream); a listener checks that what it takes is in
// order, each seq once, and counts the events and the gaps it saw
typedef struct eventer {
  tx_port out, in;
  int per_step;
  uint64_t sent, received, last_seq, gaps, out_of_order, dropped;
  double last_value;
} eventer;

static int eventer_configure(tx_setup* s, void** self) {
  eventer* e = calloc(1, sizeof *e);
  *self = e;
  const char* out = tx_param_str(s, "emit", NULL);
  const char* in = tx_param_str(s, "listen", NULL);
  uint32_t capacity = (uint32_t)tx_param_int(s, "capacity", 1024, 0, 1 << 22);
  e->per_step = (int)tx_param_int(s, "per_step", 1, 0, 1000);
  if (out) e->out = tx_setup_emit(s, out, capacity);
  if (in) e->in = tx_setup_listen(s, in);
  return 0;
}

static int eventer_init(tx_ctx* x, void* self) { // each run starts afresh, as its streams do
  (void)x;
  eventer* e = self;
  e->sent = e->received = e->last_seq = e->gaps = e->out_of_order = e->dropped = 0;
  return 0;
}

static void eventer_step(tx_ctx* x, void* self) {
  eventer* e = self;
  for (int k = 0; e->out.id && k < e->per_step; k++) {
    tx_event ev = {.kind = TX_EVENT_USER, .source = (uint32_t)k, .value = {(double)e->sent}};
    e->sent++;
    if (!tx_emit(x, e->out, &ev)) e->dropped++;
  }
  for (tx_event ev; e->in.id && tx_next_event(x, e->in, &ev);) {
    if (ev.seq <= e->last_seq) e->out_of_order++;
    else if (ev.seq != e->last_seq + 1) e->gaps += ev.seq - e->last_seq - 1;
    if (ev.value[0] != (double)(ev.seq - 1)) e->out_of_order++; // the payload travels with its seq
    e->last_seq = ev.seq;
    e->last_value = ev.value[0];
    e->received++;
  }
}

static const tx_controller_class test_eventer = {.type = "test.events", .summary = "sends and takes events",
                                                 .configure = eventer_configure, .init = eventer_init, .step = eventer_step,
                                                 .fini = counter_fini};

// a device loop: its type makes it run alone, at the top priority
static const tx_controller_class test_haptics = {.type = "haptics.test", .summary = "a counter on its own thread",
                                                 .configure = counter_configure, .step = counter_step,
                                                 .fini = counter_fini, .params = counter_params,
                                                 .nparams = TX_PARAMS_COUNT(counter_params)};
// the same by the class flag
static const tx_controller_class test_alone = {.type = "test.alone", .summary = "a counter on its own thread",
                                               .configure = counter_configure, .step = counter_step,
                                               .fini = counter_fini, .params = counter_params,
                                               .nparams = TX_PARAMS_COUNT(counter_params), .own_thread = true};

static inline void register_test_classes(void) {
  if (!tx_find_controller("test.counter")) tx_register_controller(&test_counter);
  if (!tx_find_controller("test.events")) tx_register_controller(&test_eventer);
  if (!tx_find_controller("haptics.test")) tx_register_controller(&test_haptics);
  if (!tx_find_controller("test.alone")) tx_register_controller(&test_alone);
}

#endif
