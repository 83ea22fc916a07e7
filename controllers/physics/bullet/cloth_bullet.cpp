// The skin patch on a Bullet soft body: the C interface of cloth.h over
// btSoftBody. Bullet integrates the particles and solves the links; this
// file builds the patch, drives the substeps, projects the HIP contact,
// breaks overstretched links and guards against numerical faults.
#include "cloth.h"

extern "C" {
#include "../../../model/error.h"
#include "../../range_check.h"
}

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <new>
#include <vector>

namespace {

enum link_kind : uint8_t { STRETCH, SHEAR, BEND };

// what a link means to the mesh, by link id (the Bullet link's m_tag)
struct link_info {
  int32_t slot;    // index in btSoftBody::m_links, -1 once removed
  int32_t tri[2];  // triangles it borders, -1 for none (bending links: none)
  int32_t dep[2];  // bending links that span this stretch link, or -1
  int32_t part[2]; // for a bending link: the two stretch links it spans
  float limit2;    // m^2, squared length at which it breaks: ((1 + rupture_strain) reference)^2
  link_kind kind;
};

} // namespace

struct tx_cloth {
  tx_cloth_def def;
  int n;     // particles
  int ntri;  // triangles, live or not
  int nlink; // links at creation
  btSoftBodyWorldInfo world;
  btSoftBody* body;
  btSoftBody::Material* stretch_mat; // stretch and shear links
  btSoftBody::Material* bend_mat;    // bending links
  double node_mass; // kg per particle
  double prepared_dt; // s, substep length the link constants were computed for (0: none)

  std::vector<int32_t> tri;        // (ntri x 3) vertex indices
  std::vector<uint8_t> tri_alive;  // (ntri)
  std::vector<int32_t> live;       // (ntri x 3) the live triangles, compacted; rows: nlive
  int nlive;                       // live triangles
  bool live_dirty;                 // tri_alive changed since live was compacted
  std::vector<int32_t> node_tris;  // (n x 8) triangles around each particle, -1 padded
  std::vector<link_info> info;     // (nlink)
  std::vector<btSoftBody::Link> original; // (nlink) each link as built, to put broken ones back
  std::vector<int32_t> breaking;   // (nlink) scratch: links to break after a substep
  std::vector<int32_t> tri_stamp;  // (ntri) scratch: triangles already tested this pass
  int32_t stamp;
  std::vector<int32_t> near_tris;  // (ntri) scratch: candidate triangles of one pass
  int torn;
  int faults;

  // the HIP, a kinematic sphere
  double hip[3];      // m, centre at the end of the next step
  double hip_prev[3]; // m, centre at the end of the last step
  double hip_radius;  // m, 0: none
  double contact_impulse[3]; // N s, momentum the contact gave the skin this step
  double contact_force[3];   // N, of the skin on the HIP over the last step
  double max_edge;           // m, longest rest length of a stretch or shear link
  double reach_factor;       // 1, the longest a live stretch or shear link gets, over max_edge

  // last good state
  std::vector<float> good_x, good_v;   // (n x 3) m, m/s
  std::vector<uint8_t> good_link;      // (nlink) 1 = present
  std::vector<uint8_t> good_tri;       // (ntri)
  int good_torn;
  double good_hip[3];
  bool topology_dirty; // links broke since the last save
};

extern "C" tx_cloth_def tx_cloth_def_default(void) {
  tx_cloth_def d;
  std::memset(&d, 0, sizeof d);
  d.size[0] = d.size[1] = 0.1;
  d.res[0] = d.res[1] = 42;
  d.thickness = 0.004;
  d.mass = 0.044;
  d.stretch_stiffness = 2000;
  d.bend_stiffness = 20;
  d.damping = 5;
  d.gravity = 0;
  d.fixed_border = true;
  d.rupture_strain = 0.6;
  d.iterations = 10;
  d.max_substep = 1.0 / 60;
  d.max_speed = 100;
  d.settle_time = 1;
  return d;
}

static const char* range(const char* name, double v, double lo, bool open_lo, double hi, bool open_hi,
                         const char* units) {
  return tx_check_range_msg("skin", name, v, lo, open_lo, hi, open_hi, units);
}

extern "C" const char* tx_cloth_def_check(const tx_cloth_def* d) {
  static const char* const size_name[2] = {"size[0]", "size[1]"};
  static const char* const res_name[2] = {"res[0]", "res[1]"};
  static const char* const center_name[3] = {"center[0]", "center[1]", "center[2]"};
  const char* e;
  for (int a = 0; a < 2; a++) {
    if ((e = range(size_name[a], d->size[a], 1e-3, false, 10, false, "m"))) return e;
    if ((e = tx_check_count_msg("skin", res_name[a], d->res[a], 2, 1024))) return e;
  }
  for (int a = 0; a < 3; a++)
    if ((e = range(center_name[a], d->center[a], -10, false, 10, false, "m"))) return e;
  if ((e = range("thickness", d->thickness, 0, false, 0.02, false, "m"))) return e;
  if ((e = range("mass", d->mass, 0, true, 100, false, "kg"))) return e;
  if ((e = range("stretch_stiffness", d->stretch_stiffness, 0, true, 1e9, false, "N/m"))) return e;
  if ((e = range("bend_stiffness", d->bend_stiffness, 0, false, 1e9, false, "N/m"))) return e;
  if ((e = range("damping", d->damping, 0, false, 1e4, false, "1/s"))) return e;
  if ((e = range("gravity", d->gravity, 0, false, 100, false, "m/s^2"))) return e;
  if ((e = range("rupture_strain", d->rupture_strain, 0, false, 100, false, "(strain)"))) return e;
  if ((e = tx_check_count_msg("skin", "iterations", d->iterations, 1, 200))) return e;
  if ((e = range("max_substep", d->max_substep, 1e-5, false, 0.1, false, "s"))) return e;
  if ((e = range("max_speed", d->max_speed, 0, true, 1e4, false, "m/s"))) return e;
  if ((e = range("settle_time", d->settle_time, 0, false, 10, false, "s"))) return e;
  return NULL;
}

// ---------------------------------------------------------------------------
// building the patch

static int node_index(const tx_cloth_def& d, int ix, int iz) { return iz * d.res[0] + ix; }

// the triangle of cell (cx, cz) that holds both u and v, or -1
static int32_t cell_triangle(const tx_cloth* c, int cx, int cz, int u, int v) {
  const tx_cloth_def& d = c->def;
  if (cx < 0 || cz < 0 || cx >= d.res[0] - 1 || cz >= d.res[1] - 1) return -1;
  int cell = cz * (d.res[0] - 1) + cx;
  for (int k = 0; k < 2; k++) {
    const int32_t* t = &c->tri[(size_t)(2 * cell + k) * 3];
    bool hu = t[0] == u || t[1] == u || t[2] == u, hv = t[0] == v || t[1] == v || t[2] == v;
    if (hu && hv) return 2 * cell + k;
  }
  return -1;
}

static int add_link(tx_cloth* c, int a, int b, link_kind kind) {
  int id = (int)c->info.size();
  c->body->appendLink(a, b, kind == BEND ? c->bend_mat : c->stretch_mat, false);
  btSoftBody::Link& l = c->body->m_links[c->body->m_links.size() - 1];
  l.m_tag = reinterpret_cast<void*>(static_cast<intptr_t>(id));
  link_info li;
  li.slot = c->body->m_links.size() - 1;
  li.tri[0] = li.tri[1] = li.dep[0] = li.dep[1] = li.part[0] = li.part[1] = -1;
  li.kind = kind;
  c->info.push_back(li);
  if (kind != BEND && l.m_rl > c->max_edge) c->max_edge = l.m_rl;
  return id;
}

// a bending link over the stretch links s0 and s1, which it depends on
static void add_bend(tx_cloth* c, int a, int b, int s0, int s1) {
  int id = add_link(c, a, b, BEND);
  c->info[(size_t)id].part[0] = s0;
  c->info[(size_t)id].part[1] = s1;
  for (int s : {s0, s1}) {
    link_info& li = c->info[(size_t)s];
    li.dep[li.dep[0] < 0 ? 0 : 1] = id;
  }
}

static bool build(tx_cloth* c) {
  const tx_cloth_def& d = c->def;
  const int nx = d.res[0], nz = d.res[1];
  c->n = nx * nz;
  c->ntri = 2 * (nx - 1) * (nz - 1);
  const double hx = d.size[0] / (nx - 1), hz = d.size[1] / (nz - 1);

  // particles on the grid; the border is fixed by zero mass
  std::vector<btVector3> x((size_t)c->n);
  std::vector<btScalar> m((size_t)c->n);
  c->node_mass = d.mass / c->n;
  for (int iz = 0; iz < nz; iz++)
    for (int ix = 0; ix < nx; ix++) {
      int i = node_index(d, ix, iz);
      x[(size_t)i] = btVector3((btScalar)(d.center[0] - 0.5 * d.size[0] + ix * hx), (btScalar)d.center[1],
                               (btScalar)(d.center[2] - 0.5 * d.size[1] + iz * hz));
      bool border = ix == 0 || iz == 0 || ix == nx - 1 || iz == nz - 1;
      m[(size_t)i] = (d.fixed_border && border) ? 0 : (btScalar)c->node_mass;
    }
  c->body = new btSoftBody(&c->world, c->n, x.data(), m.data());
  c->body->m_cfg.collisions = 0; // the HIP contact is ours (see cloth.h)
  c->body->m_cfg.piterations = d.iterations;
  c->body->m_cfg.kDP = 0;
  // the default 0.25 m margin stays: with it Bullet's node tree is rarely rebuilt, and nothing collides through it
  c->stretch_mat = c->body->m_materials[0];
  c->bend_mat = c->body->appendMaterial();

  // two triangles per cell along an alternating diagonal, normals towards +y
  c->tri.resize((size_t)c->ntri * 3);
  for (int cz = 0; cz < nz - 1; cz++)
    for (int cx = 0; cx < nx - 1; cx++) {
      int a = node_index(d, cx, cz), b = node_index(d, cx + 1, cz), cc = node_index(d, cx, cz + 1),
          dd = node_index(d, cx + 1, cz + 1);
      int32_t* t = &c->tri[(size_t)(cz * (nx - 1) + cx) * 6];
      if (((cx + cz) & 1) == 0) {
        int32_t v[6] = {a, dd, b, a, cc, dd};
        std::memcpy(t, v, sizeof v);
      } else {
        int32_t v[6] = {a, cc, b, b, cc, dd};
        std::memcpy(t, v, sizeof v);
      }
    }
  c->tri_alive.assign((size_t)c->ntri, 1);
  c->live = c->tri;
  c->nlive = c->ntri;
  c->node_tris.assign((size_t)c->n * 8, -1);
  for (int t = 0; t < c->ntri; t++)
    for (int k = 0; k < 3; k++) {
      int32_t* slots = &c->node_tris[(size_t)c->tri[(size_t)t * 3 + k] * 8];
      for (int s = 0; s < 8; s++)
        if (slots[s] < 0) {
          slots[s] = t;
          break;
        }
    }

  // stretch links along x and z, each bordering one triangle per side
  std::vector<int> sx((size_t)c->n, -1), sz((size_t)c->n, -1); // link from a particle to its +x / +z neighbour
  for (int iz = 0; iz < nz; iz++)
    for (int ix = 0; ix < nx; ix++) {
      int i = node_index(d, ix, iz);
      if (ix + 1 < nx) {
        int j = node_index(d, ix + 1, iz);
        int id = sx[(size_t)i] = add_link(c, i, j, STRETCH);
        c->info[(size_t)id].tri[0] = cell_triangle(c, ix, iz - 1, i, j);
        c->info[(size_t)id].tri[1] = cell_triangle(c, ix, iz, i, j);
      }
      if (iz + 1 < nz) {
        int j = node_index(d, ix, iz + 1);
        int id = sz[(size_t)i] = add_link(c, i, j, STRETCH);
        c->info[(size_t)id].tri[0] = cell_triangle(c, ix - 1, iz, i, j);
        c->info[(size_t)id].tri[1] = cell_triangle(c, ix, iz, i, j);
      }
    }
  // shear links along both diagonals; either one takes both triangles of its cell
  for (int cz = 0; cz < nz - 1; cz++)
    for (int cx = 0; cx < nx - 1; cx++) {
      int cell = cz * (nx - 1) + cx;
      int a = node_index(d, cx, cz), b = node_index(d, cx + 1, cz), cc = node_index(d, cx, cz + 1),
          dd = node_index(d, cx + 1, cz + 1);
      for (int id : {add_link(c, a, dd, SHEAR), add_link(c, b, cc, SHEAR)}) {
        c->info[(size_t)id].tri[0] = 2 * cell;
        c->info[(size_t)id].tri[1] = 2 * cell + 1;
      }
    }
  // bending links two spacings long, over the two stretch links between
  for (int iz = 0; iz < nz; iz++)
    for (int ix = 0; ix < nx; ix++) {
      int i = node_index(d, ix, iz);
      if (ix + 2 < nx) add_bend(c, i, node_index(d, ix + 2, iz), sx[(size_t)i], sx[(size_t)i + 1]);
      if (iz + 2 < nz) add_bend(c, i, node_index(d, ix, iz + 2), sz[(size_t)i], sz[(size_t)node_index(d, ix, iz + 1)]);
    }
  c->nlink = (int)c->info.size();

  // Gauss-Seidel order in colours: no two links of one colour share a
  // particle, so the solver's updates within a colour do not wait on each
  // other (about a third fewer cycles at 10404 particles), and within a
  // colour they follow the particles in memory order
  {
    btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
    const btSoftBody::Node* base = &c->body->m_nodes[0];
    auto colour = [&](int a, int b) {
      int ax = a % nx, az = a / nx, dx = b % nx - ax, dz = b / nx - az;
      if (dz == 0) return dx == 1 ? (ax & 1) : 8 + ((ax >> 1) & 1);     // stretch x, bending x
      if (dx == 0) return dz == 1 ? 2 + (az & 1) : 10 + ((az >> 1) & 1); // stretch z, bending z
      return (dx > 0 ? 4 : 6) + (az & 1);                                // the two diagonals
    };
    std::vector<std::pair<long long, int>> key((size_t)links.size());
    for (int i = 0; i < links.size(); i++) {
      int a = (int)(links[i].m_n[0] - base), b = (int)(links[i].m_n[1] - base);
      if (a > b) std::swap(a, b);
      key[(size_t)i] = {(long long)colour(a, b) << 32 | a, i};
    }
    std::sort(key.begin(), key.end());
    std::vector<btSoftBody::Link> sorted((size_t)links.size());
    for (size_t i = 0; i < key.size(); i++) sorted[i] = links[key[i].second];
    for (int i = 0; i < links.size(); i++) {
      links[i] = sorted[(size_t)i];
      c->info[(size_t)(intptr_t)links[i].m_tag].slot = i;
    }
  }

  // rest lengths and constants now, so that Bullet never resets them to a deformed shape
  c->body->updateConstants();
  c->body->m_bUpdateRtCst = false;
  c->original.assign(c->body->m_links.size(), btSoftBody::Link());
  for (int i = 0; i < c->body->m_links.size(); i++) c->original[(size_t)i] = c->body->m_links[i];

  c->breaking.resize((size_t)c->nlink);
  c->tri_stamp.assign((size_t)c->ntri, 0);
  c->near_tris.resize((size_t)c->ntri);
  c->good_x.resize((size_t)c->n * 3);
  c->good_v.resize((size_t)c->n * 3);
  c->good_link.assign((size_t)c->nlink, 1);
  c->good_tri.assign((size_t)c->ntri, 1);
  return true;
}

// Under gravity the patch first hangs for settle_time without rupture, and
// the links' lengths there become the reference of the rupture strain: the
// sag is the skin's state before any contact (the journal paper's skin hangs
// about 1 cm before the HIP arrives), and a position solver that stretches
// a hanging cloth more at finer grids must not tear it by itself.
static void settle(tx_cloth* c) {
  const double strain = c->def.rupture_strain;
  c->def.rupture_strain = 0;
  int steps = c->def.gravity > 0 ? (int)std::ceil(c->def.settle_time * 60) : 0;
  for (int s = 0; s < steps; s++)
    if (tx_cloth_step(c, 1.0 / 60) != TX_CLOTH_OK) break;
  c->def.rupture_strain = strain;
  const double f = (1 + strain) * (1 + strain);
  btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  for (int i = 0, ni = links.size(); i < ni; i++) {
    btSoftBody::Link& l = links[i];
    double now2 = (l.m_n[1]->m_x - l.m_n[0]->m_x).length2(), rest2 = (double)l.m_rl * l.m_rl;
    float limit2 = (float)(f * (now2 > rest2 ? now2 : rest2));
    c->info[(size_t)(intptr_t)l.m_tag].limit2 = limit2;
    if (c->info[(size_t)(intptr_t)l.m_tag].kind != BEND && c->max_edge > 0)
      c->reach_factor = std::max(c->reach_factor, std::sqrt((double)limit2) / c->max_edge);
  }
  for (int a = 0; a < 3; a++) c->contact_force[a] = 0;
}

extern "C" tx_cloth* tx_cloth_create(const tx_cloth_def* def) {
  const char* e = def ? tx_cloth_def_check(def) : "skin: no definition";
  if (e) {
    tx_set_error("%s", e);
    return NULL;
  }
  tx_cloth* c = new (std::nothrow) tx_cloth();
  if (!c) {
    tx_set_error("skin: out of memory");
    return NULL;
  }
  c->def = *def;
  c->world.m_gravity = btVector3(0, (btScalar)-def->gravity, 0);
  c->world.air_density = 0;
  c->world.m_sparsesdf.Initialize();
  try {
    build(c);
  } catch (const std::bad_alloc&) {
    tx_set_error("skin: out of memory for %d x %d particles", def->res[0], def->res[1]);
    tx_cloth_destroy(c);
    return NULL;
  }
  for (int a = 0; a < 3; a++) c->hip[a] = c->hip_prev[a] = c->good_hip[a] = def->center[a];
  settle(c);
  tx_cloth_save(c);
  return c;
}

extern "C" void tx_cloth_destroy(tx_cloth* c) {
  if (!c) return;
  delete c->body;
  delete c;
}

extern "C" const tx_cloth_def* tx_cloth_get_def(const tx_cloth* c) { return &c->def; }
extern "C" int tx_cloth_particle_count(const tx_cloth* c) { return c->n; }
extern "C" int tx_cloth_triangle_count(const tx_cloth* c) { return c->ntri; }
extern "C" int tx_cloth_link_count(const tx_cloth* c) { return c->body->m_links.size(); }
extern "C" int tx_cloth_torn(const tx_cloth* c) { return c->torn; }
extern "C" int tx_cloth_faults(const tx_cloth* c) { return c->faults; }

extern "C" void tx_cloth_contact_force(const tx_cloth* c, double out[3]) {
  for (int a = 0; a < 3; a++) out[a] = c->contact_force[a];
}

extern "C" tx_cloth_status tx_cloth_set_hip(tx_cloth* c, const double pos[3], double radius) {
  if (!(std::isfinite(pos[0]) && std::isfinite(pos[1]) && std::isfinite(pos[2]) && std::fabs(pos[0]) <= 1e3 &&
        std::fabs(pos[1]) <= 1e3 && std::fabs(pos[2]) <= 1e3)) {
    tx_set_error("skin: HIP position (%g, %g, %g) m, must be finite and within 1 km", pos[0], pos[1], pos[2]);
    return TX_CLOTH_BAD;
  }
  if (!(radius >= 0 && radius <= 0.1)) {
    tx_set_error("skin: HIP radius = %g m, must be finite and in [0, 0.1]", radius);
    return TX_CLOTH_BAD;
  }
  // a HIP that appears starts where it is, not at the old centre
  if (c->hip_radius == 0)
    for (int a = 0; a < 3; a++) c->hip_prev[a] = pos[a];
  for (int a = 0; a < 3; a++) c->hip[a] = pos[a];
  c->hip_radius = radius;
  return TX_CLOTH_OK;
}

// ---------------------------------------------------------------------------
// stepping

// Bullet's per-iteration link stiffness for a spring k (N/m) over a substep
// dt: the fraction k dt^2 w / (1 + k dt^2 w) of the stretch that an implicit
// spring removes in one substep (w: the two inverse masses, 1/kg)
static btScalar link_stiffness(double k, double dt, double w) {
  if (k <= 0) return 0;
  double a = k * dt * dt * w;
  double s = a / (1 + a);
  if (!(s > 1e-9)) s = 1e-9; // Bullet divides by it
  return (btScalar)(s < 1 ? s : 1);
}

static void prepare(tx_cloth* c, double dt) {
  if (dt == c->prepared_dt) return;
  double w = 2 / c->node_mass;
  c->stretch_mat->m_kLST = link_stiffness(c->def.stretch_stiffness, dt, w);
  c->bend_mat->m_kLST = link_stiffness(c->def.bend_stiffness > 0 ? c->def.bend_stiffness : 1e-12, dt, w);
  c->body->updateLinkConstants();
  c->body->m_cfg.kDP = (btScalar)(1 - std::exp(-c->def.damping * dt));
  c->prepared_dt = dt;
}

// closest point of triangle (a, b, cc) to p, as barycentric weights (Ericson's region tests)
static void closest_on_triangle(const btVector3& p, const btVector3& a, const btVector3& b, const btVector3& cc,
                                btScalar w[3]) {
  btVector3 ab = b - a, ac = cc - a, ap = p - a;
  btScalar d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) { w[0] = 1, w[1] = 0, w[2] = 0; return; }
  btVector3 bp = p - b;
  btScalar d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) { w[0] = 0, w[1] = 1, w[2] = 0; return; }
  btScalar vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    btScalar v = d1 / (d1 - d3);
    w[0] = 1 - v, w[1] = v, w[2] = 0;
    return;
  }
  btVector3 cp = p - cc;
  btScalar d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) { w[0] = 0, w[1] = 0, w[2] = 1; return; }
  btScalar vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    btScalar v = d2 / (d2 - d6);
    w[0] = 1 - v, w[1] = 0, w[2] = v;
    return;
  }
  btScalar va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    btScalar v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w[0] = 0, w[1] = 1 - v, w[2] = v;
    return;
  }
  btScalar den = 1 / (va + vb + vc);
  btScalar v = vb * den, u = vc * den;
  w[0] = 1 - v - u, w[1] = v, w[2] = u;
}

// the HIP at h, at `from` when the substep began: every live triangle closer
// than the contact distance is pushed out to it, away from the side the HIP
// came from. Adds the momentum given to the skin to the contact impulse when
// count is set, and the implied velocity to the particles when fix_velocity is.
static void project_contact(tx_cloth* c, const btVector3& h, const btVector3& from, double dt, bool count,
                            bool fix_velocity) {
  const double rc = c->hip_radius + 0.5 * c->def.thickness;
  if (c->hip_radius <= 0 || rc <= 0) return;
  btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  // candidates: triangles of particles within reach (a triangle in contact has a corner this close)
  // a live link is at most (1 + rupture_strain) its reference (the settled length under gravity)
  const double stretch = c->def.rupture_strain > 0 ? c->reach_factor : 10;
  const btScalar reach = (btScalar)(rc + stretch * c->max_edge);
  const btScalar reach2 = reach * reach;
  int ncand = 0;
  if (++c->stamp == INT32_MAX) {
    std::fill(c->tri_stamp.begin(), c->tri_stamp.end(), 0);
    c->stamp = 1;
  }
  for (int i = 0; i < c->n; i++) {
    if ((nodes[i].m_x - h).length2() > reach2) continue;
    const int32_t* ts = &c->node_tris[(size_t)i * 8];
    for (int s = 0; s < 8 && ts[s] >= 0; s++) {
      int32_t t = ts[s];
      if (!c->tri_alive[(size_t)t] || c->tri_stamp[(size_t)t] == c->stamp) continue;
      c->tri_stamp[(size_t)t] = c->stamp;
      c->near_tris[(size_t)ncand++] = t;
    }
  }
  if (!ncand) return;
  const btScalar rcs = (btScalar)rc;
  // two passes: neighbouring triangles share particles
  for (int pass = 0; pass < 2; pass++)
    for (int k = 0; k < ncand; k++) {
      const int32_t* t = &c->tri[(size_t)c->near_tris[(size_t)k] * 3];
      btSoftBody::Node* p[3] = {&nodes[t[0]], &nodes[t[1]], &nodes[t[2]]};
      btScalar w[3];
      closest_on_triangle(h, p[0]->m_x, p[1]->m_x, p[2]->m_x, w);
      btVector3 q = p[0]->m_x * w[0] + p[1]->m_x * w[1] + p[2]->m_x * w[2];
      btVector3 dq = q - h;
      btScalar dist2 = dq.length2();
      if (dist2 >= rcs * rcs) continue;
      btVector3 nt = (p[1]->m_x - p[0]->m_x).cross(p[2]->m_x - p[0]->m_x);
      btScalar ntl = nt.length();
      if (!(ntl > 0)) continue;
      nt /= ntl;
      // which side the HIP belongs on: the side it was on at the start of the
      // substep, against the triangle as it was then (m_q), so that neither
      // the HIP's move nor the links' pull can carry it through
      btVector3 q0 = p[0]->m_q * w[0] + p[1]->m_q * w[1] + p[2]->m_q * w[2];
      btVector3 n0 = (p[1]->m_q - p[0]->m_q).cross(p[2]->m_q - p[0]->m_q);
      btScalar side_from = (from - q0).dot(n0.length2() > 0 ? n0 : nt), side_now = (h - q).dot(nt);
      btScalar side = side_from != 0 ? (side_from > 0 ? 1 : -1) : (side_now >= 0 ? 1 : -1);
      btVector3 dir;
      if (side_now * side > 0 && dist2 > 1e-20f) dir = dq / btSqrt(dist2); // still on its side: away from the centre
      else dir = nt * -side;                                                // crossed: back to the far side
      btScalar depth = rcs - (q - h).dot(dir);
      if (!(depth > 0)) continue;
      btScalar wsum = 0;
      for (int j = 0; j < 3; j++) wsum += p[j]->m_im * w[j] * w[j];
      if (!(wsum > 0)) continue;
      btScalar s = depth / wsum;
      for (int j = 0; j < 3; j++) {
        if (p[j]->m_im <= 0) continue;
        btVector3 dx = dir * (s * p[j]->m_im * w[j]);
        p[j]->m_x += dx;
        if (fix_velocity) p[j]->m_v += dx * (btScalar)(1 / dt);
        if (count) {
          double m = 1.0 / p[j]->m_im;
          for (int a = 0; a < 3; a++) c->contact_impulse[a] += m * dx[a] / dt;
        }
      }
    }
}

// the HIP over one substep from h0 to h1, in moves of at most half the contact distance
static void rupture(tx_cloth* c);

static void sweep_contact(tx_cloth* c, const btVector3& h0, const btVector3& h1, double dt, bool count) {
  const double rc = c->hip_radius + 0.5 * c->def.thickness;
  if (c->hip_radius <= 0 || rc <= 0) return;
  double len = (h1 - h0).length();
  int moves = (int)std::ceil(len / (0.5 * rc));
  if (moves < 1) moves = 1;
  if (moves > 64) moves = 64; // a teleport: the path is sampled, not followed
  for (int k = 1; k <= moves; k++) {
    btVector3 h = h0.lerp(h1, (btScalar)k / (btScalar)moves);
    project_contact(c, h, h0, dt, count && k == moves, false);
  }
  // a HIP this fast drags the skin further than the links can follow within
  // the substep, and the solve would spread the strain before anyone saw it:
  // what it overstretched tears now
  if (moves > 1) rupture(c);
}

// every particle finite, slower than max_speed and near the patch
static bool healthy(const tx_cloth* c) {
  const btScalar vmax2 = (btScalar)(c->def.max_speed * c->def.max_speed);
  const btVector3 o((btScalar)c->def.center[0], (btScalar)c->def.center[1], (btScalar)c->def.center[2]);
  const btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  for (int i = 0; i < c->n; i++) {
    const btSoftBody::Node& nd = nodes[i];
    btScalar v2 = nd.m_v.length2(), d2 = (nd.m_x - o).length2();
    if (!(v2 <= vmax2) || !(d2 <= 100)) return false; // false for NaN too
  }
  return true;
}

static void remove_link(tx_cloth* c, int id) {
  link_info& li = c->info[(size_t)id];
  if (li.slot < 0) return;
  btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  int last = links.size() - 1;
  if (li.slot != last) {
    links[li.slot] = links[last];
    int moved = (int)reinterpret_cast<intptr_t>(links[li.slot].m_tag);
    c->info[(size_t)moved].slot = li.slot;
  }
  links.pop_back();
  li.slot = -1;
}

// links strained past the threshold break, taking their triangles and the bending links over them
static void rupture(tx_cloth* c) {
  if (c->def.rupture_strain <= 0) return;
  btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  int nb = 0;
  for (int i = 0, ni = links.size(); i < ni; i++) {
    const btSoftBody::Link& l = links[i];
    int id = (int)reinterpret_cast<intptr_t>(l.m_tag);
    if ((l.m_n[1]->m_x - l.m_n[0]->m_x).length2() <= c->info[(size_t)id].limit2) continue;
    if (c->info[(size_t)id].kind != BEND) c->breaking[(size_t)nb++] = id;
  }
  for (int k = 0; k < nb; k++) {
    int id = c->breaking[(size_t)k];
    link_info& li = c->info[(size_t)id];
    if (li.slot < 0) continue;
    remove_link(c, id);
    c->torn++;
    c->topology_dirty = true;
    for (int j = 0; j < 2; j++) {
      if (li.tri[j] >= 0) c->tri_alive[(size_t)li.tri[j]] = 0, c->live_dirty = true;
      if (li.dep[j] >= 0) remove_link(c, li.dep[j]);
    }
  }
}

extern "C" void tx_cloth_save(tx_cloth* c) {
  const btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  for (int i = 0; i < c->n; i++)
    for (int a = 0; a < 3; a++) {
      c->good_x[(size_t)i * 3 + a] = nodes[i].m_x[a];
      c->good_v[(size_t)i * 3 + a] = nodes[i].m_v[a];
    }
  if (c->topology_dirty) {
    for (int id = 0; id < c->nlink; id++) c->good_link[(size_t)id] = c->info[(size_t)id].slot >= 0;
    std::memcpy(c->good_tri.data(), c->tri_alive.data(), (size_t)c->ntri);
    c->topology_dirty = false;
  }
  c->good_torn = c->torn;
  for (int a = 0; a < 3; a++) c->good_hip[a] = c->hip_prev[a];
}

extern "C" void tx_cloth_restore(tx_cloth* c) {
  btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  for (int i = 0; i < c->n; i++) {
    btSoftBody::Node& nd = nodes[i];
    nd.m_x = btVector3(c->good_x[(size_t)i * 3], c->good_x[(size_t)i * 3 + 1], c->good_x[(size_t)i * 3 + 2]);
    nd.m_v = btVector3(c->good_v[(size_t)i * 3], c->good_v[(size_t)i * 3 + 1], c->good_v[(size_t)i * 3 + 2]);
    nd.m_q = nd.m_x;
    nd.m_f = btVector3(0, 0, 0);
  }
  if (c->topology_dirty) {
    // the links back as they were; the array only shrank since, so this never allocates
    btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
    links.resize(0);
    for (int id = 0; id < c->nlink; id++) {
      c->info[(size_t)id].slot = -1;
      if (!c->good_link[(size_t)id]) continue;
      c->info[(size_t)id].slot = links.size();
      links.push_back(c->original[(size_t)id]);
    }
    std::memcpy(c->tri_alive.data(), c->good_tri.data(), (size_t)c->ntri);
    c->live_dirty = true;
    c->prepared_dt = 0; // the restored links carry their build-time constants
    c->topology_dirty = false;
  }
  c->torn = c->good_torn;
  for (int a = 0; a < 3; a++) c->hip_prev[a] = c->good_hip[a];
  for (int a = 0; a < 3; a++) c->contact_force[a] = 0;
}

extern "C" tx_cloth_status tx_cloth_step(tx_cloth* c, double dt) {
  if (!(dt > 0 && dt <= 1)) {
    tx_set_error("skin: step dt = %g s, must be finite and in (0, 1]", dt);
    return TX_CLOTH_BAD;
  }
  int substeps = (int)std::ceil(dt / c->def.max_substep - 1e-9);
  if (substeps < 1) substeps = 1;
  const double h = dt / substeps;
  prepare(c, h);
  btSoftBody* b = c->body;
  const btScalar ih = (btScalar)(1 / h);
  for (int a = 0; a < 3; a++) c->contact_impulse[a] = 0;
  const btVector3 start((btScalar)c->hip_prev[0], (btScalar)c->hip_prev[1], (btScalar)c->hip_prev[2]);
  const btVector3 end((btScalar)c->hip[0], (btScalar)c->hip[1], (btScalar)c->hip[2]);
  for (int s = 0; s < substeps; s++) {
    btVector3 h0 = start.lerp(end, (btScalar)s / (btScalar)substeps);
    btVector3 h1 = start.lerp(end, (btScalar)(s + 1) / (btScalar)substeps);
    b->predictMotion((btScalar)h);
    sweep_contact(c, h0, h1, h, false);
    // Bullet's position solver for links, as btSoftBody::solveConstraints runs
    // it; that function also applies clusters through arrays it allocates on
    // every call, and this patch has no clusters, anchors or Bullet contacts
    for (int it = 0; it < c->def.iterations; it++)
      btSoftBody::PSolve_Links(b, 1, (btScalar)it / (btScalar)c->def.iterations);
    btAlignedObjectArray<btSoftBody::Node>& nodes = b->m_nodes;
    const btScalar vc = ih * (1 - b->m_cfg.kDP);
    for (int i = 0; i < c->n; i++) {
      nodes[i].m_v = (nodes[i].m_x - nodes[i].m_q) * vc;
      nodes[i].m_f = btVector3(0, 0, 0);
    }
    // the contact again after the links, with the velocities it implies
    project_contact(c, h1, h0, h, true, true);
    if (!healthy(c)) {
      c->faults++;
      tx_cloth_restore(c);
      // the HIP's move that led here is not replayed: it starts the next step where it is
      for (int a = 0; a < 3; a++) c->hip_prev[a] = c->hip[a];
      return TX_CLOTH_FAULT;
    }
    rupture(c);
  }
  for (int a = 0; a < 3; a++) {
    c->contact_force[a] = -c->contact_impulse[a] / dt;
    c->hip_prev[a] = c->hip[a];
  }
  tx_cloth_save(c);
  return TX_CLOTH_OK;
}

extern "C" bool tx_cloth_positions(const tx_cloth* c, float* out) {
  const btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  bool finite = true;
  for (int i = 0; i < c->n; i++) {
    const btVector3& x = nodes[i].m_x;
    out[i * 3] = x[0];
    out[i * 3 + 1] = x[1];
    out[i * 3 + 2] = x[2];
    finite &= std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
  }
  return finite;
}

extern "C" int tx_cloth_triangles(tx_cloth* m, int32_t* out) {
  // the compacted list changes only when links break or come back
  if (m->live_dirty) {
    int n = 0;
    for (int t = 0; t < m->ntri; t++)
      if (m->tri_alive[(size_t)t]) std::memcpy(&m->live[(size_t)n++ * 3], &m->tri[(size_t)t * 3], 3 * sizeof(int32_t));
    m->nlive = n;
    m->live_dirty = false;
  }
  std::memcpy(out, m->live.data(), (size_t)m->nlive * 3 * sizeof(int32_t));
  return m->nlive;
}

extern "C" double tx_cloth_max_strain(const tx_cloth* c) {
  double worst = 0;
  const btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  for (int i = 0, ni = links.size(); i < ni; i++) {
    const btSoftBody::Link& l = links[i];
    if (c->info[(size_t)(intptr_t)l.m_tag].kind == BEND) continue;
    double strain = (l.m_n[1]->m_x - l.m_n[0]->m_x).length() / l.m_rl - 1;
    if (strain > worst) worst = strain;
  }
  return worst;
}

extern "C" bool tx_cloth_poke(tx_cloth* c, int i, const double x[3], const double v[3]) {
  if (i < 0 || i >= c->n) return false;
  btSoftBody::Node& nd = c->body->m_nodes[i];
  nd.m_x = btVector3((btScalar)x[0], (btScalar)x[1], (btScalar)x[2]);
  nd.m_v = btVector3((btScalar)v[0], (btScalar)v[1], (btScalar)v[2]);
  return true;
}

extern "C" void tx_cloth_particle(const tx_cloth* c, int i, double out[3]) {
  if (i < 0 || i >= c->n) {
    out[0] = out[1] = out[2] = NAN;
    return;
  }
  const btVector3& x = c->body->m_nodes[i].m_x;
  for (int a = 0; a < 3; a++) out[a] = x[a];
}
