// Internal: `tactus bench cloth`, the skin's physics step at 10404 particles
// and the framework's overhead over a bare loop of the same cloth. Prints
// its tables; returns 0, 1 on failure, or 2 (one line) in a build without Bullet.
#ifndef TX_SCENARIOS_COMMAND_BENCH_CLOTH_H
#define TX_SCENARIOS_COMMAND_BENCH_CLOTH_H

// duration_s: simulated seconds of the run, 0 for the default 20
int tx_bench_cloth(double duration_s);

#endif
