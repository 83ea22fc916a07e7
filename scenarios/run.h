// Internal: running a loaded scenario, shared by `run` and `bench`.
#ifndef TX_SCENARIOS_COMMAND_RUN_H
#define TX_SCENARIOS_COMMAND_RUN_H

#include "command.h"

#include <jansson.h>

typedef struct tx_run_config {
  const char* scenario; // name or path
  double duration_s;    // 0: the scenario's
  bool lockstep;
  const char* out;      // NULL: out/SCENARIO-TIMESTAMP
  bool quiet;
  bool no_record;       // no device recordings in OUT
} tx_run_config;

// run and report; *report receives the report (caller frees) when not NULL.
// Returns 0; TX_EXIT_BAD_INPUT for a bad --out or a run that failed before its
// first step (then nothing of it is kept in the folder, and sc->system is
// already destroyed: only tx_scenario_free may follow); 1 if the run failed
// later (the report is written); 130 or 143 when SIGINT or SIGTERM stopped it.
int tx_run_scenario(tx_scenario* sc, const tx_run_config* cfg, json_t** report);

#endif
