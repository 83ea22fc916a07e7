// udp: a haptic device on the other end of a UDP socket, served by
// tactus-device (docs/device-protocol.md). The haptics thread never waits on
// the network: each read drains what arrived and keeps the newest valid
// state; each write sends one force packet and returns.
#include "device_udp.h"

#include "device_protocol.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <unistd.h>

// packets one read takes at most: a flood cannot hold the haptics tick
#define DRAIN_MAX 256
#define HELLO_EVERY_NS 20000000 // resend the hello while waiting for an answer

struct tx_device {
  int fd;
  struct sockaddr_in peer;    // the device server: the only source accepted
  uint32_t session;           // ours
  uint64_t seq;               // our last sent
  double rate_hz;             // our tick, told in the hello
  tx_dp_peer from;            // the device's session and newest sequence
  bool got_info;              // the device's hello arrived
  tx_device_info info;        // from it
  bool got_state;             // a state arrived
  tx_device_state state;      // the newest; t_ns on the device's clock
  int64_t echo_ns;            // send_ns of the newest packet accepted
  int64_t arrival_ns;         // when it arrived here, monotonic
  tx_device_udp_counts counts;
};

static bool same_addr(const struct sockaddr_in* a, const struct sockaddr_in* b) {
  return a->sin_family == b->sin_family && a->sin_addr.s_addr == b->sin_addr.s_addr && a->sin_port == b->sin_port;
}

// one valid or invalid datagram from the socket
static void consider(tx_device* d, const uint8_t* buf, size_t n, const struct sockaddr_in* from, int64_t arrival) {
  if (!same_addr(from, &d->peer)) { // connect() filters already; this holds if it ever does not
    d->counts.foreign++;
    return;
  }
  tx_dp_packet p;
  if (tx_dp_decode(buf, n, &p) != TX_DP_OK) {
    d->counts.malformed++;
    return;
  }
  // a device session is opened by its hello and kept for the run: a restarted device restarts the run
  tx_dp_verdict v = tx_dp_peer_accept(&d->from, &p, false);
  if (v == TX_DP_STALE) d->counts.stale++;
  if (v == TX_DP_OTHER_SESSION) d->counts.other_session++;
  if (v != TX_DP_ACCEPT && v != TX_DP_NEW_SESSION) return;
  d->echo_ns = p.send_ns;
  d->arrival_ns = arrival;
  if (p.type == TX_DP_STATE) {
    d->state = p.state;
    d->got_state = true;
    d->counts.states++;
  } else if (p.type == TX_DP_HELLO && !d->got_info) {
    d->info = p.hello.info;
    d->got_info = true;
  } else if (p.type != TX_DP_HELLO) {
    d->counts.unexpected++;
  }
}

// take what arrived; true if a new state was among it
static bool drain(tx_device* d) {
  uint64_t before = d->counts.states;
  for (int i = 0; i < DRAIN_MAX; i++) {
    uint8_t buf[TX_DP_MAX_SIZE + 1]; // one more: a longer datagram shows as too long, not as a fit
    struct sockaddr_in from;
    int64_t arrival;
    long got = tx_dp_recv(d->fd, buf, sizeof buf, &from, &arrival);
    if (got >= 0) consider(d, buf, (size_t)got, &from, arrival);
    else if (errno != EINTR && errno != ECONNREFUSED) break; // EAGAIN: nothing more; ICMP errors of earlier sends pass
  }
  return d->counts.states > before;
}

static void send_packet(tx_device* d, tx_dp_packet* p) {
  uint8_t buf[TX_DP_MAX_SIZE];
  size_t n = tx_dp_stamp_encode(p, d->session, &d->seq, d->echo_ns, d->arrival_ns, buf, sizeof buf);
  if (n == 0 || send(d->fd, buf, n, MSG_DONTWAIT | MSG_NOSIGNAL) != (ssize_t)n) d->counts.send_errors++;
}

static uint32_t new_session(void) {
  uint32_t s = 0;
  if (getrandom(&s, sizeof s, GRND_NONBLOCK) != (ssize_t)sizeof s) s = (uint32_t)(tx_dp_now_ns() ^ ((int64_t)getpid() << 16));
  return s ? s : 1;
}

static void close_udp(tx_device* d) {
  if (d->fd >= 0) {
    // say zero before going: the device holds the last force until told otherwise
    const double zero[3] = {0, 0, 0};
    tx_dp_packet p = {.type = TX_DP_FORCE};
    memcpy(p.force, zero, sizeof p.force);
    if (d->got_info) send_packet(d, &p);
    close(d->fd);
  }
  free(d);
}

static tx_device* fail(tx_device* d, char* err, size_t n, const char* arg, const char* fmt, const char* what) {
  char why[256];
  snprintf(why, sizeof why, fmt, what);
  snprintf(err, n, "device 'udp:%s': %s", arg, why);
  if (d) close_udp(d);
  return NULL;
}

// say hello until the device answers with its hello and a first state
static bool handshake(tx_device* d) {
  int64_t start = tx_dp_now_ns(), next_hello = start;
  int64_t deadline = start + (int64_t)(TX_DEVICE_UDP_WAIT_S * 1e9);
  for (int64_t now = start; now < deadline && !(d->got_info && d->got_state); now = tx_dp_now_ns()) {
    if (now >= next_hello && !d->got_info) {
      tx_dp_packet hello = {.type = TX_DP_HELLO, .hello.rate_hz = d->rate_hz};
      send_packet(d, &hello);
      next_hello = now + HELLO_EVERY_NS;
    }
    int wait_ms = (int)((next_hello - now) / 1000000) + 1;
    struct pollfd pfd = {d->fd, POLLIN, 0};
    poll(&pfd, 1, wait_ms < 1 ? 1 : wait_ms);
    drain(d);
  }
  return d->got_info && d->got_state;
}

static tx_device* open_udp(const char* arg, double period_s, char* err, size_t n) {
  // HOST:PORT[,bind=ADDR:PORT]
  char peer_s[128], bind_s[128] = "127.0.0.1:0";
  const char* comma = strchr(arg, ',');
  size_t len = comma ? (size_t)(comma - arg) : strlen(arg);
  if (len >= sizeof peer_s) return fail(NULL, err, n, arg, "%s", "the address is too long");
  memcpy(peer_s, arg, len);
  peer_s[len] = 0;
  if (comma) {
    if (strncmp(comma, ",bind=", 6) != 0 || strlen(comma + 6) >= sizeof bind_s)
      return fail(NULL, err, n, arg, "%s", "expected udp:HOST:PORT or udp:HOST:PORT,bind=ADDR:PORT");
    snprintf(bind_s, sizeof bind_s, "%s", comma + 6);
  }
  tx_device* d = calloc(1, sizeof *d);
  if (!d) return fail(NULL, err, n, arg, "%s", "out of memory");
  d->fd = -1;
  const char* why = NULL;
  struct sockaddr_in local;
  if (!tx_dp_parse_addr(peer_s, false, &d->peer, &why)) return fail(d, err, n, arg, "%s (udp:HOST:PORT)", why);
  if (!tx_dp_parse_addr(bind_s, true, &local, &why)) return fail(d, err, n, arg, "bind=: %s", why);
  // loopback unless told otherwise: a peer on another machine needs bind= to say which interface
  bool peer_loopback = (ntohl(d->peer.sin_addr.s_addr) >> 24) == 127;
  bool local_loopback = (ntohl(local.sin_addr.s_addr) >> 24) == 127;
  if (!comma && !peer_loopback)
    return fail(d, err, n, arg, "%s", "the backend binds to loopback: for a device on another machine add ,bind=ADDR:PORT");
  if (local_loopback && !peer_loopback)
    return fail(d, err, n, arg, "%s", "a loopback bind= cannot reach a peer on another machine");
  if (!(period_s > 0 && 1 / period_s <= TX_DP_MAX_RATE_HZ))
    return fail(d, err, n, arg, "%s", "the haptics rate is out of range");
  d->rate_hz = 1 / period_s;
  d->session = new_session();

  d->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (d->fd < 0) return fail(d, err, n, arg, "socket: %s", strerror(errno));
  int on = 1;
  setsockopt(d->fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on); // arrival stamps; without them, read time
  if (bind(d->fd, (struct sockaddr*)&local, sizeof local) != 0) return fail(d, err, n, arg, "bind: %s", strerror(errno));
  // the kernel then delivers only the peer's datagrams
  if (connect(d->fd, (struct sockaddr*)&d->peer, sizeof d->peer) != 0)
    return fail(d, err, n, arg, "connect: %s", strerror(errno));
  if (!handshake(d)) {
    const char* what = d->got_info ? "the device said hello but sent no state" : "no hello from the device";
    char msg[160];
    snprintf(msg, sizeof msg, "%s within %g s (is tactus-device serving there?)", what, TX_DEVICE_UDP_WAIT_S);
    return fail(d, err, n, arg, "%s", msg);
  }
  const tx_device_info* in = &d->info;
  bool usable = in->max_force > 0;
  for (int i = 0; i < 3; i++) usable = usable && in->workspace_min[i] < in->workspace_max[i];
  if (!usable) return fail(d, err, n, arg, "%s", "the device's hello gave no max force or an empty workspace");
  return d;
}

static void info_udp(const tx_device* d, tx_device_info* out) { *out = d->info; }

static bool read_udp(tx_device* d, double t, tx_device_state* s) {
  (void)t; // the device's clock rules: t_ns is its sampling time
  bool fresh = drain(d);
  *s = d->state;
  return fresh;
}

static void write_udp(tx_device* d, const double force[3]) {
  tx_dp_packet p = {.type = TX_DP_FORCE};
  for (int i = 0; i < 3; i++) p.force[i] = isfinite(force[i]) ? force[i] : 0; // the safety chain sees to it; twice is cheap
  send_packet(d, &p);
  d->counts.forces++;
}

void tx_device_udp_counts_get(const tx_device* d, tx_device_udp_counts* out) { *out = d->counts; }

const tx_device_backend tx_device_udp = {"udp", open_udp, info_udp, read_udp, write_udp, close_udp};
