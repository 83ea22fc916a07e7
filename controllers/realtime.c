// Real-time executor: one thread per rate group, absolute deadlines. Each
// haptics instance has a thread of its own at the top priority, and a
// scenario may name a thread for instances of one rate (system.c builds them).
//
// Tick k of a group starts at t0 + k/rate (clock_nanosleep, TIMER_ABSTIME), so
// errors never accumulate. A step that ends after the next tick's start is a
// missed deadline; that next tick then runs at once, late, unless its whole
// period is already over: such ticks are skipped, each counted as missed. Threads ask for
// SCHED_FIFO, haptics highest, then the loops of TX_FIFO_MIN_HZ and more by
// rate (faster = higher priority), and a CPU each, round-robin, haptics then the fastest on the last CPU (a
// process with no haptics thread starts on the CPU before it, leaving the last
// to a haptics thread in another process of the session); where either is
// refused they run without it and the result says so. Slower threads (the
// physics, the views) are not pinned: the kernel puts each where there is
// room. Pinned round-robin, they left one CPU half idle beside the other's
// queue (lagb: the view's renderer, which keeps to the CPUs its starter may
// use but the last, was started by the organs' pinned 30 Hz thread and so
// shared that CPU with the organs and the membranes). They stay SCHED_OTHER: a FIFO thread that overruns takes its
// whole CPU, and past the kernel's real-time share (sched_rt_runtime_us,
// 95 % by default) every FIFO thread on that CPU is stopped for the rest of
// the second, a haptics thread pinned there included (a 60 Hz band that could
// not keep up cost a hand 50 ms of ticks every second). Under SCHED_OTHER an
// overrunning physics thread takes the spare time and the haptics thread
// still preempts it at once.
#include "system_internal.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

// threads of this rate and more run SCHED_FIFO (the haptic loop's: collision,
// the instruments' coupling); slower ones SCHED_OTHER (see above)
#define TX_FIFO_MIN_HZ 1000.0

// the start line: workers report their init done, then wait for t0
typedef struct gate {
  pthread_mutex_t mutex;
  pthread_cond_t cond;
  int ready;   // workers that finished init
  bool open;   // t0 and end are set
  bool failed; // an init failed: no step and no finish, as in lockstep
  int64_t t0;  // release of tick 0, monotonic ns
  int64_t end_sim; // no tick at or after this simulation time
} gate;

typedef struct worker {
  tx_system* sys;
  int group;
  gate* gate;
  _Atomic bool* stop;
  int cpu;        // -1: no pinning
  int priority;   // SCHED_FIFO priority, 0: none
  int fifo_error; // errno of the refusal, 0 if granted
  int pin_error;
  int init_rc;
  char init_err[1024]; // the worker thread's tx_error(), for the main thread
} worker;

static void sleep_until(int64_t ns) {
  struct timespec ts = {ns / 1000000000, ns % 1000000000};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {}
}

static void apply_scheduling(worker* w) {
  if (w->priority > 0) {
    struct sched_param sp = {.sched_priority = w->priority};
    w->fifo_error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  }
  if (w->cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(w->cpu, &set);
    w->pin_error = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  }
}

static void* worker_main(void* arg) {
  worker* w = arg;
  tx_system* s = w->sys;
  group* g = &s->threads[w->group];
  char tname[16];
  if (g->name) snprintf(tname, sizeof tname, "tx-%s", g->name);
  else snprintf(tname, sizeof tname, "tx-%s%.0fHz", g->own ? "hap-" : "", g->rate_hz);
  pthread_setname_np(pthread_self(), tname);
  apply_scheduling(w);
  for (int m = 0; m < g->count && w->init_rc == 0; m++) {
    instance* in = s->inst[g->members[m]];
    if ((w->init_rc = tx_instance_init(s, in))) snprintf(w->init_err, sizeof w->init_err, "%s", tx_error());
    else if (!tx_control_keep_initial(s, in))
      w->init_rc = -1, snprintf(w->init_err, sizeof w->init_err, "out of memory for %s's initial state", in->name);
  }
  pthread_mutex_lock(&w->gate->mutex);
  w->gate->ready++;
  pthread_cond_broadcast(&w->gate->cond);
  while (!w->gate->open) pthread_cond_wait(&w->gate->cond, &w->gate->mutex);
  const int64_t t0 = w->gate->t0, end_sim = w->gate->end_sim;
  const bool failed = w->gate->failed;
  pthread_mutex_unlock(&w->gate->mutex);
  if (failed) return NULL;

  int64_t prev_start = 0;
  uint64_t prev_k = 0;
  for (uint64_t k = 0; !atomic_load_explicit(w->stop, memory_order_relaxed) && !tx_system_halted(s);) {
    int64_t tick = tx_tick_ns(g->rate_hz, k);
    tx_clock_state cs = tx_clock_read(&s->clock);
    // the end is in simulation time: a pause or a slower scale lengthens the run
    int64_t sim = tx_clock_sim(&cs, tick);
    if (sim >= end_sim || tick == INT64_MAX) break; // compared before adding: a saturated tick must not wrap
    int64_t release = t0 + tick;
    sleep_until(release);
    int64_t start = tx_mono_ns();
    int64_t expected = tx_tick_ns(g->rate_hz, k) - tx_tick_ns(g->rate_hz, prev_k);
    int64_t jitter = start - prev_start - expected;
    cs = tx_clock_read(&s->clock); // a control call may have come while asleep
    sim = tx_clock_sim(&cs, tick);
    bool catch_up = false;
    for (int m = 0; m < g->count; m++) {
      instance* in = s->inst[g->members[m]];
      if (in->dead) continue;
      int64_t at = sim; // live: every tick, at the clock's time, a nanosecond on where the clock stands
      if (in->live) {       // (paused), so its recording's time still increases
        if (at <= in->live_ns) at = in->live_ns + 1;
        in->live_ns = at;
        tx_control_apply_tunes(s, in, at);
      } else {
        tx_control_apply_reset(s, in, sim);
        tx_control_apply_tunes(s, in, sim);
        if (in->dead) continue;
        if (tx_tick_ns(g->rate_hz, in->sim_tick) > sim) continue; // the clock has not reached its next tick
        if (cs.paused) {
          // a single step: every tick up to the clock, at once
          while (!in->dead && tx_tick_ns(g->rate_hz, in->sim_tick) <= sim && !tx_system_halted(s)) {
            int64_t t = tx_tick_ns(g->rate_hz, in->sim_tick++);
            if (in->steps == 0) in->first_start_ns = start;
            in->last_start_ns = start;
            tx_hist_add(&in->step_time, tx_instance_step(s, in, t));
            catch_up = true;
          }
          continue;
        }
        // running: one step a tick, at the latest tick due (those before are skipped, as below)
        uint64_t last = (uint64_t)floor((double)sim * g->rate_hz * 1e-9);
        while (last > in->sim_tick && tx_tick_ns(g->rate_hz, last) > sim) last--;
        while (tx_tick_ns(g->rate_hz, last + 1) <= sim) last++;
        if (last > in->sim_tick) in->sim_tick = last;
        at = tx_tick_ns(g->rate_hz, in->sim_tick++);
      }
      if (in->steps == 0) in->first_start_ns = start;
      else tx_hist_add(&in->jitter, jitter < 0 ? -jitter : jitter);
      in->last_start_ns = start;
      tx_hist_add(&in->step_time, tx_instance_step(s, in, at));
    }
    prev_start = start;
    prev_k = k;
    // a step's deadline is the next tick's release. A late tick still runs,
    // at once, while part of its period is left; one whose whole period is
    // over is skipped, and counts as missed too (not after a single step's catch-up)
    int64_t done = tx_mono_ns();
    uint64_t next = k + 1;
    uint64_t missed = done - t0 > tx_tick_ns(g->rate_hz, next);
    while (tx_tick_ns(g->rate_hz, next + 1) <= done - t0) next++, missed++;
    for (int m = 0; m < g->count; m++) {
      instance* in = s->inst[g->members[m]];
      if (missed && !catch_up) in->missed += missed;
      atomic_store_explicit(&in->live_missed, in->missed, memory_order_relaxed);
      atomic_store_explicit(&in->live_jitter_ns, k ? (jitter < 0 ? -jitter : jitter) : 0, memory_order_relaxed);
    }
    k = next;
  }
  for (int m = 0; m < g->count && w->init_rc == 0; m++) tx_instance_finish(s->inst[g->members[m]]);
  return NULL;
}

// Keeps one CPU from halting while the run lasts. A halted CPU wakes late for
// the next timer, and under a hypervisor a halted virtual CPU may wait
// milliseconds to be scheduled again; a spinner in SCHED_IDLE, the lowest
// class, holds it running and yields to every other thread at once.
typedef struct spinner {
  pthread_t thread;
  int cpu;
  _Atomic bool* stop;
} spinner;

static void* spinner_main(void* arg) {
  spinner* sp = arg;
  struct sched_param none = {0};
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(sp->cpu, &set);
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &none) != 0 ||
      pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0)
    return NULL;
  pthread_setname_np(pthread_self(), "tx-awake");
  while (!atomic_load_explicit(sp->stop, memory_order_relaxed)) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  return NULL;
}

// CPU time taken by the hypervisor so far, all CPUs, in seconds; -1 if unknown
static double steal_seconds(void) {
  FILE* f = fopen("/proc/stat", "r");
  if (!f) return -1;
  unsigned long long v[8] = {0};
  int n = fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]);
  fclose(f);
  long hz = sysconf(_SC_CLK_TCK);
  return n == 8 && hz > 0 ? (double)v[7] / (double)hz : -1;
}

static int usable_cpus(int* cpus, int max) {
  cpu_set_t set;
  int n = 0;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return 0;
  for (int c = 0; c < CPU_SETSIZE && n < max; c++)
    if (CPU_ISSET(c, &set)) cpus[n++] = c;
  return n;
}

static void describe_scheduling(const worker* w, int n, bool fifo_wanted, tx_run_result* r) {
  int fifo_err = 0, pin_err = 0, fifo_asked = 0, pin_asked = 0;
  for (int i = 0; i < n; i++) {
    fifo_asked += w[i].priority > 0;
    pin_asked += w[i].cpu >= 0;
    if (w[i].priority > 0 && w[i].fifo_error) fifo_err = w[i].fifo_error;
    if (w[i].cpu >= 0 && w[i].pin_error) pin_err = w[i].pin_error;
  }
  r->fifo = fifo_wanted && !fifo_err; // every thread the policy puts on SCHED_FIFO has it
  r->pinned = pin_asked && !pin_err;
  char fifo[128], pin[96];
  if (!fifo_wanted) snprintf(fifo, sizeof fifo, "SCHED_OTHER (SCHED_FIFO not asked for)");
  else if (fifo_err) snprintf(fifo, sizeof fifo, "SCHED_OTHER (SCHED_FIFO refused: %s)", strerror(fifo_err));
  else if (!fifo_asked) snprintf(fifo, sizeof fifo, "SCHED_OTHER (no haptics and no loop of %.0f Hz or more)", TX_FIFO_MIN_HZ);
  else snprintf(fifo, sizeof fifo, "SCHED_FIFO, haptics highest, then the loops of %.0f Hz and more by rate; slower SCHED_OTHER", TX_FIFO_MIN_HZ);
  if (!pin_asked) snprintf(pin, sizeof pin, "not pinned");
  else if (pin_err) snprintf(pin, sizeof pin, "not pinned (refused: %s)", strerror(pin_err));
  else snprintf(pin, sizeof pin, "those pinned round-robin, slower threads on any CPU");
  size_t len = (size_t)snprintf(r->scheduler, sizeof r->scheduler, "%d threads; %s; %s", n, fifo, pin);
  if (r->awake_cpus && len < sizeof r->scheduler)
    snprintf(r->scheduler + len, sizeof r->scheduler - len, "; %d CPUs kept awake", r->awake_cpus);
}

int tx_run_realtime(tx_system* s, const tx_run_options* o, tx_run_result* r) {
  const int ng = s->nthreads;
  worker* w = calloc(ng, sizeof *w);
  pthread_t* th = calloc(ng, sizeof *th);
  if (!w || !th) {
    free(w), free(th);
    return tx_set_error("out of memory"), -1;
  }
  gate gt = {.mutex = PTHREAD_MUTEX_INITIALIZER, .cond = PTHREAD_COND_INITIALIZER};
  _Atomic bool stop = false;
  int cpus[CPU_SETSIZE];
  int ncpu = o->pin_threads ? usable_cpus(cpus, CPU_SETSIZE) : 0;
  int prio_max = sched_get_priority_max(SCHED_FIFO), prio_min = sched_get_priority_min(SCHED_FIFO);

  // spinners first, so the CPUs are awake before the first tick
  int all[CPU_SETSIZE];
  int nall = o->keep_cpus_awake ? usable_cpus(all, CPU_SETSIZE) : 0;
  _Atomic bool spinners_stop = false;
  spinner* spinners = nall ? calloc(nall, sizeof *spinners) : NULL;
  int nspin = 0;
  for (int i = 0; spinners && i < nall; i++) {
    spinners[nspin] = (spinner){.cpu = all[i], .stop = &spinners_stop};
    if (pthread_create(&spinners[nspin].thread, NULL, spinner_main, &spinners[nspin]) == 0) nspin++;
  }

  // the last CPU is the haptics thread's: a process without one (a
  // session's sim, on the device's host) starts on the CPU before it
  int skip = 1, pinned = 0;
  for (int g = 0; g < ng; g++) skip &= !s->threads[g].own;
  int rc = 0, started = 0;
  for (int g = 0; g < ng; g++) {
    // leave the top for the kernel's own threads; haptics just below, alone
    int prio = s->threads[g].own ? prio_max - 10 : prio_max - 12 - 2 * s->threads[g].rank;
    bool fast = s->threads[g].own || s->threads[g].rate_hz >= TX_FIFO_MIN_HZ; // the haptic loop: FIFO and pinned
    w[g] = (worker){.sys = s, .group = g, .gate = &gt, .stop = &stop,
                    .cpu = ncpu > 0 && fast ? cpus[(ncpu - 1) - ((pinned++ + skip) % ncpu)] : -1,
                    .priority = o->realtime_priority && fast ? (prio < prio_min ? prio_min : prio) : 0};
    if (pthread_create(&th[g], NULL, worker_main, &w[g]) != 0) {
      rc = -1;
      tx_set_error("could not start thread %d of %d", g + 1, ng);
      break;
    }
    started++;
  }

  // wait for every init, then open the gate with a common t0
  pthread_mutex_lock(&gt.mutex);
  while (gt.ready < started) pthread_cond_wait(&gt.cond, &gt.mutex);
  for (int g = 0; g < started && rc == 0; g++)
    if (w[g].init_rc) rc = -1, tx_set_error("%s", w[g].init_err);
  if (rc) atomic_store(&stop, true), gt.failed = true;
  // every first release lies in the future; spun-up CPUs get time to be
  // running on the host before the first tick
  gt.t0 = tx_mono_ns() + (nspin ? 100000000 : 2000000);
  double steal_start = steal_seconds();
  const int64_t end_sim = (int64_t)(o->duration_s * 1e9);
  gt.end_sim = end_sim;
  atomic_store(&s->clock.t0, gt.t0);
  gt.open = true;
  pthread_cond_broadcast(&gt.cond);
  pthread_mutex_unlock(&gt.mutex);

  while (rc == 0 && !atomic_load(&stop) && !tx_system_halted(s)) {
    int64_t now = tx_mono_ns();
    tx_clock_state cs = tx_clock_read(&s->clock);
    int64_t sim = tx_clock_sim(&cs, now - gt.t0);
    if (sim >= end_sim) break;
    // the wall time at which the clock reaches the end, if it keeps its pace
    int64_t wake = now + 100000000;
    if (!cs.paused) {
      double left = (double)(end_sim - sim) / cs.scale;
      if (left < 100000000) wake = now + (int64_t)ceil(left);
    }
    sleep_until(wake);
    cs = tx_clock_read(&s->clock);
    if (o->progress && !o->progress((double)tx_clock_sim(&cs, tx_mono_ns() - gt.t0) * 1e-9, o->progress_user)) {
      r->stopped_early = true;
      atomic_store(&stop, true);
    }
  }
  for (int g = 0; g < started; g++) pthread_join(th[g], NULL);
  int64_t finish = tx_mono_ns();
  atomic_store(&spinners_stop, true);
  for (int i = 0; i < nspin; i++) pthread_join(spinners[i].thread, NULL);
  free(spinners);
  r->awake_cpus = nspin;
  double steal_end = steal_seconds();
  r->steal_s = steal_start >= 0 && steal_end >= 0 ? steal_end - steal_start : -1;
  tx_clock_state cs = tx_clock_read(&s->clock);
  int64_t reached = tx_clock_sim(&cs, finish - gt.t0);
  r->duration_s = (double)(reached < end_sim ? reached : end_sim) * 1e-9; // simulation time reached
  describe_scheduling(w, started, o->realtime_priority, r);
  free(w);
  free(th);
  return rc;
}
