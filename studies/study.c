// tactus study: experiments that write JSON, CSV and PNG plots.
#include "../scenarios/command.h"

#include "studies.h"

#include <tactus/config.h>

#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>

int tx_study_quick_set(const tx_study_args* a, bool* quick) {
  *quick = false;
  for (int i = 0; i < a->nsets; i++) {
    const char* eq = strchr(a->sets[i], '=');
    double v;
    if (!eq || (size_t)(eq - a->sets[i]) != 5 || strncmp(a->sets[i], "quick", 5) != 0)
      return tx_bad_input("--set %s: unknown key (known: quick)", a->sets[i]);
    if (!tx_parse_num(eq + 1, 0, 1, &v) || (v != 0 && v != 1)) return tx_bad_input("--set %s: expected 0 or 1", a->sets[i]);
    *quick = v == 1;
  }
  return 0;
}

int tx_study_steps_done(json_t* card, char done[9]) {
  int n = 0;
  size_t i;
  json_t* s;
  json_array_foreach(json_object_get(card, "steps"), i, s) {
    const char* id = json_string_value(json_object_get(s, "id"));
    if (json_is_true(json_object_get(s, "done")) && id && n < 8) done[n++] = id[0];
  }
  done[n] = 0;
  return n;
}

static const struct {
  const char* name;
  int (*run)(const tx_study_args*);
  const char* what;
} studies[] = {
    {"haptic-stability", tx_study_haptic_stability,
     "largest stable wall stiffness vs Colgate's bound, with and without passivity control"},
    {"network-haptics", tx_study_network_haptics,
     "the haptics wall across a network (device and simulation apart), stiffest stable wall per delay, with and without passivity control"},
    {"needle-fit", tx_study_needle_fit, "FILE: fit the voxel tissue to a needle recording, RMS vs run time, Figure 5"},
    {"needle-stability", tx_study_needle_stability, "needle in voxels at stiff, elastic, light, fast and overlapping extremes"},
    {"skin-paper", tx_study_skin_paper,
     "the SutureHap journal paper's skin tests (Figs. 15-19) and the 60 Hz hold, per force mode; mechanics or construction"},
    {"skin-stability", tx_study_skin_stability,
     "the skin under stiffness x1e-3..x1e3, steps 1/20..1/1000 s, a teleporting and a 10 m/s HIP, zero thickness"},
    {"skin-membrane", tx_study_skin_membrane,
     "the skin against closed-form membranes (disc load, own weight), rupture under refinement, gravity sag"},
    {"instruments-stability", tx_study_instruments_stability,
     "virtual coupling stiffness bound at 1 kHz vs haptic-stability's; a 10 m/s hand, slammed jaws, a squeezed needle"},
    {"needle-puncture", tx_study_needle_puncture,
     "the curved needle's tip through physics.skin: force along the needle against depth, the puncture force"},
    {"skin-accuracy", tx_study_skin_accuracy,
     "spacing, iterations and step refined together: observed order, Richardson reference, error vs CPU time"},
    {"organ-hemisphere", tx_study_organ_hemisphere,
     "a hemisphere indented at its pole (a plate or a tip): Bullet FEM and links against Hertz and the continuum (Fig. 14)"},
    {"organ-stability", tx_study_organ_stability,
     "the hemisphere under scale x0.1..x10, stiffness, density, damping, FEM and links: blow-ups detected (Fig. 15)"},
    {"organ-removal", tx_study_organ_removal,
     "10,000 tetrahedra removed one by one at random from a loaded FEM block: no NaN, no inversion, the surface sound"},
    {"thread-accuracy", tx_study_thread_accuracy,
     "the rod hanging against the catenary: error vs nodes, iterations and step with CPU time; ftl's length error"},
    {"thread-stability", tx_study_thread_stability,
     "the thread at 10 m/s, a 10 cm teleport, coincident nodes, stiffness x1e6, steps 1e-5..1e-2 s, a knot at 20 N"},
    {"cautery-heat", tx_study_cautery_heat,
     "the organs' bioheat solver against the erfc and perfused closed forms: error vs CPU time, mesh and step, order"},
    {"suturing-accuracy", tx_study_suturing_accuracy,
     "the scripted suture with the skin and the thread refined together: the scorecard's quantities vs the finest, error vs CPU time"},
    {"suturing-stability", tx_study_suturing_stability,
     "the scripted suture with the hands jittered, the steps varied, stiffness x0.01..x100: completes, no NaN, within the clamp"},
    {"band-joint", tx_study_band_joint,
     "the gastric band's distance joint (ODE double-ball) with its two parts pulled apart at 1-20 N: length error vs time"},
};

// the studies that take a FILE after their name
static const char* const with_file[] = {"needle-fit"};

static bool takes_file(const char* name) {
  for (size_t i = 0; i < sizeof with_file / sizeof with_file[0]; i++)
    if (strcmp(name, with_file[i]) == 0) return true;
  return false;
}

int tx_cmd_study(int argc, char** argv) {
  static const struct option longs[] = {
      {"out", required_argument, 0, 'o'}, {"set", required_argument, 0, 's'}, {"help", no_argument, 0, 'h'},
      {"force", no_argument, 0, 'F'},     {0, 0, 0, 0}};
  const char* out = NULL;
  bool force = false;
  const char* sets[64];
  int nsets = 0;
  bool help = false;
  optind = 1;
  opterr = 0;
  for (int c; (c = getopt_long(argc, argv, "", longs, NULL)) != -1;) {
    if (c == 'o') out = optarg;
    else if (c == 's') {
      if (nsets == 64) return tx_bad_input("--set: at most 64");
      sets[nsets++] = optarg;
    } else if (c == 'h') help = true;
    else if (c == 'F') force = true;
    else return tx_bad_input("study: unknown or incomplete option '%s'", argv[optind - 1]);
  }
  if (help || optind < argc - 2 || optind > argc - 1) {
    printf("usage: tactus study NAME [FILE] [--out DIR [--force]] [--set KEY=VALUE]...\n\n"
           "A --out that holds files is refused unless --force. A relative FILE not found here is looked for\n"
           "in the source tree and its assets/ folder (" TX_SCENARIO_DIR "/..).\n\n");
    for (size_t i = 0; i < sizeof studies / sizeof studies[0]; i++) printf("  %-21s %s\n", studies[i].name, studies[i].what);
    return help ? 0 : tx_bad_input("study: expected one NAME from the list above");
  }
  for (size_t i = 0; i < sizeof studies / sizeof studies[0]; i++) {
    if (strcmp(argv[optind], studies[i].name) != 0) continue;
    const char* file = optind == argc - 2 ? argv[optind + 1] : NULL;
    if (takes_file(studies[i].name) && !file) return tx_bad_input("study %s: expected a FILE after the name", studies[i].name);
    if (!takes_file(studies[i].name) && file) return tx_bad_input("study %s: unexpected argument '%s'", studies[i].name, file);
    char path[PATH_MAX];
    if (file && tx_asset_locate(file, path, sizeof path) == 0) file = path;
    if (tx_out_check(out, force)) return TX_EXIT_BAD_INPUT;
    tx_out o;
    if (tx_out_open(&o, out, studies[i].name)) return tx_bad_input("%s", tx_error());
    tx_study_args a = {o.dir, sets, nsets, file};
    int rc = studies[i].run(&a);
    // bad input keeps nothing; a failed study keeps what it wrote, but never an empty folder
    if (rc == TX_EXIT_BAD_INPUT || (rc != 0 && tx_out_empty(&o))) tx_out_discard(&o);
    else tx_out_close(&o);
    return rc;
  }
  return tx_bad_input("study %s: unknown study (tactus study lists them)", argv[optind]);
}
