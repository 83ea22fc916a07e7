// Internal: `tactus bench instruments`, one ODE step of two articulated
// instruments and the curved needle.
#ifndef TX_STUDIES_BENCH_INSTRUMENTS_H
#define TX_STUDIES_BENCH_INSTRUMENTS_H

// print the table and the target; 0, 1 when the world cannot be made, 2 when
// the build has no instruments (TX_WITH_ODE, TX_WITH_URDFDOM, TX_WITH_ASSIMP)
int tx_bench_instruments(double duration_s);

#endif
