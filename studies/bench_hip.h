// Internal: `tactus bench hip`, the collision.hip query and refit costs.
#ifndef TX_SCENARIOS_COMMAND_BENCH_HIP_H
#define TX_SCENARIOS_COMMAND_BENCH_HIP_H

// print the table and the targets; 0, or 1 when out of memory
int tx_bench_hip(void);

#endif
