// Internal: `tactus bench split-session`, issue 18's target that a
// suturing-skin session split over processes misses no more haptic deadlines
// than in one. Runs `tactus run suturing-skin` as one process, as two (sim,
// device) and as three (sim, device, view) in rounds that alternate the
// set-ups, each set-up rendering the same PNG frames once, and prints each
// run's rates and missed deadlines, their medians and the verdict. Returns 0,
// 1 when a run fails, 2 in a build without DDS.
#ifndef TX_STUDIES_BENCH_SPLIT_H
#define TX_STUDIES_BENCH_SPLIT_H

// out: where the runs' folders go (NULL: a temporary folder, removed after);
// duration_s: seconds a run (0: 10)
int tx_bench_split_session(const char* out, double duration_s);

#endif
