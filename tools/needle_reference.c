// tactus-needle-reference: writes a reference needle-insertion curve from the
// published needle-force model form (controllers/voxel/insertion_model.h) in
// the haptic recording CSV format. It is model-generated, not measured.
//
//   tactus-needle-reference OUT.csv [KEY=VALUE]...
//
// keys: a1 (N/m), a2 (N/m^2), puncture_depth (m), cutting (N), friction
// (N/m), start_depth (m), max_depth (m), speed (m/s), wait (s), rate (Hz).
// Bad input: one line on stderr and exit status 2.
#include "controllers/voxel/insertion_model.h"

#include <tactus/model.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int bad(const char* fmt, const char* a, const char* b) {
  fprintf(stderr, "tactus-needle-reference: ");
  fprintf(stderr, fmt, a, b);
  fprintf(stderr, "\n");
  return 2;
}

int main(int argc, char** argv) {
  if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
    printf("usage: tactus-needle-reference OUT.csv [KEY=VALUE]...\n"
           "keys: a1 a2 puncture_depth cutting friction start_depth max_depth speed wait rate (SI units)\n");
    return 0;
  }
  if (argc < 2 || argv[1][0] == '-') return bad("%s%s", "expected OUT.csv first (--help for the keys)", "");
  tx_insertion_model m = tx_insertion_model_default();
  tx_insertion_motion mo = tx_insertion_motion_default();
  struct { const char* key; double* field; } keys[] = {
      {"a1", &m.a1}, {"a2", &m.a2}, {"puncture_depth", &m.puncture_depth}, {"cutting", &m.cutting},
      {"friction", &m.friction}, {"start_depth", &mo.start_depth}, {"max_depth", &mo.max_depth},
      {"speed", &mo.speed}, {"wait", &mo.wait}, {"rate", &mo.rate}};
  for (int i = 2; i < argc; i++) {
    const char* eq = strchr(argv[i], '=');
    if (!eq) return bad("%s: expected KEY=VALUE%s", argv[i], "");
    char* end;
    errno = 0;
    double v = strtod(eq + 1, &end);
    if (end == eq + 1 || *end || errno || !isfinite(v)) return bad("%s: %s", argv[i], "expected a finite number");
    bool found = false;
    for (size_t k = 0; k < sizeof keys / sizeof keys[0] && !found; k++)
      if (strlen(keys[k].key) == (size_t)(eq - argv[i]) && strncmp(argv[i], keys[k].key, (size_t)(eq - argv[i])) == 0)
        *keys[k].field = v, found = true;
    if (!found) return bad("%s: unknown key%s (--help lists them)", argv[i], "");
  }
  tx_recording r;
  if (!tx_insertion_generate(&m, &mo, &r)) return bad("%s%s", tx_error(), "");
  bool ok = tx_recording_write(&r, argv[1]);
  tx_recording_free(&r);
  if (!ok) return bad("%s%s", tx_error(), "");
  printf("wrote %s: a1 = %g N/m, a2 = %g N/m^2, puncture at %g m, cutting %g N, friction %g N/m\n", argv[1], m.a1, m.a2,
         m.puncture_depth, m.cutting, m.friction);
  return 0;
}
