// Internal: `tactus bench suturing`, the full suture's real-time targets:
// the suturing scenario in real time with an empty 1 kHz controller on a
// thread of its own beside it (what the machine alone costs a 1 kHz thread),
// each controller's rate against its target (within 1 %) and the haptics
// controllers' missed deadlines against the empty one's; then the same
// scenario in lockstep, its wall time against the simulated time (at most
// twice). Prints its table and targets; returns 0, 1 when a run fails, 2 on
// bad input.
#ifndef TX_STUDIES_BENCH_SUTURING_H
#define TX_STUDIES_BENCH_SUTURING_H

// out: where the runs' folders go (NULL: out/bench-suturing-TIMESTAMP);
// duration_s: seconds of each run (0: the scenario's own)
int tx_bench_suturing(const char* out, double duration_s);

#endif
