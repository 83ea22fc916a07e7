#include "instrument_desc.h"

#include "../../model/error.h"

#include <stdlib.h>

void tx_instrument_desc_free(tx_instrument_desc* d) {
  if (!d) return;
  if (d->meshes && d->urdf)
    for (int i = 0; i < d->urdf->nlinks; i++) tx_mesh_free(&d->meshes[i]);
  free(d->meshes);
  tx_urdf_free(d->urdf);
  free(d);
}

tx_instrument_desc* tx_instrument_desc_load(const char* path) {
  tx_urdf* u = tx_urdf_load(path);
  if (!u) return NULL;
  tx_instrument_desc* d = calloc(1, sizeof *d);
  if (d) d->urdf = u, d->meshes = calloc((size_t)u->nlinks, sizeof *d->meshes);
  if (!d || !d->meshes) {
    if (!d) tx_urdf_free(u);
    tx_instrument_desc_free(d);
    return tx_set_error("%s: out of memory", path), NULL;
  }
  for (int i = 0; i < u->nlinks; i++) {
    if (!u->links[i].mesh[0]) continue;
    if (!tx_mesh_load(u->links[i].mesh, &d->meshes[i])) {
      tx_error_prefix("%s: link '%s' <visual> <mesh>", path, u->links[i].name);
      tx_instrument_desc_free(d);
      return NULL;
    }
  }
  return d;
}

double tx_instrument_desc_mass(const tx_instrument_desc* d) {
  double m = 0;
  for (int i = 0; i < d->urdf->nlinks; i++) m += d->urdf->links[i].mass;
  return m;
}

int tx_instrument_desc_jaws(const tx_instrument_desc* d) {
  int n = 0;
  for (int i = 0; i < d->urdf->njoints; i++) n += !d->urdf->joints[i].fixed;
  return n;
}
