// tactus study needle-stability: the needle in voxel tissue at the extremes
// (controllers/voxel/needle_stability.h): no NaN may leave the guard, the
// energy stays bounded by the needle's work, and the steps the guard
// detected and undid are counted per case.
#include "studies.h"

#include "experiments/needle_stability.h"
#include "../views/report.h"
#include "../scenarios/command.h"

#include <jansson.h>
#include <stdio.h>
#include <string.h>

int tx_study_needle_stability(const tx_study_args* a) {
  double duration = 0;
  for (int i = 0; i < a->nsets; i++) {
    const char* text = a->sets[i];
    const char* eq = strchr(text, '=');
    if (!eq || (size_t)(eq - text) != strlen("duration_s") || strncmp(text, "duration_s", 10) != 0)
      return tx_bad_input("--set %s: unknown key (known: duration_s)", text);
    if (!tx_parse_num(eq + 1, 0.01, 60, &duration)) return tx_bad_input("--set %s: expected seconds in [0.01, 60]", text);
  }
  printf("study needle-stability: a needle into 10 x 10 x 10 voxels (5 mm) and out, guard on%s\n\n",
         duration > 0 ? " (shortened)" : "");
  printf("  %-9s %6s %7s %7s %12s %12s %7s %10s %9s %7s %8s %6s %8s\n", "case", "steps", "NaN out", "NaN end",
         "energy max J", "bound J", "bounded", "recovered", "from NaN", "faults", "peak N", "subst", "wall s");
  tx_needle_stability_result r[TX_NEEDLE_STABILITY_CASES];
  json_t* list = json_array();
  bool all = true;
  for (int k = 0; k < TX_NEEDLE_STABILITY_CASES; k++) {
    if (!tx_needle_stability_run(k, duration, &r[k])) {
      json_decref(list);
      return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    }
    const tx_needle_stability_result* x = &r[k];
    printf("  %-9s %6d %7llu %7llu %12.4g %12.4g %7s %10llu %9llu %7llu %8.4f %6d %8.2f\n", x->name, x->steps,
           (unsigned long long)x->nan_out, (unsigned long long)x->nan_state, x->energy_max, x->energy_bound,
           x->bounded ? "yes" : "NO", (unsigned long long)x->recoveries, (unsigned long long)x->recovered_nan,
           (unsigned long long)x->voxel_faults, x->peak_force, x->max_substeps, x->seconds);
    fflush(stdout);
    all &= x->nan_out == 0 && x->nan_state == 0 && x->bounded;
    json_array_append_new(list, json_pack("{s:s,s:s,s:i,s:I,s:I,s:f,s:f,s:b,s:I,s:I,s:I,s:f,s:i,s:I}", "case", x->name,
                                          "what", x->what, "steps", x->steps, "nan_out", (json_int_t)x->nan_out,
                                          "nan_state", (json_int_t)x->nan_state, "energy_max_j", x->energy_max,
                                          "energy_bound_j", x->energy_bound, "bounded", x->bounded, "recoveries",
                                          (json_int_t)x->recoveries, "recovered_from_nan", (json_int_t)x->recovered_nan,
                                          "voxel_faults", (json_int_t)x->voxel_faults, "peak_force_n", x->peak_force,
                                          "max_substeps", x->max_substeps, "cuts", (json_int_t)x->cuts));
  }
  printf("\n");
  for (int k = 0; k < TX_NEEDLE_STABILITY_CASES; k++) printf("  %-9s %s\n", r[k].name, r[k].what);
  json_t* doc = json_pack("{s:s,s:o,s:s}", "study", "needle-stability", "cases", list, "bound",
                          "energy held <= 2 x the most net work the needle did, plus half k_s (1 nm)^2 per voxel");
  if (!doc || tx_report_save(doc, a->out_dir, "needle-stability.json")) {
    fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "out of memory");
    return json_decref(doc), 1;
  }
  json_decref(doc);
  printf("\ntargets:\n  %-44s %-26s %-12s %s\n", "no NaN out, none left, energy bounded", all ? "every case" : "not every case",
         "all 6", all ? "met" : "MISSED");
  printf("wrote %s/needle-stability.json\n", a->out_dir);
  return 0;
}
