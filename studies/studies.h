// Internal: studies, experiments that sweep a case and write JSON, CSV and
// PNG plots into an output folder. Each takes its --set overrides as
// "KEY=VALUE" strings and returns 0, or TX_EXIT_BAD_INPUT (2) after one line
// on stderr for bad input.
#ifndef TX_SCENARIOS_STUDIES_H
#define TX_SCENARIOS_STUDIES_H

#include <jansson.h>
#include <stdbool.h>

typedef struct tx_study_args {
  const char* out_dir;      // made and checked already
  const char* const* sets;  // KEY=VALUE
  int nsets;
  const char* file;         // the FILE operand of a study that takes one, else NULL
} tx_study_args;

// the --set of a study with a quick path, quick=0|1: 0, or TX_EXIT_BAD_INPUT
// after one line naming the --set
int tx_study_quick_set(const tx_study_args* a, bool* quick);

// the steps a run's scorecard (OUT/scorecard.json, as read) marks done: their
// ids' first letters in done (at most 8 and a NUL) and how many
int tx_study_steps_done(json_t* card, char done[9]);

// one target line of a bench's table: what, the measured value, the limit,
// met or MISSED; _us: a time in microseconds against an upper limit
void tx_bench_target(const char* what, const char* measured, const char* limit, bool ok);
void tx_bench_target_us(const char* what, double measured_us, double limit_us);
// a run report's entry for the controller NAME (report.json's "controllers"), or NULL
json_t* tx_report_controller(json_t* report, const char* name);

int tx_study_haptic_stability(const tx_study_args* a);
int tx_study_needle_fit(const tx_study_args* a);
int tx_study_network_haptics(const tx_study_args* a);
int tx_study_needle_stability(const tx_study_args* a);
int tx_study_skin_paper(const tx_study_args* a);
int tx_study_skin_stability(const tx_study_args* a);
int tx_study_skin_accuracy(const tx_study_args* a);
int tx_study_skin_membrane(const tx_study_args* a);
int tx_study_instruments_stability(const tx_study_args* a);
int tx_study_needle_puncture(const tx_study_args* a);
int tx_study_organ_hemisphere(const tx_study_args* a);
int tx_study_organ_stability(const tx_study_args* a);
int tx_study_organ_removal(const tx_study_args* a);
int tx_study_thread_accuracy(const tx_study_args* a);
int tx_study_thread_stability(const tx_study_args* a);
int tx_study_cautery_heat(const tx_study_args* a);
int tx_study_band_joint(const tx_study_args* a);
int tx_study_suturing_accuracy(const tx_study_args* a);
int tx_study_suturing_stability(const tx_study_args* a);

#endif
