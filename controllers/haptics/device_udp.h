// Internal: what the "udp" device backend counts, for tests and reports.
//
// "udp:HOST:PORT[,bind=ADDR:PORT]" talks to a device server (tactus-device)
// at HOST:PORT with the protocol of docs/device-protocol.md. It binds to
// 127.0.0.1 on an ephemeral port unless bind= says otherwise, and takes
// packets only from HOST:PORT. Opening it says hello and waits up to
// TX_DEVICE_UDP_WAIT_S for the device's hello (its limits) and first state.
// A device lost during the run is rejoined when it comes back (device_udp.c).
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_UDP_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_UDP_H

#include "device.h"

#include <stdint.h>

#define TX_DEVICE_UDP_WAIT_S 2.0
// no state for this long: the device is lost, which one line on stderr says;
// far above a lossy link's gaps, far below a restart
#define TX_DEVICE_UDP_LOST_S 0.1
// while lost, hello is said again this often, so that a restarted server learns of this client
#define TX_DEVICE_UDP_REJOIN_S 0.05

typedef struct tx_device_udp_counts {
  uint64_t states;        // states accepted
  uint64_t stale;         // duplicated, reordered or replayed packets: dropped
  uint64_t malformed;     // packets that failed to decode (size, magic, CRC, NaN, ...): dropped
  uint64_t foreign;       // from an address other than the peer: dropped
  uint64_t other_session; // valid, but not of the session the hello opened: dropped
  uint64_t unexpected;    // valid, of the session, of a type a device does not send: dropped
  uint64_t forces;        // force packets written (send_errors of them refused)
  uint64_t send_errors;   // force packets the socket refused (never waited for)
  uint64_t losses;        // times the device was lost (no state for TX_DEVICE_UDP_LOST_S)
  uint64_t returns;       // times it came back
  uint64_t rejoins;       // new sessions of a restarted server taken on
  uint64_t other_device;  // hellos of a new session with other limits: not taken on
} tx_device_udp_counts;

// the counts of a device that tx_device_udp opened
void tx_device_udp_counts_get(const tx_device* d, tx_device_udp_counts* out);

#endif
