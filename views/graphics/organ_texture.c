// The organs' procedural tissue texture (see organ_texture.h).
#include "organ_texture.h"

#include <math.h>

// a lattice value in [0, 1], periodic in x and y
static float lattice(int x, int y, int period, uint32_t seed) {
  x = ((x % period) + period) % period, y = ((y % period) + period) % period;
  uint32_t h = (uint32_t)x * 374761393u + (uint32_t)y * 668265263u + seed * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return (float)((h ^ (h >> 16)) & 0xffffu) / 65535.0f;
}

static float noise(float u, float v, int period, uint32_t seed) {
  int x = (int)floorf(u), y = (int)floorf(v);
  float fx = u - (float)x, fy = v - (float)y;
  fx = fx * fx * (3 - 2 * fx), fy = fy * fy * (3 - 2 * fy);
  float a = lattice(x, y, period, seed), b = lattice(x + 1, y, period, seed), c = lattice(x, y + 1, period, seed),
        d = lattice(x + 1, y + 1, period, seed);
  return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy;
}

void tx_tissue_texture(uint8_t* rgb, int size) {
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++) {
      float u = (float)x / (float)size, v = (float)y / (float)size, m = 0, amp = 0.5f;
      for (int o = 0; o < 4; o++, amp *= 0.5f) {
        int period = 4 << o;
        m += amp * noise(u * (float)period, v * (float)period, period, 21u + (uint32_t)o);
      }
      // vessels: where a field crosses its middle, thinner for the finer field
      float v1 = fabsf(noise(u * 6, v * 6, 6, 5u) - 0.5f), v2 = fabsf(noise(u * 16, v * 16, 16, 9u) - 0.5f);
      float vessel = fmaxf(fmaxf(0, 1 - v1 / 0.018f), 0.6f * fmaxf(0, 1 - v2 / 0.012f));
      float speckle = noise(u * 128, v * 128, 128, 13u) - 0.5f;
      float t = 0.5f + 0.55f * (m - 0.47f) + 0.08f * speckle - 0.28f * vessel;
      t = fminf(fmaxf(t, 0), 1);
      rgb[3 * (y * size + x) + 0] = (uint8_t)(fminf(1, t + 0.06f * vessel) * 255 + 0.5f);
      rgb[3 * (y * size + x) + 1] = (uint8_t)(t * 255 + 0.5f);
      rgb[3 * (y * size + x) + 2] = (uint8_t)(t * 255 + 0.5f);
    }
}
