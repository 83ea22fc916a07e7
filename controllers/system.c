// A controller system: instances of one scenario, checked and wired to a model.
#include "system_internal.h"

#include "../model/error.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

// a configuration error at KEY: tx_error() and tx_error_key(), and -1
#define fault(key, ...) (tx_set_error_at(key, __VA_ARGS__), -1)
// an instance's first tx_setup_fail, as the error of the call that configured it
#define setup_fault(in) (tx_set_error_at((in)->fault.key, "%s", (in)->fault.message), -1)

tx_system* tx_system_create(void) {
  tx_system* s = calloc(1, sizeof(tx_system));
  if (s) tx_clock_init(&s->clock);
  return s;
}

void tx_system_destroy(tx_system* s) {
  if (!s) return;
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    if (in->configured && in->cls->fini) in->cls->fini(in->self);
    json_decref(in->params);
    json_decref(in->used);
    json_decref(in->strings);
    free(in);
  }
  for (int g = 0; g < s->ngroups; g++) free(s->groups[g].members);
  free(s->groups);
  for (int t = 0; t < s->nthreads; t++) free(s->threads[t].members);
  free(s->threads);
  for (int k = 0; k < s->nstreams; k++) tx_stream_destroy(s->streams[k].stream);
  free(s->streams);
  free(s->inst);
  free(s->declared);
  free(s->declared_names);
  free(s->declared_units);
  tx_model_destroy(s->model);
  tx_clock_destroy(&s->clock);
  free(s);
}

static const tx_component_def* declared(const tx_system* s, const char* name) {
  for (int i = 0; i < s->ndeclared; i++)
    if (strcmp(s->declared[i].name, name) == 0) return &s->declared[i];
  return NULL;
}

int tx_system_declare(tx_system* s, const tx_component_def* def) {
  if (!def->name || !*def->name || strlen(def->name) >= TX_NAME_MAX) return fault("name", "empty or too long");
  if (declared(s, def->name)) return fault("name", "component '%s' is declared twice", def->name);
  const char* units = def->units ? def->units : "1";
  if (strlen(units) >= TX_UNITS_MAX) return fault("units", "'%s' is too long", units);
  int n = s->ndeclared + 1;
  tx_component_def* d = realloc(s->declared, n * sizeof *d);
  if (d) s->declared = d;
  char(*names)[TX_NAME_MAX] = realloc(s->declared_names, n * sizeof *names);
  if (names) s->declared_names = names;
  char(*units_)[TX_UNITS_MAX] = realloc(s->declared_units, n * sizeof *units_);
  if (units_) s->declared_units = units_;
  if (!d || !names || !units_) return fault("", "out of memory");
  strcpy(s->declared_names[s->ndeclared], def->name);
  strcpy(s->declared_units[s->ndeclared], units);
  s->ndeclared = n;
  // names and units are re-pointed in finalize, after the last realloc
  s->declared[n - 1] = *def;
  return 0;
}

static bool valid_instance_name(const char* s) {
  if (!s || !*s || strlen(s) >= TX_NAME_MAX) return false;
  for (; *s; s++)
    if (!((*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '_' || *s == '-')) return false;
  return true;
}

int tx_system_add(tx_system* s, const char* name, const char* type, double rate_hz, json_t* params) {
  if (!valid_instance_name(name)) return fault("name", "'%s' must be 1-%d characters of a-z 0-9 _ -", name ? name : "", TX_NAME_MAX - 1);
  for (int i = 0; i < s->count; i++)
    if (strcmp(s->inst[i]->name, name) == 0) return fault("name", "a controller named '%s' already exists", name);
  const tx_controller_class* cls = tx_find_controller(type);
  if (!cls) return fault("type", "unknown controller type '%s'", type ? type : "");
  if (!(rate_hz >= TX_RATE_MIN_HZ && rate_hz <= TX_RATE_MAX_HZ))
    return fault("rate_hz", "%g Hz is out of range [%g, %g]", rate_hz, TX_RATE_MIN_HZ, TX_RATE_MAX_HZ);
  if (params && !json_is_object(params)) return fault("params", "expected an object");

  instance** grown = realloc(s->inst, (s->count + 1) * sizeof *grown);
  if (!grown) return fault("", "out of memory");
  s->inst = grown;
  instance* in = calloc(1, sizeof *in);
  if (!in) return fault("", "out of memory");
  s->inst[s->count++] = in;
  strcpy(in->name, name);
  in->cls = cls;
  in->rate_hz = rate_hz;
  in->params = json_incref(params);
  in->used = json_object();
  in->strings = json_array();
  in->setup = (tx_setup){s, in};
  in->ctx = (tx_ctx){s, in, 0, 0};
  if (!in->used || !in->strings) return fault("", "out of memory");

  const char* key;
  json_t* value;
  // with a table, a key it lacks is refused before configure runs, naming the valid keys
  if (cls->params && params) json_object_foreach(params, key, value) {
    if (tx_param_find(cls, key)) continue;
    char known[640] = "", where[128];
    for (int k = 0; k < cls->nparams; k++) {
      size_t len = strlen(known);
      snprintf(known + len, sizeof known - len, "%s%s", k ? ", " : "", cls->params[k].key);
    }
    snprintf(where, sizeof where, "params.%s", key);
    return fault(where, "unknown parameter for %s (valid: %s)", type, cls->nparams ? known : "none");
  }

  int rc = cls->configure(&in->setup, &in->self);
  in->configured = true; // fini frees whatever configure made, even on failure
  if (in->failed) return setup_fault(in);
  if (rc != 0) return fault("", "controller '%s' (%s) failed to configure", name, type);
  // a view only reads: any write it declared is refused, by name
  if (cls->view)
    for (int p = 0; p < in->nports; p++)
      if (in->ports[p].write)
        return fault("type", "controller '%s' (%s) is a view and may not write '%s'", name, type, in->ports[p].name);
  // without a table, every parameter in the scenario must be one configure asked for
  if (params && !cls->params) json_object_foreach(params, key, value) {
    if (json_object_get(in->used, key)) continue;
    char known[256] = "";
    const char* k;
    json_t* v;
    json_object_foreach(in->used, k, v) {
      size_t len = strlen(known);
      snprintf(known + len, sizeof known - len, "%s%s", len ? ", " : "", k);
    }
    char where[128];
    snprintf(where, sizeof where, "params.%s", key);
    return fault(where, "unknown parameter for %s (known: %s)", type, *known ? known : "none");
  }
  return 0;
}

bool tx_class_own_thread(const tx_controller_class* cls) {
  return cls->own_thread || strncmp(cls->type, "haptics", 7) == 0;
}

int tx_system_set_thread(tx_system* s, int i, const char* name) {
  instance* in = s->inst[i];
  if (!name || !*name || strlen(name) >= TX_THREAD_NAME_MAX) goto bad;
  for (const char* c = name; *c; c++)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_' || *c == '-')) goto bad;
  for (int j = 0; j < s->count; j++) {
    const instance* o = s->inst[j];
    if (j == i || strcmp(o->thread_name, name) != 0) continue;
    if (o->rate_hz != in->rate_hz)
      return fault("thread", "'%s' runs %s at %g Hz; %s at %g Hz cannot share it (one thread, one rate)", name,
                   o->name, o->rate_hz, in->name, in->rate_hz);
    if (tx_class_own_thread(o->cls) || tx_class_own_thread(in->cls))
      return fault("thread", "'%s' is the thread of %s (%s), which runs alone: %s cannot share it", name,
                   tx_class_own_thread(o->cls) ? o->name : in->name,
                   tx_class_own_thread(o->cls) ? o->cls->type : in->cls->type,
                   tx_class_own_thread(o->cls) ? in->name : o->name);
  }
  snprintf(in->thread_name, sizeof in->thread_name, "%s", name);
  return 0;
bad:
  return fault("thread", "'%s' must be 1-%d characters of a-z 0-9 _ -", name ? name : "", TX_THREAD_NAME_MAX - 1);
}

static const tx_component_def* writer_def(const tx_system* s, const char* name, int* writer) {
  for (int i = 0; i < s->count; i++)
    for (int p = 0; p < s->inst[i]->nports; p++)
      if (s->inst[i]->ports[p].write && strcmp(s->inst[i]->ports[p].name, name) == 0) {
        if (writer) *writer = i;
        return &s->inst[i]->ports[p].def;
      }
  return NULL;
}

static bool same_schema(const tx_component_def* a, const tx_component_def* b) {
  return a->type == b->type && a->rows == b->rows && a->cols == b->cols && strcmp(a->units, b->units) == 0;
}

// event streams: one emitter each, and every listen has an emitter
static int check_streams(tx_system* s) {
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    for (int p = 0; p < in->nports; p++) {
      port* pt = &in->ports[p];
      if (pt->kind == PORT_COMPONENT) continue;
      int k = 0;
      while (k < s->nstreams && strcmp(s->streams[k].name, pt->name) != 0) k++;
      if (k == s->nstreams) {
        sys_stream* grown = realloc(s->streams, (s->nstreams + 1) * sizeof *grown);
        if (!grown) return fault("", "out of memory");
        s->streams = grown;
        s->streams[s->nstreams++] = (sys_stream){.writer = -1};
        strcpy(s->streams[k].name, pt->name);
      }
      sys_stream* st = &s->streams[k];
      pt->stream = k;
      if (pt->kind == PORT_EMIT) {
        if (st->writer >= 0)
          return fault(in->name, "event stream '%s' has two writers: %s and %s", pt->name, s->inst[st->writer]->name,
                       in->name);
        st->writer = i;
        st->capacity = pt->capacity;
      } else {
        if (st->nreaders == TX_STREAM_READERS_MAX)
          return fault(in->name, "event stream '%s' has more than %d listeners", pt->name, TX_STREAM_READERS_MAX);
        pt->listener = st->nreaders;
        st->readers[st->nreaders++] = i;
      }
    }
  }
  for (int k = 0; k < s->nstreams; k++)
    if (s->streams[k].writer < 0)
      return fault(s->inst[s->streams[k].readers[0]]->name, "listens to event stream '%s', which no controller emits",
                   s->streams[k].name);
  return 0;
}

// (re)make every stream with its readers: at finalize, and before a run after one that sent events
static int make_streams(tx_system* s) {
  for (int k = 0; k < s->nstreams; k++) {
    sys_stream* st = &s->streams[k];
    tx_stream_destroy(st->stream);
    st->stream = tx_stream_create(st->name, st->capacity);
    if (!st->stream) return -1;
    for (int r = 0; r < st->nreaders; r++)
      if (tx_stream_add_reader(st->stream) != r) return -1;
  }
  return 0;
}

static int cmp_rate_desc(const void* a, const void* b) {
  double x = ((const group*)a)->rate_hz, y = ((const group*)b)->rate_hz;
  return (x < y) - (x > y);
}

static int build_groups(tx_system* s) {
  s->groups = calloc(s->count ? s->count : 1, sizeof *s->groups);
  if (!s->groups) return -1;
  for (int i = 0; i < s->count; i++) {
    int g = 0;
    while (g < s->ngroups && s->groups[g].rate_hz != s->inst[i]->rate_hz) g++;
    if (g == s->ngroups) s->groups[s->ngroups++].rate_hz = s->inst[i]->rate_hz;
  }
  qsort(s->groups, s->ngroups, sizeof *s->groups, cmp_rate_desc);
  for (int g = 0; g < s->ngroups; g++) {
    s->groups[g].members = malloc(s->count * sizeof(int));
    if (!s->groups[g].members) return -1;
    for (int i = 0; i < s->count; i++)
      if (s->inst[i]->rate_hz == s->groups[g].rate_hz) {
        s->groups[g].members[s->groups[g].count++] = i;
        s->inst[i]->group = g;
      }
  }
  return 0;
}

// the key of an instance's real-time thread: its own, its scenario name, or its rate
static bool same_thread(const instance* a, const instance* b) {
  if (tx_class_own_thread(a->cls) || tx_class_own_thread(b->cls)) return a == b;
  if (*a->thread_name || *b->thread_name) return strcmp(a->thread_name, b->thread_name) == 0;
  return a->rate_hz == b->rate_hz;
}

static int cmp_thread(const void* a, const void* b) {
  const group *x = a, *y = b;
  if (x->own != y->own) return y->own - x->own; // own threads first
  if (x->rate_hz != y->rate_hz) return (x->rate_hz < y->rate_hz) - (x->rate_hz > y->rate_hz);
  return x->members[0] - y->members[0]; // then scenario order
}

// real-time threads: one per haptics instance, one per named thread, one per
// rate for the rest; priority rank by rate among those that are not own
static int build_threads(tx_system* s) {
  s->threads = calloc(s->count, sizeof *s->threads);
  if (!s->threads) return -1;
  for (int i = 0; i < s->count; i++) {
    int t = 0;
    while (t < s->nthreads && !same_thread(s->inst[s->threads[t].members[0]], s->inst[i])) t++;
    group* th = &s->threads[t];
    if (t == s->nthreads) {
      s->nthreads++;
      th->members = malloc(s->count * sizeof(int));
      if (!th->members) return -1;
      th->rate_hz = s->inst[i]->rate_hz;
      th->own = tx_class_own_thread(s->inst[i]->cls);
      th->name = *s->inst[i]->thread_name ? s->inst[i]->thread_name : NULL;
    }
    th->members[th->count++] = i;
  }
  qsort(s->threads, s->nthreads, sizeof *s->threads, cmp_thread);
  for (int t = 0; t < s->nthreads; t++) {
    group* th = &s->threads[t];
    th->rank = 0;
    for (int u = 0; u < t; u++) // distinct faster rates before it
      if (!s->threads[u].own && s->threads[u].rate_hz > th->rate_hz &&
          (u == 0 || s->threads[u - 1].own || s->threads[u - 1].rate_hz != s->threads[u].rate_hz))
        th->rank++;
    for (int m = 0; m < th->count; m++) s->inst[th->members[m]]->thread = t;
  }
  return 0;
}

int tx_system_finalize(tx_system* s) {
  if (s->model) return 0;
  if (s->count == 0) return fault("", "no controllers");
  for (int d = 0; d < s->ndeclared; d++) {
    s->declared[d].name = s->declared_names[d];
    s->declared[d].units = s->declared_units[d];
  }
  // one writer per component, matching any declared schema
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    for (int p = 0; p < in->nports; p++) {
      if (!in->ports[p].write) continue;
      int w = -1;
      writer_def(s, in->ports[p].name, &w);
      if (w != i)
        return fault(in->name, "'%s' has two writers: %s and %s", in->ports[p].name, s->inst[w]->name, in->name);
      const tx_component_def* d = declared(s, in->ports[p].name);
      if (d && !same_schema(d, &in->ports[p].def))
        return fault(in->name, "writes '%s' as %s %ux%u %s, but the model declares %s %ux%u %s", d->name,
                     tx_type_name(in->ports[p].def.type), in->ports[p].def.rows, in->ports[p].def.cols,
                     in->ports[p].def.units, tx_type_name(d->type), d->rows, d->cols, d->units);
    }
  }
  // every read has a writer
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    for (int p = 0; p < in->nports; p++) {
      const char* name = in->ports[p].name;
      if (in->ports[p].kind != PORT_COMPONENT || in->ports[p].write || writer_def(s, name, NULL)) continue;
      if (declared(s, name)) return fault(in->name, "reads '%s', which no controller writes", name);
      return fault(in->name, "reads unknown component '%s'", name);
    }
  }
  // a read that needs a schema gets it
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    for (int p = 0; p < in->nports; p++) {
      const port* pt = &in->ports[p];
      if (pt->write || pt->kind != PORT_COMPONENT) continue;
      int w = -1;
      const tx_component_def* d = writer_def(s, pt->name, &w);
      if ((pt->want_type && d->type != pt->want_type) || (pt->want_cols && d->cols != pt->want_cols))
        return fault(in->name, "reads '%s' as %s x %u, but it is written as %s %ux%u", pt->name,
                     pt->want_type ? tx_type_name(pt->want_type) : "any", pt->want_cols, tx_type_name(d->type), d->rows,
                     d->cols);
      if (*pt->want_units && strcmp(d->units, pt->want_units) != 0)
        return fault(in->name, "%s reads '%s' in units \"%s\", but %s writes it in \"%s\"", in->name, pt->name,
                     pt->want_units, s->inst[w]->name, d->units);
    }
  }
  if (check_streams(s)) return -1;
  // declared components need a writer too, or nothing could ever fill them
  for (int d = 0; d < s->ndeclared; d++)
    if (!writer_def(s, s->declared[d].name, NULL))
      return fault("", "model component '%s' has no writer", s->declared[d].name);

  // every instance may misuse tx_write or tx_write_rows at run time: counted (context.c)
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    in->bad_port = tx_setup_warning(&in->setup, "bad_port");
    in->rows_clamped = tx_setup_warning(&in->setup, "rows_clamped");
    if (in->failed) return setup_fault(in);
  }

  s->model = tx_model_create();
  if (!s->model) return fault("", "out of memory");
  for (int i = 0; i < s->count; i++)
    for (int p = 0; p < s->inst[i]->nports; p++) {
      port* pt = &s->inst[i]->ports[p];
      if (!pt->write) continue;
      pt->comp = tx_model_add(s->model, &pt->def);
      if (!pt->comp.id) return fault(s->inst[i]->name, "%s", tx_error());
    }
  for (int i = 0; i < s->count; i++)
    for (int p = 0; p < s->inst[i]->nports; p++) {
      port* pt = &s->inst[i]->ports[p];
      if (pt->write || pt->kind != PORT_COMPONENT) continue;
      pt->comp = tx_model_find(s->model, pt->name);
      pt->reader = tx_model_add_reader(s->model, pt->comp);
      if (!pt->reader.id) return fault(s->inst[i]->name, "%s", tx_error());
    }
  if (!tx_model_commit(s->model)) return fault("", "%s", tx_error());
  if (build_groups(s) || build_threads(s)) return fault("", "out of memory");
  if (make_streams(s)) return fault("", "%s", tx_error());
  return 0;
}

// saturates at INT64_MAX ("never"), so a clock past its range ends a run rather than wrapping
int64_t tx_tick_ns(double rate_hz, uint64_t k) {
  double ns = (double)k * 1e9 / rate_hz;
  return ns < 9.2e18 ? (int64_t)llround(ns) : INT64_MAX;
}

static double digits(double v) { return v < 10 ? 1 : floor(log10(v)) + 1; }

double tx_system_trace_bytes(const tx_system* s, double duration_s) {
  // one line per publish: "sim_ns,instance,component,seq,rows,hash16\n", each
  // write published at most once per tick and once by init
  double total = 64; // the header
  for (int i = 0; i < s->count; i++) {
    const instance* in = s->inst[i];
    double ticks = ceil(duration_s * in->rate_hz) + 1;
    for (int p = 0; p < in->nports; p++) {
      const port* pt = &in->ports[p];
      if (!pt->write) continue;
      double line = digits(duration_s * 1e9) + strlen(in->name) + strlen(pt->name) + digits(ticks) +
                    digits(pt->def.rows) + 16 + 6;
      total += ticks * line;
    }
  }
  return total;
}

bool tx_system_prepare_stats(tx_system* s, double duration_s) {
  (void)duration_s; // the histograms hold a run of any length
  for (int i = 0; i < s->count; i++) {
    instance* in = s->inst[i];
    tx_hist_clear(&in->jitter);
    tx_hist_clear(&in->step_time);
    in->steps = in->missed = 0;
    in->first_start_ns = in->last_start_ns = 0;
  }
  for (int w = 0; w < s->nwarnings; w++) atomic_store(&s->warning_counts[w], 0);
  bool used = false; // a stream holds the events of the last run: start empty
  for (int k = 0; k < s->nstreams; k++) used |= tx_stream_pushed(s->streams[k].stream) > 0;
  if (used && make_streams(s)) return false;
  for (int k = 0; k < s->nresults; k++) s->result_values[k] = NAN;
  return true;
}

int tx_system_run(tx_system* s, const tx_run_options* o, tx_run_result* r) {
  *r = (tx_run_result){0};
  if (!s->model) return tx_set_error("the system is not finalized"), -1;
  if (!(o->duration_s >= TX_DURATION_MIN_S && o->duration_s <= TX_DURATION_MAX_S))
    return tx_set_error("duration %g s is out of range [%g, %g]", o->duration_s, TX_DURATION_MIN_S, TX_DURATION_MAX_S), -1;
  if (!tx_system_prepare_stats(s, o->duration_s)) return tx_set_error("out of memory for statistics"), -1;
  s->record_dir = o->record_dir;
  s->out_dir = o->out_dir;
  atomic_store(&s->halt, false);
  atomic_store(&s->halt_claim, 0);
  s->halt_reason[0] = 0;
  tx_control_start(s, o->lockstep);
  int rc = o->lockstep ? tx_run_lockstep(s, o, r) : tx_run_realtime(s, o, r);
  tx_control_end(s);
  if (tx_system_halted(s)) {
    r->halted = true;
    snprintf(r->halt_reason, sizeof r->halt_reason, "%s", s->halt_reason);
    r->halt_t_s = (double)s->halt_sim_ns * 1e-9;
  }
  return rc;
}

int tx_system_count(const tx_system* s) { return s->count; }
const char* tx_system_name(const tx_system* s, int i) { return s->inst[i]->name; }
const tx_controller_class* tx_system_class(const tx_system* s, int i) { return s->inst[i]->cls; }
double tx_system_rate(const tx_system* s, int i) { return s->inst[i]->rate_hz; }
int tx_system_thread(const tx_system* s, int i) { return s->inst[i]->thread; }
int tx_system_threads(const tx_system* s) { return s->nthreads; }
const char* tx_system_thread_name(const tx_system* s, int t) { return s->threads[t].name; }
bool tx_system_thread_own(const tx_system* s, int t) { return s->threads[t].own; }
int tx_system_streams(const tx_system* s) { return s->nstreams; }

tx_stream_info tx_system_stream(const tx_system* s, int k) {
  const sys_stream* st = &s->streams[k];
  tx_stream_info info = {st->name, s->inst[st->writer]->name, st->capacity, tx_stream_pushed(st->stream),
                         tx_stream_overflows(st->stream), st->nreaders, {0}, {0}};
  for (int r = 0; r < st->nreaders; r++) {
    info.readers[r] = s->inst[st->readers[r]]->name;
    info.lost[r] = tx_stream_lost(st->stream, r);
  }
  return info;
}
int tx_system_ports(const tx_system* s, int i) { return s->inst[i]->nports; }
tx_model* tx_system_model(tx_system* s) { return s->model; }
int tx_system_warnings(const tx_system* s) { return s->nwarnings; }
const char* tx_system_warning_key(const tx_system* s, int w) { return s->warning_keys[w]; }
int tx_system_results(const tx_system* s) { return s->nresults; }
const char* tx_system_result_key(const tx_system* s, int k) { return s->result_keys[k]; }
double tx_system_result(const tx_system* s, int k) { return s->result_values[k]; }
uint64_t tx_system_warning_count(const tx_system* s, int w) {
  return atomic_load(&((tx_system*)s)->warning_counts[w]);
}
json_t* tx_system_params(const tx_system* s, int i) { return s->inst[i]->params; }

tx_port_info tx_system_port(const tx_system* s, int i, int p) {
  const port* pt = &s->inst[i]->ports[p];
  const tx_component_def* def = pt->comp.id ? tx_model_def(s->model, pt->comp) : NULL;
  return (tx_port_info){pt->write, pt->name, def, (int)pt->kind};
}

tx_controller_stats tx_system_stats(const tx_system* s, int i) {
  const instance* in = s->inst[i];
  tx_controller_stats st = {in->steps, in->missed, 0, tx_hist_percentiles(&in->jitter),
                            tx_hist_percentiles(&in->step_time)};
  int64_t span = in->last_start_ns - in->first_start_ns;
  if (in->steps > 1 && span > 0) st.achieved_hz = (double)(in->steps - 1) * 1e9 / (double)span;
  return st;
}
