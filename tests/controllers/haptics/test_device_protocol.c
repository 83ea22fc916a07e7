// The device protocol: packets round-trip bit for bit; the bytes on the wire
// are those of docs/device-protocol.md; every corruption is rejected with the
// right error and never read past the end; the peer filter drops stale,
// duplicated and reordered packets and other sessions.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/haptics/device_protocol.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// the example FORCE packet of docs/device-protocol.md, as Python's struct and
// zlib.crc32 write it
static const uint8_t example_force[68] = {
    0x54, 0x58, 0x48, 0x44, 0x01, 0x03, 0x44, 0x00, 0x04, 0x03, 0x02, 0x01, 0x20, 0x4e, 0x00, 0x00, 0x07,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xca, 0x9a, 0x3b, 0x00, 0x00, 0x00, 0x00, 0xe0, 0x28,
    0x93, 0x3b, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0xf8, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xd0, 0xbf, 0x01, 0x32, 0xc6, 0x5e};

static tx_dp_packet hello(void) {
  tx_dp_packet p = {.type = TX_DP_HELLO, .session = 0xA1B2C3D4, .echo_hold_ns = 123, .seq = 1,
                    .send_ns = 5000000000, .echo_ns = 0};
  p.hello.rate_hz = 1000;
  p.hello.info = (tx_device_info){3.3, 500, 0.3, {-0.08, -0.06, -0.035}, {0.08, 0.06, 0.035}};
  return p;
}

static tx_dp_packet state(void) {
  tx_dp_packet p = {.type = TX_DP_STATE, .session = 77, .echo_hold_ns = 4294967295u, .seq = 1ull << 40,
                    .send_ns = INT64_MAX, .echo_ns = 42};
  p.state = (tx_device_state){{0.01, -0.002, 1e-300}, {0.5, 0.5, 0.5, -0.5}, {-0.1, 0, 0.25}, 0.3, 0x80000005u, 0};
  return p;
}

static tx_dp_packet force(void) {
  tx_dp_packet p = {.type = TX_DP_FORCE, .session = 0x01020304, .echo_hold_ns = 20000, .seq = 7,
                    .send_ns = 1000000000, .echo_ns = 999500000};
  p.force[0] = 0, p.force[1] = 1.5, p.force[2] = -0.25;
  return p;
}

// a copy in a buffer of exactly n bytes, so that a sanitizer sees any read past it
static tx_dp_error decode_exact(const uint8_t* buf, size_t n, tx_dp_packet* out) {
  uint8_t* copy = malloc(n ? n : 1);
  assert_non_null(copy);
  if (n) memcpy(copy, buf, n);
  tx_dp_error e = tx_dp_decode(copy, n, out);
  free(copy);
  return e;
}

// after changing a byte on purpose, make the CRC right again so that the check behind it is reached
static void recrc(uint8_t* buf, size_t size) {
  uint32_t c = tx_dp_crc32(buf, size - 4);
  for (int i = 0; i < 4; i++) buf[size - 4 + i] = (uint8_t)(c >> (8 * i));
}

static void crc_is_the_ieee_one(void** unused) {
  (void)unused;
  assert_int_equal(tx_dp_crc32((const uint8_t*)"123456789", 9), 0xCBF43926u);
  assert_int_equal(tx_dp_crc32(NULL, 0), 0);
  assert_int_equal(tx_dp_crc32((const uint8_t*)"a", 1), 0xE8B7BE43u);
}

static void sizes_are_as_documented(void** unused) {
  (void)unused;
  assert_int_equal(tx_dp_size(TX_DP_HELLO), 124);
  assert_int_equal(tx_dp_size(TX_DP_STATE), 140);
  assert_int_equal(tx_dp_size(TX_DP_FORCE), 68);
  assert_int_equal(tx_dp_size(0), 0);
  assert_int_equal(tx_dp_size(4), 0);
}

static void example_packet_matches_the_manual(void** unused) {
  (void)unused;
  tx_dp_packet p = force();
  uint8_t buf[TX_DP_MAX_SIZE];
  assert_int_equal(tx_dp_encode(&p, buf, sizeof buf), sizeof example_force);
  assert_memory_equal(buf, example_force, sizeof example_force);
  tx_dp_packet q;
  assert_int_equal(decode_exact(example_force, sizeof example_force, &q), TX_DP_OK);
  assert_true(q.force[1] == 1.5 && q.force[2] == -0.25 && q.seq == 7 && q.echo_hold_ns == 20000);
}

static void round_trip(const tx_dp_packet* p) {
  uint8_t buf[TX_DP_MAX_SIZE];
  size_t n = tx_dp_encode(p, buf, sizeof buf);
  assert_int_equal(n, tx_dp_size(p->type));
  assert_int_equal(tx_dp_encode(p, buf, n - 1), 0); // too small a buffer: nothing
  tx_dp_packet q;
  assert_int_equal(decode_exact(buf, n, &q), TX_DP_OK);
  assert_int_equal(q.type, p->type);
  assert_int_equal(q.session, p->session);
  assert_int_equal(q.echo_hold_ns, p->echo_hold_ns);
  assert_true(q.seq == p->seq && q.send_ns == p->send_ns && q.echo_ns == p->echo_ns);
  if (p->type == TX_DP_HELLO) {
    assert_memory_equal(&q.hello.rate_hz, &p->hello.rate_hz, sizeof(double));
    assert_memory_equal(&q.hello.info, &p->hello.info, sizeof q.hello.info);
  } else if (p->type == TX_DP_STATE) {
    tx_device_state want = p->state;
    want.t_ns = p->send_ns; // the state's time is when the device sent it
    assert_memory_equal(&q.state, &want, sizeof want);
  } else {
    assert_memory_equal(q.force, p->force, sizeof q.force);
  }
}

static void every_type_round_trips_bit_for_bit(void** unused) {
  (void)unused;
  tx_dp_packet h = hello(), s = state(), f = force();
  round_trip(&h);
  round_trip(&s);
  round_trip(&f);
  s.state.pos[1] = -0.0; // the sign of zero and subnormals survive
  s.state.vel[0] = 4.9e-324;
  round_trip(&s);
  h.hello.info = (tx_device_info){0}; // the simulator's hello carries no limits
  round_trip(&h);
}

static void every_flipped_byte_and_bit_is_rejected(void** unused) {
  (void)unused;
  tx_dp_packet all[3] = {hello(), state(), force()};
  for (int k = 0; k < 3; k++) {
    uint8_t good[TX_DP_MAX_SIZE], bad[TX_DP_MAX_SIZE];
    size_t n = tx_dp_encode(&all[k], good, sizeof good);
    assert_true(n > 0);
    tx_dp_packet q;
    for (size_t i = 0; i < n; i++) {
      for (int flip = 0; flip < 9; flip++) { // each bit alone, then the whole byte
        memcpy(bad, good, n);
        bad[i] ^= flip < 8 ? (uint8_t)(1u << flip) : 0xFF;
        tx_dp_error e = decode_exact(bad, n, &q);
        if (e == TX_DP_OK) fail_msg("type %d: byte %zu ^ %d accepted", all[k].type, i, flip);
      }
    }
  }
}

static void truncated_and_padded_packets_are_rejected(void** unused) {
  (void)unused;
  tx_dp_packet all[3] = {hello(), state(), force()};
  for (int k = 0; k < 3; k++) {
    uint8_t buf[TX_DP_MAX_SIZE + 8] = {0};
    size_t n = tx_dp_encode(&all[k], buf, sizeof buf);
    tx_dp_packet q;
    for (size_t m = 0; m < n; m++) {
      tx_dp_error e = decode_exact(buf, m, &q);
      assert_int_equal(e, m < TX_DP_HEADER_SIZE + TX_DP_CRC_SIZE ? TX_DP_ERR_SHORT : TX_DP_ERR_LENGTH);
    }
    assert_int_equal(decode_exact(buf, n + 1, &q), TX_DP_ERR_LENGTH);
    assert_int_equal(decode_exact(buf, n + 8, &q), TX_DP_ERR_LENGTH);
  }
}

// one field changed and the CRC made right: each check is reached and names the fault
static tx_dp_error patched(const tx_dp_packet* p, size_t at, uint8_t value) {
  uint8_t buf[TX_DP_MAX_SIZE];
  size_t n = tx_dp_encode(p, buf, sizeof buf);
  buf[at] = value;
  recrc(buf, n);
  tx_dp_packet q;
  return decode_exact(buf, n, &q);
}

static void wrong_header_fields_are_named(void** unused) {
  (void)unused;
  tx_dp_packet f = force();
  assert_int_equal(patched(&f, 0, 'X'), TX_DP_ERR_MAGIC);
  assert_int_equal(patched(&f, 3, 'd'), TX_DP_ERR_MAGIC);
  assert_int_equal(patched(&f, 4, 0), TX_DP_ERR_VERSION);
  assert_int_equal(patched(&f, 4, 2), TX_DP_ERR_VERSION);
  assert_int_equal(patched(&f, 5, 0), TX_DP_ERR_TYPE);
  assert_int_equal(patched(&f, 5, 4), TX_DP_ERR_TYPE);
  assert_int_equal(patched(&f, 5, 255), TX_DP_ERR_TYPE);
  assert_int_equal(patched(&f, 5, TX_DP_STATE), TX_DP_ERR_LENGTH); // a force's length under a state's type
  assert_int_equal(patched(&f, 6, 67), TX_DP_ERR_LENGTH);
  assert_int_equal(patched(&f, 7, 1), TX_DP_ERR_LENGTH);
  uint8_t buf[TX_DP_MAX_SIZE];
  size_t n = tx_dp_encode(&f, buf, sizeof buf);
  buf[n - 1] ^= 1;
  tx_dp_packet q;
  assert_int_equal(decode_exact(buf, n, &q), TX_DP_ERR_CRC);
  // session 0, sequence 0, a negative time: the encoder refuses them and the decoder names them
  tx_dp_packet z = force();
  z.session = 0;
  assert_int_equal(tx_dp_encode(&z, buf, sizeof buf), 0);
  z = force(), z.seq = 0;
  assert_int_equal(tx_dp_encode(&z, buf, sizeof buf), 0);
  for (int i = 8; i < 12; i++) assert_int_equal(patched(&f, (size_t)i, 0), TX_DP_OK); // 3 bytes of 4 left: not 0
  f.session = 0x000000FF;
  assert_int_equal(patched(&f, 8, 0), TX_DP_ERR_HEADER);
  f = force();
  assert_int_equal(patched(&f, 16, 0), TX_DP_ERR_HEADER); // seq 7 -> 0
  assert_int_equal(patched(&f, 31, 0x80), TX_DP_ERR_HEADER); // send_ns negative
  assert_int_equal(patched(&f, 39, 0xFF), TX_DP_ERR_HEADER); // echo_ns negative
}

// each double of each payload set to NaN, +Inf and -Inf in turn
static void non_finite_numbers_are_rejected(void** unused) {
  (void)unused;
  const double bad[3] = {NAN, INFINITY, -INFINITY};
  tx_dp_packet all[3] = {hello(), state(), force()};
  const int doubles[3] = {10, 11, 3};
  for (int k = 0; k < 3; k++) {
    for (int d = 0; d < doubles[k]; d++) {
      for (int b = 0; b < 3; b++) {
        uint8_t buf[TX_DP_MAX_SIZE];
        size_t n = tx_dp_encode(&all[k], buf, sizeof buf);
        uint64_t u;
        memcpy(&u, &bad[b], sizeof u);
        for (int i = 0; i < 8; i++) buf[TX_DP_HEADER_SIZE + 8 * d + i] = (uint8_t)(u >> (8 * i));
        recrc(buf, n);
        tx_dp_packet q;
        tx_dp_error e = decode_exact(buf, n, &q);
        if (e != TX_DP_ERR_NON_FINITE) fail_msg("type %d double %d = %g: %s", all[k].type, d, bad[b], tx_dp_error_name(e));
      }
    }
  }
  // nor will the encoder write one
  tx_dp_packet f = force();
  f.force[2] = NAN;
  uint8_t buf[TX_DP_MAX_SIZE];
  assert_int_equal(tx_dp_encode(&f, buf, sizeof buf), 0);
}

static void out_of_range_numbers_are_rejected(void** unused) {
  (void)unused;
  uint8_t buf[TX_DP_MAX_SIZE];
  tx_dp_packet p = state();
  p.state.quat[0] = 0.6; // not of unit length
  assert_int_equal(tx_dp_encode(&p, buf, sizeof buf), 0);
  p = state();
  p.state.quat[0] = 1e200; // its square overflows
  assert_int_equal(tx_dp_encode(&p, buf, sizeof buf), 0);
  p = state();
  assert_int_equal(patched(&p, TX_DP_HEADER_SIZE + 95, 1), TX_DP_ERR_RANGE); // the reserved word
  const double rates[] = {0, -1, 100001};
  for (int i = 0; i < 3; i++) {
    p = hello();
    p.hello.rate_hz = rates[i];
    assert_int_equal(tx_dp_encode(&p, buf, sizeof buf), 0);
  }
  p = hello();
  p.hello.info.max_force = -1;
  assert_int_equal(tx_dp_encode(&p, buf, sizeof buf), 0);
  p = hello();
  p.hello.info.workspace_min[2] = 1; // above its max
  assert_int_equal(tx_dp_encode(&p, buf, sizeof buf), 0);
  // and the decoder says why, for a packet a careless sender made
  p = hello();
  size_t n = tx_dp_encode(&p, buf, sizeof buf);
  memset(buf + TX_DP_HEADER_SIZE, 0, 8); // rate 0
  recrc(buf, n);
  tx_dp_packet q;
  assert_int_equal(decode_exact(buf, n, &q), TX_DP_ERR_RANGE);
  assert_string_equal(tx_dp_error_name(TX_DP_ERR_RANGE), "number out of range");
  assert_string_equal(tx_dp_error_name(TX_DP_ERR_COUNT), "unknown error");
}

static tx_dp_packet from(uint8_t type, uint32_t session, uint64_t seq, int64_t send_ns) {
  return (tx_dp_packet){.type = type, .session = session, .seq = seq, .send_ns = send_ns};
}

static void peer_filter_keeps_only_newer_packets(void** unused) {
  (void)unused;
  tx_dp_peer peer = {0};
  tx_dp_packet s5 = from(TX_DP_STATE, 9, 5, 500);
  assert_int_equal(tx_dp_peer_accept(&peer, &s5, true), TX_DP_OTHER_SESSION); // no hello yet
  tx_dp_packet h1 = from(TX_DP_HELLO, 9, 1, 100);
  assert_int_equal(tx_dp_peer_accept(&peer, &h1, true), TX_DP_NEW_SESSION);
  assert_int_equal(tx_dp_peer_accept(&peer, &h1, true), TX_DP_STALE); // duplicate
  tx_dp_packet s3 = from(TX_DP_STATE, 9, 3, 300), s2 = from(TX_DP_STATE, 9, 2, 200);
  assert_int_equal(tx_dp_peer_accept(&peer, &s3, true), TX_DP_ACCEPT);
  assert_int_equal(tx_dp_peer_accept(&peer, &s2, true), TX_DP_STALE); // reordered
  assert_int_equal(tx_dp_peer_accept(&peer, &s3, true), TX_DP_STALE); // duplicated
  assert_int_equal(tx_dp_peer_accept(&peer, &s5, true), TX_DP_ACCEPT); // a gap is fine
  assert_int_equal(peer.last_seq, 5);
  tx_dp_packet other = from(TX_DP_STATE, 10, 99, 900);
  assert_int_equal(tx_dp_peer_accept(&peer, &other, true), TX_DP_OTHER_SESSION);
  // a restarted peer: its hello opens a new session, if allowed and sent later than anything accepted
  tx_dp_packet h2 = from(TX_DP_HELLO, 10, 1, 1000), h_old = from(TX_DP_HELLO, 11, 1, 400);
  assert_int_equal(tx_dp_peer_accept(&peer, &h2, false), TX_DP_OTHER_SESSION);
  assert_int_equal(tx_dp_peer_accept(&peer, &h_old, true), TX_DP_OTHER_SESSION);
  assert_int_equal(tx_dp_peer_accept(&peer, &h2, true), TX_DP_NEW_SESSION);
  tx_dp_packet s2new = from(TX_DP_STATE, 10, 2, 1001);
  assert_int_equal(tx_dp_peer_accept(&peer, &s2new, true), TX_DP_ACCEPT);
  assert_int_equal(tx_dp_peer_accept(&peer, &s5, true), TX_DP_OTHER_SESSION); // the old session is over
}

static void addresses_parse_strictly(void** unused) {
  (void)unused;
  struct sockaddr_in a;
  const char* why = NULL;
  assert_true(tx_dp_parse_addr("127.0.0.1:47100", false, &a, &why));
  assert_int_equal(ntohs(a.sin_port), 47100);
  assert_int_equal(ntohl(a.sin_addr.s_addr), 0x7F000001);
  assert_true(tx_dp_parse_addr("localhost:1", false, &a, &why));
  assert_int_equal(ntohl(a.sin_addr.s_addr), 0x7F000001);
  assert_true(tx_dp_parse_addr("0.0.0.0:0", true, &a, &why));
  assert_true(tx_dp_parse_addr("127.0.0.1:65535", false, &a, &why));
  const char* bad[] = {"", ":", "127.0.0.1", "127.0.0.1:", ":80", "127.0.0.1:0", "127.0.0.1:65536",
                       "127.0.0.1:-1", "127.0.0.1:+80", "127.0.0.1:80x", "127.0.0.1:000080", "256.0.0.1:80",
                       "example.com:80", "::1:80", "127.0.0.1 :80", "127.0.0.1:8 0"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    why = NULL;
    if (tx_dp_parse_addr(bad[i], false, &a, &why)) fail_msg("'%s' accepted", bad[i]);
    assert_non_null(why);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(crc_is_the_ieee_one),
      cmocka_unit_test(sizes_are_as_documented),
      cmocka_unit_test(example_packet_matches_the_manual),
      cmocka_unit_test(every_type_round_trips_bit_for_bit),
      cmocka_unit_test(every_flipped_byte_and_bit_is_rejected),
      cmocka_unit_test(truncated_and_padded_packets_are_rejected),
      cmocka_unit_test(wrong_header_fields_are_named),
      cmocka_unit_test(non_finite_numbers_are_rejected),
      cmocka_unit_test(out_of_range_numbers_are_rejected),
      cmocka_unit_test(peer_filter_keeps_only_newer_packets),
      cmocka_unit_test(addresses_parse_strictly),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
