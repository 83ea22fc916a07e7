// net.dds: the bridge that carries components and event streams between the
// processes of one session over Cyclone DDS (docs/distributed.md).
//
// Sending: by default the moment a sent component is published, the model's
// publish hook wakes the bridge's sender thread, which writes every new
// publish (a changed seq) as a sample of its topic; else each step (or a
// thread polling every poll_us) does. Events it listens to go out from the
// step, one sample each. Receiving: a DDS listener, on Cyclone's receive thread,
// writes each sample into the local model at once (the bridge is the one
// writer of a mirrored component there), stamped with the local simulation
// time of its arrival, so a reader sees it as any publish, without waiting for
// the bridge's next tick, and its age says how long ago the peer last spoke
// (the haptics watchdog fades a force model from a lost peer to zero). Foreign (another session) and malformed samples are
// dropped and counted, never written.
#include "dds_bridge.h"

#include "../system_internal.h"
#include "net.h"

#include <tactus/stats.h>

#include <errno.h>
#include <pthread.h>
#include <semaphore.h>
#include <time.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define SEND_MAX 64
#define RECV_MAX 64
#define TAKE_MAX 16 // samples taken per listener call

static const tx_param_def params[] = {
    {"domain", TX_PARAM_INT, "1", 0, TX_NET_DOMAIN_MAX, 0, NULL, "DDS domain id: sessions on other domains never meet"},
    {"peers", TX_PARAM_STRS, NULL, 0, TX_NET_PEERS_MAX, 0, NULL,
     "other hosts (IPv4 or names); none: loopback only. CYCLONEDDS_URI, when set, replaces this"},
    {"session", TX_PARAM_STR, NULL, 0, 0, 0, "tactus", "the session's name: samples tagged with another are dropped as foreign"},
    {"send", TX_PARAM_STRS, NULL, 0, SEND_MAX, 0, NULL, "components this process writes and the others mirror"},
    {"receive", TX_PARAM_JSON, NULL, 0, 0, 0, NULL,
     "components mirrored in: [{name, type, rows, cols, units}], the writer's schema"},
    {"send_streams", TX_PARAM_STRS, NULL, 0, SEND_MAX, 0, NULL, "event streams this process emits and the others mirror"},
    {"receive_streams", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "event streams mirrored in: [{name, capacity}]"},
    {"poll_us", TX_PARAM_INT, "us", 0, 100000, 0, NULL,
     "> 0: a thread of the bridge's own polls the sent components this often, instead of sending on publish"},
    {"on_publish", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL,
     "send a component the moment its writer publishes it (the model's publish hook wakes the sender thread); false: from the bridge's step"},
    {"best_effort", TX_PARAM_STRS, NULL, 0, SEND_MAX, 0, NULL,
     "components that are poses or forces: best effort, keep last 1 (the rest: reliable, transient-local)"},
};

typedef struct bridge bridge;

typedef struct outbound {
  char name[TX_NAME_MAX];
  bool stream;
  tx_port port;          // read (component) or listen (stream)
  tx_reader reader;      // components: the port's hazard slot, for the sender thread
  tx_type type;          // components
  bool fast;             // best effort, keep last 1 (else reliable, transient-local)
  uint64_t last_seq;     // last publish sent
  dds_entity_t writer;
  int hook;              // the model's publish hook that wakes the sender, 0 if none
} outbound;

typedef struct inbound {
  bridge* b;
  char name[TX_NAME_MAX];
  bool stream;
  tx_component_def def;  // components: the schema, name and units point at name and units
  char units[TX_UNITS_MAX];
  uint32_t capacity;     // streams
  bool fast;             // best effort, keep last 1 (else reliable, transient-local)
  tx_port port;          // write (component) or emit (stream)
  tx_comp comp;          // after init
  tx_stream* ring;       // after init
  dds_entity_t reader;
  uint64_t last_seq;     // streams: the sender's last event seq, for gaps
  tx_hist* latency;      // components: mirror publish - the writer's publish, ns (one host: one clock)
  tx_result r_p50, r_p99;
} inbound;

struct bridge {
  int domain;
  const char* peers[TX_NET_PEERS_MAX];
  int npeers;
  uint64_t tag;
  outbound out[SEND_MAX * 2];
  int nout;
  inbound in[RECV_MAX * 2];
  int nin;
  tx_model* model;       // after init
  tx_ctx* ctx;           // for tx_warn from the listener (a relaxed atomic add)
  dds_entity_t participant;
  pthread_mutex_t lock;  // one listener call at a time writes the model
  _Atomic bool live;     // init done, finish not yet: the listener may write
  int poll_us;           // > 0: the sender thread polls the sent components
  bool on_publish;       // poll_us 0: the publish hook wakes the sender thread
  sem_t wake;            // posted by the publish hook
  bool wake_made;
  _Atomic bool pending;  // a publish since the sender last looked: one post per batch
  pthread_t sender;
  bool sender_started;
  _Atomic bool sender_stop;
  _Atomic int64_t clock_offset; // CLOCK_MONOTONIC - local simulation time, ns: its least value seen
  tx_warning foreign, malformed, lost, send_failed;
  tx_result r_sent, r_received, r_events_sent, r_events_received;
  _Atomic uint64_t sent, received, events_sent, events_received;
};

static bool listed(const char* const* list, int n, const char* name) {
  for (int i = 0; i < n; i++)
    if (strcmp(list[i], name) == 0) return true;
  return false;
}

static int read_receive(tx_setup* s, bridge* b, const char* const* fast, int nfast) {
  json_t* list = tx_param_json(s, "receive");
  if (list && !json_is_array(list)) return tx_setup_fail(s, "receive", "expected an array of {name, type, rows, cols, units}");
  size_t i;
  json_t* e;
  json_array_foreach(list, i, e) {
    if (b->nin == RECV_MAX) return tx_setup_fail(s, "receive", "at most %d components", RECV_MAX);
    const char* name = json_string_value(json_object_get(e, "name"));
    tx_type type = tx_type_from_name(json_string_value(json_object_get(e, "type")));
    json_t *rows = json_object_get(e, "rows"), *cols = json_object_get(e, "cols");
    const char* units = json_string_value(json_object_get(e, "units"));
    if (!name || !type || !json_is_integer(rows) || !json_is_integer(cols) || json_integer_value(rows) < 1 ||
        json_integer_value(cols) < 1 || json_integer_value(rows) > (1 << 26) || json_integer_value(cols) > 1024 ||
        strlen(name) >= TX_NAME_MAX || (units && strlen(units) >= TX_UNITS_MAX))
      return tx_setup_fail(s, "receive", "entry %zu: expected {name, type, rows, cols, units} with a valid schema", i);
    inbound* in = &b->in[b->nin++];
    snprintf(in->name, sizeof in->name, "%s", name);
    snprintf(in->units, sizeof in->units, "%s", units ? units : "1");
    in->def = (tx_component_def){in->name, type, (uint32_t)json_integer_value(rows), (uint32_t)json_integer_value(cols), in->units};
    in->port = tx_setup_write(s, &in->def);
    in->fast = listed(fast, nfast, name);
    if (!(in->latency = calloc(1, sizeof *in->latency))) return -1;
    char key[TX_NAME_MAX + 24];
    snprintf(key, sizeof key, "%s.latency_p50_us", name);
    in->r_p50 = tx_setup_result(s, key);
    snprintf(key, sizeof key, "%s.latency_p99_us", name);
    in->r_p99 = tx_setup_result(s, key);
  }
  list = tx_param_json(s, "receive_streams");
  if (list && !json_is_array(list)) return tx_setup_fail(s, "receive_streams", "expected an array of {name, capacity}");
  json_array_foreach(list, i, e) {
    if (b->nin == RECV_MAX * 2) return tx_setup_fail(s, "receive_streams", "too many");
    const char* name = json_string_value(json_object_get(e, "name"));
    json_t* cap = json_object_get(e, "capacity");
    if (!name || strlen(name) >= TX_NAME_MAX || !json_is_integer(cap))
      return tx_setup_fail(s, "receive_streams", "entry %zu: expected {name, capacity}", i);
    inbound* in = &b->in[b->nin++];
    snprintf(in->name, sizeof in->name, "%s", name);
    in->stream = true;
    in->capacity = (uint32_t)json_integer_value(cap);
    in->port = tx_setup_emit(s, name, in->capacity);
  }
  return 0;
}

static int configure(tx_setup* s, void** self) {
  bridge* b = calloc(1, sizeof *b);
  if (!b) return -1;
  *self = b;
  pthread_mutex_init(&b->lock, NULL);
  b->domain = (int)tx_table_int(s, "domain");
  b->npeers = tx_table_strs(s, "peers", b->peers, TX_NET_PEERS_MAX);
  for (int i = 0; i < b->npeers; i++)
    if (!tx_net_peer_valid(b->peers[i])) return tx_setup_fail(s, "peers", "entry %d: %s", i, tx_error());
  b->poll_us = (int)tx_table_int(s, "poll_us");
  b->on_publish = !b->poll_us && tx_table_bool(s, "on_publish");
  const char* session = tx_table_str(s, "session");
  b->tag = tx_net_session_tag(session ? session : "tactus", b->domain);
  const char* fast[SEND_MAX];
  int nfast = tx_table_strs(s, "best_effort", fast, SEND_MAX);
  const char* names[SEND_MAX];
  int n = tx_table_strs(s, "send", names, SEND_MAX);
  for (int i = 0; i < n; i++) {
    outbound* o = &b->out[b->nout++];
    snprintf(o->name, sizeof o->name, "%s", names[i]);
    o->port = tx_setup_read(s, names[i]);
    o->fast = listed(fast, nfast, names[i]);
  }
  n = tx_table_strs(s, "send_streams", names, SEND_MAX);
  for (int i = 0; i < n; i++) {
    outbound* o = &b->out[b->nout++];
    snprintf(o->name, sizeof o->name, "%s", names[i]);
    o->stream = true;
    o->port = tx_setup_listen(s, names[i]);
  }
  if (read_receive(s, b, fast, nfast)) return -1;
  for (int i = 0; i < nfast; i++) { // a best_effort entry that names nothing sent or received is a typo
    bool found = false;
    for (int k = 0; k < b->nout && !found; k++) found = !b->out[k].stream && strcmp(b->out[k].name, fast[i]) == 0;
    for (int k = 0; k < b->nin && !found; k++) found = !b->in[k].stream && strcmp(b->in[k].name, fast[i]) == 0;
    if (!found) return tx_setup_fail(s, "best_effort", "'%s' is neither sent nor received", fast[i]);
  }
  b->foreign = tx_setup_warning(s, "foreign_samples");
  b->malformed = tx_setup_warning(s, "malformed_samples");
  b->lost = tx_setup_warning(s, "events_lost");
  b->send_failed = tx_setup_warning(s, "send_failed");
  b->r_sent = tx_setup_result(s, "samples_sent");
  b->r_received = tx_setup_result(s, "samples_received");
  b->r_events_sent = tx_setup_result(s, "events_sent");
  b->r_events_received = tx_setup_result(s, "events_received");
  return 0;
}

static void on_component(dds_entity_t reader, void* arg) {
  inbound* in = arg;
  bridge* b = in->b;
  void* samples[TAKE_MAX] = {0};
  dds_sample_info_t info[TAKE_MAX];
  int n = dds_take(reader, samples, info, TAKE_MAX, TAKE_MAX); // loaned: no copy
  if (n <= 0) return;
  if (atomic_load_explicit(&b->live, memory_order_acquire)) {
    const tx_net_Snapshot* newest = NULL;
    for (int i = 0; i < n; i++) {
      if (!info[i].valid_data) continue;
      const tx_net_Snapshot* s = samples[i];
      int bad = tx_net_check(s, b->tag, &in->def);
      if (bad) tx_warn(b->ctx, bad == 1 ? b->foreign : b->malformed);
      else newest = s; // keep last: only the newest is published
    }
    if (newest) {
      pthread_mutex_lock(&b->lock);
      void* back = tx_model_back(b->model, in->comp);
      memcpy(back, newest->data._buffer, newest->data._length);
      tx_model_set_rows(b->model, in->comp, newest->rows);
      // stamped with the local simulation time of the arrival: the two processes'
      // clocks started apart, so the sender's time would make the age meaningless
      int64_t now = tx_mono_ns(), local = now - atomic_load_explicit(&b->clock_offset, memory_order_relaxed);
      tx_model_publish(b->model, in->comp, local > 0 ? local : 0);
      tx_hist_add(in->latency, now - newest->mono_ns);
      pthread_mutex_unlock(&b->lock);
      atomic_fetch_add_explicit(&b->received, 1, memory_order_relaxed);
    }
  }
  dds_return_loan(reader, samples, n);
}

static void on_event(dds_entity_t reader, void* arg) {
  inbound* in = arg;
  bridge* b = in->b;
  void* samples[TAKE_MAX] = {0};
  dds_sample_info_t info[TAKE_MAX];
  int n = dds_take(reader, samples, info, TAKE_MAX, TAKE_MAX);
  if (n <= 0) return;
  if (atomic_load_explicit(&b->live, memory_order_acquire)) {
    pthread_mutex_lock(&b->lock);
    for (int i = 0; i < n; i++) {
      if (!info[i].valid_data) continue;
      const tx_net_Event* s = samples[i];
      int bad = tx_net_check_event(s, b->tag, in->name);
      if (bad) {
        tx_warn(b->ctx, bad == 1 ? b->foreign : b->malformed);
        continue;
      }
      // the sender's seq: a gap is events its own ring refused, or that DDS lost
      if (in->last_seq && s->seq > in->last_seq + 1)
        for (uint64_t k = in->last_seq + 1; k < s->seq; k++) tx_warn(b->ctx, b->lost);
      if (s->seq > in->last_seq) in->last_seq = s->seq;
      tx_event e;
      tx_net_unpack_event(s, &e);
      int64_t local = tx_mono_ns() - atomic_load_explicit(&b->clock_offset, memory_order_relaxed);
      e.sim_ns = local > 0 ? local : 0; // as for components: the local time of the arrival
      if (tx_stream_push(in->ring, &e)) atomic_fetch_add_explicit(&b->events_received, 1, memory_order_relaxed);
    }
    pthread_mutex_unlock(&b->lock);
  }
  dds_return_loan(reader, samples, n);
}

static void* sender(void* arg);

// the model's publish hook, on the writer's thread (the haptic thread, for a
// force model): one atomic exchange, and a post only when the sender has
// looked since the last one
static void on_publish(void* user, tx_comp comp, uint64_t seq) {
  (void)comp, (void)seq;
  bridge* b = user;
  if (!atomic_exchange_explicit(&b->pending, true, memory_order_acq_rel)) sem_post(&b->wake);
}

static int init(tx_ctx* c, void* self) {
  bridge* b = self;
  b->ctx = c;
  b->model = c->sys->model;
  atomic_store(&b->clock_offset, tx_mono_ns() - tx_sim_ns(c)); // about the run's time 0, until the first step says
  b->participant = tx_net_participant(b->domain, b->peers, b->npeers);
  if (b->participant < 0) return tx_stop_run(c, "%s", tx_error()), -1;
  for (int k = 0; k < b->nout + b->nin; k++) {
    bool out = k < b->nout;
    const char* name = out ? b->out[k].name : b->in[k - b->nout].name;
    bool stream = out ? b->out[k].stream : b->in[k - b->nout].stream;
    bool fast = !stream && (out ? b->out[k].fast : b->in[k - b->nout].fast);
    char topic_name[TX_NAME_MAX + 8];
    tx_net_topic_name(topic_name, sizeof topic_name, stream, name);
    dds_qos_t* q = tx_net_qos(stream ? TX_NET_EVENTS : fast ? TX_NET_FAST : TX_NET_STATE);
    dds_entity_t topic = dds_create_topic(b->participant, stream ? &tx_net_Event_desc : &tx_net_Snapshot_desc, topic_name, q, NULL);
    dds_entity_t ep = -1;
    if (topic >= 0 && out) {
      outbound* o = &b->out[k];
      ep = o->writer = dds_create_writer(b->participant, topic, q, NULL);
      if (!o->stream) {
        const port* pt = &c->in->ports[o->port.id - 1];
        o->type = tx_model_def(b->model, pt->comp)->type;
        o->reader = pt->reader;
      }
    } else if (topic >= 0) {
      inbound* in = &b->in[k - b->nout];
      in->b = b;
      const port* pt = &c->in->ports[in->port.id - 1];
      if (in->stream) in->ring = c->sys->streams[pt->stream].stream;
      else in->comp = pt->comp;
      dds_listener_t* l = dds_create_listener(in);
      dds_lset_data_available(l, in->stream ? on_event : on_component);
      ep = in->reader = dds_create_reader(b->participant, topic, q, l);
      dds_delete_listener(l);
    }
    dds_delete_qos(q);
    if (topic < 0 || ep < 0) {
      tx_stop_run(c, "DDS topic %s: %s", topic_name, dds_strretcode(topic < 0 ? topic : ep));
      return -1;
    }
  }
  for (int k = 0; k < b->nin; k++)
    if (b->in[k].latency) tx_hist_clear(b->in[k].latency), tx_prefault(b->in[k].latency, sizeof *b->in[k].latency);
  atomic_store_explicit(&b->live, true, memory_order_release);
  bool any = false;
  for (int k = 0; k < b->nout; k++) any |= !b->out[k].stream;
  if (b->on_publish && any) {
    if (sem_init(&b->wake, 0, 0) != 0) return tx_stop_run(c, "net: cannot make the sender's semaphore"), -1;
    b->wake_made = true;
  }
  if ((b->poll_us || b->on_publish) && any) {
    if (pthread_create(&b->sender, NULL, sender, b) != 0) return tx_stop_run(c, "net: cannot start the sender thread"), -1;
    b->sender_started = true;
  }
  // hooks after the thread: a publish from now on wakes it; one before is sent by its first pass
  for (int k = 0; b->on_publish && k < b->nout; k++)
    if (!b->out[k].stream) {
      const port* pt = &c->in->ports[b->out[k].port.id - 1];
      if (!(b->out[k].hook = tx_model_add_hook(b->model, pt->comp, on_publish, b)))
        return tx_stop_run(c, "net: %s", tx_error()), -1;
    }
  return 0;
}

// send a component's publish if it is new; the thread that owns o's hazard slot calls it
static void send_component(bridge* b, outbound* o, const tx_snapshot* snap) {
  if (snap->seq == 0 || snap->seq == o->last_seq) return; // nothing new
  o->last_seq = snap->seq;
  tx_net_Snapshot s;
  tx_net_pack(&s, b->tag, o->name, o->type, snap);
  if (dds_write(o->writer, &s) < 0) tx_warn(b->ctx, b->send_failed);
  else atomic_fetch_add_explicit(&b->sent, 1, memory_order_relaxed);
}

static void send_all(bridge* b) {
  for (int k = 0; k < b->nout; k++)
    if (!b->out[k].stream) {
      tx_snapshot snap = tx_model_acquire(b->model, b->out[k].reader);
      send_component(b, &b->out[k], &snap);
    }
}

// on_publish: sends each publish as soon as the hook wakes it; poll_us > 0:
// within poll_us of it. Either way not at the bridge's next tick
static void* sender(void* arg) {
  bridge* b = arg;
  pthread_setname_np(pthread_self(), "tx-net-send");
  if (b->on_publish) {
    while (!atomic_load_explicit(&b->sender_stop, memory_order_acquire)) {
      // cleared before the pass: a publish during it posts again, and is not lost
      atomic_store_explicit(&b->pending, false, memory_order_release);
      send_all(b);
      while (sem_wait(&b->wake) != 0 && errno == EINTR) {}
    }
    return NULL;
  }
  struct timespec next;
  clock_gettime(CLOCK_MONOTONIC, &next);
  while (!atomic_load_explicit(&b->sender_stop, memory_order_acquire)) {
    send_all(b);
    next.tv_nsec += (long)b->poll_us * 1000;
    while (next.tv_nsec >= 1000000000) next.tv_nsec -= 1000000000, next.tv_sec++;
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    if (now.tv_sec > next.tv_sec || (now.tv_sec == next.tv_sec && now.tv_nsec > next.tv_nsec)) next = now; // late: no catching up
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL);
  }
  return NULL;
}

// the local simulation time that CLOCK_MONOTONIC now stands for: the least
// offset seen is the tick that ran least late
static void track_clock(tx_ctx* c, bridge* b) {
  int64_t offset = tx_mono_ns() - tx_sim_ns(c);
  if (tx_step_index(c) == 0 || offset < atomic_load_explicit(&b->clock_offset, memory_order_relaxed))
    atomic_store_explicit(&b->clock_offset, offset, memory_order_relaxed);
}

static void step(tx_ctx* c, void* self) {
  bridge* b = self;
  track_clock(c, b);
  for (int k = 0; k < b->nout; k++) {
    outbound* o = &b->out[k];
    if (o->stream) {
      for (tx_event e; tx_next_event(c, o->port, &e);) {
        tx_net_Event s;
        tx_net_pack_event(&s, b->tag, o->name, &e);
        if (dds_write(o->writer, &s) < 0) tx_warn(c, b->send_failed);
        else atomic_fetch_add_explicit(&b->events_sent, 1, memory_order_relaxed);
      }
      continue;
    }
    if (b->sender_started) continue; // the sender thread's
    tx_snapshot snap = tx_read(c, o->port);
    send_component(b, o, &snap);
  }
}

static void stop_sender(bridge* b) {
  for (int k = 0; k < b->nout; k++) // waits for a hook call under way: none after this
    if (b->out[k].hook) tx_model_remove_hook(b->model, b->out[k].hook), b->out[k].hook = 0;
  if (b->sender_started) {
    atomic_store_explicit(&b->sender_stop, true, memory_order_release);
    if (b->wake_made) sem_post(&b->wake);
    pthread_join(b->sender, NULL);
    b->sender_started = false;
  }
  if (b->wake_made) sem_destroy(&b->wake), b->wake_made = false;
}

static void finish(tx_ctx* c, void* self) {
  bridge* b = self;
  stop_sender(b);
  atomic_store_explicit(&b->live, false, memory_order_release);
  pthread_mutex_lock(&b->lock); // a listener call under way ends first
  pthread_mutex_unlock(&b->lock);
  tx_set_result(c, b->r_sent, (double)atomic_load(&b->sent));
  tx_set_result(c, b->r_received, (double)atomic_load(&b->received));
  tx_set_result(c, b->r_events_sent, (double)atomic_load(&b->events_sent));
  tx_set_result(c, b->r_events_received, (double)atomic_load(&b->events_received));
  for (int k = 0; k < b->nin; k++)
    if (b->in[k].latency && b->in[k].latency->count) {
      tx_set_result(c, b->in[k].r_p50, tx_hist_percentile(b->in[k].latency, 0.5) / 1e3);
      tx_set_result(c, b->in[k].r_p99, tx_hist_percentile(b->in[k].latency, 0.99) / 1e3);
    }
}

static void fini(void* self) {
  bridge* b = self;
  if (!b) return;
  atomic_store(&b->live, false);
  stop_sender(b); // a run whose init failed later never finished
  if (b->participant > 0) dds_delete(b->participant); // its readers, writers and topics; waits for listeners
  pthread_mutex_destroy(&b->lock);
  for (int k = 0; k < b->nin; k++) free(b->in[k].latency);
  free(b);
}

const tx_controller_class tx_net_dds_controller = {
    .type = "net.dds",
    .summary = "carries components and event streams between the processes of a session over Cyclone DDS",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
