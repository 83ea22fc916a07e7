// Internal: `tactus bench organs`, the physics.organs step with the committed
// LAGB liver and stomach (5793 tetrahedra) at 30 Hz, in both modes, a probe
// pressing the liver. Prints its table; returns 0, 1 on failure, or 2 (one
// line) in a build without Bullet.
#ifndef TX_STUDIES_BENCH_ORGANS_H
#define TX_STUDIES_BENCH_ORGANS_H

// duration_s: simulated seconds of each run, 0 for the default 4
int tx_bench_organs(double duration_s);

#endif
