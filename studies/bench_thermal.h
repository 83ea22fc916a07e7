// Internal: `tactus bench thermal`, the cautery's heat update on the
// committed LAGB liver and stomach (assets/lagb) at 100 Hz: the hook's
// source, one bioheat step of each organ and their temperatures on the drawn
// surfaces. Prints its table; returns 0, or 1 on failure.
#ifndef TX_STUDIES_BENCH_THERMAL_H
#define TX_STUDIES_BENCH_THERMAL_H

// duration_s: simulated seconds, 0 for the default 10
int tx_bench_thermal(double duration_s);

#endif
