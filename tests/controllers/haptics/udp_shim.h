// A lossy UDP relay for the device protocol tests, on loopback only: it sits
// between a simulator (the udp backend) and a device server and spoils the
// traffic both ways. Per packet: a drop, a swap with the next packet
// (reordering) or a duplicate, by chance from a fixed seed; and every
// `garbage_every` packets one injected packet: random bytes, a copy with a
// flipped byte, a truncated copy, or a replay of an old packet (a valid CRC,
// a stale sequence). Every `foreign_every` packets a forged packet with a far
// newer sequence is sent from a third socket, which both ends must ignore.
//
// Included by the loopback test and by the udp_shim program; static only.
#ifndef TX_TESTS_UDP_SHIM_H
#define TX_TESTS_UDP_SHIM_H

#include "controllers/haptics/device_protocol.h"

#include <arpa/inet.h>
#include <errno.h>
#include <poll.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#define SHIM_HISTORY 64
#define SHIM_PACKET 256

typedef struct shim_counts {
  uint64_t in, out, dropped, swapped, duplicated, garbage, replayed, forged;
} shim_counts;

typedef struct shim_dir {
  int to_fd;                        // the socket this direction sends from
  const struct sockaddr_in* to;     // and to whom
  bool holding;                     // a packet held back to swap with the next
  uint8_t held[SHIM_PACKET];
  size_t held_n;
  uint8_t history[SHIM_HISTORY][SHIM_PACKET]; // for replays
  size_t history_n[SHIM_HISTORY];
  uint64_t count;
} shim_dir;

typedef struct udp_shim {
  int a, b, c;               // a faces the client, b the server, c forges
  struct sockaddr_in server; // where b sends
  struct sockaddr_in client; // learnt from the first packet on a
  bool client_known;
  double drop, swap, duplicate; // probabilities per packet
  int garbage_every, foreign_every;
  uint64_t rng;
  shim_dir dir[2]; // 0: client to server, 1: server to client
  shim_counts counts;
} udp_shim;

static uint64_t shim_rand(udp_shim* s) { // xorshift64*: the same faults on every run
  s->rng ^= s->rng >> 12;
  s->rng ^= s->rng << 25;
  s->rng ^= s->rng >> 27;
  return s->rng * 0x2545F4914F6CDD1DULL;
}
static double shim_uniform(udp_shim* s) { return (double)(shim_rand(s) >> 11) * 0x1.0p-53; }

static int shim_socket(void) {
  int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
  if (fd >= 0 && bind(fd, (struct sockaddr*)&a, sizeof a) != 0) close(fd), fd = -1;
  return fd;
}

static uint16_t shim_port_of(int fd) {
  struct sockaddr_in a = {0};
  socklen_t len = sizeof a;
  getsockname(fd, (struct sockaddr*)&a, &len);
  return ntohs(a.sin_port);
}

// relay to 127.0.0.1:server_port; 0, or -1 if a socket cannot be had
static int shim_open(udp_shim* s, uint16_t server_port, uint64_t seed) {
  memset(s, 0, sizeof *s);
  s->server = (struct sockaddr_in){.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK),
                                   .sin_port = htons(server_port)};
  s->a = shim_socket(), s->b = shim_socket(), s->c = shim_socket();
  s->drop = 0.10, s->swap = 0.05, s->duplicate = 0.05;
  s->garbage_every = 16, s->foreign_every = 64;
  s->rng = seed ? seed : 1;
  s->dir[0] = (shim_dir){.to_fd = s->b, .to = &s->server};
  s->dir[1] = (shim_dir){.to_fd = s->a, .to = &s->client};
  return s->a >= 0 && s->b >= 0 && s->c >= 0 ? 0 : -1;
}

static void shim_close(udp_shim* s) {
  if (s->a >= 0) close(s->a);
  if (s->b >= 0) close(s->b);
  if (s->c >= 0) close(s->c);
}

static void shim_send(udp_shim* s, int fd, const struct sockaddr_in* to, const uint8_t* p, size_t n) {
  if (sendto(fd, p, n, MSG_DONTWAIT | MSG_NOSIGNAL, (const struct sockaddr*)to, sizeof *to) == (ssize_t)n)
    s->counts.out++;
}

// one injected packet, after the packet p of direction d
static void shim_inject(udp_shim* s, shim_dir* d, const uint8_t* p, size_t n) {
  if (n == 0) return;
  uint8_t junk[SHIM_PACKET];
  size_t m = n;
  memcpy(junk, p, n);
  switch (d->count / (uint64_t)s->garbage_every % 4) {
  case 0: // random bytes of a random length, sometimes behind a valid magic
    m = (size_t)(shim_rand(s) % 200);
    for (size_t i = 0; i < m; i++) junk[i] = (uint8_t)shim_rand(s);
    if (m >= 4 && shim_rand(s) % 2) memcpy(junk, "TXHD", 4);
    break;
  case 1: junk[shim_rand(s) % n] ^= (uint8_t)(1 + shim_rand(s) % 255); break; // a flipped byte
  case 2: m = (size_t)(shim_rand(s) % n); break;                             // truncated
  default: {                                                                 // an old packet again
    size_t k = (size_t)((d->count + SHIM_HISTORY / 2) % SHIM_HISTORY);
    if (d->count < SHIM_HISTORY || !d->history_n[k]) return;
    m = d->history_n[k];
    memcpy(junk, d->history[k], m);
    s->counts.replayed++;
  }
  }
  s->counts.garbage++;
  shim_send(s, d->to_fd, d->to, junk, m);
}

// a valid packet with a far newer sequence, from an address that is not the peer
static void shim_forge(udp_shim* s, shim_dir* d, const uint8_t* p, size_t n) {
  tx_dp_packet q;
  if (tx_dp_decode(p, n, &q) != TX_DP_OK) return;
  q.seq += 1000000;
  if (q.type == TX_DP_STATE) q.state.pos[0] = q.state.pos[1] = q.state.pos[2] = 9; // unmistakable
  if (q.type == TX_DP_FORCE) q.force[0] = q.force[1] = q.force[2] = 3;
  uint8_t out[TX_DP_MAX_SIZE];
  size_t m = tx_dp_encode(&q, out, sizeof out);
  if (m) s->counts.forged++, shim_send(s, s->c, d->to, out, m);
}

static void shim_packet(udp_shim* s, int which, const uint8_t* p, size_t n) {
  shim_dir* d = &s->dir[which];
  s->counts.in++;
  d->count++;
  if (n > SHIM_PACKET) return;
  memcpy(d->history[d->count % SHIM_HISTORY], p, n);
  d->history_n[d->count % SHIM_HISTORY] = n;
  double r = shim_uniform(s);
  if (r < s->drop) {
    s->counts.dropped++;
  } else if (r < s->drop + s->swap && !d->holding) {
    memcpy(d->held, p, n), d->held_n = n, d->holding = true; // goes out after the next one
  } else {
    shim_send(s, d->to_fd, d->to, p, n);
    if (d->holding) {
      shim_send(s, d->to_fd, d->to, d->held, d->held_n);
      d->holding = false;
      s->counts.swapped++;
    }
    if (shim_uniform(s) < s->duplicate) shim_send(s, d->to_fd, d->to, p, n), s->counts.duplicated++;
  }
  if (s->garbage_every && d->count % (uint64_t)s->garbage_every == 0) shim_inject(s, d, p, n);
  if (s->foreign_every && d->count % (uint64_t)s->foreign_every == 0) shim_forge(s, d, p, n);
}

// relay until *stop
static void shim_run(udp_shim* s, const atomic_int* stop) {
  while (!atomic_load(stop)) {
    struct pollfd pfd[2] = {{s->a, POLLIN, 0}, {s->b, POLLIN, 0}};
    if (poll(pfd, 2, 10) < 0 && errno != EINTR) return;
    for (int k = 0; k < 64; k++) {
      uint8_t buf[SHIM_PACKET];
      struct sockaddr_in from;
      socklen_t len = sizeof from;
      ssize_t n = recvfrom(s->a, buf, sizeof buf, MSG_DONTWAIT, (struct sockaddr*)&from, &len);
      if (n < 0) break;
      if (!s->client_known) s->client = from, s->client_known = true;
      shim_packet(s, 0, buf, (size_t)n);
    }
    for (int k = 0; k < 64; k++) {
      uint8_t buf[SHIM_PACKET];
      ssize_t n = recv(s->b, buf, sizeof buf, MSG_DONTWAIT);
      if (n < 0) break;
      if (s->client_known) shim_packet(s, 1, buf, (size_t)n);
    }
  }
}

#endif
