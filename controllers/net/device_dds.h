// Internal: a haptic device across Cyclone DDS, beside the UDP backend
// (docs/distributed.md#the-device-over-dds).
//
// The device host runs `tactus-device SPEC --dds DOMAIN[:NAME]`: a server
// that publishes the device's state at its rate and applies the forces that
// come back. The simulation host opens `--device dds:DOMAIN[:NAME]`. Two
// topics per device, both best effort, keep last 1 (a late state or force is
// worth nothing): tx/d/NAME/state and tx/d/NAME/force, of the bridge's
// Snapshot type, tagged with the session "device/NAME" on the domain.
//
// The same safety as UDP:
// - the server gives no force for more than force_timeout_s after the last
//   force arrived, and ramps it to zero over ramp_s (3 + 5 ms: zero at the
//   first tick 8 ms after the tick that took the last force, so within 10 ms
//   of its arrival at 1 kHz); a simulation that comes back (forces again)
//   is taken up, its force ramped in from zero over ramp_s;
// - the client reports no new state while none comes (the haptics
//   controller's watchdog then fades the force, haptics.device_timeout_s),
//   says so in one line after TX_DEVICE_DDS_LOST_S, and takes a server that
//   comes back (the same, or a restarted one with the same limits) again.
// Every state carries the device's limits, so a server of other limits is
// never used. Samples of another session, or malformed (size, NaN), are
// dropped and counted.
#ifndef TX_CONTROLLERS_NET_DEVICE_DDS_H
#define TX_CONTROLLERS_NET_DEVICE_DDS_H

#include "../haptics/device.h"

#include <tactus/stats.h>

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#define TX_DEVICE_DDS_WAIT_S 2.0  // the client waits this long for a first state
#define TX_DEVICE_DDS_LOST_S 0.1  // no state this long: the client says the device is lost
#define TX_DEVICE_DDS_STATE_COLS 22 // pos 3, quat 4, vel 3, grip, buttons, t_ns, max_force, max_stiffness, damping, workspace 6
#define TX_DEVICE_DDS_FORCE_COLS 4  // force 3, the mono_ns of the state it answers
#define TX_DEVICE_DDS_PEERS_MAX 8

// "DOMAIN[:NAME][,peer=HOST]...": DOMAIN in [0, 232], NAME 1-31 of
// [a-z0-9_] (default device0), the hosts to discover (none: loopback only,
// as the bridge's net.peers); false with tx_error() naming what is wrong
typedef struct tx_device_dds_spec {
  int domain;
  char name[32];
  char peer_text[TX_DEVICE_DDS_PEERS_MAX][254];
  const char* peers[TX_DEVICE_DDS_PEERS_MAX]; // into peer_text
  int npeers;
} tx_device_dds_spec;
bool tx_device_dds_parse(const char* arg, tx_device_dds_spec* out);

// the scale of the force applied at the device, age_s after the last force
// arrived, since_s after forces resumed (a new or returning simulation):
// 1 while both are fresh, a linear ramp down to 0 over ramp_s once age_s
// passes timeout_s, a linear ramp up from 0 over ramp_s after a resume
double tx_device_dds_scale(double age_s, double since_s, double timeout_s, double ramp_s);

typedef struct tx_device_dds_server_def {
  const char* spec;       // the device served: scripted:..., replay:..., sim
  const char* dds;        // "DOMAIN[:NAME][,peer=HOST]...", as tx_device_dds_parse reads it
  double rate_hz;         // states per second; 1000
  double duration_s;      // stop after this long; 0: until stopped
  double force_timeout_s; // no force this long: ramp to zero; 0.003
  double ramp_s;          // over this long, down after a timeout and up after a resume; 0.005
} tx_device_dds_server_def;

typedef struct tx_device_dds_server_stats {
  uint64_t states;        // states published
  uint64_t forces;        // forces taken and applied
  uint64_t foreign;       // samples of another session: dropped
  uint64_t malformed;     // samples of a wrong size or with NaN: dropped
  uint64_t timeouts;      // times the force ramped to zero for want of forces
  uint64_t resumes;       // times forces came again after a timeout (a simulation taken up)
  double zero_after_s;    // the longest from the last force's arrival to the first zero force written; 0 if none
  uint64_t late_ticks;    // ticks more than a period late (skipped)
  bool fifo;              // the loop ran at SCHED_FIFO
  double last_scale;      // the scale of the last force written
  double last_force[3];   // N, the last force written to the device
  tx_percentiles loop;    // ns: a state published -> the force that answers it arrives
} tx_device_dds_server_stats;

typedef struct tx_device_dds_server tx_device_dds_server;

tx_device_dds_server_def tx_device_dds_server_def_default(void);
// open the device and the DDS endpoints; NULL with one line in tx_error()
tx_device_dds_server* tx_device_dds_server_open(const tx_device_dds_server_def* def);
// serve until *stop or the duration; 0, or -1 with tx_error()
int tx_device_dds_server_run(tx_device_dds_server* s, const atomic_int* stop);
// from any thread, while it runs too
void tx_device_dds_server_get_stats(tx_device_dds_server* s, tx_device_dds_server_stats* out);
void tx_device_dds_server_close(tx_device_dds_server* s);

typedef struct tx_device_dds_counts {
  uint64_t states;    // states accepted
  uint64_t foreign;   // of another session
  uint64_t malformed; // wrong size, NaN
  uint64_t other_device; // states of a server with other limits: not used
  uint64_t forces;    // forces written
  uint64_t losses, returns; // the device lost (no state for TX_DEVICE_DDS_LOST_S) and back
} tx_device_dds_counts;
void tx_device_dds_counts_get(const tx_device* d, tx_device_dds_counts* out);

#endif
