// tactus study network-haptics: the haptics wall with the device on one side
// of a network and the simulation on the other. At each one-way delay (0, 1,
// 5, 20 ms; a round trip of twice that at the 1 kHz servo rate), the
// stiffest stable wall without and with the haptics controller's passivity
// controller, against the exact stability boundary of the delayed loop. The
// experiment is experiments/net_wall.c, in simulated time with the delay an
// exact delay line; each reported case (the stiffest stable wall and the
// first unstable one above it) is then run again with every tick carried over
// Cyclone DDS to a second process that computes the wall, and must give the
// same result bit for bit (docs/distributed.md).
#include "studies.h"

#include "experiments/net_wall.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"
#include "../scenarios/command.h"
#include "../model/error.h"

#include <tactus/config.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define DELAYS_MAX 4
static const double delays_ms[DELAYS_MAX] = {0, 1, 5, 20};

typedef struct row {
  double delay_ms;
  int ticks;            // round trip, servo periods
  double exact;         // boundary without passivity control, N/m
  tx_wall_search off, pc, port; // no passivity control; the controller's default (spring) reference; its port reference
  int dds_checked, dds_same; // cases run again over DDS, and those that agreed bit for bit
} row;

#if TX_WITH_DDS
#include "../controllers/net/net.h"

#include <sys/wait.h>

// the simulation process: answers each reading with the wall, from its listener
typedef struct wall_side {
  dds_entity_t writer;
  uint64_t tag;
} wall_side;

static void on_reading(dds_entity_t reader, void* arg) {
  wall_side* w = arg;
  void* samples[4] = {0};
  dds_sample_info_t info[4];
  int n = dds_take(reader, samples, info, 4, 4);
  for (int i = 0; i < n; i++) {
    const tx_net_Snapshot* s = samples[i];
    if (!info[i].valid_data || s->session != w->tag || s->data._length != 4 * sizeof(double)) continue;
    double in[4], out[2];
    memcpy(in, s->data._buffer, sizeof in); // K, B, x, v
    tx_wall_force(in[0], in[1], in[2], in[3], &out[0], &out[1]);
    tx_snapshot snap = {.data = out, .rows = 1, .cols = 2, .seq = s->seq};
    tx_net_Snapshot reply;
    tx_net_pack(&reply, w->tag, "study.wall_force", TX_F64, &snap);
    dds_write(w->writer, &reply);
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

typedef struct wall_link {
  pid_t child;
  int stop_fd;           // closing it ends the child
  dds_entity_t pp, writer, reader, waitset;
  uint64_t tag, seq;
} wall_link;

static int endpoints(int domain, bool device, dds_entity_t* pp, dds_entity_t* writer, dds_entity_t* reader, void* listen_arg) {
  *pp = tx_net_participant(domain, NULL, 0);
  if (*pp < 0) return -1;
  dds_qos_t* q = tx_net_qos(TX_NET_STATE); // reliable: a lockstep loop must not lose a tick
  dds_entity_t t_in = dds_create_topic(*pp, &tx_net_Snapshot_desc, "tx/study/wall/reading", q, NULL);
  dds_entity_t t_out = dds_create_topic(*pp, &tx_net_Snapshot_desc, "tx/study/wall/force", q, NULL);
  *writer = dds_create_writer(*pp, device ? t_in : t_out, q, NULL);
  dds_listener_t* l = device ? NULL : dds_create_listener(listen_arg);
  if (l) dds_lset_data_available(l, on_reading);
  *reader = dds_create_reader(*pp, device ? t_out : t_in, q, l);
  if (l) dds_delete_listener(l);
  dds_delete_qos(q);
  if (*writer < 0 || *reader < 0)
    return tx_set_error("DDS endpoints: %s", dds_strretcode(*writer < 0 ? *writer : *reader)), dds_delete(*pp), -1;
  return 0;
}

static int link_open(wall_link* k) {
  int domain = 200 + (int)(getpid() % 32);
  k->tag = tx_net_session_tag("network-haptics", domain);
  int stop[2];
  if (pipe(stop)) return tx_set_error("pipe failed"), -1;
  k->child = fork(); // before this process starts DDS: a process that has must not fork one that uses it
  if (k->child < 0) return tx_set_error("fork failed"), -1;
  if (k->child == 0) {
    close(stop[1]);
    wall_side w = {.tag = k->tag};
    dds_entity_t pp, reader;
    if (endpoints(domain, false, &pp, &w.writer, &reader, &w)) _exit(1);
    char byte;
    while (read(stop[0], &byte, 1) > 0) {}
    dds_delete(pp);
    _exit(0);
  }
  close(stop[0]);
  k->stop_fd = stop[1];
  if (endpoints(domain, true, &k->pp, &k->writer, &k->reader, NULL)) return -1;
  k->waitset = dds_create_waitset(k->pp);
  dds_entity_t rc = dds_create_readcondition(k->reader, DDS_ANY_STATE);
  dds_waitset_attach(k->waitset, rc, 0);
  // both directions matched before the first tick
  for (int i = 0; i < 500; i++) {
    dds_publication_matched_status_t pm;
    dds_subscription_matched_status_t sm;
    if (dds_get_publication_matched_status(k->writer, &pm) == 0 && dds_get_subscription_matched_status(k->reader, &sm) == 0 &&
        pm.current_count > 0 && sm.current_count > 0)
      return 0;
    usleep(10000);
  }
  return tx_set_error("the simulation process did not appear on DDS domain %d within 5 s", domain), -1;
}

static void link_close(wall_link* k) {
  if (k->pp > 0) dds_delete(k->pp);
  if (k->child > 0) {
    close(k->stop_fd);
    waitpid(k->child, NULL, 0);
  }
}

static int exchange(void* user, uint64_t tick, double K, double B, double x, double v, double* force, double* stored) {
  (void)tick;
  wall_link* k = user;
  double in[4] = {K, B, x, v};
  tx_snapshot snap = {.data = in, .rows = 1, .cols = 4, .seq = ++k->seq};
  tx_net_Snapshot s;
  tx_net_pack(&s, k->tag, "study.wall_reading", TX_F64, &snap);
  if (dds_write(k->writer, &s) < 0) return tx_set_error("DDS write failed"), -1;
  for (;;) {
    if (dds_waitset_wait(k->waitset, NULL, 0, DDS_SECS(2)) <= 0)
      return tx_set_error("no answer from the simulation process in 2 s"), -1;
    void* samples[1] = {0};
    dds_sample_info_t info[1];
    int n = dds_take(k->reader, samples, info, 1, 1);
    if (n <= 0) continue;
    const tx_net_Snapshot* r = samples[0];
    bool mine = info[0].valid_data && r->session == k->tag && r->seq == k->seq && r->data._length == 2 * sizeof(double);
    double out[2];
    if (mine) memcpy(out, r->data._buffer, sizeof out);
    dds_return_loan(k->reader, samples, n);
    if (mine) {
      *force = out[0], *stored = out[1];
      return 0;
    }
  }
}

// a case run over DDS gives exactly what it gave in this process
static int same_over_dds(wall_link* k, const tx_wall_case* c, int ticks, double K, bool* same) {
  tx_wall_case t = *c;
  t.stiffness = K;
  tx_wall_result here, there;
  tx_wall_link l = {exchange, k};
  if (!tx_wall_run_delayed(&t, ticks, NULL, &here) || !tx_wall_run_delayed(&t, ticks, &l, &there)) return -1;
  *same = here.stable == there.stable && memcmp(&here.energy_end, &there.energy_end, sizeof(double)) == 0 &&
          here.control_ticks == there.control_ticks;
  return 0;
}
#endif

static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

static int write_plot(const char* dir, const tx_wall_case* c, const row* rows, int n) {
  enum { DENSE = 41 }; // every round trip of 0 to 40 periods
  double dx[DENSE], dy[DENSE];
  for (int i = 0; i < DENSE; i++)
    dx[i] = i * c->device.period * 1e3 / 2, dy[i] = tx_net_wall_exact_bound(&c->device, c->damping, i);
  double x[DELAYS_MAX], off[DELAYS_MAX], pc[DELAYS_MAX], port[DELAYS_MAX];
  for (int i = 0; i < n; i++) x[i] = rows[i].delay_ms, off[i] = rows[i].off.k, pc[i] = rows[i].pc.k, port[i] = rows[i].port.k;
  tx_plot_series s[] = {
      {"exact boundary, delayed loop", dx, dy, DENSE, false, 3},
      {"measured, no passivity control", x, off, n, true, 9},
      {"passivity ctl, spring ref. (default)", x, pc, n, true, 10},
      {"passivity ctl, port ref.", x, port, n, true, 8},
  };
  tx_plot p = {"Stiffest stable wall, device and simulation across a network (1 kHz servo)", "one-way delay (ms)",
               "largest stable stiffness K (N/m)", false, true, s, 4};
  char path[4200];
  snprintf(path, sizeof path, "%s/network-haptics.png", dir);
  return tx_plot_png(path, &p);
}

int tx_study_network_haptics(const tx_study_args* a) {
  bool quick;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
  tx_wall_case c = tx_wall_case_default();
  c.device.period = 1e-3; // the haptics controller's 1 kHz
  int n = quick ? 2 : DELAYS_MAX;
  const double quick_delays[2] = {0, 5};
  if (quick) c.duration = 4; // a coarser criterion (about 2.5% of the boundary), for the test

  printf("study network-haptics: a wall on the simulated device (m = %g kg, b = %g N s/m, T = %g ms), the wall computed "
         "across a network;\none-way delay d each way, a round trip of 2d; %g s per case\n",
         c.device.mass, c.device.damping, c.device.period * 1e3, c.duration);
  printf("  %8s %6s %12s %12s %8s %14s %6s %14s %6s %10s\n", "delay ms", "ticks", "exact N/m", "measured", "/exact",
         "PC spring N/m", "gain", "PC port N/m", "gain", "over DDS");
  row rows[DELAYS_MAX];
#if TX_WITH_DDS
  wall_link k = {0};
  bool dds = link_open(&k) == 0;
  if (!dds) fprintf(stderr, "tactus: study network-haptics: %s\n", tx_error());
#endif
  int failed = 0;
  for (int i = 0; i < n; i++) {
    row* r = &rows[i];
    memset(r, 0, sizeof *r);
    r->delay_ms = quick ? quick_delays[i] : delays_ms[i];
    r->ticks = (int)lround(2 * r->delay_ms * 1e-3 / c.device.period);
    r->exact = tx_net_wall_exact_bound(&c.device, c.damping, r->ticks);
    tx_wall_case cpc = c;
    cpc.passivity = TX_WALL_PC_SPRING;
    r->off = tx_wall_largest_stable_delayed(&c, r->ticks, 1, 1e6, 0.01);
    r->pc = tx_wall_largest_stable_delayed(&cpc, r->ticks, 1, 1e6, 0.01);
    tx_wall_case cport = c;
    cport.passivity = TX_WALL_PC_PORT;
    r->port = tx_wall_largest_stable_delayed(&cport, r->ticks, 1, 1e6, 0.01);
#if TX_WITH_DDS
    // the stiffest stable wall and the first unstable one, without and with
    // passivity control (quick: the stable ones)
    const tx_wall_case* cases[2] = {&c, &cpc};
    const tx_wall_search* found[2] = {&r->off, &r->pc};
    for (int j = 0; dds && j < 2; j++)
      for (int u = 0; u < (quick ? 1 : 2); u++) {
        double K = u ? found[j]->k_unstable : found[j]->k;
        if (!(K > 0)) continue;
        bool same = false;
        if (same_over_dds(&k, cases[j], r->ticks, K, &same)) {
          fprintf(stderr, "tactus: study network-haptics: %s\n", tx_error());
          dds = false, failed = 1;
          break;
        }
        r->dds_checked++, r->dds_same += same;
      }
#endif
    char over[32];
    if (r->dds_checked) snprintf(over, sizeof over, "%d/%d same", r->dds_same, r->dds_checked);
    else snprintf(over, sizeof over, "-");
    printf("  %8g %6d %12.1f %12.1f %8.3f %14.1f %6.2f %14.1f %6.2f %10s\n", r->delay_ms, r->ticks, r->exact, r->off.k,
           r->off.k / r->exact, r->pc.k, r->pc.k / r->off.k, r->port.k, r->port.k / r->off.k, over);
  }
#if TX_WITH_DDS
  link_close(&k);
#endif

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "network-haptics.csv")) return tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "delay_ms,round_trip_periods,k_max_exact_n_m,k_max_measured_n_m,k_max_with_passivity_control_n_m,"
               "k_max_with_port_passivity_control_n_m,dds_cases,dds_same\n");
  json_t* cases = json_array();
  for (int i = 0; i < n; i++) {
    const row* r = &rows[i];
    fprintf(csv, "%g,%d,%.6g,%.6g,%.6g,%.6g,%d,%d\n", r->delay_ms, r->ticks, r->exact, r->off.k, r->pc.k, r->port.k,
            r->dds_checked, r->dds_same);
    json_array_append_new(cases, json_pack("{s:f,s:i,s:o,s:f,s:f,s:o,s:f,s:f,s:o,s:f,s:o,s:i,s:i}", "delay_ms", r->delay_ms,
                                           "round_trip_periods", r->ticks, "k_max_exact", num(r->exact), "k_max_measured",
                                           r->off.k, "k_unstable_measured", r->off.k_unstable, "measured_over_exact",
                                           num(r->off.k / r->exact), "k_max_with_passivity_control", r->pc.k,
                                           "k_unstable_with_passivity_control", r->pc.k_unstable, "passivity_control_gain",
                                           num(r->pc.k / r->off.k), "k_max_with_port_passivity_control", r->port.k,
                                           "port_passivity_control_gain", num(r->port.k / r->off.k), "dds_cases",
                                           r->dds_checked, "dds_same", r->dds_same));
  }
  if (!tx_aside_end(&out)) {
    json_decref(cases);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:b,s:{s:f,s:f,s:f,s:f},s:f,s:s,s:s,s:o}", "study", "network-haptics", "quick", quick,
                          "device", "mass_kg", c.device.mass, "damping_n_s_m", c.device.damping, "period_s", c.device.period,
                          "quantum_m", c.device.quantum, "duration_s", c.duration, "delay",
                          "one-way, each way, in simulated time (an exact delay line): round trip 2 d",
                          "units", "stiffness in N/m, delay in ms", "cases", cases);
  if (!doc || tx_report_save(doc, a->out_dir, "network-haptics.json")) {
    fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "out of memory");
    return json_decref(doc), 1;
  }
  json_decref(doc);
  bool plotted = write_plot(a->out_dir, &c, rows, n) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());

  printf("\ntargets:\n");
  bool all = true;
  for (int i = 0; i < n; i++) {
    const row* r = &rows[i];
    double off = fabs(r->off.k / r->exact - 1) * 100;
    bool dds_ok = r->dds_same == r->dds_checked;
    printf("  d = %-4g ms: measured within 5%% of the exact boundary: %5.1f%% off %-7s over DDS, bit for bit the same: %s\n",
           r->delay_ms, off, off <= 5 ? "met" : "MISSED", r->dds_checked ? (dds_ok ? "met" : "MISSED") : "not run");
    all &= off <= 5 && dds_ok;
  }
  printf("%s\nwrote %s/network-haptics.json, .csv%s\n", all ? "all targets met" : "some targets MISSED", a->out_dir,
         plotted ? " and .png" : "");
  return failed;
}
