// Checks skin-accuracy.json, for the study's tests:
//
//   skin_accuracy_check OUT/skin-accuracy.json            the outputs are whole
//   skin_accuracy_check --converges OUT/skin-accuracy.json and the skin converges
//
// Whole: the documented keys, one row per level and the real-time default in
// each placement (over a particle, over a cell's middle, on the path's patch),
// every row with its CPU time, the levels refining by 2 (spacing halves,
// the substep halves with it keeping k w h^2 at the path's value, at most
// 1/4, the iterations stay). Converges: for each quantity the
// status is "converging", the order p and the reference are finite, and the
// error falls at every level of the path, and the real-time default is within
// 10 % of the reference over a particle and over a cell's middle (the
// target of docs/validation.md). Exit status 0, or 1 with one line
// per failure on stderr.
#include <jansson.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#define RT_SPACING (0.1 / 60) // m, suturing-skin's spacing_m

static int failures;

static void expect(bool ok, const char* what, const char* detail) {
  if (ok) return;
  fprintf(stderr, "skin_accuracy_check: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
  failures++;
}

static double num(json_t* o, const char* key) {
  json_t* v = json_object_get(o, key);
  return json_is_number(v) ? json_number_value(v) : NAN;
}

int main(int argc, char** argv) {
  bool converges = argc == 3 && strcmp(argv[1], "--converges") == 0;
  if (argc != 2 && !converges) return fprintf(stderr, "usage: skin_accuracy_check [--converges] SKIN_ACCURACY_JSON\n"), 2;
  const char* path = argv[argc - 1];
  json_error_t e;
  json_t* doc = json_load_file(path, 0, &e);
  if (!doc) return fprintf(stderr, "skin_accuracy_check: %s: %s\n", path, e.text), 1;
  static const char* const keys[] = {"force_at_indentation_n", "rupture_force_n", "rupture_depth_m", "sag_m"};
  json_t* settings = json_object_get(doc, "settings");
  json_t* quantities = json_object_get(doc, "quantities");
  int levels = (int)num(json_object_get(doc, "refinement"), "levels");
  if (!json_is_array(settings) || !json_is_object(quantities) || !(levels >= 3) ||
      json_array_size(settings) != (size_t)levels + 2)
    return fprintf(stderr, "skin_accuracy_check: %s: expected settings (levels + 2), quantities, refinement.levels\n",
                   path), 1;
  // the path and the real-time default; the path converges: k w h^2 <= 1/4
  double kwh2 = num(json_object_get(doc, "refinement"), "k_w_h2");
  if (!(kwh2 > 0 && kwh2 <= 0.25))
    return fprintf(stderr, "skin_accuracy_check: %s: refinement.k_w_h2 %g is not in (0, 1/4]\n", path, kwh2), 1;
  for (int i = 0; i <= levels + 1; i++) {
    json_t* r = json_array_get(settings, (size_t)i);
    char what[96];
    snprintf(what, sizeof what, "setting %d", i);
    expect(num(r, "cpu_s_per_sim_s") > 0, what, "no CPU time per simulated second");
    for (int k = 0; k < 4; k++) expect(json_object_get(r, keys[k]) != NULL, what, keys[k]);
    // every level probes the continuum's centre, over a particle
    if (i < levels) {
      const char* over = json_string_value(json_object_get(r, "hip_over"));
      expect(over && strcmp(over, "particle") == 0 && num(r, "hip_offset_m") == 0, what, "HIP not over the centre particle");
    }
    if (i == 0 || i >= levels) continue;
    json_t* p = json_array_get(settings, (size_t)i - 1);
    expect(fabs(num(p, "spacing_m") / num(r, "spacing_m") - 2) < 1e-9, what, "spacing does not halve");
    expect(num(r, "iterations") == num(p, "iterations"), what, "iterations change along the path");
    // whole substeps of a 120 Hz step: within a few % of half
    expect(fabs(num(p, "time_step_s") / num(r, "time_step_s") - 2) < 0.05, what, "time step does not halve");
    expect(num(r, "k_w_h2") <= kwh2 * (1 + 1e-9) && num(r, "k_w_h2") > 0.9 * kwh2, what,
           "k w h^2 is not the path's");
    expect(fabs(num(p, "edge_m") - num(r, "edge_m")) < 1e-12, what, "the patch's edge changes along the path");
  }
  // suturing-skin's skin as it ships: the implicit solver, one 1/60 s substep a step; the path
  // is XPBD's. Twice, on the path's patch: the HIP over its centre particle, then half a
  // spacing along x and z (over a cell's middle)
  const char* placement[2] = {"particle", "cell middle"};
  const char* name[2] = {"real time (particle)", "real time (cell middle)"};
  double path_edge = num(json_array_get(settings, 0), "edge_m");
  for (int i = 0; i < 2; i++) {
    json_t* rt = json_array_get(settings, (size_t)levels + (size_t)i);
    const char* rts = json_string_value(json_object_get(rt, "solver"));
    expect(rts && strcmp(rts, "implicit") == 0 && fabs(num(rt, "time_step_s") * 60 - 1) < 1e-9 &&
               num(rt, "rate_hz") == 60 && fabs(num(rt, "spacing_m") - RT_SPACING) < 1e-12,
           "the real-time default", "is not physics.skin's (implicit, 1/60 s substeps, suturing-skin's 1/600 m at 60 Hz)");
    const char* over = json_string_value(json_object_get(rt, "hip_over"));
    expect(over && strcmp(over, placement[i]) == 0 && fabs(num(rt, "hip_offset_m") - (i ? RT_SPACING / 2 : 0)) < 1e-12,
           "the real-time default", "its HIP is not over a particle, then over a cell's middle");
    const char* nm = json_string_value(json_object_get(rt, "setting"));
    expect(nm && strcmp(nm, name[i]) == 0, "the real-time default", "is not named for its placement");
    expect(fabs(num(rt, "edge_m") - path_edge) < 1e-12, "the real-time default", "is not on the path's patch");
  }
  for (int l = 0; l < levels; l++) {
    const char* ps = json_string_value(json_object_get(json_array_get(settings, (size_t)l), "solver"));
    expect(ps && strcmp(ps, "xpbd") == 0, "the path", "is not XPBD's");
  }
  for (int k = 0; k < 4; k++) {
    json_t* q = json_object_get(quantities, keys[k]);
    const char* status = json_string_value(json_object_get(q, "status"));
    expect(status != NULL && json_is_boolean(json_object_get(q, "error_falls")), keys[k], "no status or error_falls");
    expect(json_object_get(q, "real_time_particle_error_rel") && json_object_get(q, "real_time_cell_error_rel"), keys[k],
           "no real-time error in each placement");
    // the target: the real-time default within 10 % of the reference, over a particle and over a cell's middle
    if (converges) {
      char rt_detail[160];
      snprintf(rt_detail, sizeof rt_detail, "real-time error %g (particle), %g (cell middle), not within 0.1",
               num(q, "real_time_particle_error_rel"), num(q, "real_time_cell_error_rel"));
      expect(num(q, "real_time_particle_error_rel") < 0.1 && num(q, "real_time_cell_error_rel") < 0.1, keys[k], rt_detail);
    }
    if (!converges || !status) continue;
    char detail[160];
    snprintf(detail, sizeof detail, "status %s, p %g, reference %g", status, num(q, "order_p"), num(q, "reference"));
    expect(strcmp(status, "converging") == 0 && isfinite(num(q, "order_p")) && isfinite(num(q, "reference")), keys[k],
           detail);
    // the error at every level, falling
    double prev = INFINITY;
    char err_key[64];
    snprintf(err_key, sizeof err_key, "%s_error_rel", keys[k]);
    for (int i = 0; i < levels; i++) {
      double err = num(json_array_get(settings, (size_t)i), err_key);
      snprintf(detail, sizeof detail, "level %d error %g after %g", i, err, prev);
      expect(err < prev, keys[k], detail);
      prev = err;
    }
    expect(json_is_true(json_object_get(q, "error_falls")), keys[k], "error_falls is not true");
  }
  json_decref(doc);
  return failures ? 1 : 0;
}
