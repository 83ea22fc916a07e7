// Internal: `tactus bench voxels`, the haptic frequency of the voxel needle
// scene against the number of voxels, beside the voxel needle-insertion
// paper's Table 1.
#ifndef TX_SCENARIOS_COMMAND_BENCH_VOXELS_H
#define TX_SCENARIOS_COMMAND_BENCH_VOXELS_H

// duration_s: seconds of insertion per case, 0 for the whole scripted insert
// motion (3.8 s). Returns 0, or 1 when a run failed.
int tx_bench_voxels(double duration_s);

#endif
