// Checks skin-paper.json against the SutureHap journal paper's findings, for
// the study's test:
//
//   skin_paper_check OUT/skin-paper.json
//
// In paper mode (the papers' method) every counted finding must hold, with
// the thresholds docs/hip.md states. In every mode the study ran, 20 cases;
// every finding has a verdict per mode and a holds_from that agrees with
// them: "mechanics" only where it holds in mechanics mode (or, for the sag,
// in some mode) and that mode's force moves with the skin's stiffness,
// "construction" only where it holds in some mode. Exit status 0, or 1 with
// one line per failure on stderr.
#include <jansson.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

static json_t* cases;
static int failures;

static double get(const char* label, const char* key) {
  size_t i;
  json_t* c;
  json_array_foreach(cases, i, c) if (strcmp(json_string_value(json_object_get(c, "case")), label) == 0 &&
                                      strcmp(json_string_value(json_object_get(c, "mode")), "paper") == 0) {
    json_t* v = json_object_get(c, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
  }
  return NAN;
}

static void expect(bool ok, const char* what, double a, double b) {
  if (ok) return;
  fprintf(stderr, "skin_paper_check: %s (%.6g, %.6g)\n", what, a, b);
  failures++;
}

int main(int argc, char** argv) {
  if (argc != 2) return fprintf(stderr, "usage: skin_paper_check SKIN_PAPER_JSON\n"), 2;
  json_error_t e;
  json_t* doc = json_load_file(argv[1], 0, &e);
  if (!doc) return fprintf(stderr, "skin_paper_check: %s: %s\n", argv[1], e.text), 1;
  cases = json_object_get(doc, "cases");
  json_t* modes = json_object_get(doc, "modes");
  json_t* findings = json_object_get(doc, "findings");
  json_t* change = json_object_get(json_object_get(doc, "stiffness_x1000"), "change");
  if (!json_is_array(modes) || !json_is_array(findings) || json_array_size(findings) != 10 || !json_is_object(change))
    return fprintf(stderr, "skin_paper_check: expected modes, 10 findings and stiffness_x1000.change\n"), 1;
  if (!json_is_array(cases) || json_array_size(cases) != 20 * json_array_size(modes))
    return fprintf(stderr, "skin_paper_check: expected 20 cases per mode\n"), 1;
  bool paper = false, mechanics = false;
  size_t k;
  json_t* v;
  json_array_foreach(modes, k, v) {
    paper |= strcmp(json_string_value(v), "paper") == 0;
    mechanics |= strcmp(json_string_value(v), "mechanics") == 0;
  }
  // every finding: a verdict per mode run, and a holds_from that follows from them
  json_array_foreach(findings, k, v) {
    const char* name = json_string_value(json_object_get(v, "finding"));
    const char* from = json_string_value(json_object_get(v, "holds_from"));
    json_t* holds = json_object_get(v, "holds");
    json_t* hp = json_object_get(holds, "paper");
    json_t* hm = json_object_get(holds, "mechanics");
    char what[128];
    snprintf(what, sizeof what, "finding %s: a verdict per mode and holds_from", name ? name : "?");
    if (!name || !from || (paper && !json_is_boolean(hp)) || (mechanics && !json_is_boolean(hm))) {
      expect(false, what, 0, 0);
      continue;
    }
    bool sag = strcmp(name, "gravity_sag") == 0;
    double dm = json_number_value(json_object_get(change, "mechanics"));
    snprintf(what, sizeof what, "finding %s: holds_from %s against its verdicts", name, from);
    if (strcmp(from, "mechanics") == 0)
      expect(sag ? (json_is_true(hp) || json_is_true(hm)) : (json_is_true(hm) && dm > 1e-6), what, 0, 0);
    else if (strcmp(from, "construction") == 0)
      expect(!sag && (json_is_true(hp) || json_is_true(hm)), what, 0, 0);
    else if (strcmp(from, "neither") == 0)
      expect(!json_is_true(hp) && !json_is_true(hm), what, 0, 0);
    else
      expect(strcmp(from, "undetermined") == 0 && !mechanics && json_is_true(hp), what, 0, 0);
  }
  if (!paper) return json_decref(doc), failures ? 1 : 0; // the papers' thresholds are for the papers' method
  static const char* const pierces[] = {"26 rays", "98 rays", "radius 0.05 cm", "radius 0.1 cm", "0.2 cm", "0.8 cm",
                                        "0.2 cm, gravity", "0.8 cm, gravity", "bottom-up", "top-down",
                                        "0.25 cm, pierce", "0.1 cm, pierce", "local model"};
  // force proportional to displacement before rupture, and zero within 1 ms of it
  for (size_t i = 0; i < sizeof pierces / sizeof pierces[0]; i++) {
    double r2 = get(pierces[i], "r2"), zero = get(pierces[i], "zero_after_rupture_s");
    char what[128];
    snprintf(what, sizeof what, "%s: linear fit R^2 >= 0.95", pierces[i]);
    expect(r2 >= 0.95, what, r2, 0.95);
    snprintf(what, sizeof what, "%s: force zero within 1 ms of rupture", pierces[i]);
    expect(zero <= 1e-3 + 1e-9, what, zero, 1e-3);
  }
  double a = get("radius 0.1 cm", "peak_force_n"), b = get("radius 0.05 cm", "peak_force_n");
  expect(a > b, "larger radius, larger peak force", a, b);
  a = get("0.8 cm", "peak_force_n"), b = get("0.2 cm", "peak_force_n");
  expect(a > b, "thicker skin, larger force", a, b);
  a = get("0.8 cm, gravity", "peak_force_n"), b = get("0.2 cm, gravity", "peak_force_n");
  expect(a > b, "thicker skin, larger force, with gravity", a, b);
  a = get("0.2 cm, gravity", "contact_y_m"), b = get("0.2 cm", "contact_y_m");
  expect(a < b - 1e-4, "gravity: the skin sags, first contact lower", a, b);
  static const char* const slides[] = {"x over", "x under", "z over", "z under"};
  for (int i = 0; i < 4; i++) {
    double mean = get(slides[i], "tangent_mean_n"), cv = get(slides[i], "tangent_cv");
    char what[128];
    snprintf(what, sizeof what, "slide %s: steady tangential force against the motion", slides[i]);
    expect(mean < 0 && cv <= 0.25, what, mean, cv);
  }
  // The paper's "denser skin, smoother force" is not asserted: with physics.skin's face contact
  // the skin is held exactly at the HIP's surface on either mesh, and the finer mesh wraps the
  // HIP so that more rays join the contact (docs/hip.md, "What does not reproduce"). The study
  // prints both roughness values; here they must at least have been measured.
  a = get("0.1 cm, pierce", "roughness"), b = get("0.25 cm, pierce", "roughness");
  expect(isfinite(a) && isfinite(b), "roughness measured for both spacings", a, b);
  a = get("sample-and-hold", "max_step_n"), b = get("local model", "max_step_n");
  expect(a >= 10 * b, "largest 1 ms step: sample-and-hold >= 10x the local model", a, b);
  json_decref(doc);
  return failures ? 1 : 0;
}
