// tactus bench split-session (see bench_split.h). Each run is a real
// `tactus run` process, started as a user starts a session
// (docs/distributed.md); the numbers come from each process's report.json.
#include "bench_split.h"
#include "studies.h"

#include "../scenarios/command.h"

#include <tactus/config.h>

#include <jansson.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char** environ;


#if TX_WITH_DDS
enum { ROUNDS = 5, SETUPS = 3 };

static const char* const SETUP_NAMES[SETUPS] = {"one process", "sim + device", "sim + device + view"};

// what one run measured: the device process's haptics, the sim's HIP and skin
typedef struct split_run {
  double missed;      // haptics deadlines missed
  double steps;       // haptics steps
  double haptics_hz;  // achieved
  double hip_hz, skin_hz;
  double steal_s;     // the host's steal time over the device process's run (a VM's host taking the CPU)
} split_run;

// start `tactus run suturing-skin ARGS... --out DIR` with its output in DIR.log
static pid_t start(const char* exe, const char* dir, const char* const* args) {
  const char* argv[24] = {exe, "run", "suturing-skin", "--quiet", "--out", dir};
  int n = 6;
  for (; *args && n < 22; args++) argv[n++] = *args;
  argv[n] = NULL;
  char log[4400];
  snprintf(log, sizeof log, "%s.log", dir);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  if (posix_spawn(&pid, exe, &fa, NULL, (char* const*)argv, environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

static bool finished(pid_t pid) {
  int status = 0;
  return pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

static double controller_num(json_t* report, const char* name, const char* key) {
  json_t* c = tx_report_controller(report, name);
  return c ? json_number_value(json_object_get(c, key)) : -1;
}

// the run's numbers from the device's and the sim's reports (the same
// report in one process)
static bool read_run(const char* device_dir, const char* sim_dir, split_run* r) {
  char path[4200];
  snprintf(path, sizeof path, "%s/report.json", device_dir);
  json_t* dev = json_load_file(path, 0, NULL);
  snprintf(path, sizeof path, "%s/report.json", sim_dir);
  json_t* sim = json_load_file(path, 0, NULL);
  bool ok = dev && sim;
  if (ok) {
    r->missed = controller_num(dev, "haptics", "missed");
    r->steps = controller_num(dev, "haptics", "steps");
    r->haptics_hz = controller_num(dev, "haptics", "achieved_hz");
    r->hip_hz = controller_num(sim, "hip", "achieved_hz");
    r->skin_hz = controller_num(sim, "skin", "achieved_hz");
    r->steal_s = json_number_value(json_object_get(dev, "host_steal_s"));
    ok = r->missed >= 0 && r->steps > 0 && r->hip_hz > 0 && r->skin_hz > 0;
  }
  json_decref(dev), json_decref(sim);
  return ok;
}

// one set-up once: its processes started sim first (discovery before the
// first pose), each longer-lived than the device, whose run is measured
static bool run_setup(const char* exe, const char* base, int setup, double seconds, int domain, split_run* r) {
  char secs[32], longer[32], dom[48], dev[4300], sim[4300], view[4300];
  snprintf(secs, sizeof secs, "%g", seconds);
  snprintf(longer, sizeof longer, "%g", seconds + 1.5);
  snprintf(dom, sizeof dom, "net.domain=%d", domain);
  snprintf(dev, sizeof dev, "%s-device", base);
  snprintf(sim, sizeof sim, "%s-sim", base);
  snprintf(view, sizeof view, "%s-view", base);
  if (setup == 0) {
    const char* one[] = {"--duration", secs, "--view", "png", NULL};
    return finished(start(exe, base, one)) && read_run(base, base, r);
  }
  // the PNG frames are rendered once in every set-up: by the sim, or by a view of their own
  const char* sim_args[] = {"--role", "sim", "--duration", longer, "--set", dom, setup == 1 ? "--view" : NULL, "png", NULL};
  const char* view_args[] = {"--role", "view", "--duration", longer, "--set", dom, "--view", "png", NULL};
  const char* dev_args[] = {"--role", "device", "--duration", secs, "--set", dom, NULL};
  pid_t ps = start(exe, sim, sim_args), pv = setup == 2 ? start(exe, view, view_args) : 0;
  struct timespec head = {0, 500000000};
  nanosleep(&head, NULL);
  pid_t pd = start(exe, dev, dev_args);
  bool ok = finished(pd);
  ok = finished(ps) && ok;
  if (pv) ok = finished(pv) && ok;
  return ok && read_run(dev, sim, r);
}

static int by_value(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

static double median(const double* v, int n) {
  double s[ROUNDS];
  memcpy(s, v, sizeof(double) * (size_t)n);
  qsort(s, (size_t)n, sizeof(double), by_value);
  return n % 2 ? s[n / 2] : (s[n / 2 - 1] + s[n / 2]) / 2;
}

#endif

int tx_bench_split_session(const char* out, double duration_s) {
#if !TX_WITH_DDS
  (void)out, (void)duration_s;
  return tx_bad_input("bench split-session: this build has no Cyclone DDS (configured with TX_WITH_DDS=OFF)");
#else
  double seconds = duration_s > 0 ? duration_s : 10;
  char dir[4096], exe[4096];
  if (tx_out_dir(out, "bench-split-session", dir, sizeof dir)) return TX_EXIT_BAD_INPUT;
  ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (len <= 0) return perror("tactus: bench split-session: /proc/self/exe"), 1;
  exe[len] = 0;
  int domain = 100 + (int)(getpid() % 100);
  printf("bench split-session: suturing-skin for %g s a run, %d rounds alternating %s, %s and %s\n"
         "(each renders the same PNG frames once; DDS domain %d); the runs are in %s\n\n",
         seconds, ROUNDS, SETUP_NAMES[0], SETUP_NAMES[1], SETUP_NAMES[2], domain, dir);
  printf("  %5s  %-20s %8s %8s %11s %9s %9s %10s\n", "round", "set-up", "missed", "of", "haptics Hz", "hip Hz", "skin Hz",
         "steal s");
  split_run runs[SETUPS][ROUNDS];
  bool rates_held = true;
  for (int round = 0; round < ROUNDS; round++)
    for (int k = 0; k < SETUPS; k++) {
      int setup = (round + k) % SETUPS;  // each set-up first, middle and last in turn
      char base[4200];
      snprintf(base, sizeof base, "%s/round%d-%c", dir, round + 1, "123"[setup]);
      split_run* r = &runs[setup][round];
      if (!run_setup(exe, base, setup, seconds, domain, r)) {
        fprintf(stderr, "tactus: bench split-session: the %s run of round %d failed (see %s*.log)\n", SETUP_NAMES[setup],
                round + 1, base);
        return 1;
      }
      rates_held &= r->haptics_hz >= 990 && r->hip_hz >= 3960 && r->skin_hz >= 59.4;
      printf("  %5d  %-20s %8.0f %8.0f %11.2f %9.1f %9.3f %10.3f\n", round + 1, SETUP_NAMES[setup], r->missed, r->steps,
             r->haptics_hz, r->hip_hz, r->skin_hz, r->steal_s);
      fflush(stdout);
    }
  double med[SETUPS], lo[SETUPS], hi[SETUPS];
  printf("\n  %-20s %14s %14s\n", "set-up", "missed, median", "missed, range");
  for (int s = 0; s < SETUPS; s++) {
    double m[ROUNDS];
    lo[s] = 1e300, hi[s] = -1;
    for (int round = 0; round < ROUNDS; round++) {
      m[round] = runs[s][round].missed;
      if (m[round] < lo[s]) lo[s] = m[round];
      if (m[round] > hi[s]) hi[s] = m[round];
    }
    med[s] = median(m, ROUNDS);
    printf("  %-20s %14.0f %8.0f to %.0f\n", SETUP_NAMES[s], med[s], lo[s], hi[s]);
  }
  printf("\ntargets (medians of the rounds; a run's misses are mostly the host's stalls, so the ranges overlap):\n");
  char m[64], l[64];
  for (int s = 1; s < SETUPS; s++) {
    char what[64];
    snprintf(what, sizeof what, "haptics missed, %s", SETUP_NAMES[s]);
    snprintf(m, sizeof m, "%.0f", med[s]);
    snprintf(l, sizeof l, "<= %.0f (one)", med[0]);
    tx_bench_target(what, m, l, med[s] <= med[0]);
  }
  tx_bench_target("rates held in every run (1 kHz, 4 kHz, 60 Hz)", rates_held ? "yes" : "no", ">= 99 %", rates_held);
  return 0;
#endif
}
