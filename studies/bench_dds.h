// Internal: `tactus bench dds`, a session of two processes on loopback through
// the net.dds bridge: the pose -> sim -> force round trip, model to model, and
// the added latency of a 10404 x 3 float mesh mirrored at 60 Hz, beside a raw
// DDS round trip. Prints its table and targets; returns 0, 1 on failure, 2
// in a build without DDS.
#ifndef TX_STUDIES_BENCH_DDS_H
#define TX_STUDIES_BENCH_DDS_H

#include <stdbool.h>

// duration_s: seconds of the session (0: 5); net_hz: the bridges' rate; sim_hz: the echoing sim's rate;
// poll_us: > 0, the bridges' sender threads poll this often (0: they send on publish);
// on_arrival: the sim answers each pose from its publish hook (else on its tick)
int tx_bench_dds(double duration_s, double net_hz, double sim_hz, int poll_us, bool on_arrival);

#endif
