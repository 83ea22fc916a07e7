// tactus study skin-paper: the SutureHap journal paper's collision tests
// (Figures 15 to 19) on the suturing-skin scenario, in lockstep, plus the
// local force model against the papers' 60 Hz sample-and-hold, in each force
// mode of collision.hip (--set modes=paper,mechanics; both by default).
//
// Each case is the scenario with a few --set overrides (hip.force_mode among
// them) and a scripted hand; its ticks come back from the view.force_curve
// CSV of its run. Every experiment writes EXPERIMENT.csv (every tick of its
// cases, a mode column) and EXPERIMENT.png (force against HIP position, the
// papers' plots); the whole study writes skin-paper.csv and skin-paper.json
// (one row per case and mode), skin-paper-findings.csv (one row per finding:
// whether it holds in each mode, and where it comes from) and prints them.
//
// Where a finding comes from: a finding that holds in mechanics mode, whose
// force moves when the skin is made 1000 times stiffer, holds from the
// skin's mechanics; one that holds only in paper mode, or in a mode whose
// force does not move with the skin (a fixed function of the HIP's
// displacement), holds by construction. A build whose collision.hip has no
// force_mode runs its one method, the paper's, and says so.
#include "studies.h"
#include "skin_metrics.h"

#include "../model/error.h"
#include "../scenarios/command.h"
#include "../controllers/haptics/device_scripted.h"
#include "../scenarios/run.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define TICKS_MAX 14000 // 14 s at 1 kHz, longer than every motion
#define SETS_MAX 24

// the hand motions, each written as a scripted CSV under its file name (the
// waypoints are the one table of controllers/haptics/device_scripted.c)
typedef struct motion {
  const char* name;  // the CSV's stem, as the cases name it
  const char* table; // its name in the table of hand motions
} motion;

static const motion motions[] = {
    {"pierce-up", "paper-pierce-up"},     {"pierce-up-hanging", "paper-pierce-up-hanging"},
    {"pierce-down", "paper-pierce-down"}, {"slide-x-over", "slide-x-over"},
    {"slide-x-under", "slide-x-under"},   {"slide-z-over", "slide-z-over"},
    {"slide-z-under", "slide-z-under"},
};

typedef struct skin_case {
  const char* experiment; // file stem of its experiment
  const char* label;      // legend and row name
  const char* motion;     // one of motions[]
  int rays;               // 26 or 98
  double radius;          // m
  double thickness;       // m
  double spacing;         // m
  bool gravity;
  bool sample_hold;       // the papers' rendering instead of the local model
} skin_case;

// the paper's defaults: 26 rays, HIP 0.05 cm, skin 0.4 cm, spacing 0.25 cm, no gravity
#define PAPER 26, 0.0005, 0.004, 0.0025, false, false
static const skin_case cases[] = {
    {"rays", "26 rays", "pierce-up", PAPER},
    {"rays", "98 rays", "pierce-up", 98, 0.0005, 0.004, 0.0025, false, false},
    {"radius", "radius 0.05 cm", "pierce-up", PAPER},
    {"radius", "radius 0.1 cm", "pierce-up", 26, 0.001, 0.004, 0.0025, false, false},
    {"thickness", "0.2 cm", "pierce-up", 26, 0.0005, 0.002, 0.0025, false, false},
    {"thickness", "0.8 cm", "pierce-up", 26, 0.0005, 0.008, 0.0025, false, false},
    {"thickness", "0.2 cm, gravity", "pierce-up-hanging", 26, 0.0005, 0.002, 0.0025, true, false},
    {"thickness", "0.8 cm, gravity", "pierce-up-hanging", 26, 0.0005, 0.008, 0.0025, true, false},
    {"direction", "bottom-up", "pierce-up", PAPER},
    {"direction", "top-down", "pierce-down", PAPER},
    {"sliding", "x over", "slide-x-over", PAPER},
    {"sliding", "x under", "slide-x-under", PAPER},
    {"sliding", "z over", "slide-z-over", PAPER},
    {"sliding", "z under", "slide-z-under", PAPER},
    {"spacing", "0.25 cm, pierce", "pierce-up", PAPER},
    {"spacing", "0.1 cm, pierce", "pierce-up", 26, 0.0005, 0.004, 0.001, false, false},
    {"spacing", "0.25 cm, slide x", "slide-x-under", PAPER},
    {"spacing", "0.1 cm, slide x", "slide-x-under", 26, 0.0005, 0.004, 0.001, false, false},
    {"sample-hold", "local model", "pierce-down", PAPER},
    {"sample-hold", "sample-and-hold", "pierce-down", 26, 0.0005, 0.004, 0.0025, false, true},
};
#define NCASES ((int)(sizeof cases / sizeof cases[0]))

typedef struct run_data {
  int n;
  double t[TICKS_MAX], pos[3][TICKS_MAX], f[3][TICKS_MAX], contacts[TICKS_MAX], pierced[TICKS_MAX], torn[TICKS_MAX],
      skin_t[TICKS_MAX];
  int push_axis, slide_axis; // 1 (y) for piercing; 0 or 2 when sliding (-1: none)
  tx_skin_metrics m;
} run_data;

// the waypoints of a case's motion (every name in motions[] is in the table)
static const tx_hand_motion* find_motion(const char* name) {
  for (size_t i = 0; i < sizeof motions / sizeof motions[0]; i++)
    if (strcmp(motions[i].name, name) == 0) return tx_hand_motion_find(motions[i].table);
  return NULL;
}

static int write_motions(const char* dir) {
  for (size_t i = 0; i < sizeof motions / sizeof motions[0]; i++) {
    const tx_hand_motion* m = tx_hand_motion_find(motions[i].table);
    char name[96];
    snprintf(name, sizeof name, "%s.csv", motions[i].name);
    tx_aside o;
    if (!m || !tx_aside_begin(&o, dir, name)) return -1;
    fprintf(o.f, "t_s,x_m,y_m,z_m\n");
    for (int k = 0; k < m->count; k++)
      fprintf(o.f, "%g,%g,%g,%g\n", m->t_pos[k][0], m->t_pos[k][1], m->t_pos[k][2], m->t_pos[k][3]);
    if (!tx_aside_end(&o)) return -1;
  }
  return 0;
}

// read OUT/.../force_displacement.csv back
static int read_curve(const char* path, run_data* d) {
  FILE* f = fopen(path, "r");
  if (!f) return fprintf(stderr, "tactus: %s: %s\n", path, strerror(errno)), -1;
  char line[512];
  d->n = 0;
  if (!fgets(line, sizeof line, f)) return fclose(f), -1; // the header
  while (d->n < TICKS_MAX && fgets(line, sizeof line, f)) {
    int i = d->n;
    if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &d->t[i], &d->pos[0][i], &d->pos[1][i],
               &d->pos[2][i], &d->f[0][i], &d->f[1][i], &d->f[2][i], &d->contacts[i], &d->pierced[i], &d->torn[i],
               &d->skin_t[i]) != 11) {
      fclose(f);
      return fprintf(stderr, "tactus: %s:%d: not a force curve row\n", path, i + 2), -1;
    }
    d->n++;
  }
  fclose(f);
  return 0;
}

// the force modes of collision.hip (its parameter force_mode)
#define MODES_MAX 2
static const char* const mode_names[MODES_MAX] = {"paper", "mechanics"};

// whether a controller class declares a parameter
static bool class_has_param(const char* type, const char* key) {
  const tx_controller_class* k = tx_find_controller(type);
  for (int i = 0; k && i < k->nparams; i++)
    if (strcmp(k->params[i].key, key) == 0) return true;
  return false;
}

// mode: "paper"/"mechanics", or NULL to leave the HIP's force_mode as built;
// extra: one more --set (the stiffness probe), or NULL
static int run_case(const tx_study_args* a, const char* motions_dir, const skin_case* c, const char* mode,
                    const char* extra, const char* dir, run_data* d) {
  const tx_hand_motion* mo = find_motion(c->motion);
  char buf[SETS_MAX][4400];
  const char* sets[SETS_MAX + 64];
  int n = 0;
  snprintf(buf[n++], sizeof buf[0], "duration_s=%g", mo->t_pos[mo->count - 1][0]);
  snprintf(buf[n++], sizeof buf[0], "skin.spacing_m=%g", c->spacing);
  snprintf(buf[n++], sizeof buf[0], "skin.thickness_m=%g", c->thickness);
  snprintf(buf[n++], sizeof buf[0], "skin.gravity=%s", c->gravity ? "true" : "false");
  snprintf(buf[n++], sizeof buf[0], "skin.hip_radius_m=%g", c->radius);
  snprintf(buf[n++], sizeof buf[0], "hip.radius_m=%g", c->radius);
  snprintf(buf[n++], sizeof buf[0], "hip.rays=%d", c->rays);
  snprintf(buf[n++], sizeof buf[0], "haptics.mode=%s", c->sample_hold ? "sample_hold" : "local");
  snprintf(buf[n++], sizeof buf[0], "haptics.device=scripted:%s/%s.csv", motions_dir, c->motion);
  snprintf(buf[n++], sizeof buf[0], "curve.axis=%c", c->motion[0] == 's' ? c->motion[6] : 'y');
  // the skin these findings were set on: XPBD at ten substeps of one iteration, with the
  // 1 N/m rupture calibrated for it; the implicit default takes some 200 ms a step at the
  // papers' 0.1 cm (docs/skin.md), and --set skin.solver=implicit (and a rupture tension)
  // runs the study on it
  snprintf(buf[n++], sizeof buf[0], "skin.solver=xpbd");
  snprintf(buf[n++], sizeof buf[0], "skin.max_substep_s=%.17g", 1.0 / 600);
  snprintf(buf[n++], sizeof buf[0], "skin.rupture_tension_n_per_m=1");
  if (mode) snprintf(buf[n++], sizeof buf[0], "hip.force_mode=%s", mode);
  if (extra) snprintf(buf[n++], sizeof buf[0], "%s", extra);
  for (int i = 0; i < n; i++) sets[i] = buf[i];
  for (int i = 0; i < a->nsets && n < SETS_MAX + 64; i++)
    if (strncmp(a->sets[i], "modes=", 6) != 0) sets[n++] = a->sets[i]; // the user's --set come last
  tx_scenario* sc = tx_load_for_command("suturing-skin", sets, n, NULL, 0);
  if (!sc) return TX_EXIT_BAD_INPUT;
  tx_run_config cfg = {.scenario = "suturing-skin", .lockstep = true, .out = dir, .quiet = true, .no_record = false};
  int rc = tx_run_scenario(sc, &cfg, NULL);
  tx_scenario_free(sc);
  if (rc) return rc;
  char path[4500];
  snprintf(path, sizeof path, "%s/force_displacement.csv", dir);
  if (read_curve(path, d)) return 1;
  d->push_axis = 1;
  d->slide_axis = c->motion[0] == 's' ? c->motion[6] - 'x' : -1;
  tx_skin_series s = {d->n,        d->t,           d->pos[1], d->f[1], d->slide_axis >= 0 ? d->f[d->slide_axis] : NULL,
                      d->contacts, d->pierced,     d->torn,   d->skin_t};
  // sliding is steady from 1.5 s (after the descent) to 6.5 s (before the lift)
  d->m = tx_skin_measure(&s, 1.5, 6.5);
  return 0;
}

// a case's label for a plot: its lengths ("radius 0.05 cm") in the plots' unit
static void label_in_plot_unit(const char* in, char* out, size_t n) {
  size_t o = 0;
  while (*in && o + 1 < n) {
    char* end;
    double v = strtod(in, &end);
    if (end != in && (in[0] == '.' || (in[0] >= '0' && in[0] <= '9')) && strncmp(end, " cm", 3) == 0) {
      int w = snprintf(out + o, n - o, "%g " TX_PLOT_LENGTH_UNIT, tx_plot_length(v / 100));
      if (w < 0 || (size_t)w >= n - o) break;
      o += (size_t)w;
      in = end + 3;
    } else
      out[o++] = *in++;
  }
  out[o] = 0;
}

// EXPERIMENT.csv and EXPERIMENT.png from the cases [first, last)
static int write_experiment(const char* dir, const char* name, run_data* const runs[][NCASES], const char* const* modes,
                            int nmodes, int first, int last) {
  char path[4300], file[96];
  snprintf(file, sizeof file, "%s.csv", name);
  tx_aside o;
  if (!tx_aside_begin(&o, dir, file)) return -1;
  FILE* f = o.f;
  fprintf(f, "mode,case,t_s,x_m,y_m,z_m,fx_n,fy_n,fz_n,contacts,pierced,torn\n");
  for (int m = 0; m < nmodes; m++)
    for (int c = first; c < last; c++) {
      const run_data* d = runs[m][c];
      for (int i = 0; i < d->n; i++)
        fprintf(f, "%s,\"%s\",%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.0f,%.0f,%.0f\n", modes[m], cases[c].label, d->t[i],
                d->pos[0][i], d->pos[1][i], d->pos[2][i], d->f[0][i], d->f[1][i], d->f[2][i], d->contacts[i],
                d->pierced[i], d->torn[i]);
    }
  if (!tx_aside_end(&o)) return -1;
  // force against position: along y for piercing; for sliding the tangential force along the slide
  // with two modes each case is drawn twice, its label led by the mode
  tx_plot_series s[8];
  static double xs[8][TICKS_MAX];
  static char labels[8][128];
  bool slide[8];
  int ns = 0;
  for (int m = 0; m < nmodes; m++)
    for (int c = first; c < last && ns < 8; c++, ns++) {
      const run_data* d = runs[m][c];
      int ax = d->slide_axis >= 0 ? d->slide_axis : 1;
      for (int i = 0; i < d->n; i++) xs[ns][i] = tx_plot_length(d->pos[ax][i]);
      char label[96];
      label_in_plot_unit(cases[c].label, label, sizeof label);
      if (nmodes > 1) snprintf(labels[ns], sizeof labels[ns], "%s: %s", modes[m], label);
      else snprintf(labels[ns], sizeof labels[ns], "%s", label);
      s[ns] = (tx_plot_series){labels[ns], xs[ns], d->f[ax], d->n, false, 1 + ns};
      slide[ns] = d->slide_axis >= 0;
    }
  // piercing and sliding have different x axes: a panel each. Curves that
  // coincide (the four slides are symmetric) would hide one another: then
  // each case of that kind gets a panel of its own, which says so.
  tx_plot panels[8];
  static char titles[8][160];
  int np = 0;
  for (int kind = 0; kind < 2; kind++) {
    int members[8], nm = 0;
    bool coincide = false;
    for (int i = 0; i < ns; i++)
      if (slide[i] == (kind == 1)) {
        for (int k = 0; k < nm; k++) coincide |= tx_plot_series_coincide(&s[members[k]], &s[i]);
        members[nm++] = i;
      }
    if (!nm) continue;
    const char* xl = kind ? "HIP position along the slide (" TX_PLOT_LENGTH_UNIT ")" : "HIP y (" TX_PLOT_LENGTH_UNIT ")";
    const char* yl = kind ? "tangential force on the device (N)" : "force Fy on the device (N)";
    for (int k = 0; k < (coincide ? nm : 1); k++) {
      panels[np] = (tx_plot){titles[np], xl, yl, false, false, coincide ? &s[members[k]] : &s[members[0]], coincide ? 1 : nm};
      int same = -1;
      for (int j = 0; coincide && j < k && same < 0; j++)
        if (tx_plot_series_coincide(&s[members[j]], &s[members[k]])) same = members[j];
      snprintf(titles[np], sizeof titles[np], "%s: %s%s%s%s", name, coincide ? s[members[k]].label : kind ? "sliding" : "piercing",
               same >= 0 ? " (the same curve as " : "", same >= 0 ? s[same].label : "", same >= 0 ? ")" : "");
      np++;
    }
  }
  snprintf(path, sizeof path, "%s/%s.png", dir, name);
  if (np == 1) {
    snprintf(titles[0], sizeof titles[0], "skin-paper: %s", name);
    return tx_plot_png(path, &panels[0]);
  }
  return tx_plot_png_panels(path, panels, np, 2);
}

// ---------------------------------------------------------------------------
// the paper's findings, each measured in every mode

typedef struct finding {
  const char* key;   // in the JSON and CSV
  const char* what;  // as printed
  bool counted;      // part of "all counted findings reproduced"
  bool about_force;  // its evidence is the force on the hand (else the skin's shape: the sag)
} finding;

static const finding findings[] = {
    {"linear_before_rupture", "force ~ displacement before rupture: R^2 >= 0.95", true, true},
    {"radius", "larger radius, larger peak force", true, true},
    {"thickness", "thicker skin, larger force (no gravity)", true, true},
    {"thickness_gravity", "thicker skin, larger force (gravity)", true, true},
    {"zero_after_rupture", "force back to zero within 1 ms of rupture", true, true},
    {"gravity_sag", "gravity: the skin sags, first contact lower", true, false},
    {"sliding_steady", "sliding: steady tangential force against the motion", true, true},
    {"density_pierce", "denser skin, smoother force (pierce; not counted)", false, true},
    {"density_slide", "denser skin, smoother force (slide; not counted)", false, true},
    {"sample_hold_steps", "largest 1 ms force step: sample-and-hold / local >= 10", true, true},
};
#define NFINDINGS ((int)(sizeof findings / sizeof findings[0]))

// finding i in one mode's runs: whether it holds, and what was measured
static bool measure_finding(int i, run_data* const* runs, char* measured, size_t n) {
  const tx_skin_metrics* m[NCASES];
  for (int c = 0; c < NCASES; c++) m[c] = &runs[c]->m;
  switch (i) {
  case 0: {
    double worst = 1;
    for (int c = 0; c < NCASES; c++)
      if (runs[c]->slide_axis < 0 && !(m[c]->r2 >= worst)) worst = m[c]->r2;
    snprintf(measured, n, "lowest R^2 %.4f", worst);
    return worst >= 0.95;
  }
  case 1:
    snprintf(measured, n, "%.4f N (0.1 cm) vs %.4f N (0.05 cm)", m[3]->peak, m[2]->peak);
    return m[3]->peak > m[2]->peak;
  case 2:
    snprintf(measured, n, "peak %.4f N (0.8) vs %.4f N (0.2)", m[5]->peak, m[4]->peak);
    return m[5]->peak > m[4]->peak;
  case 3:
    snprintf(measured, n, "peak %.4f N (0.8) vs %.4f N (0.2)", m[7]->peak, m[6]->peak);
    return m[7]->peak > m[6]->peak;
  case 4: {
    double worst = 0;
    for (int c = 0; c < NCASES; c++)
      if (runs[c]->slide_axis < 0 && !(m[c]->zero_after_s <= worst)) worst = m[c]->zero_after_s;
    snprintf(measured, n, "slowest %.3f ms", worst * 1e3);
    return worst <= 1e-3 + 1e-9;
  }
  case 5:
    snprintf(measured, n, "y %.3f cm (gravity) vs %.3f cm", 100 * m[6]->contact_pos, 100 * m[4]->contact_pos);
    return m[6]->contact_pos < m[4]->contact_pos - 1e-4;
  case 6: {
    double worst = 0;
    bool opposes = true;
    for (int c = 10; c < 14; c++) {
      if (!(m[c]->tangent_cv <= worst)) worst = m[c]->tangent_cv;
      opposes &= m[c]->tangent_mean < 0; // every slide moves toward +x or +z
    }
    snprintf(measured, n, "0.5 s means vary by <= %.0f%%%s", 100 * worst, opposes ? "" : ", not all opposing");
    return opposes && worst <= 0.25;
  }
  case 7:
    snprintf(measured, n, "roughness %.3g (0.1 cm) vs %.3g (0.25 cm)", m[15]->roughness, m[14]->roughness);
    return m[15]->roughness < m[14]->roughness;
  case 8:
    snprintf(measured, n, "roughness %.3g (0.1 cm) vs %.3g (0.25 cm)", m[17]->roughness, m[16]->roughness);
    return m[17]->roughness < m[16]->roughness;
  default: {
    double ratio = m[19]->max_step / m[18]->max_step;
    snprintf(measured, n, "%.2f mN / %.3f mN = %.1fx", 1e3 * m[19]->max_step, 1e3 * m[18]->max_step, ratio);
    return ratio >= 10;
  }
  }
}

// How far the force of the top-down pierce moves when the skin is made 1000
// times stiffer: the largest change of Fy, before the softer skin's rupture,
// over its peak. Zero means the force is a fixed function of the HIP's
// displacement in that mode: what it shows, it shows by construction.
static double stiffness_change(const run_data* base, const run_data* stiff) {
  int end = base->m.rupture >= 0 ? base->m.rupture : base->n;
  double worst = 0;
  for (int i = 0; i < end && i < stiff->n; i++) {
    double d = fabs(base->f[1][i] - stiff->f[1][i]);
    if (d > worst) worst = d;
  }
  return base->m.peak > 0 ? worst / base->m.peak : NAN;
}
#define PROBE_CASE 9                    // top-down, the paper's defaults
#define PROBE_SET "skin.stretch_stiffness=2e6" // x1000 the default 2000 N/m
#define SKIN_DEPENDS 1e-6               // a relative change above this: the force depends on the skin

// where a finding comes from: "mechanics" when it holds in mechanics mode
// and that mode's force depends on the skin; "construction" when it holds
// only in paper mode, or where the force does not depend on the skin;
// "neither" when it holds in no mode; "undetermined" when only paper mode
// ran and its force does depend on the skin
static const char* holds_from(const finding* f, const bool* holds, const bool* ran, const bool* depends) {
  int P = 0, M = 1;
  if (!f->about_force) { // the skin's own shape: mechanics in whichever mode it holds
    for (int m = 0; m < MODES_MAX; m++)
      if (ran[m] && holds[m]) return "mechanics";
    return "neither";
  }
  if (ran[M] && holds[M]) return depends[M] ? "mechanics" : "construction";
  if (ran[P] && holds[P]) return ran[M] || !depends[P] ? "construction" : "undetermined";
  return "neither";
}

// the study's own --set modes=LIST; 0, or 2 after one line
static int parse_modes(const tx_study_args* a, bool has_param, bool* ran) {
  const char* list = NULL;
  for (int i = 0; i < a->nsets; i++)
    if (strncmp(a->sets[i], "modes=", 6) == 0) list = a->sets[i] + 6;
  for (int m = 0; m < MODES_MAX; m++) ran[m] = list ? false : (m == 0 || has_param);
  if (!list) return 0;
  char buf[128];
  snprintf(buf, sizeof buf, "%s", list);
  int count = 0;
  for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
    int m = 0;
    while (m < MODES_MAX && strcmp(t, mode_names[m]) != 0) m++;
    if (m == MODES_MAX) return tx_bad_input("--set modes: unknown force mode '%s' (paper, mechanics)", t);
    ran[m] = true, count++;
  }
  if (!count) return tx_bad_input("--set modes: expected paper, mechanics or both");
  if (ran[1] && !has_param)
    return tx_bad_input("--set modes: collision.hip has no parameter force_mode in this build (the paper method only)");
  return 0;
}

int tx_study_skin_paper(const tx_study_args* a) {
  char motions_dir[4200], runs_dir[4200];
  bool has_param = class_has_param("collision.hip", "force_mode"), ran[MODES_MAX];
  int bad = parse_modes(a, has_param, ran);
  if (bad) return bad;
  const char* modes[MODES_MAX];
  int nmodes = 0;
  for (int m = 0; m < MODES_MAX; m++)
    if (ran[m]) modes[nmodes++] = mode_names[m];
  snprintf(motions_dir, sizeof motions_dir, "%s/motions", a->out_dir);
  snprintf(runs_dir, sizeof runs_dir, "%s/runs", a->out_dir);
  if ((mkdir(motions_dir, 0777) && errno != EEXIST) || (mkdir(runs_dir, 0777) && errno != EEXIST) ||
      write_motions(motions_dir))
    return tx_bad_input("--out %s: cannot write the hand motions", a->out_dir);
  static run_data* runs[MODES_MAX][NCASES];
  run_data* probes[MODES_MAX] = {0};
  double change[MODES_MAX];
  memset(runs, 0, sizeof runs);
  int rc = 0;
  printf("study skin-paper: the SutureHap journal paper's collision tests on suturing-skin, lockstep, force mode%s",
         nmodes > 1 ? "s" : "");
  for (int m = 0; m < nmodes; m++) printf(" %s", modes[m]);
  printf("%s\n", has_param ? "" : " (collision.hip has no force_mode in this build: its one method is the paper's)");
  printf("  %-9s %-12s %-18s %8s %9s %9s %7s %9s %9s %9s %8s\n", "mode", "experiment", "case", "contact", "peak N",
         "rupture", "R^2", "zero ms", "max step", "rough", "tangent");
  printf("  %-9s %-12s %-18s %8s %9s %9s %7s %9s %9s %9s %8s\n", "", "", "", "y cm", "", "y cm", "", "", "mN", "1", "N");
  for (int k = 0; k < nmodes && !rc; k++) {
    const char* mode = has_param ? modes[k] : NULL;
    char dir[4400];
    snprintf(dir, sizeof dir, "%s/%s", runs_dir, modes[k]);
    if (mkdir(dir, 0777) && errno != EEXIST) return fprintf(stderr, "tactus: %s: %s\n", dir, strerror(errno)), 1;
    for (int i = 0; i < NCASES && !rc; i++) {
      if (!(runs[k][i] = malloc(sizeof *runs[k][i]))) return fprintf(stderr, "tactus: out of memory\n"), 1;
      snprintf(dir, sizeof dir, "%s/%s/%02d-%s", runs_dir, modes[k], i, cases[i].experiment);
      rc = run_case(a, motions_dir, &cases[i], mode, NULL, dir, runs[k][i]);
      if (rc) break;
      const tx_skin_metrics* m = &runs[k][i]->m;
      printf("  %-9s %-12s %-18s %8.3f %9.4f %9.3f %7.4f %9.3f %9.3f %9.2g %8.4f\n", modes[k], cases[i].experiment,
             cases[i].label, 100 * m->contact_pos, m->peak, m->rupture >= 0 ? 100 * runs[k][i]->pos[1][m->rupture] : NAN,
             m->r2, 1e3 * m->zero_after_s, 1e3 * m->max_step, m->roughness, m->tangent_mean);
      fflush(stdout);
    }
    // the same pierce on a skin 1000 times stiffer
    if (!rc && !(probes[k] = malloc(sizeof *probes[k]))) return fprintf(stderr, "tactus: out of memory\n"), 1;
    snprintf(dir, sizeof dir, "%s/%s/stiff-x1000", runs_dir, modes[k]);
    if (!rc) rc = run_case(a, motions_dir, &cases[PROBE_CASE], mode, PROBE_SET, dir, probes[k]);
    if (!rc) {
      change[k] = stiffness_change(runs[k][PROBE_CASE], probes[k]);
      printf("  %-9s %-12s %-18s the force before rupture moves by %.3g of its peak\n", modes[k], "stiffness",
             "x1000 (top-down)", change[k]);
    }
  }
  if (!rc) { // per experiment: CSV and PNG
    for (int i = 0; i < NCASES && !rc;) {
      int j = i;
      while (j < NCASES && strcmp(cases[j].experiment, cases[i].experiment) == 0) j++;
      if (write_experiment(a->out_dir, cases[i].experiment, runs, modes, nmodes, i, j)) {
        fprintf(stderr, "tactus: %s\n", tx_error());
        if (strstr(tx_error(), ".csv")) rc = 1; // a missing plot (no PLplot) leaves the CSV
      }
      i = j;
    }
  }
  // the findings in each mode, and where each comes from
  bool holds[NFINDINGS][MODES_MAX] = {{0}}, depends[MODES_MAX] = {0};
  const char* from[NFINDINGS];
  char measured[NFINDINGS][MODES_MAX][160];
  if (!rc) {
    for (int k = 0; k < nmodes; k++) {
      int m = strcmp(modes[k], "paper") == 0 ? 0 : 1;
      depends[m] = !(change[k] <= SKIN_DEPENDS);
      for (int f = 0; f < NFINDINGS; f++) holds[f][m] = measure_finding(f, runs[k], measured[f][m], sizeof measured[f][m]);
    }
    for (int f = 0; f < NFINDINGS; f++) from[f] = holds_from(&findings[f], holds[f], ran, depends);
  }
  if (!rc) { // one row per case and mode: skin-paper.csv and .json; one per finding: skin-paper-findings.csv
    tx_aside o;
    FILE* f = tx_aside_begin(&o, a->out_dir, "skin-paper.csv") ? o.f : NULL;
    json_t* list = json_array();
    if (!f || !list)
      return tx_aside_drop(&o), json_decref(list), fprintf(stderr, "tactus: %s\n", f ? "out of memory" : tx_error()), 1;
    fprintf(f, "mode,experiment,case,rays,radius_m,thickness_m,spacing_m,gravity,sample_hold,contact_y_m,peak_force_n,"
               "rupture_y_m,r2,slope_n_m,zero_after_rupture_s,max_step_n,roughness,tangent_mean_n,tangent_cv\n");
    for (int k = 0; k < nmodes; k++)
      for (int i = 0; i < NCASES; i++) {
        const skin_case* c = &cases[i];
        const tx_skin_metrics* m = &runs[k][i]->m;
        double rup = m->rupture >= 0 ? runs[k][i]->pos[1][m->rupture] : NAN;
        fprintf(f, "%s,%s,\"%s\",%d,%g,%g,%g,%d,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", modes[k],
                c->experiment, c->label, c->rays, c->radius, c->thickness, c->spacing, c->gravity, c->sample_hold,
                m->contact_pos, m->peak, rup, m->r2, m->slope, m->zero_after_s, m->max_step, m->roughness,
                m->tangent_mean, m->tangent_cv);
        json_t* row = json_pack("{s:s,s:s,s:s,s:i,s:f,s:f,s:f,s:b,s:b}", "mode", modes[k], "experiment", c->experiment,
                                "case", c->label, "rays", c->rays, "radius_m", c->radius, "thickness_m", c->thickness,
                                "spacing_m", c->spacing, "gravity", c->gravity, "sample_hold", c->sample_hold);
        // NaN is no JSON number: an unmeasured value is left out
        const struct { const char* k; double v; } nums[] = {
            {"contact_y_m", m->contact_pos}, {"peak_force_n", m->peak}, {"rupture_y_m", rup}, {"r2", m->r2},
            {"slope_n_m", m->slope}, {"zero_after_rupture_s", m->zero_after_s}, {"max_step_n", m->max_step},
            {"roughness", m->roughness}, {"tangent_mean_n", m->tangent_mean}, {"tangent_cv", m->tangent_cv}};
        for (size_t q = 0; q < sizeof nums / sizeof nums[0]; q++)
          if (isfinite(nums[q].v)) json_object_set_new(row, nums[q].k, json_real(nums[q].v));
        json_array_append_new(list, row);
      }
    if (!tx_aside_end(&o)) return json_decref(list), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    // the findings: one row each, a column per mode
    f = tx_aside_begin(&o, a->out_dir, "skin-paper-findings.csv") ? o.f : NULL;
    json_t* flist = json_array();
    if (!f || !flist)
      return tx_aside_drop(&o), json_decref(list), json_decref(flist),
             fprintf(stderr, "tactus: %s\n", f ? "out of memory" : tx_error()), 1;
    fprintf(f, "finding,counted,holds_paper,holds_mechanics,holds_from,measured_paper,measured_mechanics\n");
    for (int i = 0; i < NFINDINGS; i++) {
      json_t* holds_o = json_object();
      json_t* meas_o = json_object();
      fprintf(f, "%s,%d", findings[i].key, findings[i].counted);
      for (int m = 0; m < MODES_MAX; m++) {
        fprintf(f, ",%s", ran[m] ? (holds[i][m] ? "yes" : "no") : "");
        json_object_set_new(holds_o, mode_names[m], ran[m] ? json_boolean(holds[i][m]) : json_null());
        if (ran[m]) json_object_set_new(meas_o, mode_names[m], json_string(measured[i][m]));
      }
      fprintf(f, ",%s,\"%s\",\"%s\"\n", from[i], ran[0] ? measured[i][0] : "", ran[1] ? measured[i][1] : "");
      json_array_append_new(flist, json_pack("{s:s,s:s,s:b,s:o,s:s,s:o}", "finding", findings[i].key, "what",
                                             findings[i].what, "counted", findings[i].counted, "holds", holds_o,
                                             "holds_from", from[i], "measured", meas_o));
    }
    if (!tx_aside_end(&o)) return json_decref(list), json_decref(flist), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    json_t* probe = json_object();
    for (int k = 0; k < nmodes; k++) json_object_set_new(probe, modes[k], isfinite(change[k]) ? json_real(change[k]) : json_null());
    json_t* mlist = json_array();
    for (int k = 0; k < nmodes; k++) json_array_append_new(mlist, json_string(modes[k]));
    json_t* doc = json_pack(
        "{s:s,s:s,s:o,s:b,s:{s:s,s:o},s:o,s:o}", "study", "skin-paper", "units",
        "SI: m, N, s; roughness and tangent_cv are ratios", "modes", mlist, "force_mode_parameter", has_param,
        "stiffness_x1000", "meaning",
        "largest change of the top-down pierce's force before rupture, over its peak, with stretch_stiffness x1000; "
        "0: the force is a fixed function of the HIP's displacement",
        "change", probe, "findings", flist, "cases", list);
    if (!doc || tx_report_save(doc, a->out_dir, "skin-paper.json"))
      return json_decref(doc), fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "skin-paper: out of memory"), 1;
    json_decref(doc);
  }
  if (!rc) {
    // the table of findings: each mode, and where it comes from
    printf("\nfindings (holds from: mechanics = the skin's mechanics; construction = the force is a fixed function of "
           "the HIP's displacement, or it holds only in paper mode):\n");
    printf("  %-54s", "finding");
    for (int k = 0; k < nmodes; k++) printf(" %-52s", modes[k]);
    printf(" holds from\n");
    bool all = true;
    for (int i = 0; i < NFINDINGS; i++) {
      printf("  %-54s", findings[i].what);
      for (int k = 0; k < nmodes; k++) {
        int m = strcmp(modes[k], "paper") == 0 ? 0 : 1;
        char cell[200];
        snprintf(cell, sizeof cell, "%s %s", holds[i][m] ? "met" : "MISSED", measured[i][m]);
        printf(" %-52.52s", cell);
        if (m == 0 && findings[i].counted) all &= holds[i][m]; // the papers' method reproduces the papers
      }
      printf(" %s\n", from[i]);
    }
    printf("%s\nwrote %s/skin-paper.json, .csv, skin-paper-findings.csv, and a CSV and PNG per experiment\n",
           !ran[0] ? "paper mode not run" : all ? "all counted findings reproduced in paper mode"
                                                : "some counted findings NOT reproduced in paper mode",
           a->out_dir);
  }
  for (int k = 0; k < MODES_MAX; k++) {
    for (int i = 0; i < NCASES; i++) free(runs[k][i]);
    free(probes[k]);
  }
  return rc;
}
