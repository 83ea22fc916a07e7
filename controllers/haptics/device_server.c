// A device served over UDP; see device_server.h and docs/device-protocol.md.
#include "device_server.h"

#include "../../model/error.h"

#include "device.h"
#include "device_protocol.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define DRAIN_MAX 256          // packets taken per wake: a flood cannot starve the state ticks
#define IDLE_WAIT_NS 100000000 // between checks of the stop flag before the first hello

struct tx_device_server {
  tx_device_server_def def;
  tx_device_handle dev;
  tx_device_info info;
  int fd;
  uint32_t session;           // ours
  uint64_t seq;               // our last sent
  bool locked;                // the peer is known
  struct sockaddr_in peer;    // then, the only source accepted
  tx_dp_peer from;            // the peer's session and newest sequence
  uint32_t client;            // the session of the client served last, 0 before the first
  int64_t echo_ns;            // send_ns of the newest packet accepted
  int64_t arrival_ns;         // when it arrived, monotonic
  bool streaming;             // a client said hello and has not gone: states flow
  int64_t first_ns;           // the first hello, for the duration
  int64_t t0_ns;              // when this client's stream started: device time 0
  bool ramp_pending;          // a client said hello: its next force starts the ramp
  int64_t ramp_from_ns;       // the force the ramp started from
  int64_t next_ns;            // the next state tick
  int64_t last_force_ns;      // arrival of the newest force
  bool forcing;               // a force from the peer is on the device
  int64_t last_echo_measured; // the newest state a round trip was measured for
  tx_hist loop, link;         // round trips, ns, the whole session
  tx_device_server_stats stats;
};

tx_device_server_def tx_device_server_def_default(void) {
  tx_device_server_def d = {
      .rate_hz = 1000, .force_timeout_s = 0.02, .client_timeout_s = 1, .ramp_s = 0.005, .align_s = 120e-6};
  d.listen.sin_family = AF_INET;
  d.listen.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  d.listen.sin_port = htons(TX_DEVICE_SERVER_PORT);
  d.peer.sin_family = AF_INET;
  return d;
}

tx_device_server* tx_device_server_open(const tx_device_server_def* def) {
  if (!def->spec || !*def->spec) return tx_set_error("no device to serve"), NULL;
  if (!(def->rate_hz > 0 && def->rate_hz <= TX_DP_MAX_RATE_HZ))
    return tx_set_error("rate %g Hz: expected (0, %g]", def->rate_hz, TX_DP_MAX_RATE_HZ), NULL;
  if (!(def->duration_s >= 0 && def->duration_s <= 1e7)) return tx_set_error("duration: out of range"), NULL;
  if (!(def->force_timeout_s > 0 && def->force_timeout_s <= 10))
    return tx_set_error("force timeout: expected (0, 10] s"), NULL;
  if (!(def->client_timeout_s > 0 && def->client_timeout_s <= 60))
    return tx_set_error("client timeout: expected (0, 60] s"), NULL;
  if (!(def->ramp_s >= 0 && def->ramp_s <= 1)) return tx_set_error("ramp: expected [0, 1] s"), NULL;
  tx_device_server* s = calloc(1, sizeof *s);
  if (!s) return tx_set_error("out of memory"), NULL;
  s->def = *def;
  s->fd = -1;
  if (tx_device_open(def->spec, 1 / def->rate_hz, &s->dev)) {
    tx_device_server_close(s);
    return NULL;
  }
  s->dev.backend->info(s->dev.device, &s->info);
  char where[64];
  s->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  int on = 1;
  if (s->fd >= 0) setsockopt(s->fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  if (s->fd < 0 || bind(s->fd, (const struct sockaddr*)&def->listen, sizeof def->listen) != 0) {
    tx_set_error("--listen %s: %s", tx_dp_addr_text(&def->listen, where, sizeof where), strerror(errno));
    tx_device_server_close(s);
    return NULL;
  }
  if (getrandom(&s->session, sizeof s->session, GRND_NONBLOCK) != (ssize_t)sizeof s->session)
    s->session = (uint32_t)(tx_dp_now_ns() ^ ((int64_t)getpid() << 16));
  if (!s->session) s->session = 1;
  if (def->peer.sin_port) s->locked = true, s->peer = def->peer;
  return s;
}

uint16_t tx_device_server_port(const tx_device_server* s) {
  struct sockaddr_in a = {0};
  socklen_t len = sizeof a;
  getsockname(s->fd, (struct sockaddr*)&a, &len);
  return ntohs(a.sin_port);
}

static void send_packet(tx_device_server* s, tx_dp_packet* p) {
  uint8_t buf[TX_DP_MAX_SIZE];
  size_t size = tx_dp_stamp_encode(p, s->session, &s->seq, s->echo_ns, s->arrival_ns, buf, sizeof buf);
  if (size == 0 || sendto(s->fd, buf, size, MSG_DONTWAIT | MSG_NOSIGNAL, (const struct sockaddr*)&s->peer,
                          sizeof s->peer) != (ssize_t)size)
    s->stats.send_errors++;
}

static void zero_device(tx_device_server* s) {
  const double zero[3] = {0, 0, 0};
  s->dev.backend->write(s->dev.device, zero);
  s->forcing = false;
}

// one datagram
// Both ends tick at the same rate but in no set phase, so a state can wait up
// to a whole period at the client before its tick reads it. The client tells
// how long it waited (echo_hold_ns); shift the next sends a quarter of the way
// toward the aim each time, the error taken within half a period either way
// (a wait of almost a period means the state came just after a tick).
static void align(tx_device_server* s, uint32_t hold_ns) {
  if (s->def.align_s <= 0) return;
  const int64_t period = (int64_t)llround(1e9 / s->def.rate_hz);
  int64_t error = (int64_t)hold_ns - (int64_t)llround(s->def.align_s * 1e9);
  error %= period;
  if (error > period / 2) error -= period;
  if (error < -period / 2) error += period;
  s->next_ns += error / 4;
}

// a client's hello was accepted: a new client (or a new run of the
// same one) starts the device's time again; any client starting or coming
// back after it was let go has its forces ramp from zero
static void hello_accepted(tx_device_server* s, const tx_dp_packet* p) {
  bool new_client = p->session != s->client;
  if (new_client) { // the forces and round trips of the one before no longer count
    if (s->forcing) zero_device(s);
    s->last_echo_measured = 0;
    s->client = p->session;
    s->stats.clients++;
  }
  if (new_client || !s->streaming) {
    s->ramp_pending = true;
    int64_t now = tx_dp_now_ns();
    if (!s->first_ns) s->first_ns = now;
    if (new_client) s->t0_ns = now;
    if (!s->streaming) s->next_ns = now;
    s->streaming = true;
  }
}

// the client fell silent: stop streaming to it, and without a fixed peer let
// the next client that says hello take its place
static void let_go(tx_device_server* s) {
  if (s->forcing) zero_device(s);
  s->streaming = false;
  if (!s->def.peer.sin_port) s->locked = false;
  s->from = (tx_dp_peer){0}; // whoever comes next opens a session of its own clock
  s->stats.clients_gone++;
}

static void consider(tx_device_server* s, const uint8_t* buf, size_t n, const struct sockaddr_in* from,
                     int64_t arrival) {
  if (s->locked && !tx_dp_same_addr(from, &s->peer)) {
    s->stats.foreign++;
    return;
  }
  tx_dp_packet p;
  if (tx_dp_decode(buf, n, &p) != TX_DP_OK) {
    s->stats.malformed++;
    return;
  }
  if (!s->locked) { // the first valid hello picks the peer, until it is gone
    if (p.type != TX_DP_HELLO) {
      s->stats.other_session++;
      return;
    }
    s->locked = true;
    s->peer = *from;
  }
  // a new session of the same peer (a new run) may start while serving
  tx_dp_verdict v = tx_dp_peer_accept(&s->from, &p, true);
  if (v == TX_DP_STALE) s->stats.stale++;
  if (v == TX_DP_OTHER_SESSION) s->stats.other_session++;
  if (v != TX_DP_ACCEPT && v != TX_DP_NEW_SESSION) return;
  s->echo_ns = p.send_ns;
  s->arrival_ns = arrival;
  if (p.type == TX_DP_HELLO) {
    hello_accepted(s, &p);
    tx_dp_packet hello = {.type = TX_DP_HELLO, .hello = {s->def.rate_hz, s->info}};
    send_packet(s, &hello);
    s->stats.hellos++;
  } else if (p.type == TX_DP_FORCE && s->streaming) {
    // the safety ramp: a client's forces after its hello are scaled from zero
    // (its first) up over ramp_s, so a switch of clients never steps the force
    if (s->ramp_pending) s->ramp_from_ns = arrival, s->ramp_pending = false;
    double ramp = (double)(arrival - s->ramp_from_ns) * 1e-9, force[3];
    double gain = s->def.ramp_s > 0 && ramp < s->def.ramp_s ? fmax(0, ramp / s->def.ramp_s) : 1;
    if (gain < 1) s->stats.ramped++;
    for (int i = 0; i < 3; i++) force[i] = gain * p.force[i];
    s->dev.backend->write(s->dev.device, force);
    s->stats.forces++;
    s->last_force_ns = arrival;
    s->forcing = true;
    // the first force computed from a state measures its round trip, on our clock only
    if (p.echo_ns > s->last_echo_measured && p.echo_ns >= s->t0_ns && p.echo_ns <= arrival) {
      s->last_echo_measured = p.echo_ns;
      int64_t loop = arrival - p.echo_ns;
      tx_hist_add(&s->loop, loop);
      tx_hist_add(&s->link, loop - (int64_t)p.echo_hold_ns);
      s->stats.round_trips++;
      align(s, p.echo_hold_ns);
    }
  } else if (p.type != TX_DP_FORCE) {
    s->stats.unexpected++;
  }
}

static int drain(tx_device_server* s) {
  for (int i = 0; i < DRAIN_MAX; i++) {
    uint8_t buf[TX_DP_MAX_SIZE + 1];
    struct sockaddr_in from;
    int64_t arrival;
    long got = tx_dp_recv(s->fd, buf, sizeof buf, &from, &arrival);
    if (got >= 0) consider(s, buf, (size_t)got, &from, arrival);
    else if (errno == EAGAIN || errno == EWOULDBLOCK) return 0;
    else if (errno != EINTR && errno != ECONNREFUSED) return tx_set_error("receive: %s", strerror(errno)), -1;
  }
  return 0;
}

// the state tick: sample the device at its scheduled time and send it
static void tick(tx_device_server* s, int64_t now, int64_t period) {
  double t = (double)(s->next_ns - s->t0_ns) * 1e-9;
  tx_device_state st;
  if (s->dev.backend->read(s->dev.device, t, &st)) { // a device with nothing new (a replay's end) falls silent
    tx_dp_packet p = {.type = TX_DP_STATE, .state = st};
    send_packet(s, &p);
    s->stats.states++;
  }
  s->next_ns += period;
  if (now - s->next_ns > period) { // far behind: skip the missed ticks rather than burst them
    s->stats.late_ticks++;
    s->next_ns = now + period;
  }
}

int tx_device_server_run(tx_device_server* s, const atomic_int* stop) {
  const int64_t period = (int64_t)llround(1e9 / s->def.rate_hz);
  const int64_t duration = (int64_t)llround(s->def.duration_s * 1e9), force_timeout = (int64_t)llround(s->def.force_timeout_s * 1e9);
  const int64_t client_timeout = (int64_t)llround(s->def.client_timeout_s * 1e9);
  int rc = 0;
  while (!atomic_load(stop)) {
    int64_t now = tx_dp_now_ns();
    if (s->first_ns && duration && now - s->first_ns >= duration) break;
    if (s->streaming && now >= s->next_ns) tick(s, now, period);
    if (s->forcing && now - s->last_force_ns > force_timeout) { // the simulator went quiet
      zero_device(s);
      s->stats.force_timeouts++;
    }
    // sleep until input, the next tick or a signal
    int64_t wait = s->streaming ? s->next_ns - tx_dp_now_ns() : IDLE_WAIT_NS;
    if (wait < 0) wait = 0;
    struct timespec to = {wait / 1000000000, wait % 1000000000};
    struct pollfd pfd = {s->fd, POLLIN, 0};
    if (ppoll(&pfd, 1, &to, NULL) < 0 && errno != EINTR) {
      rc = -1, tx_set_error("poll: %s", strerror(errno));
      break;
    }
    if (drain(s)) {
      rc = -1;
      break;
    }
    // after the drain: what waited in the socket while this thread was held up still counts
    if (s->streaming && tx_dp_now_ns() - s->arrival_ns > client_timeout) let_go(s);
  }
  zero_device(s);
  return rc;
}

void tx_device_server_get_stats(const tx_device_server* s, tx_device_server_stats* out) {
  *out = s->stats;
  out->loop = tx_hist_percentiles(&s->loop);
  out->link = tx_hist_percentiles(&s->link);
}

void tx_device_server_close(tx_device_server* s) {
  if (!s) return;
  if (s->dev.device) zero_device(s);
  tx_device_close(&s->dev);
  if (s->fd >= 0) close(s->fd);
  free(s);
}
