// Run control: pause, resume, single step, reset and the time scale.
//
// Two kinds of instance: *live* ones (haptics, on threads of their own, and
// views) step on every tick of their thread, so the device loop never stops
// and the window keeps drawing; *simulated* ones (every other controller) step
// on the simulation clock, which a pause stops, a step advances, and the time
// scale slows. A reset rebuilds every simulated instance on its own thread
// (fini, configure with the same parameters, init) and restores what it writes
// as it was after its first init; live instances keep their state (the
// device, its recording, the window). See docs/trainer.md.
#include "system_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tx_clock_init(tx_clock* c) {
  pthread_mutex_init(&c->mutex, NULL);
  pthread_condattr_t a;
  pthread_condattr_init(&a);
  pthread_condattr_setclock(&a, CLOCK_MONOTONIC);
  pthread_cond_init(&c->cond, &a);
  pthread_condattr_destroy(&a);
  atomic_init(&c->scale, 1.0);
}

void tx_clock_destroy(tx_clock* c) {
  pthread_mutex_destroy(&c->mutex);
  pthread_cond_destroy(&c->cond);
}

// the fields as they are: for the writer, under the mutex
static tx_clock_state raw(tx_clock* c) {
  return (tx_clock_state){atomic_load_explicit(&c->anchor_wall, memory_order_relaxed),
                          atomic_load_explicit(&c->anchor_sim, memory_order_relaxed),
                          atomic_load_explicit(&c->scale, memory_order_relaxed),
                          atomic_load_explicit(&c->paused, memory_order_relaxed)};
}

tx_clock_state tx_clock_read(tx_clock* c) {
  tx_clock_state st;
  for (;;) {
    uint64_t v = atomic_load_explicit(&c->version, memory_order_acquire);
    st.anchor_wall = atomic_load_explicit(&c->anchor_wall, memory_order_relaxed);
    st.anchor_sim = atomic_load_explicit(&c->anchor_sim, memory_order_relaxed);
    st.scale = atomic_load_explicit(&c->scale, memory_order_relaxed);
    st.paused = atomic_load_explicit(&c->paused, memory_order_relaxed);
    atomic_thread_fence(memory_order_acquire);
    if (!(v & 1) && atomic_load_explicit(&c->version, memory_order_relaxed) == v) return st;
  }
}

int64_t tx_clock_sim(const tx_clock_state* st, int64_t run_ns) {
  if (st->paused) return st->anchor_sim;
  int64_t d = run_ns - st->anchor_wall;
  if (d < 0) d = 0;
  if (st->scale != 1.0) d = (int64_t)llround((double)d * st->scale);
  return d > INT64_MAX - st->anchor_sim ? INT64_MAX : st->anchor_sim + d; // saturates: "never"
}

// the executor's time now
static int64_t run_now(tx_clock* c) {
  if (atomic_load(&c->lockstep)) return atomic_load(&c->now);
  int64_t t0 = atomic_load(&c->t0);
  return t0 ? tx_mono_ns() - t0 : 0;
}

static void write_begin(tx_clock* c) {
  pthread_mutex_lock(&c->mutex);
  atomic_fetch_add_explicit(&c->version, 1, memory_order_relaxed);
  atomic_thread_fence(memory_order_release);
}

static void write_end(tx_clock* c) {
  atomic_fetch_add_explicit(&c->version, 1, memory_order_release);
  pthread_cond_broadcast(&c->cond);
  pthread_mutex_unlock(&c->mutex);
}

// re-anchor at the executor's time now, so the simulation time stays continuous
static void reanchor(tx_clock* c) {
  tx_clock_state st = raw(c);
  int64_t now = run_now(c);
  atomic_store_explicit(&c->anchor_sim, tx_clock_sim(&st, now), memory_order_relaxed);
  atomic_store_explicit(&c->anchor_wall, now, memory_order_relaxed);
}

// one line in RECORD_DIR/controls.csv, beside the devices' recordings; 0, or -1 with tx_error()
static int log_control(tx_system* s, const char* action, double value) {
  const char* dir = atomic_load(&s->clock.running) ? s->record_dir : NULL;
  if (!dir) return 0;
  char path[4096];
  if (snprintf(path, sizeof path, "%s/controls.csv", dir) >= (int)sizeof path)
    return tx_set_error("%s/controls.csv: path too long", dir), -1;
  FILE* f = fopen(path, "a");
  if (!f) return tx_set_error("%s: %s", path, strerror(errno)), -1;
  tx_clock_state st = tx_clock_read(&s->clock);
  if (ftell(f) == 0) fprintf(f, "t_s,action,value\n");
  fprintf(f, "%.9f,%s,%.17g\n", (double)tx_clock_sim(&st, run_now(&s->clock)) * 1e-9, action, value);
  if (fclose(f) != 0) return tx_set_error("%s: %s", path, strerror(errno)), -1;
  return 0;
}

int tx_system_pause(tx_system* s) {
  tx_clock* c = &s->clock;
  write_begin(c);
  bool was = atomic_load_explicit(&c->paused, memory_order_relaxed);
  if (!was) {
    reanchor(c);
    atomic_store_explicit(&c->paused, true, memory_order_relaxed);
  }
  write_end(c);
  return was ? 0 : log_control(s, "pause", 0);
}

int tx_system_resume(tx_system* s) {
  tx_clock* c = &s->clock;
  write_begin(c);
  bool was = atomic_load_explicit(&c->paused, memory_order_relaxed);
  if (was) {
    atomic_store_explicit(&c->anchor_wall, run_now(c), memory_order_relaxed);
    atomic_store_explicit(&c->paused, false, memory_order_relaxed);
  }
  write_end(c);
  return was ? log_control(s, "resume", 0) : 0;
}

bool tx_system_paused(const tx_system* s) { return atomic_load(&((tx_system*)s)->clock.paused); }

double tx_system_step_period(const tx_system* s) {
  double slowest = 0;
  for (int i = 0; i < s->count; i++) {
    const instance* in = s->inst[i];
    if (tx_class_own_thread(in->cls) || in->cls->view) continue;
    if (slowest == 0 || in->rate_hz < slowest) slowest = in->rate_hz;
  }
  return slowest > 0 ? 1.0 / slowest : 0;
}

int tx_system_step(tx_system* s) {
  double period = tx_system_step_period(s);
  if (tx_system_pause(s)) return -1;
  if (period <= 0) return 0; // nothing simulated: nothing to advance
  tx_clock* c = &s->clock;
  write_begin(c);
  // to the slowest simulated instance's next tick: every simulated instance runs each of its ticks up to it
  double rate = 1.0 / period;
  int64_t at = atomic_load_explicit(&c->anchor_sim, memory_order_relaxed);
  uint64_t k = (uint64_t)floor((double)at * rate * 1e-9);
  while (k > 0 && tx_tick_ns(rate, k) > at) k--;
  while (tx_tick_ns(rate, k) <= at) k++;
  atomic_store_explicit(&c->anchor_sim, tx_tick_ns(rate, k), memory_order_relaxed);
  atomic_fetch_add(&c->steps, 1);
  write_end(c);
  return log_control(s, "step", period);
}

int tx_system_reset(tx_system* s) {
  atomic_fetch_add(&s->clock.resets, 1);
  pthread_mutex_lock(&s->clock.mutex);
  pthread_cond_broadcast(&s->clock.cond); // a paused lockstep run carries it out at once
  pthread_mutex_unlock(&s->clock.mutex);
  return log_control(s, "reset", 0);
}

uint64_t tx_system_resets(const tx_system* s) { return atomic_load(&((tx_system*)s)->clock.resets); }

uint64_t tx_system_resets_done(const tx_system* s) {
  uint64_t done = UINT64_MAX;
  for (int i = 0; i < s->count; i++) {
    const instance* in = s->inst[i];
    if (in->live) continue;
    uint64_t seen = atomic_load(&((instance*)in)->reset_done);
    if (seen < done) done = seen;
  }
  return done == UINT64_MAX ? tx_system_resets(s) : done;
}

int tx_system_set_time_scale(tx_system* s, double scale) {
  if (!(scale >= TX_TIME_SCALE_MIN && scale <= 1.0))
    return tx_set_error("time scale %g is out of range [%g, 1]", scale, TX_TIME_SCALE_MIN), -1;
  tx_clock* c = &s->clock;
  write_begin(c);
  reanchor(c);
  atomic_store_explicit(&c->scale, scale, memory_order_relaxed);
  write_end(c);
  return log_control(s, "time_scale", scale);
}

double tx_system_time_scale(const tx_system* s) { return atomic_load(&((tx_system*)s)->clock.scale); }

double tx_system_sim_time(const tx_system* s) {
  tx_clock* c = &((tx_system*)s)->clock;
  tx_clock_state st = tx_clock_read(c);
  return (double)tx_clock_sim(&st, run_now(c)) * 1e-9;
}

bool tx_param_live(const tx_controller_class* cls, const char* key) {
  for (int i = 0; cls->live && cls->live[i]; i++)
    if (strcmp(cls->live[i], key) == 0) return true;
  return false;
}

static _Atomic(tx_system*) running_system;
tx_system* tx_system_running(void) { return atomic_load(&running_system); }

tx_live_stats tx_system_live(const tx_system* s, int i) {
  instance* in = s->inst[i];
  return (tx_live_stats){atomic_load_explicit(&in->live_steps, memory_order_relaxed),
                         atomic_load_explicit(&in->live_missed, memory_order_relaxed),
                         atomic_load_explicit(&in->live_jitter_ns, memory_order_relaxed)};
}

void tx_control_start(tx_system* s, bool lockstep) {
  tx_clock* c = &s->clock;
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    in->live = tx_class_own_thread(in->cls) || in->cls->view;
    in->dead = false;
    in->sim_tick = 0;
    in->index = i;
    in->live_ns = -1;
    in->reset_seen = atomic_load(&c->resets); // a reset asked for before the run is the start itself
    atomic_store(&in->reset_done, in->reset_seen);
    atomic_store(&in->live_steps, 0);
    atomic_store(&in->live_missed, 0);
    atomic_store(&in->live_jitter_ns, 0);
  }
  s->clock_resets_seen = atomic_load(&c->resets);
  pthread_mutex_lock(&c->mutex);
  s->ntunes = 0; // tunes asked for before the run wait for it
  pthread_mutex_unlock(&c->mutex);
  write_begin(c);
  atomic_store_explicit(&c->anchor_wall, 0, memory_order_relaxed);
  atomic_store_explicit(&c->anchor_sim, 0, memory_order_relaxed);
  atomic_store(&c->now, 0);
  atomic_store(&c->t0, 0);
  atomic_store(&c->lockstep, lockstep);
  write_end(c);
  atomic_store(&c->running, true);
  atomic_store(&running_system, s);
}

void tx_control_end(tx_system* s) {
  tx_system* expected = s;
  atomic_compare_exchange_strong(&running_system, &expected, NULL);
  atomic_store(&s->clock.running, false);
  atomic_store(&s->clock.t0, 0);
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    free(in->initial);
    free(in->initial_rows);
    in->initial = NULL;
    in->initial_rows = NULL;
  }
}

bool tx_control_keep_initial(tx_system* s, instance* in) {
  if (in->live) return true;
  size_t total = 0;
  for (int p = 0; p < in->nports; p++)
    if (in->ports[p].write) total += tx_model_bytes(s->model, in->ports[p].comp);
  in->initial = malloc(total ? total : 1);
  in->initial_rows = calloc(in->nports ? in->nports : 1, sizeof *in->initial_rows);
  if (!in->initial || !in->initial_rows) return false;
  char* at = in->initial;
  for (int p = 0; p < in->nports; p++) {
    if (!in->ports[p].write) continue;
    size_t bytes = tx_model_bytes(s->model, in->ports[p].comp);
    tx_snapshot snap = tx_model_latest(s->model, in->ports[p].comp);
    // never published: its buffer as the model made it (zeros), at full capacity
    memcpy(at, snap.data ? snap.data : tx_model_back(s->model, in->ports[p].comp), bytes);
    in->initial_rows[p] = snap.seq ? snap.rows : tx_model_def(s->model, in->ports[p].comp)->rows;
    at += bytes;
  }
  return true;
}

static bool same_ports(const port* a, const port* b, int n) {
  for (int p = 0; p < n; p++) {
    if (a[p].write != b[p].write || a[p].kind != b[p].kind || strcmp(a[p].name, b[p].name) != 0) return false;
    if (a[p].write && (a[p].def.type != b[p].def.type || a[p].def.rows != b[p].def.rows ||
                       a[p].def.cols != b[p].def.cols || strcmp(a[p].units, b[p].units) != 0))
      return false;
  }
  return true;
}

// the rebuild failed: the instance steps no more and the run stops with the reason
static void rebuild_failed(instance* in, int64_t sim_ns, const char* why) {
  in->dead = true;
  in->ctx.sim_ns = sim_ns;
  tx_stop_run(&in->ctx, "reset: %s", why);
}

void tx_control_apply_reset(tx_system* s, instance* in, int64_t sim_ns) {
  uint64_t want = atomic_load(&s->clock.resets);
  if (in->live || in->dead || in->reset_seen == want) return;
  in->reset_seen = want;
  const int n = in->nports;
  port* saved = malloc((n ? n : 1) * sizeof *saved);
  if (!saved) {
    rebuild_failed(in, sim_ns, "out of memory");
    return;
  }
  memcpy(saved, in->ports, n * sizeof *saved);
  // a new instance from the same parameters: whatever the old one held is gone
  if (in->cls->fini) in->cls->fini(in->self);
  in->self = NULL;
  in->nports = 0;
  in->failed = false;
  int rc = in->cls->configure(&in->setup, &in->self);
  bool same = rc == 0 && !in->failed && in->nports == n && same_ports(saved, in->ports, n);
  char why[sizeof in->fault.message + 64];
  if (in->failed) snprintf(why, sizeof why, "configure failed: %s", in->fault.message);
  else snprintf(why, sizeof why, "configure %s", rc ? "failed" : "declared other ports than at the start");
  memcpy(in->ports, saved, n * sizeof *saved); // the model's ids and readers stay as finalize made them
  in->nports = n;
  free(saved);
  if (!same) {
    rebuild_failed(in, sim_ns, why);
    return;
  }
  // what it writes, as after its first init; then init again, which publishes over it
  const char* at = in->initial;
  for (int p = 0; p < n && at; p++) {
    port* pt = &in->ports[p];
    if (!pt->write) continue;
    size_t bytes = tx_model_bytes(s->model, pt->comp);
    memcpy(tx_model_back(s->model, pt->comp), at, bytes);
    tx_model_set_rows(s->model, pt->comp, in->initial_rows[p]);
    pt->dirty = true;
    at += bytes;
  }
  in->ctx.sim_ns = sim_ns;
  in->ctx.step = in->steps;
  if (in->cls->init && in->cls->init(&in->ctx, in->self) != 0) {
    tx_instance_publish(s, in, sim_ns);
    rebuild_failed(in, sim_ns, "init failed");
    return;
  }
  tx_instance_publish(s, in, sim_ns);
  atomic_store(&in->reset_done, want);
}

int tx_system_tune(tx_system* s, int i, const char* key, double value) {
  if (i < 0 || i >= s->count) return tx_set_error("no controller %d", i), -1;
  instance* in = s->inst[i];
  const tx_controller_class* cls = in->cls;
  int p = 0;
  while (p < cls->nparams && strcmp(cls->params[p].key, key ? key : "") != 0) p++;
  if (!cls->params || p == cls->nparams) return tx_set_error("%s (%s) has no parameter '%s'", in->name, cls->type, key ? key : ""), -1;
  const tx_param_def* d = &cls->params[p];
  if (!tx_param_live(cls, key)) return tx_set_error("%s.%s cannot change during a run", in->name, key), -1;
  bool ok = d->kind == TX_PARAM_BOOL ? (value == 0 || value == 1)
                                     : value >= d->min && value <= d->max && (d->kind != TX_PARAM_INT || value == floor(value));
  if (!ok) {
    if (d->kind == TX_PARAM_BOOL) return tx_set_error("%s.%s: %g is not 0 or 1", in->name, key, value), -1;
    return tx_set_error("%s.%s: %g is out of range [%g, %g]%s", in->name, key, value, d->min, d->max,
                        d->kind == TX_PARAM_INT ? " or not whole" : ""), -1;
  }
  pthread_mutex_lock(&s->clock.mutex);
  int n = s->ntunes_pending;
  if (n < TX_TUNES_PENDING) {
    s->tunes_pending[s->ntunes_pending++] = (tune_entry){i, p, value, 0};
    atomic_fetch_add(&in->tune_pending, 1);
  }
  pthread_mutex_unlock(&s->clock.mutex);
  if (n == TX_TUNES_PENDING) return tx_set_error("%d changes are already waiting", TX_TUNES_PENDING), -1;
  char what[2 * TX_NAME_MAX + 16];
  snprintf(what, sizeof what, "tune %s.%s", in->name, key);
  return log_control(s, what, value);
}

void tx_control_apply_tunes(tx_system* s, instance* in, int64_t sim_ns) {
  if (!atomic_load_explicit(&in->tune_pending, memory_order_acquire) || in->dead) return;
  if (pthread_mutex_trylock(&s->clock.mutex) != 0) return; // the haptics thread never waits: next tick
  int kept = 0;
  for (int k = 0; k < s->ntunes_pending; k++) {
    tune_entry e = s->tunes_pending[k];
    if (e.inst != in->index) {
      s->tunes_pending[kept++] = e;
      continue;
    }
    in->ctx.sim_ns = sim_ns;
    in->cls->tune(&in->ctx, in->self, in->cls->params[e.param].key, e.value);
    e.t_s = (double)sim_ns * 1e-9;
    if (s->ntunes < TX_TUNES_MAX) s->tunes[s->ntunes++] = e;
    atomic_fetch_sub(&in->tune_pending, 1);
  }
  s->ntunes_pending = kept;
  pthread_mutex_unlock(&s->clock.mutex);
}

int tx_system_tunes(tx_system* s) {
  pthread_mutex_lock(&s->clock.mutex);
  int n = s->ntunes;
  pthread_mutex_unlock(&s->clock.mutex);
  return n;
}

tx_tune_info tx_system_tune_at(tx_system* s, int k) {
  pthread_mutex_lock(&s->clock.mutex);
  tune_entry e = s->tunes[k];
  pthread_mutex_unlock(&s->clock.mutex);
  const instance* in = s->inst[e.inst];
  return (tx_tune_info){e.t_s, in->name, in->cls->params[e.param].key, e.value};
}
