// Internal: the subcommands of `tactus` and what they share.
#ifndef TX_SCENARIOS_COMMAND_H
#define TX_SCENARIOS_COMMAND_H

#include "../loader.h"

#include <stdbool.h>
#include <stddef.h>

#define TX_EXIT_BAD_INPUT 2

int tx_cmd_list(int argc, char** argv);
int tx_cmd_describe(int argc, char** argv);
int tx_cmd_run(int argc, char** argv);
int tx_cmd_bench(int argc, char** argv);
int tx_cmd_study(int argc, char** argv);
int tx_cmd_export(int argc, char** argv);
// a run replaying recordings ends with the longest of them (s); 0 when no
// device replays or a --set gives duration_s
double tx_replay_duration(const char* const* devices, int ndevices, const char* const* sets, int nsets);

// the program name that starts every error line: "tactus" or "tactus-device"
extern const char* tx_program;
// print "PROGRAM: MESSAGE" on one line to stderr; returns TX_EXIT_BAD_INPUT
int tx_bad_input(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// parse a whole number string in [min, max]
bool tx_parse_num(const char* s, double min, double max, double* out);
// make the output folder (given, or out/STEM-TIMESTAMP) and check that it takes files
int tx_out_dir(const char* given, const char* stem, char* dir, size_t n, char* err, size_t en);
// load a scenario by name or path; prints the error and returns NULL on failure
tx_scenario* tx_load_for_command(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                 int ndevices);
// the same, with a graphics view ("png" or "window"; NULL or "none" for none) drawn in a stereo mode
tx_scenario* tx_load_for_command_view(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                      int ndevices, const char* view, const char* stereo, bool lockstep);
// stop requests (SIGINT, SIGTERM) end a run cleanly; the progress callback of a run
void tx_catch_stop_signals(void);
bool tx_progress(double elapsed_s, void* total_s);

#endif
