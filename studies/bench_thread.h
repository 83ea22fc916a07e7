// Internal: `tactus bench thread`, one step of the suture thread (both
// models) at 100 and 1000 nodes, coiled so that its turns touch (self
// collision active). Prints its table and targets; returns 0, or 1 on failure.
#ifndef TX_STUDIES_BENCH_THREAD_H
#define TX_STUDIES_BENCH_THREAD_H

// duration_s: simulated seconds per row (and of settling), 0 for the defaults
int tx_bench_thread(double duration_s);

#endif
