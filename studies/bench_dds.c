// tactus bench dds: a session split over two processes on loopback, through
// the net.dds bridge, as `tactus run SCENARIO --role ...` runs it.
//
// The device process writes a pose at 1 kHz (its send time in the payload);
// the sim process echoes each new pose as a force; the device process times
// the force's arrival in its own model (the mirror's publish) against the
// pose's send time: the round trip, model to model. By default the bridges
// send on publish (the model's publish hook wakes their sender threads) and
// the sim's force path runs on arrival: a publish hook on the mirrored pose
// computes and publishes the force at once, as a HIP woken by a new pose
// would; without on_arrival it answers on its own 4 kHz tick. Meanwhile the device process publishes a
// 10404 x 3 float mesh at 60 Hz, reliable and transient-local, and the sim
// side's bridge times each mirror against the writer's publish (one host, one
// CLOCK_MONOTONIC). A raw DDS ping-pong of the same sample type beside it is
// the floor the transport sets.
#include "bench_dds.h"
#include "studies.h"

#include <tactus/config.h>

#if TX_WITH_DDS
#include "../controllers/net/net.h"
#include "../controllers/system_internal.h"
#include "../scenarios/loader.h"
#include "../model/error.h"

#include <tactus/stats.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define MESH_ROWS 10404 // 102 x 102 vertices, the papers' skin

static tx_hist rtt; // device side: pose sent -> force mirrored back, ns

typedef struct echo {
  tx_port in, out;
  uint64_t last;
  bool on_arrival;       // sim: the force path runs from the pose's publish hook
  tx_model* model;       // after init, on_arrival
  tx_comp pose, force;
  int hook;
} echo;

static int device_configure(tx_setup* s, void** self) {
  echo* e = calloc(1, sizeof *e);
  if (!e) return -1;
  *self = e;
  e->out = tx_setup_write(s, &(tx_component_def){"bench.pose", TX_F64, 1, 2, "ns, 1"});
  e->in = tx_setup_read_as(s, "bench.force", TX_F64, 2);
  return 0;
}
static void device_step(tx_ctx* c, void* self) {
  echo* e = self;
  double* p = tx_write(c, e->out);
  p[0] = (double)tx_mono_ns(); // exact in a double for 104 days of uptime
  p[1] = (double)tx_step_index(c);
  tx_snapshot f = tx_read(c, e->in);
  if (f.seq == e->last || f.seq == 0) return;
  e->last = f.seq;
  const double* echoed = f.data;
  if (echoed[0] > 0) tx_hist_add(&rtt, f.mono_ns - (int64_t)echoed[0]); // the force's arrival in this model
}

static const tx_param_def sim_params[] = {
    {"on_arrival", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "answer each pose from its publish hook, not on the next tick"},
};

static int sim_configure(tx_setup* s, void** self) {
  echo* e = calloc(1, sizeof *e);
  if (!e) return -1;
  *self = e;
  e->in = tx_setup_read_as(s, "bench.pose", TX_F64, 2);
  tx_setup_read_as(s, "bench.mesh", TX_F32, 3); // mirrored in, timed by the bridge
  e->out = tx_setup_write(s, &(tx_component_def){"bench.force", TX_F64, 1, 2, "ns, 1"});
  e->on_arrival = tx_table_bool(s, "on_arrival");
  return 0;
}

// on the thread that published the pose (the bridge's listener): this hook is
// then the force's one writer, the step never writes it
static void sim_on_pose(void* user, tx_comp comp, uint64_t seq) {
  (void)comp, (void)seq;
  echo* e = user;
  tx_snapshot p = tx_model_latest(e->model, e->pose); // the publisher's own thread: no slot needed
  memcpy(tx_model_back(e->model, e->force), p.data, 2 * sizeof(double));
  tx_model_publish(e->model, e->force, p.sim_ns);
}

static int sim_init(tx_ctx* c, void* self) {
  echo* e = self;
  if (!e->on_arrival) return 0;
  e->model = c->sys->model;
  e->pose = c->in->ports[e->in.id - 1].comp;
  e->force = c->in->ports[e->out.id - 1].comp;
  if (!(e->hook = tx_model_add_hook(e->model, e->pose, sim_on_pose, e))) return tx_stop_run(c, "%s", tx_error()), -1;
  return 0;
}

static void sim_fini(void* self) {
  echo* e = self;
  if (e && e->hook) tx_model_remove_hook(e->model, e->hook);
  free(e);
}

static void sim_step(tx_ctx* c, void* self) {
  echo* e = self;
  if (e->on_arrival) return; // the hook answers
  tx_snapshot p = tx_read(c, e->in);
  if (p.seq == e->last || p.seq == 0) return;
  e->last = p.seq;
  memcpy(tx_write(c, e->out), p.data, 2 * sizeof(double));
}

static int mesh_configure(tx_setup* s, void** self) {
  echo* e = calloc(1, sizeof *e);
  if (!e) return -1;
  *self = e;
  e->out = tx_setup_write(s, &(tx_component_def){"bench.mesh", TX_F32, MESH_ROWS, 3, "m"});
  return 0;
}
static void mesh_step(tx_ctx* c, void* self) {
  echo* e = self;
  float* x = tx_write(c, e->out);
  for (int i = 0; i < MESH_ROWS * 3; i++) x[i] = (float)(tx_step_index(c) % 1000) * 1e-3f + (float)i * 1e-6f;
}

static const tx_controller_class classes[] = {
    {.type = "bench.dds_device", .summary = "writes a timed pose, times the echoed force", .configure = device_configure,
     .step = device_step, .fini = free},
    {.type = "bench.dds_sim", .summary = "echoes each new pose as a force", .configure = sim_configure, .init = sim_init,
     .step = sim_step, .fini = sim_fini, .params = sim_params, .nparams = TX_PARAMS_COUNT(sim_params)},
    {.type = "bench.dds_mesh", .summary = "writes a 10404 x 3 float mesh", .configure = mesh_configure, .step = mesh_step,
     .fini = free},
};

// the raw floor: one process pings a Snapshot of the pose's size, the other
// answers at once from its listener; round trips in ns into h
static void raw_pong(dds_entity_t reader, void* arg) {
  dds_entity_t writer = *(dds_entity_t*)arg;
  void* samples[1] = {0};
  dds_sample_info_t info[1];
  if (dds_take(reader, samples, info, 1, 1) == 1 && info[0].valid_data) dds_write(writer, samples[0]);
  dds_return_loan(reader, samples, 1);
}

static int raw_side(int domain, bool ping, int count, tx_hist* h, int ready_fd, int go_fd) {
  dds_entity_t pp = tx_net_participant(domain, NULL, 0);
  if (pp < 0) return -1;
  dds_qos_t* q = tx_net_qos(TX_NET_FAST);
  dds_entity_t t_ping = dds_create_topic(pp, &tx_net_Snapshot_desc, "tx/bench/ping", q, NULL);
  dds_entity_t t_pong = dds_create_topic(pp, &tx_net_Snapshot_desc, "tx/bench/pong", q, NULL);
  dds_entity_t writer = dds_create_writer(pp, ping ? t_ping : t_pong, q, NULL);
  dds_listener_t* l = ping ? NULL : dds_create_listener(&writer);
  if (l) dds_lset_data_available(l, raw_pong);
  dds_entity_t reader = dds_create_reader(pp, ping ? t_pong : t_ping, q, l);
  if (l) dds_delete_listener(l);
  dds_delete_qos(q);
  if (writer < 0 || reader < 0) return dds_delete(pp), tx_set_error("raw DDS endpoints: %s", dds_strretcode(writer < 0 ? writer : reader)), -1;
  char byte = 1;
  if (!ping) { // answer until told to stop
    if (write(ready_fd, &byte, 1) != 1) return dds_delete(pp), -1;
    if (read(go_fd, &byte, 1) < 0) byte = 0;
    dds_delete(pp);
    return 0;
  }
  dds_entity_t ws = dds_create_waitset(pp);
  dds_entity_t rc = dds_create_readcondition(reader, DDS_ANY_STATE);
  dds_waitset_attach(ws, rc, 0);
  double pose[2] = {0};
  tx_snapshot snap = {.data = pose, .rows = 1, .cols = 2};
  for (int i = 0, sent = 0; sent < count + 200 && i < 4 * (count + 200); i++) { // 200 warm-up pings, not counted
    tx_net_Snapshot s;
    snap.seq = (uint64_t)i + 1;
    tx_net_pack(&s, 1, "bench.pose", TX_F64, &snap);
    int64_t t0 = tx_mono_ns();
    dds_write(writer, &s);
    void* samples[1] = {0};
    dds_sample_info_t info[1];
    bool got = false;
    while (!got && dds_waitset_wait(ws, NULL, 0, DDS_MSECS(20)) > 0) {
      int n = dds_take(reader, samples, info, 1, 1);
      got = n == 1 && info[0].valid_data && ((tx_net_Snapshot*)samples[0])->seq == snap.seq;
      if (n > 0) dds_return_loan(reader, samples, n);
    }
    if (got && ++sent > 200) tx_hist_add(h, tx_mono_ns() - t0);
    usleep(200);
  }
  dds_delete(pp);
  return 0;
}

static double result(tx_system* s, const char* key) {
  for (int k = 0; k < tx_system_results(s); k++)
    if (strcmp(tx_system_result_key(s, k), key) == 0) return tx_system_result(s, k);
  return -1;
}

// one role of the bench scenario, run in real time; returns 0 or 1
static int run_role(const char* text, const char* role, double seconds, tx_run_result* r, tx_scenario** out) {
  tx_load_options o = {.role = role};
  tx_scenario* sc = tx_scenario_load_text("bench-dds", text, strlen(text), &o);
  if (!sc) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  tx_run_options ro = {.duration_s = seconds, .realtime_priority = true, .pin_threads = false, .keep_cpus_awake = false};
  if (tx_system_run(sc->system, &ro, r)) {
    fprintf(stderr, "tactus: bench dds: %s: %s\n", role, tx_error());
    tx_scenario_free(sc);
    return 1;
  }
  *out = sc;
  return 0;
}

int tx_bench_dds(double duration_s, double net_hz, double sim_hz, int poll_us, bool on_arrival) {
  for (size_t i = 0; i < sizeof classes / sizeof classes[0]; i++)
    if (!tx_find_controller(classes[i].type)) tx_register_controller(&classes[i]);
  double seconds = duration_s > 0 ? duration_s : 5;
  int domain = 100 + (int)(getpid() % 100); // apart from a session on domain 0 and from another bench
  char text[1024];
  snprintf(text, sizeof text,
           "{\"name\": \"bench-dds-%d\", \"roles\": {\"device\": [\"device\", \"mesh\"], \"sim\": [\"sim\"]},"
           " \"net\": {\"domain\": %d, \"rate_hz\": %g, \"poll_us\": %d, \"fast\": [\"bench.pose\", \"bench.force\"], \"state\": [\"bench.mesh\"]},"
           " \"controllers\": [{\"name\": \"device\", \"type\": \"bench.dds_device\", \"rate_hz\": 1000},"
           " {\"name\": \"mesh\", \"type\": \"bench.dds_mesh\", \"rate_hz\": 60},"
           " {\"name\": \"sim\", \"type\": \"bench.dds_sim\", \"rate_hz\": %g, \"params\": {\"on_arrival\": %s}}]}",
           (int)getpid(), domain, net_hz, poll_us, sim_hz, on_arrival ? "true" : "false");
  printf("bench dds: two processes on loopback (domain %d), %g s; bridges at %g Hz, %s; the echoing sim %s\n", domain, seconds,
         net_hz, poll_us ? "a sender thread polling" : "sending on publish", on_arrival ? "answering on arrival" : "on its tick");
  if (poll_us) printf("  the sender threads poll every %d us\n", poll_us);
  fflush(stdout);

  // the raw floor first, so that the session below runs alone. Both ends are
  // children: a process that has started DDS must not fork another that uses it
  int ready[2], go[2], back[2];
  if (pipe(ready) || pipe(go) || pipe(back)) return perror("tactus: bench dds: pipe"), 1;
  pid_t pong = fork();
  if (pong < 0) return perror("tactus: bench dds: fork"), 1;
  if (pong == 0) { // its own copy of go's write end would keep it waiting for ever
    close(go[1]), close(ready[0]), close(back[0]), close(back[1]);
    _exit(raw_side(domain, false, 0, NULL, ready[1], go[0]) ? 1 : 0);
  }
  close(ready[1]), close(go[0]);
  pid_t ping = fork();
  if (ping < 0) return perror("tactus: bench dds: fork"), 1;
  if (ping == 0) {
    close(back[0]);
    static tx_hist raw;
    tx_hist_clear(&raw);
    char byte;
    if (read(ready[0], &byte, 1) != 1 || raw_side(domain, true, 2000, &raw, -1, -1)) _exit(1);
    tx_percentiles p = tx_hist_percentiles(&raw);
    double v[4] = {p.p50, p.p99, p.max, (double)raw.count};
    _exit(write(back[1], v, sizeof v) == (ssize_t)sizeof v ? 0 : 1);
  }
  close(back[1]), close(ready[0]);
  double raw_v[4] = {0};
  ssize_t raw_got = read(back[0], raw_v, sizeof raw_v);
  close(back[0]);
  close(go[1]); // the pong side ends
  waitpid(ping, NULL, 0);
  waitpid(pong, NULL, 0);
  if (raw_got != (ssize_t)sizeof raw_v) return fprintf(stderr, "tactus: bench dds: the raw round trip failed\n"), 1;

  // the session: sim in a child, device here; the child sends its numbers back
  int nums[2];
  if (pipe(nums)) return perror("tactus: bench dds: pipe"), 1;
  pid_t sim = fork();
  if (sim < 0) return perror("tactus: bench dds: fork"), 1;
  if (sim == 0) {
    close(nums[0]);
    tx_run_result r;
    tx_scenario* sc = NULL;
    if (run_role(text, "sim", seconds + 1, &r, &sc)) _exit(1);
    double v[4] = {result(sc->system, "net.bench.mesh.latency_p50_us"), result(sc->system, "net.bench.mesh.latency_p99_us"),
                   result(sc->system, "net.bench.pose.latency_p99_us"), result(sc->system, "net.samples_received")};
    tx_scenario_free(sc);
    _exit(write(nums[1], v, sizeof v) == (ssize_t)sizeof v ? 0 : 1);
  }
  close(nums[1]);
  tx_hist_clear(&rtt);
  tx_run_result r;
  tx_scenario* sc = NULL;
  usleep(300000); // the sim process up first: discovery before the first pose
  int rc = run_role(text, "device", seconds, &r, &sc);
  double v[4] = {-1, -1, -1, -1};
  ssize_t got = read(nums[0], v, sizeof v);
  close(nums[0]);
  int status = 0;
  waitpid(sim, &status, 0);
  if (rc || got != (ssize_t)sizeof v || !WIFEXITED(status) || WEXITSTATUS(status)) {
    tx_scenario_free(sc);
    return fprintf(stderr, "tactus: bench dds: the sim process failed\n"), 1;
  }
  double force_p99 = result(sc->system, "net.bench.force.latency_p99_us");
  tx_scenario_free(sc);

  tx_percentiles rt = tx_hist_percentiles(&rtt);
  printf("\n%-52s %8s %10s %10s %10s\n", "", "samples", "p50 us", "p99 us", "max us");
  printf("%-52s %8.0f %10.1f %10.1f %10.1f\n", "raw DDS round trip (listener echo, no model)", raw_v[3], raw_v[0] / 1e3,
         raw_v[1] / 1e3, raw_v[2] / 1e3);
  printf("%-52s %8llu %10.1f %10.1f %10.1f\n", "pose -> sim -> force, model to model", (unsigned long long)rtt.count, rt.p50 / 1e3,
         rt.p99 / 1e3, rt.max / 1e3);
  printf("%-52s %8s %10s %10.1f %10s\n", "  of which pose, publish -> mirrored (one way)", "", "", v[2], "");
  printf("%-52s %8s %10s %10.1f %10s\n", "  of which force, publish -> mirrored (one way)", "", "", force_p99, "");
  printf("%-52s %8s %10.1f %10.1f %10s\n", "mesh 10404 x 3 f32 at 60 Hz, publish -> mirrored", "", v[0], v[1], "");
  printf("\ntargets:\n");
  tx_bench_target_us("pose to sim and force back, round trip p99", rt.p99 / 1e3, 300);
  tx_bench_target_us("mesh mirrored at 60 Hz, added latency p99", v[1], 1000);
  bool ok = rtt.count > 0 && rt.p99 <= 300e3 && v[1] >= 0 && v[1] <= 1000;
  printf("%s\n", ok ? "all targets met" : "some targets MISSED");
  return rtt.count > 0 && v[1] >= 0 ? 0 : 1;
}

#else

#include <stdio.h>

int tx_bench_dds(double duration_s, double net_hz, double sim_hz, int poll_us, bool on_arrival) {
  (void)duration_s, (void)net_hz, (void)sim_hz, (void)poll_us, (void)on_arrival;
  fprintf(stderr, "tactus: bench dds: this build has no DDS (configure with -DTX_WITH_DDS=ON)\n");
  return 2;
}

#endif
