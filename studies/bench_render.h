// Internal: `tactus bench render`, in its own file (bench_render.c).
#ifndef TX_SCENARIOS_COMMAND_BENCH_RENDER_H
#define TX_SCENARIOS_COMMAND_BENCH_RENDER_H

#include <stdbool.h>

// frame times of the graphics view, mono and stereo, beside 1 kHz haptics; the exit status
int tx_bench_render(const char* out, double duration_s);
// only its last table: the trainer's panels' cost in a 640 x 480 window (render-gui)
int tx_bench_render_gui(const char* out, double duration_s);

#endif
