// Force rendering: the local force model, or the papers' sample-and-hold.
#include "render.h"

void tx_render_force(const tx_force_model* m, tx_render_mode mode, const double x[3], double f[3]) {
  for (int i = 0; i < 3; i++) {
    f[i] = m->f0[i];
    if (mode != TX_RENDER_LOCAL_MODEL) continue;
    for (int j = 0; j < 3; j++) f[i] += m->k[3 * i + j] * (x[j] - m->x0[j]);
  }
}

void tx_render_coupling(double kc, double bc, const double tool_x[3], const double tool_v[3], const double x[3],
                        const double v[3], double f[3]) {
  for (int i = 0; i < 3; i++) f[i] = kc * (tool_x[i] - x[i]) + bc * (tool_v[i] - v[i]);
}
