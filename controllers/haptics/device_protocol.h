// Internal: the binary protocol between a haptic device server
// (tactus-device) and the "udp" device backend; docs/device-protocol.md is
// its manual. Every packet is one UDP datagram:
//
//   header (40 bytes) | payload (fixed size per type) | CRC-32 (4 bytes)
//
// All fields are little-endian and written byte by byte, so the encoding is
// the same on every machine whatever its struct layout. Decoding checks
// everything (size, magic, version, type, length, CRC, finite and in-range
// numbers) before a value is trusted, and never reads past the buffer.
//
//     uint8_t buf[TX_DP_MAX_SIZE];
//     tx_dp_packet p = {.type = TX_DP_FORCE, .session = s, .seq = ++seq, .send_ns = now};
//     memcpy(p.force, f, sizeof p.force);
//     size_t n = tx_dp_encode(&p, buf, sizeof buf); // 0: nothing valid to send
//     ...
//     tx_dp_packet q;
//     tx_dp_error e = tx_dp_decode(buf, n, &q);      // TX_DP_OK or why not
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_PROTOCOL_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_PROTOCOL_H

#include <tactus/haptics.h>

#include <netinet/in.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define TX_DP_MAGIC0 'T' // "TXHD": tactus haptic device
#define TX_DP_MAGIC1 'X'
#define TX_DP_MAGIC2 'H'
#define TX_DP_MAGIC3 'D'
#define TX_DP_VERSION 1

#define TX_DP_HEADER_SIZE 40
#define TX_DP_CRC_SIZE 4
#define TX_DP_HELLO_SIZE (TX_DP_HEADER_SIZE + 80 + TX_DP_CRC_SIZE) // 124
#define TX_DP_STATE_SIZE (TX_DP_HEADER_SIZE + 96 + TX_DP_CRC_SIZE) // 140
#define TX_DP_FORCE_SIZE (TX_DP_HEADER_SIZE + 24 + TX_DP_CRC_SIZE) // 68
#define TX_DP_MAX_SIZE TX_DP_STATE_SIZE

// a rate in a hello is within (0, TX_DP_MAX_RATE_HZ]
#define TX_DP_MAX_RATE_HZ 100000.0

typedef enum tx_dp_type {
  TX_DP_HELLO = 1, // both ways: who I am; from the device, its info
  TX_DP_STATE = 2, // device to simulator: the device's pose
  TX_DP_FORCE = 3, // simulator to device: the force to output
} tx_dp_type;

typedef enum tx_dp_error {
  TX_DP_OK = 0,
  TX_DP_ERR_SHORT,      // fewer bytes than a header and a CRC
  TX_DP_ERR_MAGIC,      // not "TXHD"
  TX_DP_ERR_VERSION,    // a version this build does not speak
  TX_DP_ERR_TYPE,       // an unknown message type
  TX_DP_ERR_LENGTH,     // the length field, the datagram and the type disagree
  TX_DP_ERR_CRC,        // the CRC does not match
  TX_DP_ERR_HEADER,     // session or sequence 0, or a negative timestamp
  TX_DP_ERR_NON_FINITE, // a NaN or an infinity in the payload
  TX_DP_ERR_RANGE,      // a number out of range: a rate, a quaternion not of unit length, a reserved field set
  TX_DP_ERR_COUNT
} tx_dp_error;

typedef struct tx_dp_packet {
  uint8_t type;          // tx_dp_type
  uint32_t session;      // the sender's id for its lifetime, not 0
  uint32_t echo_hold_ns; // ns the echoed packet waited at the sender before this one left, saturated
  uint64_t seq;          // the sender's packet count, from 1, one sequence for every type
  int64_t send_ns;       // the sender's monotonic clock when this left, ns
  int64_t echo_ns;       // send_ns of the newest packet the sender accepted from its peer, 0 if none
  union {
    struct {
      double rate_hz;      // Hz: the tick asked for (from the simulator), the state rate (from the device)
      tx_device_info info; // the device's limits (from the device); zeros from the simulator
    } hello;
    tx_device_state state; // t_ns is not sent: decode sets it to send_ns
    double force[3];       // N
  };
} tx_dp_packet;

// the CRC-32 of IEEE 802.3 / zlib: reflected polynomial 0xEDB88320, initial
// value and final xor 0xFFFFFFFF; crc("123456789") = 0xCBF43926
uint32_t tx_dp_crc32(const uint8_t* data, size_t n);

// the packet's size for its type, 0 for an unknown type
size_t tx_dp_size(uint8_t type);
// write p into buf; returns its size, or 0 if cap is too small or p would not decode
size_t tx_dp_encode(const tx_dp_packet* p, uint8_t* buf, size_t cap);
// stamp p as a sender's next packet (its session, ++*seq, now, and the echo of
// the peer's newest accepted packet with how long it has waited since its
// arrival at arrival_ns), then encode it; the size, or 0
size_t tx_dp_stamp_encode(tx_dp_packet* p, uint32_t session, uint64_t* seq, int64_t echo_ns, int64_t arrival_ns,
                          uint8_t* buf, size_t cap);
// read n bytes into *out; on an error *out is unspecified
tx_dp_error tx_dp_decode(const uint8_t* buf, size_t n, tx_dp_packet* out);
// "bad CRC", ... for messages and counters
const char* tx_dp_error_name(tx_dp_error e);

// what a receiver remembers of its peer, to drop stale, duplicated and
// reordered packets: only a sequence number above the last accepted one
// passes, within the peer's current session
typedef struct tx_dp_peer {
  uint32_t session;     // the peer's session, 0 before its first hello
  uint64_t last_seq;    // the newest accepted sequence number
  int64_t last_send_ns; // its send_ns
} tx_dp_peer;

typedef enum tx_dp_verdict {
  TX_DP_ACCEPT = 0,     // newer than anything accepted: use it
  TX_DP_NEW_SESSION,    // a hello that starts (or restarts) the peer's session: use it
  TX_DP_STALE,          // duplicated, reordered or replayed: drop
  TX_DP_OTHER_SESSION,  // not of the peer's current session: drop
} tx_dp_verdict;

// judge a decoded packet from the peer's address, and remember it if it
// passes; a hello from a new session passes only when it was sent after
// everything accepted so far (monotonic clocks of one machine), and only
// if restart is true
tx_dp_verdict tx_dp_peer_accept(tx_dp_peer* peer, const tx_dp_packet* p, bool restart);

// "A.B.C.D:PORT" or "localhost:PORT" into an IPv4 address; port 0 only if
// any_port; false with a reason when it is not one
bool tx_dp_parse_addr(const char* s, bool any_port, struct sockaddr_in* out, const char** why);
// the same IPv4 address and port
bool tx_dp_same_addr(const struct sockaddr_in* a, const struct sockaddr_in* b);
// "A.B.C.D:PORT" into buf, which it returns
const char* tx_dp_addr_text(const struct sockaddr_in* a, char* buf, size_t n);
// the monotonic clock, ns
int64_t tx_dp_now_ns(void);

// take one datagram from a non-blocking socket: its size (cap for one of cap
// bytes or more, so give cap > TX_DP_MAX_SIZE), its sender, and when it
// arrived on the monotonic clock (the kernel's stamp where SO_TIMESTAMPNS is
// on, else now). -1 with errno when there is none (EAGAIN) or on an error
long tx_dp_recv(int fd, uint8_t* buf, size_t cap, struct sockaddr_in* from, int64_t* arrival_ns);

#endif
