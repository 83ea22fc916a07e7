// libFuzzer target for the "sim:" device spec parser (tx_sim_device_parse):
// whatever the spec, it is refused with one line naming a key, or it gives a
// device that init accepts and that stays finite however it is driven. Each
// accepted spec is integrated at the shortest, the usual and the longest
// period, under forces far above the clamp and a hand jumping across the
// workspace, so a range that lets the integration blow up is found here.
#include "model/error.h"
#include "controllers/haptics/sim_device.h"

#include <tactus/model.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void drive(const tx_sim_device_def* def, double period) {
  tx_sim_device_def d = *def;
  d.period = period;
  tx_sim_device dev;
  if (!tx_sim_device_init(&dev, &d)) {
    if (!*tx_error() || strchr(tx_error(), '\n')) abort(); // refused, then with one line
    return;
  }
  for (int k = 0; k < 400; k++) {
    double s = (k / 7) % 2 ? 1 : -1; // a square wave: the hardest a held force can push
    const double f[3] = {s * 1e6, -s * 1e6, k % 3 ? 0 : s * 1e6};
    const double target[3] = {-s * 10, s * 10, 0};
    tx_sim_device_step(&dev, f, target);
    for (int i = 0; i < 3; i++)
      if (!isfinite(dev.x[i]) || !isfinite(dev.v[i]) || !isfinite(dev.state.pos[i]) || !isfinite(dev.state.vel[i]))
        abort();
    if (!isfinite(dev.work)) abort();
  }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // an exact-size string, so that a read past its end is caught
  char* spec = malloc(size + 1);
  if (!spec) return 0;
  memcpy(spec, data, size);
  spec[size] = 0;
  tx_sim_device_def def = tx_sim_device_def_default();
  char hand[64] = "pierce-down";
  tx_set_error("%s", ""); // a message left must be this parse's
  if (tx_sim_device_parse(spec, &def, hand, sizeof hand)) {
    if (tx_sim_device_def_check(&def) || !memchr(hand, 0, sizeof hand)) abort();
    drive(&def, 1e-4); // 10 kHz, the fastest haptics tick
    drive(&def, 1e-3);
    drive(&def, 0.1); // the longest period the device takes
  } else if (!*tx_error() || strchr(tx_error(), '\n')) {
    abort(); // one line, always
  }
  free(spec);
  return 0;
}
