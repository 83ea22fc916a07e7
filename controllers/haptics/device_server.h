// Internal: serve any device over UDP (docs/device-protocol.md): the heart
// of tactus-device, and of the loopback tests.
//
// The server binds to its listen address, waits for a hello from its peer
// (the one given, or else the first valid hello), answers it with the
// device's limits, then sends a state packet every 1/rate_hz seconds and
// applies each new force packet to the device. Forces that stop coming for
// force_timeout_s zero the device; so does stopping. A client not heard from for
// client_timeout_s is gone: the server stops streaming and, without a fixed
// peer, takes the next client that says hello. Each client's forces (a new
// one, or one back after it was gone) ramp from zero over ramp_s.
//
//     tx_device_server_def def = tx_device_server_def_default();
//     def.spec = "scripted:pierce-down";
//     tx_device_server* s = tx_device_server_open(&def);
//     printf("port %u\n", tx_device_server_port(s));
//     tx_device_server_run(s, &stop);  // until stop is set or the duration ends
//     tx_device_server_close(s);
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_SERVER_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_SERVER_H

#include <tactus/stats.h>

#include <netinet/in.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#define TX_DEVICE_SERVER_PORT 47100 // the default listen port

typedef struct tx_device_server_def {
  const char* spec;          // the device served, as for --device: scripted:..., replay:..., sim
  struct sockaddr_in listen; // where to bind; 127.0.0.1:TX_DEVICE_SERVER_PORT by default, port 0 for any free one
  struct sockaddr_in peer;   // the one client answered; port 0: whoever says hello first
  double rate_hz;            // state packets per second, (0, 100000]; 1000
  double duration_s;         // stop this long after the first hello; 0: until stopped
  double force_timeout_s;    // no new force for this long zeroes the device; 0.02
  double client_timeout_s;   // nothing from the client for this long: it is gone; 1 (below the client's 2 s wait for a hello), (0, 60]
  double ramp_s;             // a client's forces ramp from zero (its first after a hello) over this long; 0.005, [0, 1]
  double align_s;            // aim for each state to wait this long at the client before its
                             // tick reads it, by shifting when states are sent; 0: free-running;
                             // 120e-6: enough for the link and the client's wake-up jitter
} tx_device_server_def;

typedef struct tx_device_server_stats {
  uint64_t hellos;         // hellos answered
  uint64_t states;         // state packets sent
  uint64_t forces;         // force packets applied to the device
  uint64_t stale;          // duplicated, reordered or replayed packets: dropped
  uint64_t malformed;      // packets that failed to decode: dropped
  uint64_t foreign;        // from an address other than the peer: dropped
  uint64_t other_session;  // of no session a hello opened: dropped
  uint64_t unexpected;     // of a type a simulator does not send: dropped
  uint64_t send_errors;    // packets the socket refused
  uint64_t force_timeouts; // times the device was zeroed for want of forces
  uint64_t clients;        // client sessions served: the first, and each new one after
  uint64_t clients_gone;   // times a client fell silent for client_timeout_s and was let go
  uint64_t ramped;         // forces scaled down by the ramp after a client's hello
  uint64_t late_ticks;     // state ticks more than one period late
  uint64_t round_trips;    // forces that answered a state for the first time
  tx_percentiles loop;     // ns: a state leaves -> the first force computed from it arrives (with the client's tick wait)
  tx_percentiles link;     // ns: the same less the time the state waited at the client (networks and stacks)
} tx_device_server_stats;

typedef struct tx_device_server tx_device_server;

tx_device_server_def tx_device_server_def_default(void);
// open the device and bind; NULL with a one-line message in tx_error() naming what is wrong
tx_device_server* tx_device_server_open(const tx_device_server_def* def);
uint16_t tx_device_server_port(const tx_device_server* s); // as bound
// serve until *stop is non-zero (a signal handler or another thread may set
// it) or the duration has passed; 0, or -1 with the message in tx_error() on a socket error
int tx_device_server_run(tx_device_server* s, const atomic_int* stop);
void tx_device_server_get_stats(const tx_device_server* s, tx_device_server_stats* out);
void tx_device_server_close(tx_device_server* s);

#endif
