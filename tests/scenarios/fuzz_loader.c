// libFuzzer target: arbitrary bytes as a scenario file. The loader must
// answer every input with a scenario or one error line: no crash, no leak,
// no read out of bounds, no undefined behaviour. Plugins are never loaded.
//
// The first byte also picks some --set overrides when it is JSON whitespace,
// so that inputs stay valid JSON while the overrides get exercised too.
#include "model/error.h"
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
  tx_set_error("%s", ""); // a message left must be this load's
  tx_scenario* s = tx_scenario_load_text("fuzz.json", (const char*)data, size, &o);
  // failure must leave a message of one line; success none
  if (!s && (!*tx_error() || strchr(tx_error(), '\n'))) __builtin_trap();
  tx_scenario_free(s);
  return 0;
}
