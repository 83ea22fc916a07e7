// Run-time API of a controller, and one step of an instance with its publishes.
#include "system_internal.h"

#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static port* port_of(tx_ctx* c, tx_port p, bool write) {
  if (p.id < 1 || p.id > c->in->nports) return NULL;
  port* pt = &c->in->ports[p.id - 1];
  return pt->write == write && pt->kind == PORT_COMPONENT ? pt : NULL;
}

// a write to a port the instance never declared: a bug in the controller.
// Counted and the run stopped with the reason, never a silent NULL; no
// allocation here (tx_stop_run formats on the stack), so the haptic path stays safe.
static port* write_port(tx_ctx* c, tx_port p, const char* call) {
  port* pt = port_of(c, p, true);
  if (pt) return pt;
  tx_warn(c, c->in->bad_port);
  if (p.id >= 1 && p.id <= c->in->nports)
    tx_stop_run(c, "%s on port %u ('%s'), which it declared as a read, not a write", call, p.id,
                c->in->ports[p.id - 1].name);
  else
    tx_stop_run(c, "%s on port %u, which it never declared (it has %d ports)", call, p.id, c->in->nports);
  return NULL;
}

tx_snapshot tx_read(tx_ctx* c, tx_port p) {
  port* pt = port_of(c, p, false);
  return pt ? tx_model_acquire(c->sys->model, pt->reader) : (tx_snapshot){0};
}

void* tx_write(tx_ctx* c, tx_port p) {
  port* pt = write_port(c, p, "tx_write");
  if (!pt) return NULL;
  pt->dirty = true;
  return tx_model_back(c->sys->model, pt->comp);
}

void* tx_write_copy(tx_ctx* c, tx_port p) {
  port* pt = write_port(c, p, "tx_write_copy");
  if (!pt) return NULL;
  pt->dirty = true;
  return tx_model_back_copy(c->sys->model, pt->comp);
}

void tx_write_rows(tx_ctx* c, tx_port p, uint32_t rows) {
  port* pt = write_port(c, p, "tx_write_rows");
  if (!pt) return;
  if (rows > pt->def.rows) { // the rest would be lost without a word
    tx_warn(c, c->in->rows_clamped);
    tx_stop_run(c, "tx_write_rows(%u) on '%s', beyond its capacity of %u rows", rows, pt->name, pt->def.rows);
  }
  tx_model_set_rows(c->sys->model, pt->comp, rows); // still clamped, so no reader looks past the buffer
}

const tx_component_def* tx_port_schema(tx_ctx* c, tx_port p) {
  if (p.id < 1 || p.id > c->in->nports || c->in->ports[p.id - 1].kind != PORT_COMPONENT) return NULL;
  return tx_model_def(c->sys->model, c->in->ports[p.id - 1].comp);
}

int64_t tx_sim_ns(const tx_ctx* c) { return c->sim_ns; }
const char* tx_record_dir(const tx_ctx* c) { return c->sys->record_dir; }
const char* tx_output_dir(const tx_ctx* c) { return c->sys->out_dir; }

// read after the run, once every thread has joined
void tx_set_result(tx_ctx* c, tx_result r, double value) {
  if (r.id >= 1 && r.id <= c->sys->nresults) c->sys->result_values[r.id - 1] = value;
}
uint64_t tx_step_index(const tx_ctx* c) { return c->step; }
double tx_rate(const tx_ctx* c) { return c->in->rate_hz; }

void tx_warn(tx_ctx* c, tx_warning w) {
  if (w.id >= 1 && w.id <= c->sys->nwarnings)
    atomic_fetch_add_explicit(&c->sys->warning_counts[w.id - 1], 1, memory_order_relaxed);
}

// the first reason wins; who gives it is the prefix ("INSTANCE" or the file)
static void stop_run(tx_system* s, int64_t sim_ns, const char* who, const char* reason) {
  int expected = 0;
  if (!atomic_compare_exchange_strong(&s->halt_claim, &expected, 1)) return;
  snprintf(s->halt_reason, sizeof s->halt_reason, "%s: %s", who, reason ? reason : "stopped");
  s->halt_sim_ns = sim_ns;
  atomic_store_explicit(&s->halt, true, memory_order_release);
}

void tx_stop_run(tx_ctx* c, const char* fmt, ...) {
  if (atomic_load_explicit(&c->sys->halt_claim, memory_order_relaxed)) return; // the first reason wins
  char reason[sizeof c->sys->halt_reason - TX_NAME_MAX - 2]; // room for "INSTANCE: "
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(reason, sizeof reason, fmt, ap);
  va_end(ap);
  stop_run(c->sys, c->sim_ns, c->in->name, reason);
}

static void trace_publish(tx_system* s, const instance* in, const port* pt) {
  tx_snapshot snap = tx_model_latest(s->model, pt->comp);
  const tx_component_def* def = tx_model_def(s->model, pt->comp);
  uint64_t h = tx_hash(TX_HASH_SEED, snap.data, (size_t)snap.rows * def->cols * tx_type_size(def->type));
  uint64_t stamp[3] = {(uint64_t)snap.sim_ns, snap.seq, h};
  s->trace_hash = tx_hash(s->trace_hash, stamp, sizeof stamp);
  // a write error (a full disk) stops the run now, not after the whole duration
  if (s->trace && fprintf(s->trace, "%" PRId64 ",%s,%s,%" PRIu64 ",%u,%016" PRIx64 "\n", snap.sim_ns, in->name,
                          pt->name, snap.seq, snap.rows, h) < 0) {
    stop_run(s, snap.sim_ns, s->trace_name ? s->trace_name : "trace", strerror(errno ? errno : EIO));
    s->trace = NULL;
  }
}

// an event port of this kind, or NULL: a misuse is counted and stops the run, as for tx_write
static port* event_port(tx_ctx* c, tx_port p, port_kind kind, const char* call) {
  if (p.id >= 1 && p.id <= c->in->nports && c->in->ports[p.id - 1].kind == kind) return &c->in->ports[p.id - 1];
  tx_warn(c, c->in->bad_port);
  tx_stop_run(c, "%s on port %u, which it did not declare with %s", call, p.id,
              kind == PORT_EMIT ? "tx_setup_emit" : "tx_setup_listen");
  return NULL;
}

uint64_t tx_emit(tx_ctx* c, tx_port p, const tx_event* e) {
  port* pt = event_port(c, p, PORT_EMIT, "tx_emit");
  if (!pt || !e) return 0;
  tx_system* s = c->sys;
  tx_event ev = *e;
  ev.sim_ns = c->sim_ns;
  uint64_t seq = tx_stream_push(s->streams[pt->stream].stream, &ev);
  if (s->tracing) { // lockstep: every event sent is part of the run's hash, a dropped one as seq 0
    ev.seq = seq;
    uint64_t h = tx_hash(TX_HASH_SEED, &ev, sizeof ev);
    uint64_t stamp[3] = {(uint64_t)ev.sim_ns, seq, h};
    s->trace_hash = tx_hash(s->trace_hash, stamp, sizeof stamp);
    if (s->trace && fprintf(s->trace, "%" PRId64 ",%s,%s,%" PRIu64 ",event,%016" PRIx64 "\n", ev.sim_ns, c->in->name,
                            pt->name, seq, h) < 0) {
      stop_run(s, ev.sim_ns, s->trace_name ? s->trace_name : "trace", strerror(errno ? errno : EIO));
      s->trace = NULL;
    }
  }
  return seq;
}

bool tx_next_event(tx_ctx* c, tx_port p, tx_event* out) {
  port* pt = event_port(c, p, PORT_LISTEN, "tx_next_event");
  return pt && out && tx_stream_next(c->sys->streams[pt->stream].stream, pt->listener, out);
}

// the swap-buffer step: publish every component the instance wrote
static void publish_written(tx_system* s, instance* in, int64_t sim_ns) {
  for (int p = 0; p < in->nports; p++) {
    port* pt = &in->ports[p];
    if (!pt->dirty) continue;
    pt->dirty = false;
    tx_model_publish(s->model, pt->comp, sim_ns);
    if (s->tracing) trace_publish(s, in, pt);
  }
}

int64_t tx_instance_step(tx_system* s, instance* in, int64_t sim_ns) {
  int64_t t0 = tx_mono_ns();
  in->ctx.sim_ns = sim_ns;
  in->ctx.step = in->steps;
  in->cls->step(&in->ctx, in->self);
  publish_written(s, in, sim_ns);
  in->steps++;
  atomic_store_explicit(&in->live_steps, in->steps, memory_order_relaxed);
  return tx_mono_ns() - t0;
}

void tx_instance_finish(instance* in) {
  if (in->cls->finish) in->cls->finish(&in->ctx, in->self);
}

int tx_instance_init(tx_system* s, instance* in) {
  in->ctx.sim_ns = 0;
  in->ctx.step = 0;
  if (!in->cls->init) return 0;
  if (in->cls->init(&in->ctx, in->self) != 0) {
    // a reason given with tx_stop_run is the one to report
    if (tx_system_halted(s)) return tx_set_error("%s", s->halt_reason), -1;
    return tx_set_error("controller '%s' failed to initialise", in->name), -1;
  }
  publish_written(s, in, 0); // what init wrote is the first publish, at time 0
  return 0;
}

void tx_instance_publish(tx_system* s, instance* in, int64_t sim_ns) { publish_written(s, in, sim_ns); }
