// The device plots' rings (gui_series.h).
#include "gui_series.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

bool tx_series_push(tx_series_set* s, const char* name, double t_s, const double pos[3], const double* force) {
  int d = 0;
  while (d < s->count && strcmp(s->dev[d].name, name) != 0) d++;
  if (d == s->count) {
    if (s->count == TX_SERIES_DEVICES) return false;
    memset(&s->dev[d], 0, sizeof s->dev[d]);
    snprintf(s->dev[d].name, sizeof s->dev[d].name, "%s", name);
    s->dev[d].last_t = -INFINITY;
    s->count++;
  }
  tx_series* e = &s->dev[d];
  if (!(t_s > e->last_t)) return true;
  e->last_t = t_s;
  e->has_force = force != NULL;
  double f[3] = {0, 0, 0};
  if (force) memcpy(f, force, sizeof f);
  for (int k = 0; k < 3; k++) {
    e->fxyz[k] = (float)f[k];
    e->pos[k][e->next] = (float)(pos[k] * 1e3);
  }
  e->force[e->next] = (float)sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  e->next = (e->next + 1) % TX_SERIES_LEN;
  if (e->count < TX_SERIES_LEN) e->count++;
  return true;
}
