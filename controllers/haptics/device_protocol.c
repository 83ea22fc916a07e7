// The device protocol's encoding, decoding and packet filter; see
// device_protocol.h and docs/device-protocol.md.
#include "device_protocol.h"

#include <arpa/inet.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>

// CRC-32 four bits at a time: a 16-entry table, small and fast enough for
// packets of 140 bytes at 10 kHz
static const uint32_t crc_nibble[16] = {
    0x00000000, 0x1DB71064, 0x3B6E20C8, 0x26D930AC, 0x76DC4190, 0x6B6B51F4, 0x4DB26158, 0x5005713C,
    0xEDB88320, 0xF00F9344, 0xD6D6A3E8, 0xCB61B38C, 0x9B64C2B0, 0x86D3D2D4, 0xA00AE278, 0xBDBDF21C};

uint32_t tx_dp_crc32(const uint8_t* data, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; i++) {
    c ^= data[i];
    c = (c >> 4) ^ crc_nibble[c & 15];
    c = (c >> 4) ^ crc_nibble[c & 15];
  }
  return c ^ 0xFFFFFFFFu;
}

size_t tx_dp_size(uint8_t type) {
  switch (type) {
  case TX_DP_HELLO: return TX_DP_HELLO_SIZE;
  case TX_DP_STATE: return TX_DP_STATE_SIZE;
  case TX_DP_FORCE: return TX_DP_FORCE_SIZE;
  default: return 0;
  }
}

// little-endian fields, byte by byte
static void put_u16(uint8_t* b, uint16_t v) {
  b[0] = (uint8_t)v;
  b[1] = (uint8_t)(v >> 8);
}
static void put_u32(uint8_t* b, uint32_t v) {
  for (int i = 0; i < 4; i++) b[i] = (uint8_t)(v >> (8 * i));
}
static void put_u64(uint8_t* b, uint64_t v) {
  for (int i = 0; i < 8; i++) b[i] = (uint8_t)(v >> (8 * i));
}
static void put_f64(uint8_t* b, double v) { // the IEEE 754 binary64 bit pattern
  uint64_t u;
  memcpy(&u, &v, sizeof u);
  put_u64(b, u);
}
static uint16_t get_u16(const uint8_t* b) { return (uint16_t)(b[0] | (uint16_t)b[1] << 8); }
static uint32_t get_u32(const uint8_t* b) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; i--) v = v << 8 | b[i];
  return v;
}
static uint64_t get_u64(const uint8_t* b) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; i--) v = v << 8 | b[i];
  return v;
}
static double get_f64(const uint8_t* b) {
  uint64_t u = get_u64(b);
  double v;
  memcpy(&v, &u, sizeof v);
  return v;
}
static void put_f64s(uint8_t* b, const double* v, int count) {
  for (int i = 0; i < count; i++) put_f64(b + 8 * i, v[i]);
}
// false if any is not finite
static bool get_f64s(const uint8_t* b, double* v, int count) {
  bool finite = true;
  for (int i = 0; i < count; i++) {
    v[i] = get_f64(b + 8 * i);
    finite = finite && isfinite(v[i]);
  }
  return finite;
}

size_t tx_dp_encode(const tx_dp_packet* p, uint8_t* buf, size_t cap) {
  size_t size = tx_dp_size(p->type);
  if (size == 0 || cap < size) return 0;
  memset(buf, 0, size);
  buf[0] = TX_DP_MAGIC0, buf[1] = TX_DP_MAGIC1, buf[2] = TX_DP_MAGIC2, buf[3] = TX_DP_MAGIC3;
  buf[4] = TX_DP_VERSION;
  buf[5] = p->type;
  put_u16(buf + 6, (uint16_t)size);
  put_u32(buf + 8, p->session);
  put_u32(buf + 12, p->echo_hold_ns);
  put_u64(buf + 16, p->seq);
  put_u64(buf + 24, (uint64_t)p->send_ns);
  put_u64(buf + 32, (uint64_t)p->echo_ns);
  uint8_t* b = buf + TX_DP_HEADER_SIZE;
  const tx_device_info* in = &p->hello.info;
  const tx_device_state* s = &p->state;
  switch (p->type) {
  case TX_DP_HELLO:
    put_f64(b, p->hello.rate_hz);
    put_f64(b + 8, in->max_force);
    put_f64(b + 16, in->max_stiffness);
    put_f64(b + 24, in->damping);
    put_f64s(b + 32, in->workspace_min, 3);
    put_f64s(b + 56, in->workspace_max, 3);
    break;
  case TX_DP_STATE:
    put_f64s(b, s->pos, 3);
    put_f64s(b + 24, s->quat, 4);
    put_f64s(b + 56, s->vel, 3);
    put_f64(b + 80, s->grip);
    put_u32(b + 88, s->buttons);
    put_u32(b + 92, 0); // reserved
    break;
  default: put_f64s(b, p->force, 3); break;
  }
  put_u32(buf + size - TX_DP_CRC_SIZE, tx_dp_crc32(buf, size - TX_DP_CRC_SIZE));
  // what is sent must be what a peer accepts: no NaN, no zero session, ...
  tx_dp_packet check;
  return tx_dp_decode(buf, size, &check) == TX_DP_OK ? size : 0;
}

tx_dp_error tx_dp_decode(const uint8_t* buf, size_t n, tx_dp_packet* out) {
  // the frame: every check before a payload byte is read
  if (n < TX_DP_HEADER_SIZE + TX_DP_CRC_SIZE) return TX_DP_ERR_SHORT;
  if (buf[0] != TX_DP_MAGIC0 || buf[1] != TX_DP_MAGIC1 || buf[2] != TX_DP_MAGIC2 || buf[3] != TX_DP_MAGIC3)
    return TX_DP_ERR_MAGIC;
  if (buf[4] != TX_DP_VERSION) return TX_DP_ERR_VERSION;
  size_t size = tx_dp_size(buf[5]);
  if (size == 0) return TX_DP_ERR_TYPE;
  if (get_u16(buf + 6) != size || n != size) return TX_DP_ERR_LENGTH;
  if (get_u32(buf + size - TX_DP_CRC_SIZE) != tx_dp_crc32(buf, size - TX_DP_CRC_SIZE)) return TX_DP_ERR_CRC;

  // the header
  memset(out, 0, sizeof *out);
  out->type = buf[5];
  out->session = get_u32(buf + 8);
  out->echo_hold_ns = get_u32(buf + 12);
  out->seq = get_u64(buf + 16);
  out->send_ns = (int64_t)get_u64(buf + 24);
  out->echo_ns = (int64_t)get_u64(buf + 32);
  if (out->session == 0 || out->seq == 0 || out->send_ns < 0 || out->echo_ns < 0) return TX_DP_ERR_HEADER;

  // the payload
  const uint8_t* b = buf + TX_DP_HEADER_SIZE;
  if (out->type == TX_DP_HELLO) {
    tx_device_info* in = &out->hello.info;
    bool finite = get_f64s(b, &out->hello.rate_hz, 1);
    finite = get_f64s(b + 8, &in->max_force, 1) && finite;
    finite = get_f64s(b + 16, &in->max_stiffness, 1) && finite;
    finite = get_f64s(b + 24, &in->damping, 1) && finite;
    finite = get_f64s(b + 32, in->workspace_min, 3) && finite;
    finite = get_f64s(b + 56, in->workspace_max, 3) && finite;
    if (!finite) return TX_DP_ERR_NON_FINITE;
    if (!(out->hello.rate_hz > 0 && out->hello.rate_hz <= TX_DP_MAX_RATE_HZ)) return TX_DP_ERR_RANGE;
    if (in->max_force < 0 || in->max_stiffness < 0 || in->damping < 0) return TX_DP_ERR_RANGE;
    for (int i = 0; i < 3; i++)
      if (in->workspace_min[i] > in->workspace_max[i]) return TX_DP_ERR_RANGE;
  } else if (out->type == TX_DP_STATE) {
    tx_device_state* s = &out->state;
    bool finite = get_f64s(b, s->pos, 3);
    finite = get_f64s(b + 24, s->quat, 4) && finite;
    finite = get_f64s(b + 56, s->vel, 3) && finite;
    finite = get_f64s(b + 80, &s->grip, 1) && finite;
    if (!finite) return TX_DP_ERR_NON_FINITE;
    s->buttons = get_u32(b + 88);
    if (get_u32(b + 92) != 0) return TX_DP_ERR_RANGE;
    // a unit quaternion (a huge component makes q2 infinite, which fails too)
    double q2 = 0;
    for (int i = 0; i < 4; i++) q2 += s->quat[i] * s->quat[i];
    if (!(fabs(q2 - 1) <= 1e-6)) return TX_DP_ERR_RANGE;
    s->t_ns = out->send_ns;
  } else {
    if (!get_f64s(b, out->force, 3)) return TX_DP_ERR_NON_FINITE;
  }
  return TX_DP_OK;
}

const char* tx_dp_error_name(tx_dp_error e) {
  static const char* const names[TX_DP_ERR_COUNT] = {
      "ok", "too short", "bad magic", "unknown version", "unknown type", "bad length", "bad CRC",
      "bad header", "non-finite number", "number out of range"};
  return (unsigned)e < TX_DP_ERR_COUNT ? names[e] : "unknown error";
}

tx_dp_verdict tx_dp_peer_accept(tx_dp_peer* peer, const tx_dp_packet* p, bool restart) {
  if (p->session != peer->session) {
    // only a hello opens a session; a late hello of an older session is not newer than what was accepted
    if (p->type != TX_DP_HELLO) return TX_DP_OTHER_SESSION;
    if (peer->session && (!restart || p->send_ns <= peer->last_send_ns)) return TX_DP_OTHER_SESSION;
    *peer = (tx_dp_peer){p->session, p->seq, p->send_ns};
    return TX_DP_NEW_SESSION;
  }
  if (p->seq <= peer->last_seq) return TX_DP_STALE;
  peer->last_seq = p->seq;
  peer->last_send_ns = p->send_ns;
  return TX_DP_ACCEPT;
}

bool tx_dp_parse_addr(const char* s, bool any_port, struct sockaddr_in* out, const char** why) {
  *out = (struct sockaddr_in){.sin_family = AF_INET};
  const char* colon = strrchr(s, ':');
  if (!colon) return *why = "expected HOST:PORT", false;
  char host[64];
  size_t len = (size_t)(colon - s);
  if (len == 0 || len >= sizeof host) return *why = "expected an IPv4 address or localhost before ':'", false;
  memcpy(host, s, len);
  host[len] = 0;
  if (strcmp(host, "localhost") == 0) snprintf(host, sizeof host, "127.0.0.1");
  if (inet_pton(AF_INET, host, &out->sin_addr) != 1)
    return *why = "expected an IPv4 address (such as 127.0.0.1) or localhost before ':'", false;
  const char* p = colon + 1;
  unsigned long port = 0;
  if (!*p || strlen(p) > 5 || strspn(p, "0123456789") != strlen(p)) return *why = "expected a port number after ':'", false;
  for (; *p; p++) port = port * 10 + (unsigned long)(*p - '0');
  if (port > 65535 || (port == 0 && !any_port))
    return *why = any_port ? "the port must be in [0, 65535]" : "the port must be in [1, 65535]", false;
  out->sin_port = htons((uint16_t)port);
  return true;
}

bool tx_dp_same_addr(const struct sockaddr_in* a, const struct sockaddr_in* b) {
  return a->sin_family == b->sin_family && a->sin_addr.s_addr == b->sin_addr.s_addr && a->sin_port == b->sin_port;
}

const char* tx_dp_addr_text(const struct sockaddr_in* a, char* buf, size_t n) {
  char ip[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &a->sin_addr, ip, sizeof ip);
  snprintf(buf, n, "%s:%u", ip, ntohs(a->sin_port));
  return buf;
}

int64_t tx_dp_now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

long tx_dp_recv(int fd, uint8_t* buf, size_t cap, struct sockaddr_in* from, int64_t* arrival_ns) {
  union {
    char raw[CMSG_SPACE(sizeof(struct timespec))];
    struct cmsghdr align;
  } control;
  *from = (struct sockaddr_in){0};
  struct iovec iov = {buf, cap};
  struct msghdr msg = {.msg_name = from, .msg_namelen = sizeof *from, .msg_iov = &iov, .msg_iovlen = 1,
                       .msg_control = control.raw, .msg_controllen = sizeof control.raw};
  ssize_t got = recvmsg(fd, &msg, MSG_DONTWAIT);
  if (got < 0) return -1;
  int64_t now = tx_dp_now_ns();
  *arrival_ns = now;
  for (struct cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
    // the stamp is on the realtime clock: move it by the clocks' present offset
    struct timespec stamp, real;
    memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
    clock_gettime(CLOCK_REALTIME, &real);
    int64_t waited = ((int64_t)real.tv_sec - stamp.tv_sec) * 1000000000 + (real.tv_nsec - stamp.tv_nsec);
    if (waited > 0 && waited < 1000000000) *arrival_ns = now - waited; // a stepped clock gives nothing sensible
  }
  if (msg.msg_flags & MSG_TRUNC) got = (ssize_t)cap;
  return (long)got;
}

size_t tx_dp_stamp_encode(tx_dp_packet* p, uint32_t session, uint64_t* seq, int64_t echo_ns, int64_t arrival_ns,
                          uint8_t* buf, size_t cap) {
  int64_t now = tx_dp_now_ns();
  p->session = session;
  p->seq = ++*seq;
  p->send_ns = now;
  p->echo_ns = echo_ns;
  int64_t hold = echo_ns ? now - arrival_ns : 0;
  p->echo_hold_ns = hold <= 0 ? 0 : hold >= UINT32_MAX ? UINT32_MAX : (uint32_t)hold;
  return tx_dp_encode(p, buf, cap);
}
