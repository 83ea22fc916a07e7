// Internal: `tactus bench lagb`, gastric banding's real-time targets: the
// lagb scenario in real time three times, with no view, with the offscreen
// view (png) and with its side-by-side stereo; each controller's achieved
// rate in each, the frames rendered a second, and the targets: every
// physics controller at 20 Hz or more, every collision controller at 1 kHz
// or more, both hands' haptics within 1 % of 1 kHz, and 30 frames a second
// in mono and in stereo. Prints its table and targets; returns 0, 1 when a
// run fails, 2 on bad input.
#ifndef TX_STUDIES_BENCH_LAGB_H
#define TX_STUDIES_BENCH_LAGB_H

// out: where the runs' folders go (NULL: out/bench-lagb-TIMESTAMP);
// duration_s: seconds of each run (0: the scenario's own, 21.5 s)
int tx_bench_lagb(const char* out, double duration_s);

#endif
