// udp: a haptic device on the other end of a UDP socket, served by
// tactus-device (docs/device-protocol.md). The haptics thread never waits on
// the network: each read drains what arrived and keeps the newest valid
// state; each write sends one force packet and returns. A device with no
// state for TX_DEVICE_UDP_LOST_S is lost: one line says so, hello is said
// again every TX_DEVICE_UDP_REJOIN_S, and a server that answers with the
// same limits (the same one, or one restarted) is rejoined, which another
// line says. The force meanwhile is the haptics controller's: its watchdog
// fades it to zero within about 10 ms of the last state.
#include "device_udp.h"

#include "../../model/error.h"

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
#include <unistd.h>

// packets one read takes at most: a flood cannot hold the haptics tick
#define DRAIN_MAX 256
#define HELLO_EVERY_NS 20000000 // resend the hello while waiting for an answer

struct tx_device {
  char name[160];             // "udp:HOST:PORT", for messages
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
  int64_t last_state_ns;      // when the newest state was taken, monotonic
  int64_t sent_ns;            // when the newest packet left, monotonic
  bool lost;                  // no state for TX_DEVICE_UDP_LOST_S
  int64_t lost_ns;            // since when, monotonic
  int64_t next_hello_ns;      // while lost: when to say hello again
  bool told_other;            // while lost: the line about a server with other limits was written
  tx_device_udp_counts counts;
};

static bool same_info(const tx_device_info* a, const tx_device_info* b) {
  bool same = a->max_force == b->max_force && a->max_stiffness == b->max_stiffness && a->damping == b->damping;
  for (int i = 0; i < 3; i++) same = same && a->workspace_min[i] == b->workspace_min[i] && a->workspace_max[i] == b->workspace_max[i];
  return same;
}

// One line on stderr from the haptics thread. It must not wait or allocate:
// the line is formatted on the stack (integers and strings only, which
// snprintf formats without the heap), then written with one write(2), which
// takes no lock, unlike stdio's stderr shared with the other threads; and
// only if stderr can take it at once (a pipe nobody drains would otherwise
// block the tick). A line that cannot be written now is dropped: the counts
// and the run's device_silent warnings still tell the story.
static void say(const char* line, size_t n) {
  struct pollfd pfd = {STDERR_FILENO, POLLOUT, 0};
  if (poll(&pfd, 1, 0) == 1 && (pfd.revents & POLLOUT)) {
    ssize_t w = write(STDERR_FILENO, line, n);
    (void)w; // nothing better to do with a short or failed write of a message
  }
}

// t = 3.012 s, from the simulation time of the tick
static long long ms_of(double t) { return isfinite(t) && fabs(t) < 1e15 ? llround(t * 1e3) : 0; }

static void say_lost(const tx_device* d, double t) {
  char line[320];
  long long ms = ms_of(t);
  int n = snprintf(line, sizeof line,
                   "tactus: device %s lost at t = %lld.%03lld s: no state for %d ms; no force until it is back, "
                   "hello every %d ms\n",
                   d->name, ms / 1000, ms % 1000, (int)(TX_DEVICE_UDP_LOST_S * 1e3), (int)(TX_DEVICE_UDP_REJOIN_S * 1e3));
  if (n > 0) say(line, (size_t)n < sizeof line ? (size_t)n : sizeof line - 1);
}

static void say_back(const tx_device* d, double t, int64_t lost_for_ns, bool restarted) {
  char line[320];
  long long ms = ms_of(t), gone = lost_for_ns / 1000000;
  int n = snprintf(line, sizeof line, "tactus: device %s back at t = %lld.%03lld s after %lld.%03lld s%s\n", d->name,
                   ms / 1000, ms % 1000, gone / 1000, gone % 1000, restarted ? " (a restarted server, rejoined)" : "");
  if (n > 0) say(line, (size_t)n < sizeof line ? (size_t)n : sizeof line - 1);
}

// one valid or invalid datagram from the socket
static void consider(tx_device* d, const uint8_t* buf, size_t n, const struct sockaddr_in* from, int64_t arrival) {
  if (!tx_dp_same_addr(from, &d->peer)) { // connect() filters already; this holds if it ever does not
    d->counts.foreign++;
    return;
  }
  tx_dp_packet p;
  if (tx_dp_decode(buf, n, &p) != TX_DP_OK) {
    d->counts.malformed++;
    return;
  }
  // a restarted server opens a new session with its hello; it is rejoined only
  // if it serves a device of the same limits, which the run's safety chain was
  // set up with
  bool reopen = p.type == TX_DP_HELLO && d->got_info && p.session != d->from.session;
  if (reopen && !same_info(&p.hello.info, &d->info)) {
    d->counts.other_session++;
    d->counts.other_device++;
    return;
  }
  tx_dp_verdict v = tx_dp_peer_accept(&d->from, &p, true);
  if (v == TX_DP_STALE) d->counts.stale++;
  if (v == TX_DP_OTHER_SESSION) d->counts.other_session++;
  if (v != TX_DP_ACCEPT && v != TX_DP_NEW_SESSION) return;
  if (reopen) d->counts.rejoins++;
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
  d->sent_ns = p->send_ns;
  if (n == 0 || send(d->fd, buf, n, MSG_DONTWAIT | MSG_NOSIGNAL) != (ssize_t)n) d->counts.send_errors++;
}

static void send_hello(tx_device* d) {
  tx_dp_packet hello = {.type = TX_DP_HELLO, .hello.rate_hz = d->rate_hz};
  send_packet(d, &hello);
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

static tx_device* fail(tx_device* d, const char* arg, const char* fmt, const char* what) {
  char why[256];
  snprintf(why, sizeof why, fmt, what);
  tx_set_error("device 'udp:%s': %s", arg, why);
  if (d) close_udp(d);
  return NULL;
}

// say hello until the device answers with its hello and a first state
static bool handshake(tx_device* d) {
  int64_t start = tx_dp_now_ns(), next_hello = start;
  int64_t deadline = start + (int64_t)(TX_DEVICE_UDP_WAIT_S * 1e9);
  for (int64_t now = start; now < deadline && !(d->got_info && d->got_state); now = tx_dp_now_ns()) {
    if (now >= next_hello && !d->got_info) {
      send_hello(d);
      next_hello = now + HELLO_EVERY_NS;
    }
    int wait_ms = (int)((next_hello - now) / 1000000) + 1;
    struct pollfd pfd = {d->fd, POLLIN, 0};
    poll(&pfd, 1, wait_ms < 1 ? 1 : wait_ms);
    drain(d);
  }
  return d->got_info && d->got_state;
}

static tx_device* open_udp(const char* arg, double period_s) {
  // HOST:PORT[,bind=ADDR:PORT]
  char peer_s[128], bind_s[128] = "127.0.0.1:0";
  const char* comma = strchr(arg, ',');
  size_t len = comma ? (size_t)(comma - arg) : strlen(arg);
  if (len >= sizeof peer_s) return fail(NULL, arg, "%s", "the address is too long");
  memcpy(peer_s, arg, len);
  peer_s[len] = 0;
  if (comma) {
    if (strncmp(comma, ",bind=", 6) != 0 || strlen(comma + 6) >= sizeof bind_s)
      return fail(NULL, arg, "%s", "expected udp:HOST:PORT or udp:HOST:PORT,bind=ADDR:PORT");
    snprintf(bind_s, sizeof bind_s, "%s", comma + 6);
  }
  tx_device* d = calloc(1, sizeof *d);
  if (!d) return fail(NULL, arg, "%s", "out of memory");
  d->fd = -1;
  snprintf(d->name, sizeof d->name, "udp:%s", peer_s);
  const char* why = NULL;
  struct sockaddr_in local;
  if (!tx_dp_parse_addr(peer_s, false, &d->peer, &why)) return fail(d, arg, "%s (udp:HOST:PORT)", why);
  if (!tx_dp_parse_addr(bind_s, true, &local, &why)) return fail(d, arg, "bind=: %s", why);
  // loopback unless told otherwise: a peer on another machine needs bind= to say which interface
  bool peer_loopback = (ntohl(d->peer.sin_addr.s_addr) >> 24) == 127;
  bool local_loopback = (ntohl(local.sin_addr.s_addr) >> 24) == 127;
  if (!comma && !peer_loopback)
    return fail(d, arg, "%s", "the backend binds to loopback: for a device on another machine add ,bind=ADDR:PORT");
  if (local_loopback && !peer_loopback)
    return fail(d, arg, "%s", "a loopback bind= cannot reach a peer on another machine");
  if (!(period_s > 0 && 1 / period_s <= TX_DP_MAX_RATE_HZ))
    return fail(d, arg, "%s", "the haptics rate is out of range");
  d->rate_hz = 1 / period_s;
  d->session = new_session();

  d->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (d->fd < 0) return fail(d, arg, "socket: %s", strerror(errno));
  int on = 1;
  setsockopt(d->fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on); // arrival stamps; without them, read time
  if (bind(d->fd, (struct sockaddr*)&local, sizeof local) != 0) return fail(d, arg, "bind: %s", strerror(errno));
  // the kernel then delivers only the peer's datagrams
  if (connect(d->fd, (struct sockaddr*)&d->peer, sizeof d->peer) != 0)
    return fail(d, arg, "connect: %s", strerror(errno));
  if (!handshake(d)) {
    const char* what = d->got_info ? "the device said hello but sent no state" : "no hello from the device";
    char msg[160];
    snprintf(msg, sizeof msg, "%s within %g s (is tactus-device serving there?)", what, TX_DEVICE_UDP_WAIT_S);
    return fail(d, arg, "%s", msg);
  }
  const tx_device_info* in = &d->info;
  bool usable = in->max_force > 0;
  for (int i = 0; i < 3; i++) usable = usable && in->workspace_min[i] < in->workspace_max[i];
  if (!usable) return fail(d, arg, "%s", "the device's hello gave no max force or an empty workspace");
  d->last_state_ns = tx_dp_now_ns();
  return d;
}

static void info_udp(const tx_device* d, tx_device_info* out) { *out = d->info; }

// t, the simulation time, only names the moment in messages: the device's
// clock rules, t_ns is its sampling time
static bool read_udp(tx_device* d, double t, tx_device_state* s) {
  uint64_t rejoins = d->counts.rejoins, other = d->counts.other_device;
  bool fresh = drain(d);
  int64_t now = tx_dp_now_ns();
  if (fresh) {
    if (d->lost) {
      d->lost = false;
      d->counts.returns++;
      say_back(d, t, now - d->lost_ns, d->counts.rejoins > rejoins);
    }
    d->last_state_ns = now;
  } else if (!d->lost && now - d->last_state_ns > (int64_t)(TX_DEVICE_UDP_LOST_S * 1e9)) {
    d->lost = true;
    d->lost_ns = now;
    d->next_hello_ns = now;
    d->told_other = false;
    d->counts.losses++;
    say_lost(d, t);
  }
  if (d->lost && d->counts.other_device > other && !d->told_other) {
    d->told_other = true;
    char line[320];
    int n = snprintf(line, sizeof line, "tactus: device %s: a server of other limits answered; not used, as the "
                     "run's safety limits are those of the device it started with\n", d->name);
    if (n > 0) say(line, (size_t)n < sizeof line ? (size_t)n : sizeof line - 1);
  }
  if (d->lost && now >= d->next_hello_ns) { // a restarted server knows no client until it hears a hello
    send_hello(d);
    d->next_hello_ns = now + (int64_t)(TX_DEVICE_UDP_REJOIN_S * 1e9);
  } else if (now - d->sent_ns > (int64_t)(TX_DEVICE_UDP_LOST_S * 1e9)) {
    // nothing sent for a while (the run's setup between the open and its first
    // tick, a stalled machine): the server may have let this client go, so say
    // hello at once rather than be lost first
    send_hello(d);
  }
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

const tx_device_backend tx_device_udp = {"udp", open_udp, info_udp, read_udp, write_udp, close_udp, NULL, NULL};
