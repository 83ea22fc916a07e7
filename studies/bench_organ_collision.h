// Internal: `tactus bench organ-collision`, one collision.organ query against
// the committed liver and stomach surfaces, and their refit.
#ifndef TX_STUDIES_BENCH_ORGAN_COLLISION_H
#define TX_STUDIES_BENCH_ORGAN_COLLISION_H

// print the table and the target; duration_s: simulated seconds of 4 kHz
// queries (0: 10 s). 0, 1 when the assets cannot be read or memory is out,
// 2 when the build has no assimp (TX_WITH_ASSIMP)
int tx_bench_organ_collision(double duration_s);

#endif
