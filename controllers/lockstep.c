// Lockstep executor: every controller on this thread, on a virtual clock.
//
// The next step is always the earliest pending tick. At equal times the slower
// group goes first, so that a fast consumer sees what a slow producer (physics)
// published at the same instant; within a group, scenario order. Nothing the
// controllers see depends on wall time, so two runs give bit-identical traces;
// wall time only paces the progress calls, so that a stop request is never kept
// waiting by a slow step or a clock that hardly moves.
//
// Run control (system_control.c): a pause stops every instance, haptics
// included (nothing here is real time), until a resume or a single step; a
// reset rebuilds the simulated instances before the next tick, in scenario
// order. The time scale does not apply: nothing here follows the wall clock.
#include "system_internal.h"

#include <stdlib.h>
#include <time.h>

// paused: wait for a control call, or 100 ms of wall time for the progress call
static void wait_paused(tx_system* s) {
  tx_clock* c = &s->clock;
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  ts.tv_nsec += 100000000;
  if (ts.tv_nsec >= 1000000000) ts.tv_sec++, ts.tv_nsec -= 1000000000;
  pthread_mutex_lock(&c->mutex);
  uint64_t resets = atomic_load(&c->resets), version = atomic_load(&c->version);
  while (atomic_load(&c->version) == version && atomic_load(&c->resets) == resets &&
         pthread_cond_timedwait(&c->cond, &c->mutex, &ts) == 0) {}
  pthread_mutex_unlock(&c->mutex);
}

int tx_run_lockstep(tx_system* s, const tx_run_options* o, tx_run_result* r) {
  s->tracing = true;
  s->trace = o->trace;
  s->trace_name = o->trace_name;
  s->trace_hash = TX_HASH_SEED;
  int rc = 0;
  for (int i = 0; i < s->count && rc == 0; i++) {
    rc = tx_instance_init(s, s->inst[i]);
    if (rc == 0 && !tx_control_keep_initial(s, s->inst[i])) rc = -1, tx_set_error("out of memory for %s's initial state", s->inst[i]->name);
  }

  uint64_t* next = calloc(s->ngroups, sizeof *next);
  if (!next && rc == 0) rc = -1, tx_set_error("out of memory");
  const int64_t end_ns = (int64_t)(o->duration_s * 1e9);
  int64_t last_progress = 0, last_wall = tx_mono_ns(), reached = end_ns;
  while (rc == 0) {
    int g = -1;
    int64_t t = 0;
    for (int k = s->ngroups - 1; k >= 0; k--) { // slowest first wins ties
      int64_t tk = tx_tick_ns(s->groups[k].rate_hz, next[k]);
      if (g < 0 || tk < t) g = k, t = tk;
    }
    if (t >= end_ns || tx_system_halted(s)) {
      if (t < end_ns) reached = t;
      break;
    }
    // a reset first, at the time of the tick that comes next
    if (atomic_load(&s->clock.resets) != s->clock_resets_seen) {
      s->clock_resets_seen = atomic_load(&s->clock.resets);
      for (int i = 0; i < s->count; i++) tx_control_apply_reset(s, s->inst[i], t);
      continue;
    }
    tx_clock_state cs = tx_clock_read(&s->clock);
    if (cs.paused && t > cs.anchor_sim) { // the clock stands before this tick: wait, and still ask progress
      wait_paused(s);
      int64_t now = tx_mono_ns();
      if (o->progress && now - last_wall >= 100000000) {
        last_wall = now;
        if (!o->progress((double)cs.anchor_sim * 1e-9, o->progress_user)) {
          r->stopped_early = true;
          reached = cs.anchor_sim;
          break;
        }
      }
      continue;
    }
    atomic_store(&s->clock.now, t);
    for (int m = 0; m < s->groups[g].count; m++) {
      instance* in = s->inst[s->groups[g].members[m]];
      if (in->dead) continue;
      tx_control_apply_tunes(s, in, t);
      if (in->steps == 0) in->first_start_ns = t;
      in->last_start_ns = t;
      tx_hist_add(&in->step_time, tx_instance_step(s, in, t));
      tx_hist_add(&in->jitter, 0);
    }
    next[g]++;
    // every 100 ms of simulated time, or of wall time: a slow step, or a clock
    // that hardly moves, must not keep a stop request waiting
    if (!o->progress) continue;
    int64_t now = tx_mono_ns(); // cheap beside a step, which reads it twice
    if (t - last_progress >= 100000000 || now - last_wall >= 100000000) {
      last_progress = t;
      last_wall = now;
      if (!o->progress((double)t * 1e-9, o->progress_user)) {
        r->stopped_early = true;
        reached = t;
        break;
      }
    }
  }
  free(next);
  for (int i = 0; i < s->count && rc == 0; i++) tx_instance_finish(s->inst[i]);
  r->duration_s = (double)reached * 1e-9; // simulated time reached: all of it, unless stopped
  r->trace_hash = s->trace_hash;
  snprintf(r->scheduler, sizeof r->scheduler, "lockstep: one thread, virtual clock");
  s->tracing = false;
  s->trace = NULL;
  return rc;
}
