// dds: a haptic device across Cyclone DDS (device_dds.h): the client backend
// that `--device dds:DOMAIN[:NAME]` opens, and the server behind
// `tactus-device SPEC --dds DOMAIN[:NAME]`.
#include "device_dds.h"

#include "../../model/error.h"
#include "net.h"

#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define TAKE_MAX 16
#define DRAIN_MAX 256 // samples one read takes at most: a flood cannot hold the haptics tick
#define STATE_COLS TX_DEVICE_DDS_STATE_COLS
#define FORCE_COLS TX_DEVICE_DDS_FORCE_COLS

bool tx_device_dds_parse(const char* arg, tx_device_dds_spec* out) {
  memset(out, 0, sizeof *out);
  char text[512];
  if (strlen(arg) >= sizeof text) return tx_set_error("too long"), false;
  snprintf(text, sizeof text, "%s", arg);
  char* rest = strchr(text, ',');
  if (rest) *rest++ = 0;
  char* colon = strchr(text, ':');
  if (colon) *colon = 0;
  char* end;
  long d = strtol(text, &end, 10);
  if (!*text || *end || d < 0 || d > TX_NET_DOMAIN_MAX || strlen(text) > 3)
    return tx_set_error("domain '%s': expected an integer in [0, %d]", text, TX_NET_DOMAIN_MAX), false;
  const char* n = colon ? colon + 1 : "device0";
  size_t nlen = strlen(n);
  bool ok = nlen > 0 && nlen < sizeof out->name;
  for (size_t i = 0; ok && i < nlen; i++) ok = (n[i] >= 'a' && n[i] <= 'z') || (n[i] >= '0' && n[i] <= '9') || n[i] == '_';
  if (!ok) return tx_set_error("name '%s': expected 1-31 characters of a-z 0-9 _", n), false;
  out->domain = (int)d;
  snprintf(out->name, sizeof out->name, "%s", n);
  for (char* item = rest; item;) {
    char* next = strchr(item, ',');
    if (next) *next++ = 0;
    if (strncmp(item, "peer=", 5) != 0) return tx_set_error("'%s': expected peer=HOST", item), false;
    if (out->npeers == TX_DEVICE_DDS_PEERS_MAX) return tx_set_error("at most %d peers", TX_DEVICE_DDS_PEERS_MAX), false;
    if (!tx_net_peer_valid(item + 5)) return tx_error_prefix("peer"), false;
    snprintf(out->peer_text[out->npeers], sizeof out->peer_text[0], "%s", item + 5);
    out->peers[out->npeers] = out->peer_text[out->npeers];
    out->npeers++;
    item = next;
  }
  return true;
}

double tx_device_dds_scale(double age_s, double since_s, double timeout_s, double ramp_s) {
  double down = age_s <= timeout_s ? 1 : ramp_s > 0 ? 1 - (age_s - timeout_s) / ramp_s : 0;
  double up = ramp_s > 0 ? since_s / ramp_s : 1;
  double s = down < up ? down : up;
  return s < 0 ? 0 : s > 1 ? 1 : s;
}

static uint64_t session_tag(const char* name, int domain) {
  char session[64];
  snprintf(session, sizeof session, "device/%s", name);
  return tx_net_session_tag(session, domain);
}

// a participant (loopback unless CYCLONEDDS_URI says otherwise), and the two topics
static int endpoints(const tx_device_dds_spec* spec, bool server, dds_entity_t* pp, dds_entity_t* writer, dds_entity_t* reader) {
  const char* name = spec->name;
  *pp = tx_net_participant(spec->domain, spec->peers, spec->npeers);
  if (*pp < 0) return -1;
  char state[96], force[96];
  snprintf(state, sizeof state, "tx/d/%s/state", name);
  snprintf(force, sizeof force, "tx/d/%s/force", name);
  dds_qos_t* q = tx_net_qos(TX_NET_FAST);
  dds_entity_t ts = dds_create_topic(*pp, &tx_net_Snapshot_desc, state, q, NULL);
  dds_entity_t tf = dds_create_topic(*pp, &tx_net_Snapshot_desc, force, q, NULL);
  *writer = ts < 0 || tf < 0 ? -1 : dds_create_writer(*pp, server ? ts : tf, q, NULL);
  *reader = ts < 0 || tf < 0 ? -1 : dds_create_reader(*pp, server ? tf : ts, q, NULL);
  dds_delete_qos(q);
  if (*writer < 0 || *reader < 0) {
    tx_set_error("DDS endpoints: %s", dds_strretcode(*writer < 0 ? *writer : *reader));
    dds_delete(*pp);
    *pp = 0;
    return -1;
  }
  return 0;
}

static bool all_finite(const double* v, int n) {
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

// 0 fits, 1 foreign, 2 malformed
static int check(const tx_net_Snapshot* s, uint64_t tag, const tx_component_def* def, double* out) {
  int bad = tx_net_check(s, tag, def);
  if (bad) return bad;
  if (s->rows != 1) return 2;
  memcpy(out, s->data._buffer, def->cols * sizeof(double));
  return all_finite(out, (int)def->cols) ? 0 : 2;
}

static void pack_state(double* v, const tx_device_state* s, const tx_device_info* info) {
  memcpy(v, s->pos, sizeof s->pos);
  memcpy(v + 3, s->quat, sizeof s->quat);
  memcpy(v + 7, s->vel, sizeof s->vel);
  v[10] = s->grip;
  v[11] = (double)s->buttons;
  v[12] = (double)s->t_ns;
  v[13] = info->max_force, v[14] = info->max_stiffness, v[15] = info->damping;
  memcpy(v + 16, info->workspace_min, 3 * sizeof(double));
  memcpy(v + 19, info->workspace_max, 3 * sizeof(double));
}

static void unpack_state(const double* v, tx_device_state* s, tx_device_info* info) {
  memcpy(s->pos, v, sizeof s->pos);
  memcpy(s->quat, v + 3, sizeof s->quat);
  memcpy(s->vel, v + 7, sizeof s->vel);
  s->grip = v[10];
  s->buttons = v[11] >= 0 && v[11] <= 4294967295.0 ? (uint32_t)v[11] : 0;
  s->t_ns = fabs(v[12]) < 9e18 ? (int64_t)v[12] : 0;
  info->max_force = v[13], info->max_stiffness = v[14], info->damping = v[15];
  memcpy(info->workspace_min, v + 16, 3 * sizeof(double));
  memcpy(info->workspace_max, v + 19, 3 * sizeof(double));
}

static bool same_info(const tx_device_info* a, const tx_device_info* b) {
  bool same = a->max_force == b->max_force && a->max_stiffness == b->max_stiffness && a->damping == b->damping;
  for (int i = 0; i < 3; i++) same = same && a->workspace_min[i] == b->workspace_min[i] && a->workspace_max[i] == b->workspace_max[i];
  return same;
}

static const tx_component_def state_def = {"device.state", TX_F64, 1, STATE_COLS, "1"};
static const tx_component_def force_def = {"device.force", TX_F64, 1, FORCE_COLS, "1"};

// ---- the client: a tx_device_backend

struct tx_device {
  char name[64];       // "dds:DOMAIN:NAME", for messages
  dds_entity_t pp, writer, reader;
  uint64_t tag;
  uint64_t seq;
  tx_device_info info;
  tx_device_state state;
  int64_t state_mono;  // the server's publish time of the newest state, echoed with each force
  int64_t last_state_ns;
  bool lost;
  int64_t lost_ns;
  bool told_other;
  tx_device_dds_counts counts;
};

// one line on stderr from the haptics thread: formatted on the stack, one
// write(2), only if stderr takes it at once (as the udp backend)
static void say(const char* line, int n) {
  if (n <= 0) return;
  struct pollfd pfd = {STDERR_FILENO, POLLOUT, 0};
  if (poll(&pfd, 1, 0) == 1 && (pfd.revents & POLLOUT)) {
    ssize_t w = write(STDERR_FILENO, line, (size_t)n);
    (void)w;
  }
}

// takes what arrived, keeps the newest valid state; true if there was one
static bool drain(tx_device* d, bool first) {
  bool fresh = false;
  for (int taken = 0; taken < DRAIN_MAX;) {
    void* samples[TAKE_MAX] = {0};
    dds_sample_info_t si[TAKE_MAX];
    int n = dds_take(d->reader, samples, si, TAKE_MAX, TAKE_MAX);
    if (n <= 0) break;
    taken += n;
    for (int i = 0; i < n; i++) {
      if (!si[i].valid_data) continue;
      const tx_net_Snapshot* s = samples[i];
      double v[STATE_COLS];
      int bad = check(s, d->tag, &state_def, v);
      if (bad) {
        if (bad == 1) d->counts.foreign++;
        else d->counts.malformed++;
        continue;
      }
      tx_device_state st;
      tx_device_info info;
      unpack_state(v, &st, &info);
      if (first) d->info = info, first = false;
      else if (!same_info(&info, &d->info)) { // the run's safety chain was set up with the first server's limits
        d->counts.other_device++;
        continue;
      }
      d->state = st;
      d->state_mono = s->mono_ns;
      d->counts.states++;
      fresh = true;
    }
    dds_return_loan(d->reader, samples, n);
  }
  return fresh;
}

static void write_dds(tx_device* d, const double force[3]);

static void close_dds(tx_device* d) {
  if (!d) return;
  if (d->pp > 0) {
    double zero[3] = {0};
    if (d->writer > 0) write_dds(d, zero); // the server's ramp would take it down anyway
    dds_delete(d->pp);
  }
  free(d);
}

static tx_device* open_dds(const char* arg, double period_s) {
  (void)period_s;
  tx_device_dds_spec* spec = malloc(sizeof *spec);
  if (!spec) return tx_set_error("out of memory"), NULL;
  if (!tx_device_dds_parse(arg, spec)) return free(spec), tx_error_prefix("device 'dds:%s'", arg), NULL;
  tx_device* d = calloc(1, sizeof *d);
  if (!d) return free(spec), tx_set_error("out of memory"), NULL;
  snprintf(d->name, sizeof d->name, "dds:%d:%s", spec->domain, spec->name);
  d->tag = session_tag(spec->name, spec->domain);
  int bad = endpoints(spec, false, &d->pp, &d->writer, &d->reader);
  free(spec);
  if (bad) {
    tx_error_prefix("device %s", d->name);
    free(d);
    return NULL;
  }
  dds_entity_t ws = dds_create_waitset(d->pp);
  dds_entity_t rc = dds_create_readcondition(d->reader, DDS_ANY_STATE);
  dds_waitset_attach(ws, rc, 0);
  int64_t until = tx_mono_ns() + (int64_t)(TX_DEVICE_DDS_WAIT_S * 1e9);
  bool got = false;
  while (!got && tx_mono_ns() < until) {
    dds_waitset_wait(ws, NULL, 0, DDS_MSECS(50));
    got = drain(d, true);
  }
  dds_delete(ws);
  if (!got) {
    tx_set_error("device %s: no state from a server in %g s (is `tactus-device SPEC --dds %s` running?)", d->name,
                 TX_DEVICE_DDS_WAIT_S, arg);
    close_dds(d);
    return NULL;
  }
  d->last_state_ns = tx_mono_ns();
  return d;
}

static void info_dds(const tx_device* d, tx_device_info* out) { *out = d->info; }

static long long ms_of(double t) { return isfinite(t) && fabs(t) < 1e15 ? llround(t * 1e3) : 0; }

static bool read_dds(tx_device* d, double t, tx_device_state* s) {
  uint64_t other = d->counts.other_device;
  bool fresh = drain(d, false);
  int64_t now = tx_mono_ns();
  char line[320];
  long long ms = ms_of(t);
  if (fresh) {
    if (d->lost) {
      d->lost = false;
      d->counts.returns++;
      long long gone = (now - d->lost_ns) / 1000000;
      say(line, snprintf(line, sizeof line, "tactus: device %s back at t = %lld.%03lld s after %lld.%03lld s\n", d->name,
                         ms / 1000, ms % 1000, gone / 1000, gone % 1000));
    }
    d->last_state_ns = now;
  } else if (!d->lost && now - d->last_state_ns > (int64_t)(TX_DEVICE_DDS_LOST_S * 1e9)) {
    d->lost = true;
    d->lost_ns = now;
    d->told_other = false;
    d->counts.losses++;
    say(line, snprintf(line, sizeof line, "tactus: device %s lost at t = %lld.%03lld s: no state for %d ms; no force until it is back\n",
                       d->name, ms / 1000, ms % 1000, (int)(TX_DEVICE_DDS_LOST_S * 1e3)));
  }
  if (d->counts.other_device > other && !d->told_other) {
    d->told_other = true;
    say(line, snprintf(line, sizeof line, "tactus: device %s: a server of other limits answered; not used, as the run's "
                       "safety limits are those of the device it started with\n", d->name));
  }
  *s = d->state;
  return fresh;
}

static void write_dds(tx_device* d, const double force[3]) {
  double v[FORCE_COLS];
  for (int i = 0; i < 3; i++) v[i] = isfinite(force[i]) ? force[i] : 0;
  v[3] = (double)d->state_mono; // the state this force answers: the server times the loop
  tx_snapshot snap = {.data = v, .rows = 1, .cols = FORCE_COLS, .seq = ++d->seq, .mono_ns = tx_mono_ns()};
  tx_net_Snapshot s;
  tx_net_pack(&s, d->tag, force_def.name, TX_F64, &snap);
  if (dds_write(d->writer, &s) == 0) d->counts.forces++;
}

void tx_device_dds_counts_get(const tx_device* d, tx_device_dds_counts* out) { *out = d->counts; }

const tx_device_backend tx_device_dds = {"dds", open_dds, info_dds, read_dds, write_dds, close_dds, NULL, NULL};

// ---- the server

struct tx_device_dds_server {
  tx_device_dds_server_def def;
  tx_device_dds_spec spec;
  tx_device_handle dev;
  tx_device_info info;
  dds_entity_t pp, writer, reader;
  uint64_t tag;
  pthread_mutex_t lock; // the stats, for another thread
  tx_device_dds_server_stats stats;
  tx_hist* loop;
};

tx_device_dds_server_def tx_device_dds_server_def_default(void) {
  return (tx_device_dds_server_def){.spec = "sim", .dds = "0", .rate_hz = 1000, .force_timeout_s = 0.003, .ramp_s = 0.005};
}

tx_device_dds_server* tx_device_dds_server_open(const tx_device_dds_server_def* def) {
  if (!(def->rate_hz >= 1 && def->rate_hz <= 100000)) return tx_set_error("rate %g Hz: expected [1, 100000]", def->rate_hz), NULL;
  if (!(def->force_timeout_s > 0 && def->force_timeout_s <= 1)) return tx_set_error("force timeout %g s: expected (0, 1]", def->force_timeout_s), NULL;
  if (!(def->ramp_s >= 0 && def->ramp_s <= 1)) return tx_set_error("ramp %g s: expected [0, 1]", def->ramp_s), NULL;
  tx_device_dds_server* s = calloc(1, sizeof *s);
  if (!s || !(s->loop = calloc(1, sizeof *s->loop))) return free(s), tx_set_error("out of memory"), NULL;
  if (!tx_device_dds_parse(def->dds ? def->dds : "0", &s->spec)) return free(s->loop), free(s), NULL;
  s->def = *def;
  pthread_mutex_init(&s->lock, NULL);
  tx_hist_clear(s->loop);
  if (tx_device_open(def->spec, 1 / def->rate_hz, &s->dev)) return tx_device_dds_server_close(s), NULL;
  s->dev.backend->info(s->dev.device, &s->info);
  s->tag = session_tag(s->spec.name, s->spec.domain);
  if (endpoints(&s->spec, true, &s->pp, &s->writer, &s->reader)) return tx_device_dds_server_close(s), NULL;
  return s;
}

static void sleep_until(int64_t ns) {
  struct timespec ts = {ns / 1000000000, ns % 1000000000};
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL); // a signal wakes it early: the loop looks at stop
}

int tx_device_dds_server_run(tx_device_dds_server* s, const atomic_int* stop) {
  // the ramp to zero is timed by this loop's ticks: real-time priority where
  // the system grants it (as a haptics thread), else it runs without
  struct sched_param sp = {.sched_priority = sched_get_priority_max(SCHED_FIFO) - 10};
  bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  pthread_mutex_lock(&s->lock);
  s->stats.fifo = fifo;
  pthread_mutex_unlock(&s->lock);
  const int64_t period = (int64_t)llround(1e9 / s->def.rate_hz), t0 = tx_mono_ns();
  const double timeout = s->def.force_timeout_s, ramp = s->def.ramp_s;
  double force[3] = {0};
  int64_t last_force = 0, resumed = 0; // arrival of the newest force, and of the first after a silence
  bool timed_out = true, zero_noted = true;
  uint64_t seq = 0;
  for (uint64_t k = 0;; k++) {
    int64_t tick = t0 + (int64_t)k * period;
    sleep_until(tick);
    int64_t now = tx_mono_ns();
    if (atomic_load(stop) || (s->def.duration_s > 0 && now - t0 >= (int64_t)(s->def.duration_s * 1e9))) break;
    if (now - tick > period) { // late: skip, no burst
      k += (uint64_t)((now - tick) / period);
      pthread_mutex_lock(&s->lock);
      s->stats.late_ticks++;
      pthread_mutex_unlock(&s->lock);
    }
    tx_device_state st;
    if (s->dev.backend->read(s->dev.device, (double)(now - t0) * 1e-9, &st)) {
      double v[STATE_COLS];
      pack_state(v, &st, &s->info);
      tx_snapshot snap = {.data = v, .rows = 1, .cols = STATE_COLS, .seq = ++seq, .mono_ns = now};
      tx_net_Snapshot out;
      tx_net_pack(&out, s->tag, state_def.name, TX_F64, &snap);
      if (dds_write(s->writer, &out) == 0) {
        pthread_mutex_lock(&s->lock);
        s->stats.states++;
        pthread_mutex_unlock(&s->lock);
      }
    }
    // the newest valid force
    bool got = false;
    double newest[FORCE_COLS] = {0};
    uint64_t foreign = 0, malformed = 0;
    for (int taken = 0; taken < DRAIN_MAX;) {
      void* samples[TAKE_MAX] = {0};
      dds_sample_info_t si[TAKE_MAX];
      int n = dds_take(s->reader, samples, si, TAKE_MAX, TAKE_MAX);
      if (n <= 0) break;
      taken += n;
      for (int i = 0; i < n; i++) {
        if (!si[i].valid_data) continue;
        double v[FORCE_COLS];
        int bad = check(samples[i], s->tag, &force_def, v);
        if (bad == 1) foreign++;
        else if (bad) malformed++;
        else memcpy(newest, v, sizeof v), got = true;
      }
      dds_return_loan(s->reader, samples, n);
    }
    pthread_mutex_lock(&s->lock);
    s->stats.foreign += foreign, s->stats.malformed += malformed;
    if (got) {
      if (timed_out) { // a simulation, new or back: taken up, ramped in from zero
        timed_out = false;
        resumed = now;
        if (last_force) s->stats.resumes++;
      }
      memcpy(force, newest, sizeof force);
      last_force = now;
      zero_noted = false;
      s->stats.forces++;
      if (newest[3] > 0) tx_hist_add(s->loop, now - (int64_t)newest[3]);
    }
    double age = (double)(now - last_force) * 1e-9, since = (double)(now - resumed) * 1e-9;
    double scale = last_force ? tx_device_dds_scale(age, since, timeout, ramp) : 0;
    if (!timed_out && age > timeout) timed_out = true, s->stats.timeouts++;
    double f[3] = {force[0] * scale, force[1] * scale, force[2] * scale};
    s->dev.backend->write(s->dev.device, f);
    if (timed_out && scale == 0 && !zero_noted) { // the lost simulation's force is gone
      zero_noted = true;
      double after = (double)(now - last_force) * 1e-9;
      if (after > s->stats.zero_after_s) s->stats.zero_after_s = after;
    }
    s->stats.last_scale = scale;
    memcpy(s->stats.last_force, f, sizeof f);
    pthread_mutex_unlock(&s->lock);
  }
  double zero[3] = {0};
  s->dev.backend->write(s->dev.device, zero);
  pthread_mutex_lock(&s->lock);
  memset(s->stats.last_force, 0, sizeof s->stats.last_force);
  pthread_mutex_unlock(&s->lock);
  return 0;
}

void tx_device_dds_server_get_stats(tx_device_dds_server* s, tx_device_dds_server_stats* out) {
  pthread_mutex_lock(&s->lock);
  *out = s->stats;
  out->loop = tx_hist_percentiles(s->loop);
  pthread_mutex_unlock(&s->lock);
}

void tx_device_dds_server_close(tx_device_dds_server* s) {
  if (!s) return;
  if (s->pp > 0) dds_delete(s->pp);
  tx_device_close(&s->dev);
  pthread_mutex_destroy(&s->lock);
  free(s->loop);
  free(s);
}
