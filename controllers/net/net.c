// The Cyclone DDS side of the bridge: configuration, topics, QoS, packing.
#include "net.h"

#include "../../model/error.h"

#include <arpa/inet.h>
#include <pthread.h>
#include <sched.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool tx_net_peer_valid(const char* peer) {
  size_t n = peer ? strlen(peer) : 0;
  if (n == 0 || n > 253) return tx_set_error("expected an IPv4 address or a host name, got '%s'", peer ? peer : ""), false;
  struct in_addr a;
  if (inet_pton(AF_INET, peer, &a) == 1) return true;
  bool digits_and_dots = true;
  for (const char* c = peer; *c; c++) {
    bool ok = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '-' || *c == '.';
    if (!ok) return tx_set_error("'%s': a peer is an IPv4 address or a host name, not '%c'", peer, *c), false;
    if (!(*c >= '0' && *c <= '9') && *c != '.') digits_and_dots = false;
  }
  // 10.0.0.300 is a bad address, not a host name
  if (digits_and_dots) return tx_set_error("'%s' is not an IPv4 address", peer), false;
  if (peer[0] == '-' || peer[0] == '.' || strstr(peer, "..")) return tx_set_error("'%s' is not a host name", peer), false;
  return true;
}

int tx_net_config(char* out, size_t size, const char* const* peers, int npeers) {
  return tx_net_config_priority(out, size, peers, npeers, 0);
}

int tx_net_config_priority(char* out, size_t size, const char* const* peers, int npeers, int priority) {
  if (npeers < 0 || npeers > TX_NET_PEERS_MAX) return tx_set_error("at most %d peers", TX_NET_PEERS_MAX), -1;
  char list[TX_NET_CONFIG_MAX / 2] = "";
  size_t len = 0;
  for (int i = 0; i < npeers; i++) {
    if (!tx_net_peer_valid(peers[i])) return tx_error_prefix("peers[%d]", i), -1;
    int w = snprintf(list + len, sizeof list - len, "<Peer address=\"%s\"/>", peers[i]);
    if (w < 0 || (size_t)w >= sizeof list - len) return tx_set_error("the peer list is too long"), -1;
    len += (size_t)w;
  }
  // loopback alone unless peers are named; no multicast either way, so
  // discovery goes only where the list says
  const char* iface = npeers ? "<NetworkInterface autodetermine=\"true\"/>" : "<NetworkInterface address=\"127.0.0.1\"/>";
  char threads[320] = "";
  if (priority > 0)
    snprintf(threads, sizeof threads,
             "<Threads><Thread name=\"recv\"><Scheduling><Class>realtime</Class><Priority>%d</Priority></Scheduling>"
             "</Thread></Threads><Internal><MultipleReceiveThreads>false</MultipleReceiveThreads></Internal>", priority);
  int w = snprintf(out, size,
                   "<CycloneDDS><Domain id=\"any\"><General><Interfaces>%s</Interfaces>"
                   "<AllowMulticast>false</AllowMulticast></General>"
                   "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
                   "<Peers><Peer address=\"127.0.0.1\"/>%s</Peers></Discovery>%s</Domain></CycloneDDS>",
                   iface, list, threads);
  if (w < 0 || (size_t)w >= size) return tx_set_error("the configuration is too long"), -1;
  return 0;
}

uint64_t tx_net_session_tag(const char* session, int domain) {
  char text[128];
  snprintf(text, sizeof text, "%s/%d", session, domain);
  uint64_t h = 1469598103934665603ull;
  for (const unsigned char* c = (const unsigned char*)text; *c; c++) h = (h ^ *c) * 1099511628211ull;
  return h;
}

void tx_net_topic_name(char* out, size_t size, bool stream, const char* name) {
  // DDS topic names take letters, digits, '_' and '/', not '.': a component
  // name has no '/', so "skin.x" -> "tx/c/skin/x" is one to one
  int n = snprintf(out, size, "tx/%s/%s", stream ? "e" : "c", name);
  for (char* c = out + 5; n > 5 && *c; c++)
    if (*c == '.') *c = '/';
}

static void* try_fifo(void* arg) {
  struct sched_param sp = {.sched_priority = sched_get_priority_min(SCHED_FIFO)};
  *(bool*)arg = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  return NULL;
}

// whether this process may run a thread at SCHED_FIFO (root, CAP_SYS_NICE or
// an RLIMIT_RTPRIO): asked once, on a thread of its own
static bool fifo_ok;
static void ask_fifo(void) {
  pthread_t t;
  if (pthread_create(&t, NULL, try_fifo, &fifo_ok) == 0) pthread_join(t, NULL);
}
static bool fifo_allowed(void) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, ask_fifo);
  return fifo_ok;
}

dds_entity_t tx_net_participant(int domain, const char* const* peers, int npeers) {
  if (domain < 0 || domain > TX_NET_DOMAIN_MAX) return tx_set_error("domain %d is not in [0, %d]", domain, TX_NET_DOMAIN_MAX), -1;
  const char* uri = getenv("CYCLONEDDS_URI");
  if (!uri || !*uri) {
    char xml[TX_NET_CONFIG_MAX];
    // Cyclone's receive thread delivers every sample (a device's state, a
    // force model): on a busy host at normal priority it runs in bursts, and a
    // keep-last-1 reader then sees one sample in several. Where SCHED_FIFO is
    // allowed it runs just below the haptics thread.
    int priority = fifo_allowed() ? sched_get_priority_max(SCHED_FIFO) - 11 : 0;
    if (tx_net_config_priority(xml, sizeof xml, peers, npeers, priority)) return -1;
    dds_entity_t d = dds_create_domain((dds_domainid_t)domain, xml);
    // a second bridge in this process shares the domain already made
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET)
      return tx_set_error("DDS domain %d: %s", domain, dds_strretcode(d)), d;
  }
  dds_entity_t p = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (p < 0) tx_set_error("DDS participant on domain %d: %s", domain, dds_strretcode(p));
  return p;
}

dds_qos_t* tx_net_qos(tx_net_kind kind) {
  dds_qos_t* q = dds_create_qos();
  switch (kind) {
  case TX_NET_FAST:
    dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    break;
  case TX_NET_STATE:
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    break;
  case TX_NET_EVENTS:
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL); // a late reader still gets what was sent
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_destination_order(q, DDS_DESTINATIONORDER_BY_SOURCE_TIMESTAMP);
    break;
  }
  return q;
}

void tx_net_pack(tx_net_Snapshot* out, uint64_t tag, const char* name, tx_type type, const tx_snapshot* snap) {
  out->session = tag;
  snprintf(out->name, sizeof out->name, "%s", name);
  out->seq = snap->seq;
  out->sim_ns = snap->sim_ns;
  out->mono_ns = snap->mono_ns; // the writer's publish: the mirror's added latency is measured from it
  out->type = (uint8_t)type;
  out->rows = snap->rows;
  out->cols = snap->cols;
  uint32_t bytes = (uint32_t)((size_t)snap->rows * snap->cols * tx_type_size(type));
  out->data = (dds_sequence_octet){._maximum = bytes, ._length = bytes, ._buffer = (uint8_t*)snap->data, ._release = false};
}

int tx_net_check(const tx_net_Snapshot* s, uint64_t tag, const tx_component_def* def) {
  if (s->session != tag) return 1;
  if (memchr(s->name, 0, sizeof s->name) == NULL || strcmp(s->name, def->name) != 0) return 2;
  if (s->type != (uint8_t)def->type || s->cols != def->cols || s->rows > def->rows) return 2;
  if ((uint64_t)s->data._length != (uint64_t)s->rows * s->cols * tx_type_size(def->type)) return 2;
  return 0;
}

void tx_net_pack_event(tx_net_Event* out, uint64_t tag, const char* stream, const tx_event* e) {
  out->session = tag;
  snprintf(out->stream, sizeof out->stream, "%s", stream);
  out->seq = e->seq;
  out->sim_ns = e->sim_ns;
  out->mono_ns = tx_mono_ns();
  out->kind = e->kind;
  out->source = e->source;
  memcpy(out->value, e->value, sizeof out->value);
}

int tx_net_check_event(const tx_net_Event* s, uint64_t tag, const char* stream) {
  if (s->session != tag) return 1;
  if (memchr(s->stream, 0, sizeof s->stream) == NULL || strcmp(s->stream, stream) != 0) return 2;
  return 0;
}

void tx_net_unpack_event(const tx_net_Event* s, tx_event* out) {
  *out = (tx_event){.seq = s->seq, .sim_ns = s->sim_ns, .kind = s->kind, .source = s->source};
  memcpy(out->value, s->value, sizeof out->value);
}
