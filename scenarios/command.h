// Internal: the subcommands of `tactus` and what they share.
#ifndef TX_SCENARIOS_COMMAND_H
#define TX_SCENARIOS_COMMAND_H

#include "loader.h"

#include <stdbool.h>
#include <stddef.h>

#define TX_EXIT_BAD_INPUT 2

int tx_cmd_list(int argc, char** argv);
int tx_cmd_describe(int argc, char** argv);
int tx_cmd_describe_instrument(const char* path); // app/describe_instrument.c
int tx_cmd_run(int argc, char** argv);
int tx_cmd_bench(int argc, char** argv);
int tx_cmd_study(int argc, char** argv);
int tx_cmd_export(int argc, char** argv);
// a run replaying recordings ends with the longest of them (s); 0 when no
// device replays or a --set gives duration_s
double tx_replay_duration(const char* const* devices, int ndevices, const char* const* sets, int nsets);
// a replay device's recording cut short (a killed run) plays its whole blocks:
// one warning line each, once the scenario has taken them (devices print nothing)
void tx_replay_warn(tx_system* sys);

// the program name that starts every error line: "tactus" or "tactus-device"
extern const char* tx_program;
// print "PROGRAM: MESSAGE" on one line to stderr; returns TX_EXIT_BAD_INPUT
int tx_bad_input(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// parse a whole number string in [min, max]
bool tx_parse_num(const char* s, double min, double max, double* out);
// make the output folder (given, or out/STEM-TIMESTAMP) and check that it takes files
int tx_out_dir(const char* given, const char* stem, char* dir, size_t n);
// a given --out that already holds files is refused (status 2, one line) unless force
int tx_out_check(const char* given, bool force);

// an output folder and what it held before this run, so that a failed run can
// take back what it wrote
typedef struct tx_out {
  char dir[4096];  // the folder
  char made[4096]; // the outermost folder made for it, "" when it existed
  char** had;      // names it held before (with --force)
  int nhad;
} tx_out;
// tx_out_dir, remembering; on failure nothing made is left
int tx_out_open(tx_out* o, const char* given, const char* stem);
// true when nothing was added since tx_out_open
bool tx_out_empty(const tx_out* o);
// remove all that was added since tx_out_open (the folder too, if it was made), then close
void tx_out_discard(tx_out* o);
// keep what was written
void tx_out_close(tx_out* o);
// load a scenario by name or path; prints the error and returns NULL on failure
tx_scenario* tx_load_for_command(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                 int ndevices);
// the same, with a graphics view ("png" or "window"; NULL or "none" for none) drawn in a stereo mode
tx_scenario* tx_load_for_command_view(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                      int ndevices, const char* view, const char* stereo, bool lockstep);
// stop requests (SIGINT, SIGTERM) end a run cleanly; the progress callback of a run
void tx_catch_stop_signals(void);
bool tx_progress(double elapsed_s, void* total_s);
// the stop signal caught since tx_catch_stop_signals (SIGINT, SIGTERM), or 0
int tx_stop_signal(void);

#endif
