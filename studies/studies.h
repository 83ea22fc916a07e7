// Internal: studies, experiments that sweep a case and write JSON, CSV and
// PNG plots into an output folder. Each takes its --set overrides as
// "KEY=VALUE" strings and returns 0, or TX_EXIT_BAD_INPUT (2) after one line
// on stderr for bad input.
#ifndef TX_SCENARIOS_STUDIES_H
#define TX_SCENARIOS_STUDIES_H

typedef struct tx_study_args {
  const char* out_dir;      // made and checked already
  const char* const* sets;  // KEY=VALUE
  int nsets;
  const char* file;         // the FILE operand of a study that takes one, else NULL
} tx_study_args;

int tx_study_haptic_stability(const tx_study_args* a);
int tx_study_needle_fit(const tx_study_args* a);
int tx_study_needle_stability(const tx_study_args* a);
int tx_study_skin_paper(const tx_study_args* a);
int tx_study_skin_stability(const tx_study_args* a);
int tx_study_skin_accuracy(const tx_study_args* a);
int tx_study_skin_membrane(const tx_study_args* a);
int tx_study_instruments_stability(const tx_study_args* a);
int tx_study_organ_hemisphere(const tx_study_args* a);
int tx_study_thread_accuracy(const tx_study_args* a);
int tx_study_thread_stability(const tx_study_args* a);

#endif
