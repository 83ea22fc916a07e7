// Instruments drawn from their URDF visual meshes (renderer.h): each link's
// mesh, read with assimp through the instruments' loader, placed by its
// <visual> origin and scale in the link frame once, then each frame at the
// link poses that physics.instruments publishes (INSTRUMENT.links), as one
// triangle mesh for the renderer. A hand that switches instruments lists
// them all; INSTRUMENT.held says which one it holds.
#include "renderer.h"

#include <tactus/config.h>

#include "../../model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if TX_WITH_URDFDOM && TX_WITH_ASSIMP
#include "../../controllers/instruments/instrument_desc.h"

#define HELD_MAX 4 // instruments one hand can list

typedef struct one {
  int nlinks;
  int first[TX_DRAW_INSTRUMENT_LINKS + 1]; // the vertices of link l: first[l] to first[l + 1]
  float* x;   // vertices in their link's frame, m
  int32_t* tri; // indices into x, all links
  uint32_t nv, nt;
} one;

struct tx_instrument_mesh {
  one ins[HELD_MAX];
  int n;
  float* world; // the held one's vertices placed, m
};

static void rotate_d(const double q[4], const double v[3], double out[3]) {
  double w = q[0], x = q[1], y = q[2], z = q[3];
  double t[3] = {2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])};
  out[0] = v[0] + w * t[0] + (y * t[2] - z * t[1]);
  out[1] = v[1] + w * t[1] + (z * t[0] - x * t[2]);
  out[2] = v[2] + w * t[2] + (x * t[1] - y * t[0]);
}

// one description's meshes, in their link frames
static int take(one* o, const tx_instrument_desc* d) {
  const tx_urdf* u = d->urdf;
  if (u->nlinks > TX_DRAW_INSTRUMENT_LINKS) return tx_set_error("%s: more than %d links", u->name, TX_DRAW_INSTRUMENT_LINKS), -1;
  uint32_t nv = 0, nt = 0;
  for (int l = 0; l < u->nlinks; l++) nv += (uint32_t)d->meshes[l].nvertices, nt += (uint32_t)d->meshes[l].ntriangles;
  o->x = malloc((nv ? nv : 1) * 3 * sizeof(float));
  o->tri = malloc((nt ? nt : 1) * 3 * sizeof(int32_t));
  if (!o->x || !o->tri) return tx_set_error("out of memory"), -1;
  o->nlinks = u->nlinks;
  uint32_t v = 0, t = 0;
  for (int l = 0; l < u->nlinks; l++) {
    const tx_mesh* m = &d->meshes[l];
    const tx_urdf_link* k = &u->links[l];
    o->first[l] = (int)v;
    for (int j = 0; j < m->ntriangles; j++)
      for (int c = 0; c < 3; c++) o->tri[3 * (t + (uint32_t)j) + c] = (int32_t)v + m->triangles[3 * j + c];
    t += (uint32_t)m->ntriangles;
    for (int i = 0; i < m->nvertices; i++, v++) {
      double p[3], r[3];
      for (int c = 0; c < 3; c++) p[c] = m->vertices[3 * i + c] * k->mesh_scale[c];
      rotate_d(k->mesh_pose.q, p, r);
      for (int c = 0; c < 3; c++) o->x[3 * v + c] = (float)(r[c] + k->mesh_pose.p[c]);
    }
  }
  o->first[u->nlinks] = (int)v;
  o->nv = nv, o->nt = nt;
  return 0;
}

tx_instrument_mesh* tx_instrument_mesh_load(const char* list) {
  tx_instrument_mesh* m = calloc(1, sizeof *m);
  char copy[TX_DRAW_URDF_MAX], path[2048], *save = NULL;
  if (!m) return tx_set_error("out of memory"), NULL;
  snprintf(copy, sizeof copy, "%s", list);
  uint32_t most = 0;
  for (char* nm = strtok_r(copy, " \t", &save); nm; nm = strtok_r(NULL, " \t", &save)) {
    if (m->n == HELD_MAX) {
      tx_instrument_mesh_free(m);
      return tx_set_error("more than %d instruments", HELD_MAX), NULL;
    }
    // a bare name is a shipped instrument, as physics.instruments reads it
    size_t len = strlen(nm);
    if (strchr(nm, '/') || (len > 5 && strcmp(nm + len - 5, ".urdf") == 0)) snprintf(path, sizeof path, "%s", nm);
    else snprintf(path, sizeof path, "%s/instruments/%s.urdf", TX_ASSET_DIR, nm);
    tx_instrument_desc* d = tx_instrument_desc_load(path);
    int rc = d ? take(&m->ins[m->n++], d) : -1;
    tx_instrument_desc_free(d);
    if (rc) {
      tx_instrument_mesh_free(m);
      return NULL;
    }
    if (m->ins[m->n - 1].nv > most) most = m->ins[m->n - 1].nv;
  }
  if (m->n == 0) {
    tx_instrument_mesh_free(m);
    return tx_set_error("no instrument named"), NULL;
  }
  if (!(m->world = malloc((most ? most : 1) * 3 * sizeof(float)))) {
    tx_instrument_mesh_free(m);
    return tx_set_error("out of memory"), NULL;
  }
  return m;
}

void tx_instrument_mesh_free(tx_instrument_mesh* m) {
  if (!m) return;
  for (int i = 0; i < m->n; i++) free(m->ins[i].x), free(m->ins[i].tri);
  free(m->world);
  free(m);
}

bool tx_instrument_mesh_place(tx_instrument_mesh* m, double held, const tx_pose* links, uint32_t nlinks,
                              const float** x, uint32_t* nv, const int32_t** tri, uint32_t* nt) {
  if (!isfinite(held) || held < 0 || held >= m->n) return false;
  const one* o = &m->ins[(int)held];
  if (nlinks < (uint32_t)o->nlinks) return false;
  for (int l = 0; l < o->nlinks; l++) {
    const double* q = links[l].quat;
    double qn = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(qn > 1e-9) || !isfinite(qn + links[l].pos[0] + links[l].pos[1] + links[l].pos[2])) return false;
    double u[4] = {q[0] / qn, q[1] / qn, q[2] / qn, q[3] / qn};
    for (int i = o->first[l]; i < o->first[l + 1]; i++) {
      double p[3] = {o->x[3 * i], o->x[3 * i + 1], o->x[3 * i + 2]}, r[3];
      rotate_d(u, p, r);
      for (int c = 0; c < 3; c++) m->world[3 * i + c] = (float)(r[c] + links[l].pos[c]);
    }
  }
  *x = m->world, *nv = o->nv, *tri = o->tri, *nt = o->nt;
  return true;
}

#else

struct tx_instrument_mesh {
  int unused;
};

tx_instrument_mesh* tx_instrument_mesh_load(const char* list) {
  (void)list;
  return tx_set_error("this build reads no instruments (TX_WITH_URDFDOM and TX_WITH_ASSIMP are OFF)"), NULL;
}
void tx_instrument_mesh_free(tx_instrument_mesh* m) { free(m); }
bool tx_instrument_mesh_place(tx_instrument_mesh* m, double held, const tx_pose* links, uint32_t nlinks,
                              const float** x, uint32_t* nv, const int32_t** tri, uint32_t* nt) {
  (void)m, (void)held, (void)links, (void)nlinks, (void)x, (void)nv, (void)tri, (void)nt;
  return false;
}

#endif
