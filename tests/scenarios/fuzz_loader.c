// libFuzzer target: arbitrary bytes as a scenario file. The loader must
// answer every input with a scenario or one error line: no crash, no leak,
// no read out of bounds, no undefined behaviour. Plugins are never loaded.
//
// The first byte also picks some --set overrides when it is JSON whitespace,
// so that inputs stay valid JSON while the overrides get exercised too.
#include "scenarios/loader.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

static const char* const sets[] = {
    "a.rate_hz=50", "a.work_us=0", "duration_s=2", "a.reads=[\"t.x\"]",
    "b.rows=3",     "b.write=t.y", "a.units=N",    "nobody.x=1",
};

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  int first = 0, count = 0;
  if (size > 0) {
    switch (data[0]) {
    case ' ': first = 0, count = 2; break;
    case '\t': first = 2, count = 2; break;
    case '\n': first = 4, count = 3; break;
    case '\r': first = 0, count = 8; break;
    default: break;
    }
  }
  tx_load_options o = {.sets = sets + first, .nsets = count, .allow_plugins = false};
  char err[1024];
  err[0] = 0;
  tx_scenario* s = tx_scenario_load_text("fuzz.json", (const char*)data, size, &o, err, sizeof err);
  // failure must leave a message of one line; success none
  if (!s && (!err[0] || strchr(err, '\n'))) __builtin_trap();
  tx_scenario_free(s);
  return 0;
}
