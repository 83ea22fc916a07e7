// Internal: the run report, as OUT/report.json and as a table on a terminal.
#ifndef TX_VIEWS_REPORT_H
#define TX_VIEWS_REPORT_H

#include "../controllers/system.h"

#include <jansson.h>

typedef struct tx_report {
  const char* scenario;
  bool lockstep;
  const tx_run_result* result;
  tx_system* system;
} tx_report;

// the report as JSON (new reference): scenario, mode, duration_s, controllers, warnings, scheduler
json_t* tx_report_json(const tx_report* r);
// write json to DIR/NAME through a temporary file, so that it is whole or absent
int tx_report_save(const json_t* json, const char* dir, const char* name);
// set aside room for the report of s in DIR/NAME.tmp before a run, so that a
// disk the run fills still takes it (tx_report_save writes there); fails when
// the disk cannot hold even that
int tx_report_reserve(tx_system* s, const char* dir, const char* name);
// give the room back, for a run that writes no report
void tx_report_unreserve(const char* dir, const char* name);
// the summary table of a report made by tx_report_json
void tx_report_print(FILE* f, const json_t* report);

#endif
