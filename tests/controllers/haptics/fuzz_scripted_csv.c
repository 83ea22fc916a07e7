// libFuzzer target for the scripted device's waypoint reader
// (`--device scripted:FILE.csv`): whatever the text, it returns an error of
// one line naming the file, or a device whose every reading, before, between
// and after the waypoints, is finite, within 10 m, with a unit quaternion.
#include "model/error.h"
#include "controllers/haptics/device_scripted.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0; // fmemopen needs a buffer
  char* buf = malloc(size);
  if (!buf) return 0;
  memcpy(buf, data, size);
  FILE* f = fmemopen(buf, size, "r");
  if (!f) return free(buf), 0;
  tx_device* d = tx_scripted_read_csv(f, "fuzz.csv");
  fclose(f);
  free(buf);
  if (!d) {
    if (strncmp(tx_error(), "fuzz.csv", 8) != 0 || strchr(tx_error(), '\n')) abort();
    return 0;
  }
  // t from before the start to past the end, by uneven steps
  for (double t = -1; t < 1e6; t = t < 1 ? t + 0.037 : t * 1.7) {
    tx_device_state s;
    if (!tx_device_scripted.read(d, t, &s)) abort();
    double q2 = 0;
    for (int k = 0; k < 4; k++) q2 += s.quat[k] * s.quat[k];
    if (!(fabs(q2 - 1) < 1e-9) || !isfinite(s.grip)) abort();
    for (int k = 0; k < 3; k++)
      if (!(fabs(s.pos[k]) <= 10) || !isfinite(s.vel[k])) abort();
  }
  tx_device_scripted.close(d);
  return 0;
}
