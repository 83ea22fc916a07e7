// The skin patch on a Bullet soft body: the C interface of cloth.h over
// btSoftBody. Bullet holds the particles and links; this file builds the
// patch, integrates it (implicit Euler by Newton and preconditioned CG, or
// XPBD), projects the HIP contact, breaks links
// where the membrane tension passes the rupture tension and guards against
// numerical faults.
#include "cloth.h"

extern "C" {
#include "../../../model/error.h"
#include "../../range_check.h"
#include "../skin_grid.h"
}

#include <BulletSoftBody/btSoftBody.h>

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
  int32_t end[2];  // its particles
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
  double area;      // m^2, rest area per particle (one cell)
  std::vector<double> lambda;      // (links now, by slot) XPBD multipliers of the substep, N s^2
  std::vector<float> length;       // (links now, by slot) m, each link's length in the last iteration
  std::vector<float> tension;      // (nlink, by id) N, each link's tension over the last substep
  std::vector<float> hanging;      // (nlink, by id) N, its tension once the patch hung (settle; 0 without gravity)
  std::vector<float> local;        // (n) scratch: sum of f L / 2 over a particle's stretched links, N m
  std::vector<int32_t> node_links; // (n x 12) link ids at each particle, -1 padded
  std::vector<btVector3> load;     // (n) N, external force on each particle
  int loaded;                      // particles with a non-zero load
  std::vector<double> spring_k;    // (n) N/m, a zero-length spring from each particle to its anchor (0: none)
  std::vector<double> spring_a;    // (n x 3) m, the anchors
  int sprung;                      // particles with a spring
  double peak_tension;             // N/m, largest averaged tension of the last step's checks
  double sub_peak;                 // N/m, the same over the current substep's checks
  double prev_peak;                // N/m, the same over the last substep's (the step before, across steps)
  bool broke;                      // a link tore in the last step
  double broke_at[3];              // m, the HIP centre where the criterion was first met in it

  // the implicit solver's work vectors, all made at create (Bullet's btConjugateGradient
  // allocates two arrays an iteration: its multAndAdd and sub return by value)
  std::vector<double> y;           // (n x 3) m, the inertial prediction of the substep
  std::vector<double> dx, rr, zz, pp, qq; // (n x 3) CG: solution, residual, preconditioned, direction, A p
  std::vector<double> warm;        // (n x 3) m, the last Newton step's solution: the next one's start
  std::vector<double> grad;        // (n x 3) N, gradient of the substep's energy
  std::vector<double> hess;        // (links x 6) N/m, each link's SPD Hessian block, by slot
  std::vector<double> pinv;        // (n x 6) m/N, inverse of each particle's diagonal block
  std::vector<int32_t> lend;       // (links x 2) the particles of each link, by slot
  std::vector<uint8_t> hold;       // (n) held along hold_n in the solve (the contact moved it)
  std::vector<uint8_t> held_solve; // (n) held at the end of the last solve (its active set)
  std::vector<uint8_t> state;      // (n) in the solve: 0 fixed, 1 free, 2 held (hold and the mass, packed)
  std::vector<double> mh2;         // (n) N/m, m / h^2 of each particle plus its spring's k, 0 when fixed
  std::vector<double> hold_n;      // (n x 3) 1, the contact's push on a held particle, summed
  // the two-level preconditioner (coarse_block > 0): blocks of coarse_block x coarse_block particles,
  // each one coarse particle; the Galerkin product P^T S A S P, banded, factored each Newton step
  std::vector<int32_t> agg;        // (n) each particle's block
  int nagg, agg_cols, band;        // blocks; blocks along x; the band's half-width in unknowns
  std::vector<double> coarse;      // (nagg x 3 x (band + 1)) the lower band, then its Cholesky factor
  std::vector<double> cvec;        // (nagg x 3) the coarse residual, then the correction
  tx_cloth_solve_info stats;       // the last step's

  std::vector<int32_t> tri;        // (ntri x 3) vertex indices
  std::vector<uint8_t> tri_alive;  // (ntri)
  std::vector<int32_t> live;       // (ntri x 3) the live triangles, compacted; rows: nlive
  int nlive;                       // live triangles
  bool live_dirty;                 // tri_alive changed since live was compacted
  std::vector<int32_t> node_tris;  // (n x 8) triangles around each particle, -1 padded
  std::vector<link_info> info;     // (nlink)
  std::vector<btSoftBody::Link> original; // (nlink) each link as built, to put broken ones back
  std::vector<int32_t> breaking;   // (nlink) scratch: links to break after a substep
  std::vector<uint8_t> breaking_far; // (nlink) scratch: 1, judged beyond the HIP's reach (a pull, not the tip)
  std::vector<int32_t> tri_stamp;  // (ntri) scratch: triangles already tested this pass
  int32_t stamp;
  std::vector<int32_t> near_tris;  // (ntri) scratch: candidate triangles of one pass
  std::vector<int32_t> held_tri;   // (ntri) the last substep whose contact touched it
  int32_t substep_id;              // counts substeps, for held_tri
  int torn;
  int torn_pulled; // of them, torn beyond the HIP's reach
  int faults;

  // grasped particles (tx_cloth_pin): kinematic, moved to pin_to across a step
  std::vector<btScalar> im0;      // (n) each particle's inverse mass as built: 0 fixed
  std::vector<uint8_t> pinned;    // (n)
  std::vector<double> pin_from;   // (n x 3) m, where a pinned particle began the step
  std::vector<double> pin_to;     // (n x 3) m, where it ends the step
  int npinned;

  // the HIP, a kinematic sphere
  double hip[3];      // m, centre at the end of the next step
  double hip_prev[3]; // m, centre at the end of the last step
  double hip_radius;  // m, 0: none
  double contact_force[3];   // N, of the skin on the HIP over the last step
  double contact_at[3];      // m, the HIP centre at the end of the last step, where contact_force holds
  double contact_depth;      // m, the largest displacement from rest of a particle the contact moved in the last step
  int contact_moves;         // particle moves the contact made in the last step
  int contact_held;          // particles the contact holds at the end of the last step
  std::vector<float> rest_x; // (n x 3) m, the particles at rest (after settling): what the indentation is measured from
  std::vector<uint8_t> in_contact; // (n) the last substep's contact moved this particle
  double contact_dir[3];     // 1, the pushes' unit directions of the last substep's contact on the skin, summed
  int contact_pushes;        // how many were summed
  double max_edge;           // m, longest rest length of a stretch or shear link
  double reach_factor;       // 1, twice the longest live stretch or shear link after the last substep, over
                             // max_edge: a triangle in contact has a corner within rc + reach_factor max_edge
  double hip_now[3];         // m, the HIP centre the contact last used (a sweep's move, or the substep's end)

  // the pierce: a tear at the contact is the HIP's puncture; from then on the contact ignores the
  // triangles of the hole's rim (every particle then within rim_radius of the HIP), until the HIP is
  // clear of them: no rim triangle within the contact distance, and farther than rim_radius from where
  // it went through or back out on the side it came from (docs/skin.md, "The pierce")
  bool pierced;
  double pierce_at[3];       // m, the HIP centre at the tear
  double pierce_dir[3];      // 1, into the skin at the tear (the contact's push, or the HIP's travel)
  double rim_radius;         // m
  std::vector<uint8_t> rim;  // (n) the hole's rim: ignored by the contact while pierced
  int pierces;               // pierces so far
  bool touching;             // the contact found a triangle within its reach in this substep
  bool rim_left;             // pierced, and the HIP has left the hole (beyond rim_radius, or back out)
  bool pierce_dirty;         // the pierce changed since the last save

  // pieces cut off from the patch (no link path to a fixed or pinned particle): frozen where they
  // were cut off, without links or triangles, their indices kept (docs/skin.md, "Detached pieces")
  std::vector<uint8_t> freed;    // (n)
  std::vector<int32_t> flood;    // (n) scratch: the search's queue
  std::vector<int32_t> piece_of; // (n) scratch: the search's marks
  int nfreed, pieces;            // particles and pieces freed so far
  bool anchored;                 // the patch has a fixed particle: without one nothing is cut off from it
  bool detach_check;             // links broke or a pin let go since the last search

  // last good state
  std::vector<float> good_x, good_v;   // (n x 3) m, m/s
  std::vector<uint8_t> good_link;      // (nlink) 1 = present
  std::vector<uint8_t> good_tri;       // (ntri)
  std::vector<float> good_tension;     // (nlink) N, the warm start
  int good_torn, good_torn_pulled;
  double good_hip[3];
  std::vector<uint8_t> good_rim, good_freed; // (n)
  bool good_pierced;
  double good_pierce_at[3], good_pierce_dir[3], good_rim_radius;
  int good_pierces, good_nfreed, good_pieces;
  bool topology_dirty; // links broke since the last save
};

// what rupture counts of a link's tension: beyond what it held once the patch hung
static inline float excess(const tx_cloth* c, int id) { return c->tension[(size_t)id] - c->hanging[(size_t)id]; }

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
  d.clamp_radius = 0;
  d.pretension = 0;
  d.rupture_tension = 80;
  d.blunt_rupture_tension = 0;
  d.rupture_length = 0.002;
  d.solver = TX_CLOTH_IMPLICIT;
  d.iterations = 1;
  d.newton_steps = 2;
  d.cg_iterations = 100;
  d.cg_tolerance = 1e-2;
  d.max_substep = 1.0 / 60;
  d.max_speed = 100;
  d.settle_time = 1;
  d.reading = TX_CLOTH_BALANCE;
  d.coarse_block = 0;
  return d;
}

static int range(const char* name, double v, double lo, bool open_lo, double hi, bool open_hi, const char* units) {
  return tx_check_range("skin", name, v, lo, open_lo, hi, open_hi, units);
}

extern "C" int tx_cloth_def_check(const tx_cloth_def* d) {
  static const char* const size_name[2] = {"size[0]", "size[1]"};
  static const char* const res_name[2] = {"res[0]", "res[1]"};
  static const char* const center_name[3] = {"center[0]", "center[1]", "center[2]"};
  for (int a = 0; a < 2; a++) {
    if (range(size_name[a], d->size[a], 1e-3, false, 10, false, "m")) return -1;
    if (tx_check_count("skin", res_name[a], d->res[a], 2, 1024)) return -1;
  }
  for (int a = 0; a < 3; a++)
    if (range(center_name[a], d->center[a], -10, false, 10, false, "m")) return -1;
  if (range("thickness", d->thickness, 0, false, 0.02, false, "m")) return -1;
  if (range("mass", d->mass, 0, true, 100, false, "kg")) return -1;
  if (range("stretch_stiffness", d->stretch_stiffness, 0, true, 1e9, false, "N/m")) return -1;
  if (range("bend_stiffness", d->bend_stiffness, 0, false, 1e9, false, "N/m")) return -1;
  if (range("damping", d->damping, 0, false, 1e4, false, "1/s")) return -1;
  if (range("gravity", d->gravity, 0, false, 100, false, "m/s^2")) return -1;
  if (range("clamp_radius", d->clamp_radius, 0, false, 10, false, "m")) return -1;
  // a prestrain under 50 %: the links stay far from zero length
  if (range("pretension", d->pretension, 0, false, 0.5 * (3 * d->stretch_stiffness + 4 * d->bend_stiffness), false,
            "N/m"))
    return -1;
  if (range("rupture_tension", d->rupture_tension, 0, false, 1e7, false, "N/m")) return -1;
  if (range("blunt_rupture_tension", d->blunt_rupture_tension, 0, false, 1e7, false, "N/m")) return -1;
  if (range("rupture_length", d->rupture_length, 1e-4, false, 0.05, false, "m")) return -1;
  if (d->solver != TX_CLOTH_IMPLICIT && d->solver != TX_CLOTH_XPBD) {
    tx_set_error("skin: solver = %d, must be %d (implicit) or %d (xpbd)", d->solver, TX_CLOTH_IMPLICIT, TX_CLOTH_XPBD);
    return -1;
  }
  if (d->reading != TX_CLOTH_BALANCE && d->reading != TX_CLOTH_HELD) {
    tx_set_error("skin: reading = %d, must be %d (balance) or %d (held)", d->reading, TX_CLOTH_BALANCE, TX_CLOTH_HELD);
    return -1;
  }
  if (d->coarse_block != 0 && tx_check_count("skin", "coarse_block", d->coarse_block, 2, 64)) return -1;
  if (tx_check_count("skin", "iterations", d->iterations, 1, 200)) return -1;
  if (tx_check_count("skin", "newton_steps", d->newton_steps, 1, 20)) return -1;
  if (tx_check_count("skin", "cg_iterations", d->cg_iterations, 1, 10000)) return -1;
  if (range("cg_tolerance", d->cg_tolerance, 1e-12, false, 1, false, "1")) return -1;
  if (range("max_substep", d->max_substep, 1e-6, false, 0.1, false, "s")) return -1;
  if (range("max_speed", d->max_speed, 0, true, 1e4, false, "m/s")) return -1;
  if (range("settle_time", d->settle_time, 0, false, 10, false, "s")) return -1;
  return 0;
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
  li.end[0] = a;
  li.end[1] = b;
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

  // particles and triangles on the skin's grid (skin_grid.h); the border and
  // what lies beyond the clamp radius are fixed by zero mass
  std::vector<float> grid((size_t)c->n * 3);
  c->tri.resize((size_t)c->ntri * 3);
  tx_skin_grid(nx, nz, hx, hz, d.center, grid.data(), c->tri.data());
  std::vector<btVector3> x((size_t)c->n);
  std::vector<btScalar> m((size_t)c->n);
  c->node_mass = d.mass / c->n;
  c->area = hx * hz;
  for (int iz = 0; iz < nz; iz++)
    for (int ix = 0; ix < nx; ix++) {
      int i = node_index(d, ix, iz);
      const float* g = &grid[(size_t)i * 3];
      x[(size_t)i] = btVector3(g[0], g[1], g[2]);
      bool border = ix == 0 || iz == 0 || ix == nx - 1 || iz == nz - 1;
      double rx = ix * hx - 0.5 * d.size[0], rz = iz * hz - 0.5 * d.size[1];
      bool clamped = d.clamp_radius > 0 && rx * rx + rz * rz >= d.clamp_radius * d.clamp_radius * (1 - 1e-12);
      m[(size_t)i] = ((d.fixed_border && border) || clamped) ? 0 : (btScalar)c->node_mass;
    }
  c->body = new btSoftBody(&c->world, c->n, x.data(), m.data());
  c->im0.resize((size_t)c->n);
  for (int i = 0; i < c->n; i++) c->im0[(size_t)i] = c->body->m_nodes[i].m_im;
  c->pinned.assign((size_t)c->n, 0);
  c->pin_from.assign((size_t)c->n * 3, 0.0);
  c->pin_to.assign((size_t)c->n * 3, 0.0);
  c->body->m_cfg.collisions = 0; // the HIP contact is ours (see cloth.h)
  c->body->m_cfg.piterations = d.iterations;
  c->body->m_cfg.kDP = 0;
  // the default 0.25 m margin stays: with it Bullet's node tree is rarely rebuilt, and nothing collides through it
  c->stretch_mat = c->body->m_materials[0];
  c->bend_mat = c->body->appendMaterial();

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

  // rest lengths now, so that Bullet never resets them to a deformed shape;
  // under pretension every link is shortened by the same factor 1 - T / K,
  // K = C11 + C12 = 3 k + 4 k_bend the lattice's biaxial modulus, so that
  // the flat patch holds the isotropic tension T (docs/skin.md)
  c->body->updateConstants();
  c->body->m_bUpdateRtCst = false;
  if (d.pretension > 0) {
    const double shrink = 1 - d.pretension / (3 * d.stretch_stiffness + 4 * d.bend_stiffness);
    for (int i = 0; i < c->body->m_links.size(); i++) {
      btSoftBody::Link& l = c->body->m_links[i];
      if (l.m_material == c->bend_mat && d.bend_stiffness <= 0) continue;
      l.m_rl = (btScalar)(l.m_rl * shrink);
    }
  }
  c->original.assign(c->body->m_links.size(), btSoftBody::Link());
  for (int i = 0; i < c->body->m_links.size(); i++) c->original[(size_t)i] = c->body->m_links[i];

  c->node_links.assign((size_t)c->n * 12, -1);
  for (int id = 0; id < c->nlink; id++)
    for (int e = 0; e < 2; e++) {
      int32_t* slots = &c->node_links[(size_t)c->info[(size_t)id].end[e] * 12];
      for (int k = 0; k < 12; k++)
        if (slots[k] < 0) {
          slots[k] = id;
          break;
        }
    }
  c->lambda.assign((size_t)c->nlink, 0);
  c->length.assign((size_t)c->nlink, 0);
  c->tension.assign((size_t)c->nlink, 0);
  c->hanging.assign((size_t)c->nlink, 0);
  c->local.assign((size_t)c->n, 0);
  c->load.assign((size_t)c->n, btVector3(0, 0, 0));
  c->spring_k.assign((size_t)c->n, 0.0);
  c->spring_a.assign((size_t)c->n * 3, 0.0);
  c->reach_factor = 2;
  c->breaking.resize((size_t)c->nlink);
  c->breaking_far.resize((size_t)c->nlink);
  c->tri_stamp.assign((size_t)c->ntri, 0);
  c->near_tris.resize((size_t)c->ntri);
  c->held_tri.assign((size_t)c->ntri, 0);
  c->good_x.resize((size_t)c->n * 3);
  c->rest_x.assign((size_t)c->n * 3, 0.0f);
  c->in_contact.assign((size_t)c->n, 0);
  c->good_v.resize((size_t)c->n * 3);
  c->good_link.assign((size_t)c->nlink, 1);
  c->good_tri.assign((size_t)c->ntri, 1);
  c->good_tension.assign((size_t)c->nlink, 0);
  c->rim.assign((size_t)c->n, 0);
  c->good_rim.assign((size_t)c->n, 0);
  c->freed.assign((size_t)c->n, 0);
  c->good_freed.assign((size_t)c->n, 0);
  c->flood.assign((size_t)c->n, 0);
  c->piece_of.assign((size_t)c->n, 0);
  c->anchored = false;
  for (int i = 0; i < c->n; i++) c->anchored |= !(c->im0[(size_t)i] > 0);
  if (d.solver == TX_CLOTH_IMPLICIT) {
    const size_t n3 = (size_t)c->n * 3;
    for (std::vector<double>* v : {&c->y, &c->dx, &c->rr, &c->zz, &c->pp, &c->qq, &c->warm, &c->grad, &c->hold_n})
      v->assign(n3, 0.0);
    c->hess.assign((size_t)c->nlink * 6, 0.0);
    c->pinv.assign((size_t)c->n * 6, 0.0);
    c->lend.assign((size_t)c->nlink * 2, 0);
    c->hold.assign((size_t)c->n, 0);
    c->state.assign((size_t)c->n, 0);
    c->held_solve.assign((size_t)c->n, 0);
    c->mh2.assign((size_t)c->n, 0.0);
    if (d.coarse_block > 0) {
      const int b = d.coarse_block, cx = (nx + b - 1) / b, cz = (nz + b - 1) / b;
      c->agg.assign((size_t)c->n, 0);
      for (int iz = 0; iz < nz; iz++)
        for (int ix = 0; ix < nx; ix++) c->agg[(size_t)node_index(d, ix, iz)] = (iz / b) * cx + ix / b;
      c->nagg = cx * cz;
      c->agg_cols = cx;
      // a link spans at most two spacings (bending), so it joins blocks at most one apart
      // along x and z when b >= 2: the band reaches cx + 1 blocks back
      c->band = 3 * (cx + 1) + 2;
      c->coarse.assign((size_t)c->nagg * 3 * (size_t)(c->band + 1), 0.0);
      c->cvec.assign((size_t)c->nagg * 3, 0.0);
    }
  }
  return true;
}

// Under gravity the patch first hangs for settle_time without rupture: the
// skin is then already sagging when the HIP arrives (the journal paper's
// skin hangs about 1 cm before first contact), and the fall from flat, which
// is no part of any experiment, cannot tear it.
static void settle(tx_cloth* c) {
  const double tear = c->def.rupture_tension, blunt = c->def.blunt_rupture_tension;
  c->def.rupture_tension = c->def.blunt_rupture_tension = 0;
  int steps = c->def.gravity > 0 ? (int)std::ceil(c->def.settle_time * 60) : 0;
  for (int s = 0; s < steps; s++)
    if (tx_cloth_step(c, 1.0 / 60) != TX_CLOTH_OK) break;
  c->def.rupture_tension = tear;
  c->def.blunt_rupture_tension = blunt;
  if (steps > 0) c->hanging = c->tension; // same size: no allocation beyond create
  for (int a = 0; a < 3; a++) c->contact_force[a] = 0;
  c->peak_tension = 0;
}

// the indentation of the contact is measured from the patch at rest: flat, or hanging after settling
static void take_rest(tx_cloth* c) {
  for (int i = 0; i < c->n; i++)
    for (int a = 0; a < 3; a++) c->rest_x[(size_t)i * 3 + a] = c->body->m_nodes[i].m_x[a];
  c->contact_depth = 0;
  c->contact_moves = 0;
  c->contact_held = 0;
}

extern "C" tx_cloth* tx_cloth_create(const tx_cloth_def* def) {
  if (!def) return tx_set_error("skin: no definition"), nullptr;
  if (tx_cloth_def_check(def)) return nullptr;
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
  take_rest(c);
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
extern "C" int tx_cloth_torn_pulled(const tx_cloth* c) { return c->torn_pulled; }
extern "C" int tx_cloth_faults(const tx_cloth* c) { return c->faults; }

extern "C" void tx_cloth_contact_force(const tx_cloth* c, double out[3]) {
  for (int a = 0; a < 3; a++) out[a] = c->contact_force[a];
}

extern "C" void tx_cloth_contact(const tx_cloth* c, tx_cloth_contact_info* out) {
  for (int a = 0; a < 3; a++) {
    out->f[a] = c->contact_force[a];
    out->x[a] = c->contact_at[a];
  }
  out->depth = c->contact_depth;
  out->moves = c->contact_moves;
  out->held = c->contact_held;
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

// One substep of the particles: gravity and the loads, then the positions
// they predict (explicit velocity, as Bullet's predictMotion, without its
// collision trees, which this patch does not use)
static void predict(tx_cloth* c, double h) {
  btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  const btVector3 g = c->world.m_gravity * (btScalar)h;
  const btScalar hs = (btScalar)h;
  const bool implicit = c->def.solver == TX_CLOTH_IMPLICIT;
  for (int i = 0; i < c->n; i++) {
    btSoftBody::Node& nd = nodes[i];
    nd.m_q = nd.m_x;
    if (nd.m_im > 0) {
      nd.m_v += g;
      if (c->loaded > 0) nd.m_v += c->load[(size_t)i] * (nd.m_im * hs);
      const double ks = c->sprung > 0 && !implicit ? c->spring_k[(size_t)i] : 0; // the implicit solve takes it whole
      for (int a = 0; a < 3 && ks > 0; a++)
        nd.m_v[a] += (btScalar)(ks * (c->spring_a[(size_t)i * 3 + a] - nd.m_x[a]) * nd.m_im * hs);
    }
    nd.m_x += nd.m_v * hs;
    if (implicit) {
      // y, the inertial prediction with the loads, is what the energy measures from; the
      // Newton steps start where the particles are, so that a patch at rest is the solve's
      // fixed point whatever the Newton steps (from y, one step of a slack membrane settles
      // short of its equilibrium), and the skin resting on the HIP still touches it when the
      // contact is found (carried by its velocity it would leave the stopped HIP, and its
      // tension would pull it through in the solve)
      for (int a = 0; a < 3; a++) c->y[(size_t)i * 3 + a] = nd.m_x[a];
      nd.m_x = nd.m_q;
    }
  }
}

// XPBD (Macklin, Mueller and Chentanez 2016): each link is the constraint
// C = |x1 - x0| - rest with compliance 1/k; its multiplier lambda collects
// the correction over the iterations, and the update
// dlambda = (-C - a lambda) / (w + a), a = 1 / (k h^2), makes the converged
// substep implicit Euler with the spring's true k, whatever the iterations
// (Bullet's PSolve_Links scales each iteration's correction instead, which
// tends to a rigid link as iterations grow). The links run in the colour
// order of build().
static void solve_links(tx_cloth* c, double h) {
  btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  const int nl = links.size();
  double* lam = c->lambda.data();
  const double as = 1 / (c->def.stretch_stiffness * h * h);
  const double ab = c->def.bend_stiffness > 0 ? 1 / (c->def.bend_stiffness * h * h) : -1;
  const btSoftBody::Material* bend = c->bend_mat;
  float* length = c->length.data(); // kept for measure_links, which then need not visit the particles
  std::fill(lam, lam + nl, 0.0);
  std::fill(length, length + nl, 0.0f);
  for (int it = 0; it < c->def.iterations; it++)
    for (int i = 0; i < nl; i++) {
      btSoftBody::Link& l = links[i];
      const double at = l.m_material == bend ? ab : as;
      if (at < 0) continue; // bending links without stiffness
      btSoftBody::Node* n0 = l.m_n[0];
      btSoftBody::Node* n1 = l.m_n[1];
      const double w = (double)n0->m_im + n1->m_im;
      if (!(w > 0)) continue;
      const btVector3 d = n1->m_x - n0->m_x;
      const double len = d.length();
      length[i] = (float)len;
      if (!(len > 0)) continue;
      const double dl = (-(len - l.m_rl) - at * lam[i]) / (w + at);
      lam[i] += dl;
      const btVector3 corr = d * (btScalar)(dl / len);
      n0->m_x -= corr * n0->m_im;
      n1->m_x += corr * n1->m_im;
    }
}

// ---------------------------------------------------------------------------
// the implicit solver
//
// Backward Euler on the links: the substep's positions x minimise
// E(x) = |x - y|^2_M / (2 h^2) + U(x), y = x0 + h v0 + h^2 M^-1 f_ext the
// inertial prediction and U the springs' energy sum k (l - l0)^2 / 2. Each
// Newton step solves (M / h^2 + H) dx = -grad E by conjugate gradients
// preconditioned with the 3 x 3 diagonal blocks, matrix-free over the links,
// with H each link's SPD part k (n n^T + max(0, 1 - l0 / l) (I - n n^T)): the
// transverse term is the link's tension over its length, negative under
// compression, where it is dropped (a compressed link buckles, it does not
// push sideways). Fixed particles do not move; a particle the contact moved
// keeps its position along the contact's normal and slides across it (the
// filter S = I - n n^T of Baraff and Witkin, SIGGRAPH 1998). Every vector is
// made at create: Bullet's btConjugateGradient (BulletSoftBody) allocates two
// arrays an iteration, which a step must not.

// the filter: nothing for a fixed particle, the tangential part for a held one
static inline void filter(const tx_cloth* c, int i, double* v) {
  const uint8_t st = c->state[(size_t)i];
  if (st == 0) {
    v[0] = v[1] = v[2] = 0;
    return;
  }
  if (st == 2) {
    const double* n = &c->hold_n[(size_t)i * 3];
    const double d = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    for (int a = 0; a < 3; a++) v[a] -= d * n[a];
  }
}

// the springs' gradient and SPD Hessian blocks at the current positions, each
// particle's diagonal block inverted, and grad E into c->grad
static void assemble(tx_cloth* c, double h) {
  const btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  const btSoftBody::Node* base = &c->body->m_nodes[0];
  const int n = c->n, nl = links.size();
  const double ks = c->def.stretch_stiffness, kb = c->def.bend_stiffness, ih2 = 1 / (h * h);
  double* g = c->grad.data();
  double* pi = c->pinv.data(); // the diagonal blocks first, inverted below
  for (int i = 0; i < n; i++) {
    const double m = base[i].m_im > 0 ? 1 / (double)base[i].m_im : 0, w = m * ih2;
    c->state[(size_t)i] = m > 0 ? (c->hold[(size_t)i] ? 2 : 1) : 0;
    for (int a = 0; a < 3; a++) g[i * 3 + a] = w * ((double)base[i].m_x[a] - c->y[(size_t)i * 3 + a]);
    const double kp = m > 0 && c->sprung > 0 ? c->spring_k[(size_t)i] : 0; // its spring: k (x - anchor), Hessian k I
    for (int a = 0; a < 3 && kp > 0; a++) g[i * 3 + a] += kp * ((double)base[i].m_x[a] - c->spring_a[(size_t)i * 3 + a]);
    c->mh2[(size_t)i] = w + kp;
    double* b = &pi[i * 6];
    b[0] = b[1] = b[2] = w + kp;
    b[3] = b[4] = b[5] = 0;
  }
  for (int s = 0; s < nl; s++) {
    const btSoftBody::Link& l = links[s];
    const int a = (int)(l.m_n[0] - base), b = (int)(l.m_n[1] - base);
    c->lend[(size_t)s * 2] = a;
    c->lend[(size_t)s * 2 + 1] = b;
    double* H = &c->hess[(size_t)s * 6];
    const double k = l.m_material == c->bend_mat ? kb : ks;
    double d[3] = {(double)l.m_n[1]->m_x[0] - l.m_n[0]->m_x[0], (double)l.m_n[1]->m_x[1] - l.m_n[0]->m_x[1],
                   (double)l.m_n[1]->m_x[2] - l.m_n[0]->m_x[2]};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(k > 0) || !(len > 0)) {
      for (int e = 0; e < 6; e++) H[e] = 0;
      continue;
    }
    for (double& v : d) v /= len;
    const double f = k * (len - (double)l.m_rl); // pulls a towards b when stretched
    for (int e = 0; e < 3; e++) {
      g[a * 3 + e] -= f * d[e];
      g[b * 3 + e] += f * d[e];
    }
    const double t = std::max(0.0, 1 - (double)l.m_rl / len), kn = k * (1 - t), kt = k * t;
    H[0] = kn * d[0] * d[0] + kt, H[1] = kn * d[1] * d[1] + kt, H[2] = kn * d[2] * d[2] + kt;
    H[3] = kn * d[0] * d[1], H[4] = kn * d[0] * d[2], H[5] = kn * d[1] * d[2];
    for (int e = 0; e < 6; e++) pi[a * 6 + e] += H[e], pi[b * 6 + e] += H[e];
  }
  for (int i = 0; i < n; i++) { // inverse of the symmetric block (xx, yy, zz, xy, xz, yz)
    double* m = &pi[i * 6];
    const double c00 = m[1] * m[2] - m[5] * m[5], c01 = m[4] * m[5] - m[3] * m[2], c02 = m[3] * m[5] - m[4] * m[1];
    const double det = m[0] * c00 + m[3] * c01 + m[4] * c02;
    if (!(std::fabs(det) > 0) || !std::isfinite(det)) {
      for (int e = 0; e < 6; e++) m[e] = 0;
      continue;
    }
    const double id = 1 / det;
    const double i11 = (m[0] * m[2] - m[4] * m[4]) * id, i22 = (m[0] * m[1] - m[3] * m[3]) * id,
                 i12 = (m[3] * m[4] - m[0] * m[5]) * id;
    m[0] = c00 * id, m[1] = i11, m[2] = i22, m[3] = c01 * id, m[4] = c02 * id, m[5] = i12;
  }
}

// out = S (M / h^2 + H) S v
static void apply_system(tx_cloth* c, const double* v, double* out) {
  const int n = c->n, nl = c->body->m_links.size();
  const double* mh2 = c->mh2.data();
  for (int i = 0; i < n; i++) {
    const double w = mh2[i];
    for (int a = 0; a < 3; a++) out[i * 3 + a] = w * v[i * 3 + a];
  }
  const int32_t* le = c->lend.data();
  const double* hs = c->hess.data();
  for (int s = 0; s < nl; s++) {
    const int a = le[s * 2], b = le[s * 2 + 1];
    const double* H = &hs[s * 6];
    const double d0 = v[a * 3] - v[b * 3], d1 = v[a * 3 + 1] - v[b * 3 + 1], d2 = v[a * 3 + 2] - v[b * 3 + 2];
    const double r0 = H[0] * d0 + H[3] * d1 + H[4] * d2, r1 = H[3] * d0 + H[1] * d1 + H[5] * d2,
                 r2 = H[4] * d0 + H[5] * d1 + H[2] * d2;
    out[a * 3] += r0, out[a * 3 + 1] += r1, out[a * 3 + 2] += r2;
    out[b * 3] -= r0, out[b * 3 + 1] -= r1, out[b * 3 + 2] -= r2;
  }
  for (int i = 0; i < n; i++) filter(c, i, &out[i * 3]);
}

static void coarse_correct(tx_cloth* c, const double* r, double* z);

// z = S P^-1 r
static void precondition(tx_cloth* c, const double* r, double* z) {
  const double* pi = c->pinv.data();
  for (int i = 0; i < c->n; i++) {
    const double* m = &pi[i * 6];
    const double* v = &r[i * 3];
    z[i * 3] = m[0] * v[0] + m[3] * v[1] + m[4] * v[2];
    z[i * 3 + 1] = m[3] * v[0] + m[1] * v[1] + m[5] * v[2];
    z[i * 3 + 2] = m[4] * v[0] + m[5] * v[1] + m[2] * v[2];
    filter(c, i, &z[i * 3]);
  }
  if (c->def.coarse_block > 0) coarse_correct(c, r, z);
}

static double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); i++) s += a[i] * b[i];
  return s;
}

// the substep's energy E at the particles' positions (J)
static double energy(const tx_cloth* c, double h) {
  const btSoftBody::Node* base = &c->body->m_nodes[0];
  const double ih2 = 1 / (h * h);
  double e = 0;
  for (int i = 0; i < c->n; i++) {
    if (!(base[i].m_im > 0)) continue;
    double s = 0;
    for (int a = 0; a < 3; a++) {
      const double d = (double)base[i].m_x[a] - c->y[(size_t)i * 3 + a];
      s += d * d;
    }
    e += 0.5 * ih2 / (double)base[i].m_im * s;
    const double ks = c->sprung > 0 ? c->spring_k[(size_t)i] : 0;
    for (int a = 0; a < 3 && ks > 0; a++) {
      const double d = (double)base[i].m_x[a] - c->spring_a[(size_t)i * 3 + a];
      e += 0.5 * ks * d * d;
    }
  }
  const btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  for (int i = 0, nl = links.size(); i < nl; i++) {
    const btSoftBody::Link& l = links[i];
    const double k = l.m_material == c->bend_mat ? c->def.bend_stiffness : c->def.stretch_stiffness;
    const double d = (double)(l.m_n[1]->m_x - l.m_n[0]->m_x).length() - (double)l.m_rl;
    e += 0.5 * k * d * d;
  }
  return e;
}

// The coarse level (Galerkin, unsmoothed aggregation): a coarse particle per
// block, its displacement given to each of the block's particles through its
// filter S (fixed: none; held: across the contact's normal). Its matrix
// P^T S (M / h^2 + H) S P from the same link blocks as the fine product, so
// torn links are simply absent from it; banded (blocks are numbered row by
// row and a link joins neighbouring blocks only) and factored by Cholesky.
// The preconditioner is then additive, block Jacobi plus P A_c^-1 P^T: the
// Jacobi part damps the short waves and the coarse part the long ones, which
// Jacobi alone needs some res iterations to spread across the patch.
static inline double& cband(tx_cloth* c, int r, int col) { // lower band, r >= col
  return c->coarse[(size_t)r * (size_t)(c->band + 1) + (size_t)(col - r + c->band)];
}

// S_i as a full 3 x 3 (0 for fixed, I - n n^T for held, I for free)
static void filter_matrix(const tx_cloth* c, int i, double S[9]) {
  const uint8_t st = c->state[(size_t)i];
  for (int e = 0; e < 9; e++) S[e] = 0;
  if (st == 0) return;
  S[0] = S[4] = S[8] = 1;
  if (st == 2) {
    const double* n = &c->hold_n[(size_t)i * 3];
    for (int r = 0; r < 3; r++)
      for (int q = 0; q < 3; q++) S[r * 3 + q] -= n[r] * n[q];
  }
}

// adds the 3 x 3 block B (row major) at coarse blocks (I, J), lower band only
static void coarse_add(tx_cloth* c, int I, int J, const double B[9]) {
  for (int r = 0; r < 3; r++)
    for (int q = 0; q < 3; q++) {
      const int R = I * 3 + r, Q = J * 3 + q;
      if (Q <= R) cband(c, R, Q) += B[r * 3 + q];
    }
}

static void build_coarse(tx_cloth* c) {
  std::fill(c->coarse.begin(), c->coarse.end(), 0.0);
  const int n = c->n, nl = c->body->m_links.size();
  double S[9], Sa[9], Sb[9], T[9], B[9];
  for (int i = 0; i < n; i++) { // the mass, S (m / h^2) S = (m / h^2) S
    if (c->state[(size_t)i] == 0) continue;
    filter_matrix(c, i, S);
    for (int e = 0; e < 9; e++) B[e] = c->mh2[(size_t)i] * S[e];
    coarse_add(c, c->agg[(size_t)i], c->agg[(size_t)i], B);
  }
  const int32_t* le = c->lend.data();
  for (int s = 0; s < nl; s++) {
    const int a = le[s * 2], b = le[s * 2 + 1];
    const uint8_t sa = c->state[(size_t)a], sb = c->state[(size_t)b];
    const int A = c->agg[(size_t)a], Bk = c->agg[(size_t)b];
    if ((sa == 0 && sb == 0) || (A == Bk && sa == 1 && sb == 1)) continue; // nothing, or sums to zero in its block
    const double* h = &c->hess[(size_t)s * 6];
    const double H[9] = {h[0], h[3], h[4], h[3], h[1], h[5], h[4], h[5], h[2]};
    filter_matrix(c, a, Sa);
    filter_matrix(c, b, Sb);
    // blocks: (A,A) Sa H Sa, (B,B) Sb H Sb, (A,B) -Sa H Sb, (B,A) -Sb H Sa
    const double* Sl[2] = {Sa, Sb};
    const int K[2] = {A, Bk};
    for (int u = 0; u < 2; u++)
      for (int v = 0; v < 2; v++) {
        if (K[v] > K[u]) continue; // the lower band: blocks (I, J) with J <= I
        for (int r = 0; r < 3; r++)
          for (int q = 0; q < 3; q++) {
            double t = 0;
            for (int m = 0; m < 3; m++) t += Sl[u][r * 3 + m] * H[m * 3 + q];
            T[r * 3 + q] = t;
          }
        const double sign = u == v ? 1 : -1;
        for (int r = 0; r < 3; r++)
          for (int q = 0; q < 3; q++) {
            double t = 0;
            for (int m = 0; m < 3; m++) t += T[r * 3 + m] * Sl[v][m * 3 + q];
            B[r * 3 + q] = sign * t;
          }
        coarse_add(c, K[u], K[v], B);
      }
  }
  // Cholesky of the band in place; an unknown with nothing in it (a block of fixed
  // particles, or one held along a single normal) is dropped
  const int N = c->nagg * 3, w = c->band;
  for (int j = 0; j < N; j++) {
    double d = cband(c, j, j);
    const int k0 = std::max(0, j - w);
    const double d0 = d;
    for (int k = k0; k < j; k++) d -= cband(c, j, k) * cband(c, j, k);
    if (!(d > 1e-10 * std::fabs(d0)) || !(d0 > 0)) { // drop it: zero its column below
      cband(c, j, j) = 0;
      for (int i = j + 1; i <= std::min(N - 1, j + w); i++) cband(c, i, j) = 0;
      continue;
    }
    const double l = std::sqrt(d);
    cband(c, j, j) = l;
    for (int i = j + 1; i <= std::min(N - 1, j + w); i++) {
      double v = cband(c, i, j);
      for (int k = std::max(k0, i - w); k < j; k++) v -= cband(c, i, k) * cband(c, j, k);
      cband(c, i, j) = v / l;
    }
  }
}

// z += S P A_c^-1 P^T r
static void coarse_correct(tx_cloth* c, const double* r, double* z) {
  double* y = c->cvec.data();
  std::fill(c->cvec.begin(), c->cvec.end(), 0.0);
  for (int i = 0; i < c->n; i++) {
    if (c->state[(size_t)i] == 0) continue;
    double v[3] = {r[i * 3], r[i * 3 + 1], r[i * 3 + 2]};
    filter(c, i, v);
    double* t = &y[(size_t)c->agg[(size_t)i] * 3];
    t[0] += v[0], t[1] += v[1], t[2] += v[2];
  }
  const int N = c->nagg * 3, w = c->band;
  for (int i = 0; i < N; i++) { // L y = b
    const double l = cband(c, i, i);
    if (l == 0) {
      y[i] = 0;
      continue;
    }
    double v = y[i];
    for (int k = std::max(0, i - w); k < i; k++) v -= cband(c, i, k) * y[k];
    y[i] = v / l;
  }
  for (int i = N - 1; i >= 0; i--) { // L^T x = y
    const double l = cband(c, i, i);
    if (l == 0) {
      y[i] = 0;
      continue;
    }
    double v = y[i];
    for (int k = i + 1; k <= std::min(N - 1, i + w); k++) v -= cband(c, k, i) * y[k];
    y[i] = v / l;
  }
  for (int i = 0; i < c->n; i++) {
    if (c->state[(size_t)i] == 0) continue;
    const double* t = &y[(size_t)c->agg[(size_t)i] * 3];
    double v[3] = {t[0], t[1], t[2]};
    filter(c, i, v);
    z[i * 3] += v[0], z[i * 3 + 1] += v[1], z[i * 3 + 2] += v[2];
  }
}

// one Newton step: solves S (M / h^2 + H) S dx = -S grad E by PCG (from the
// last substep's dx with warm), moves the particles by dx; the relative
// residual reached. *gg: |S grad E|^2 before the step; none is taken when
// that is stop2 or less (converged)
static double newton_step(tx_cloth* c, double h, bool warm, double* gg, double stop2) {
  const int n3 = c->n * 3;
  assemble(c, h);
  double* g = c->grad.data();
  for (int i = 0; i < c->n; i++) filter(c, i, &g[i * 3]);
  double bb = 0;
  for (int i = 0; i < n3; i++) bb += g[i] * g[i];
  *gg = bb;
  if (!(bb > stop2)) return 0;
  if (c->def.coarse_block > 0) build_coarse(c);
  double* x = c->dx.data();
  double* r = c->rr.data();
  if (warm) std::memcpy(x, c->warm.data(), (size_t)n3 * sizeof(double));
  else std::fill(c->dx.begin(), c->dx.end(), 0.0);
  for (int i = 0; i < c->n; i++) filter(c, i, &x[i * 3]);
  apply_system(c, x, c->qq.data());
  for (int i = 0; i < n3; i++) r[i] = -g[i] - c->qq[(size_t)i];
  if (!(dot(c->rr, c->rr) < bb)) { // the warm start is worse than none: from zero
    std::fill(c->dx.begin(), c->dx.end(), 0.0);
    for (int i = 0; i < n3; i++) r[i] = -g[i];
  }
  precondition(c, r, c->zz.data());
  c->pp = c->zz; // same size: a copy, no allocation
  double rz = dot(c->rr, c->zz), rr = dot(c->rr, c->rr);
  const double tol2 = c->def.cg_tolerance * c->def.cg_tolerance * bb;
  int it = 0;
  double* p = c->pp.data();
  double* q = c->qq.data();
  double* z = c->zz.data();
  while (it < c->def.cg_iterations && rr > tol2) {
    apply_system(c, p, q);
    const double pq = dot(c->pp, c->qq);
    if (!(pq > 0)) break;
    const double alpha = rz / pq;
    rr = 0;
    for (int i = 0; i < n3; i++) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      rr += r[i] * r[i];
    }
    it++;
    if (rr <= tol2) break;
    precondition(c, r, z);
    const double rz1 = dot(c->rr, c->zz), beta = rz1 / rz;
    rz = rz1;
    for (int i = 0; i < n3; i++) p[i] = z[i] + beta * p[i];
  }
  c->stats.cg_iterations += it;
  // a backtracking line search on E: a full step from a slack membrane, whose
  // transverse stiffness is nearly nothing, overshoots, and undamped the steps
  // that follow go round a cycle instead of reaching the equilibrium
  btSoftBody::Node* nodes = &c->body->m_nodes[0];
  double* x0 = c->zz.data(); // free once the CG is done
  for (int i = 0; i < c->n; i++)
    for (int a = 0; a < 3; a++) x0[i * 3 + a] = nodes[i].m_x[a];
  const double e0 = energy(c, h);
  double step = 1;
  for (int tries = 0;; tries++) {
    for (int i = 0; i < c->n; i++)
      for (int a = 0; a < 3; a++) nodes[i].m_x[a] = (btScalar)(x0[i * 3 + a] + step * x[i * 3 + a]);
    if (tries == 8 || energy(c, h) <= e0 + 1e-12 * std::fabs(e0)) break; // (float positions: a little noise)
    step *= 0.5;
  }
  if (step < 1)
    for (int i = 0; i < n3; i++) x[i] *= step;
  if (warm) c->warm = c->dx; // same size: a copy, no allocation
  return std::sqrt(rr / bb);
}

// held particles whose contact would have to pull them (towards the HIP) to
// hold them: the constraint force grad E . n is negative; how many let go
static int release_pulling(tx_cloth* c, double h) {
  assemble(c, h);
  int freed = 0;
  for (int i = 0; i < c->n; i++) {
    if (!c->hold[(size_t)i]) continue;
    const double* n = &c->hold_n[(size_t)i * 3];
    const double* g = &c->grad[(size_t)i * 3];
    if (g[0] * n[0] + g[1] * n[1] + g[2] * n[2] < 0) c->hold[(size_t)i] = 0, freed++;
  }
  return freed;
}

#define KEEP_TOUCH 1.03 // a triangle the HIP touched stays held before the solve out to this over the contact distance
#define KEEP_STILL 0.01 // ... while the HIP moves less than this over the contact distance in the substep
#define NEWTON_STOP 0.1 // Newton stops at this gradient over the first step's

// the substep's positions: newton_steps Newton steps from where the contact
// left the particles; held particles that would pull are let go and the
// solve goes on one step more (at most once)
static void solve_implicit(tx_cloth* c, double h) {
  for (int i = 0; i < c->n; i++) {
    if (!c->hold[(size_t)i]) continue;
    double* n = &c->hold_n[(size_t)i * 3];
    const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0) n[0] /= l, n[1] /= l, n[2] /= l;
    else c->hold[(size_t)i] = 0;
  }
  // Newton steps until the gradient is a tenth of the first one's (a slack
  // membrane falling from flat needs two or three; a pierce, one)
  double g0 = 0, gg = 0;
  for (int s = 0; s < c->def.newton_steps; s++) {
    const double stop2 = s == 0 ? 0 : NEWTON_STOP * NEWTON_STOP * g0;
    const double res = newton_step(c, h, s == 0, &gg, stop2);
    if (s == 0) g0 = gg;
    else if (!(gg > stop2)) break;
    if (res > c->stats.residual) c->stats.residual = res;
    c->stats.newton++;
  }
  bool any = false;
  for (int i = 0; i < c->n && !any; i++) any = c->hold[(size_t)i] != 0;
  int freed = any ? release_pulling(c, h) : 0;
  if (freed > 0) {
    c->stats.released += freed;
    const double res = newton_step(c, h, false, &gg, 0);
    if (res > c->stats.residual) c->stats.residual = res;
    c->stats.newton++;
  }
  c->held_solve = c->hold; // same size: a copy, no allocation
  std::fill(c->hold.begin(), c->hold.end(), 0);
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

// a triangle with a corner on the rim of the hole the HIP went through
static inline bool on_rim(const tx_cloth* c, int32_t t) {
  const int32_t* v = &c->tri[(size_t)t * 3];
  return c->rim[(size_t)v[0]] || c->rim[(size_t)v[1]] || c->rim[(size_t)v[2]];
}

// The HIP's puncture: a tear at its contact. Every particle within
// rim_radius of the HIP (a triangle it touches has a corner within rc +
// reach_factor max_edge) is the hole's rim, which the contact ignores from
// now on; what the contact held is let go, so nothing of it pushes the HIP
// after the tear. A further tear at the contact while pierced widens the rim.
static void pierce_start(tx_cloth* c) {
  const double rc = c->hip_radius + 0.5 * c->def.thickness, R = rc + c->reach_factor * c->max_edge;
  const btVector3 h((btScalar)c->hip_now[0], (btScalar)c->hip_now[1], (btScalar)c->hip_now[2]);
  const btScalar R2 = (btScalar)(R * R);
  const btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  const bool implicit = c->def.solver == TX_CLOTH_IMPLICIT;
  for (int i = 0; i < c->n; i++) {
    if ((nodes[i].m_x - h).length2() > R2) continue;
    c->rim[(size_t)i] = 1;
    c->in_contact[(size_t)i] = 0;
    if (implicit) c->hold[(size_t)i] = c->held_solve[(size_t)i] = 0;
  }
  // into the skin: the way the contact pushed it, else the way the HIP went
  double d[3] = {c->contact_dir[0], c->contact_dir[1], c->contact_dir[2]};
  double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(l > 0)) {
    for (int a = 0; a < 3; a++) d[a] = c->hip[a] - c->hip_prev[a];
    l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  }
  for (int a = 0; a < 3; a++) {
    c->pierce_dir[a] = l > 0 ? d[a] / l : (a == 1 ? -1 : 0);
    c->pierce_at[a] = c->hip_now[a];
    c->contact_dir[a] = 0;
  }
  c->contact_pushes = 0;
  if (!c->pierced) c->pierces++;
  c->pierced = true;
  c->rim_left = false;
  c->rim_radius = R;
  c->pierce_dirty = true;
}

// the pierce ends once the HIP at h is clear of the hole: farther than rim_radius from where it went
// through, or back out on the side it came from by the contact distance, and no rim triangle within
// the contact distance of it (a flap still on it keeps it pierced)
static void pierce_check_clear(tx_cloth* c, const btVector3& h) {
  if (!c->pierced) return;
  const double rc = c->hip_radius + 0.5 * c->def.thickness;
  double d[3], dist2 = 0, along = 0;
  for (int a = 0; a < 3; a++) d[a] = (double)h[a] - c->pierce_at[a], dist2 += d[a] * d[a], along += d[a] * c->pierce_dir[a];
  c->rim_left = dist2 > c->rim_radius * c->rim_radius || along < -rc;
  if (!c->rim_left) return;
  const btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  const btScalar reach = (btScalar)(rc + c->reach_factor * c->max_edge), touch = (btScalar)(rc * 1.01);
  for (int i = 0; i < c->n; i++) {
    if (!c->rim[(size_t)i] || (nodes[i].m_x - h).length2() > reach * reach) continue;
    const int32_t* ts = &c->node_tris[(size_t)i * 8];
    for (int s = 0; s < 8 && ts[s] >= 0; s++) {
      if (!c->tri_alive[(size_t)ts[s]]) continue;
      const int32_t* t = &c->tri[(size_t)ts[s] * 3];
      btScalar w[3];
      closest_on_triangle(h, nodes[t[0]].m_x, nodes[t[1]].m_x, nodes[t[2]].m_x, w);
      const btVector3 q = nodes[t[0]].m_x * w[0] + nodes[t[1]].m_x * w[1] + nodes[t[2]].m_x * w[2];
      if ((q - h).length2() < touch * touch) return;
    }
  }
  c->pierced = false;
  std::fill(c->rim.begin(), c->rim.end(), 0);
  c->pierce_dirty = true;
}

// the HIP at h, at `from` when the substep began: every live triangle closer
// than the contact distance is pushed out to it, away from the side the HIP
// came from. With count set, records the indentation and (after the links,
// fix_velocity) the particles held and the push's direction; with fix_velocity,
// gives the particles the implied velocity.
static void project_contact(tx_cloth* c, const btVector3& h, const btVector3& from, double dt, bool count,
                            bool fix_velocity) {
  const double rc = c->hip_radius + 0.5 * c->def.thickness;
  if (c->hip_radius <= 0 || rc <= 0) return;
  btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  // candidates: triangles of particles within reach (a triangle in contact has a corner this close)
  // a triangle's edges are live links: at most reach_factor max_edge within the substep (see tx_cloth)
  const double stretch = c->reach_factor;
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
      if (c->pierced && c->rim_left && on_rim(c, t)) continue; // the tip has gone on: flaps slide off behind it
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
      // a triangle resting on the sphere (within 1 %) holds the HIP too, pushed this pass or not
      const btScalar touch = rcs * (btScalar)1.01;
      int32_t* held = &c->held_tri[(size_t)c->near_tris[(size_t)k]];
      bool near = dist2 < touch * touch;
      if (near) c->touching = true;
      // after the links, a triangle the HIP touched (this substep before them, or at the end of
      // the last) is checked however far it went: links stretched far enough pull it across
      // the sphere in one solve, and it must come back to the HIP's side instead of leaving
      // the HIP through an untorn skin. Only one that went over the HIP (its closest point less
      // than the contact distance across its plane): a hole's rim beside the HIP lets it by
      bool recheck = false;
      if (fix_velocity && !(dist2 < touch * touch) && *held >= c->substep_id - 1) {
        btVector3 nn = (p[1]->m_x - p[0]->m_x).cross(p[2]->m_x - p[0]->m_x);
        btScalar nl2 = nn.length2();
        btVector3 across = nl2 > 0 ? dq - nn * (dq.dot(nn) / nl2) : dq;
        recheck = across.length2() < rcs * rcs;
      }
      // before the implicit solve, a triangle the HIP touched at the last substep stays held
      // out to KEEP_TOUCH: skin resting on a HIP that stopped sits just beyond the 1 %, and
      // solved free its tension carried it up through the sphere, the contact after the
      // links threw it 2 r + t back and tore what it stretched
      const btScalar keep_r = rcs * (btScalar)KEEP_TOUCH;
      const bool still = (h - from).length2() < (btScalar)(KEEP_STILL * KEEP_STILL) * rcs * rcs;
      const bool keep = !fix_velocity && !near && c->def.solver == TX_CLOTH_IMPLICIT && still &&
                        *held >= c->substep_id - 1 && dist2 < keep_r * keep_r;
      if (near || keep) *held = c->substep_id;
      if (!near && !recheck && !keep) continue;
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
      if (keep) { // only held in the solve, and only on its side: nothing to push
        for (int j = 0; j < 3 && side_now * side > 0; j++) {
          if (p[j]->m_im <= 0 || !(w[j] > 0)) continue;
          const size_t pi = (size_t)(p[j] - &nodes[0]);
          const btVector3 radial = p[j]->m_x - h;
          c->hold[pi] = 1;
          for (int a = 0; a < 3; a++) c->hold_n[pi * 3 + a] = radial[a];
        }
        continue;
      }
      if (!near && side_now * side > 0) continue; // held, but on its side and out of reach: let go
      btVector3 dir;
      if (side_now * side > 0 && dist2 > 1e-20f) dir = dq / btSqrt(dist2); // still on its side: away from the centre
      else dir = nt * -side;                                                // crossed: back to the far side
      btScalar depth = rcs - (q - h).dot(dir);
      // the rim of the hole a pierced HIP went through is kept out of it, but its push is no force on the HIP
      const bool rim = c->pierced && on_rim(c, c->near_tris[(size_t)k]);
      if (count && fix_velocity && !rim) { // the particles the HIP holds, and which way it pushes them
        for (int j = 0; j < 3; j++)
          if (w[j] > 0) c->in_contact[(size_t)(p[j] - &nodes[0])] = 1;
        for (int a = 0; a < 3; a++) c->contact_dir[a] += dir[a];
        c->contact_pushes++;
      }
      btScalar wsum = 0;
      for (int j = 0; j < 3; j++) wsum += p[j]->m_im * w[j] * w[j];
      if (depth > 0 && wsum > 0) {
        btScalar s = depth / wsum;
        for (int j = 0; j < 3; j++) {
          if (p[j]->m_im <= 0) continue;
          btVector3 dx = dir * (s * p[j]->m_im * w[j]);
          p[j]->m_x += dx;
          if (fix_velocity) p[j]->m_v += dx * (btScalar)(1 / dt);
          if (count) {
            const float* r0 = &c->rest_x[(size_t)(p[j] - &nodes[0]) * 3];
            double moved = (p[j]->m_x - btVector3(r0[0], r0[1], r0[2])).length();
            if (moved > c->contact_depth) c->contact_depth = moved;
            c->contact_moves++;
          }
        }
      }
      // the implicit solve holds the corners of a triangle the HIP touches, pushed now or
      // not (one already resting on it, moving with it), each on its sphere about the HIP's
      // centre: free to slide across, not to come in
      if (!fix_velocity && near && c->def.solver == TX_CLOTH_IMPLICIT)
        for (int j = 0; j < 3; j++) {
          if (p[j]->m_im <= 0 || !(w[j] > 0)) continue;
          const size_t pi = (size_t)(p[j] - &nodes[0]);
          const btVector3 radial = p[j]->m_x - h;
          c->hold[pi] = 1;
          for (int a = 0; a < 3; a++) c->hold_n[pi * 3 + a] = radial[a];
        }
    }
}

// the HIP over one substep from h0 to h1, in moves of at most half the contact distance
static void rupture(tx_cloth* c, const btVector3* near);

static void sweep_contact(tx_cloth* c, const btVector3& h0, const btVector3& h1, double dt, bool count) {
  const double rc = c->hip_radius + 0.5 * c->def.thickness;
  if (c->hip_radius <= 0 || rc <= 0) return;
  if (++c->substep_id == INT32_MAX) {
    std::fill(c->held_tri.begin(), c->held_tri.end(), 0);
    c->substep_id = 1;
  }
  double len = (h1 - h0).length();
  int moves = (int)std::ceil(len / (0.5 * rc));
  if (moves < 1) moves = 1;
  if (moves > 64) moves = 64; // a teleport: the path is sampled, not followed
  pierce_check_clear(c, h0);
  c->touching = false;
  // a HIP this fast drags the skin further than the links can follow within
  // the substep, and the solve would spread the strain before anyone saw it:
  // what it overstretched tears now, move by move (a substep of the implicit
  // solver is a whole 60 Hz step: torn only at its end, the skin would be
  // dragged centimetres with the HIP)
  for (int k = 1; k <= moves; k++) {
    btVector3 h = h0.lerp(h1, (btScalar)k / (btScalar)moves);
    for (int a = 0; a < 3; a++) c->hip_now[a] = h[a];
    project_contact(c, h, h0, dt, count, false);
    if (moves > 1) rupture(c, &h);
  }
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

// a stretch or shear link goes, as a tear or a cut takes it: with the
// triangles it borders and the bending links across it
static void sever_link(tx_cloth* c, int id) {
  const link_info& li = c->info[(size_t)id];
  remove_link(c, id);
  c->tension[(size_t)id] = 0;
  for (int j = 0; j < 2; j++) {
    if (li.tri[j] >= 0) c->tri_alive[(size_t)li.tri[j]] = 0, c->live_dirty = true;
    if (li.dep[j] >= 0) remove_link(c, li.dep[j]), c->tension[(size_t)li.dep[j]] = 0;
  }
  c->topology_dirty = c->detach_check = true;
}

// largest eigenvalue of the symmetric 3 x 3 matrix (xx, yy, zz, xy, xz, yz)
// (the trigonometric solution of the characteristic cubic)
static double largest_eigenvalue(const double m[6]) {
  const double p1 = m[3] * m[3] + m[4] * m[4] + m[5] * m[5];
  const double q = (m[0] + m[1] + m[2]) / 3;
  if (p1 <= 1e-30 * (q * q + 1e-300)) return std::max(m[0], std::max(m[1], m[2]));
  const double a = m[0] - q, b = m[1] - q, cc = m[2] - q;
  const double p2 = a * a + b * b + cc * cc + 2 * p1;
  const double p = std::sqrt(p2 / 6);
  // det((M - q I) / p) / 2
  const double det = a * (b * cc - m[5] * m[5]) - m[3] * (m[3] * cc - m[5] * m[4]) + m[4] * (m[3] * m[5] - b * m[4]);
  double r = det / (2 * p * p * p);
  r = r < -1 ? -1 : (r > 1 ? 1 : r);
  return q + 2 * p * std::cos(std::acos(r) / 3);
}

// The membrane tension at particle i (N/m): the link stresses f L n n^T
// around it, weighted by the smooth kernel (1 - r^2 / l^2)^2 of the rest
// distance r from the particle to a link's middle (l = rupture_length),
// over the kernel's integral pi l^2 / 3, and its largest principal value.
// As the spacing shrinks the sum tends to the continuum average of the
// stress over the disc, so the value does not depend on the mesh once
// l spans a few spacings; below that it is the average over what the mesh
// resolves.
static double membrane_tension(const tx_cloth* c, int i) {
  const tx_cloth_def& d = c->def;
  const int nx = d.res[0], nz = d.res[1];
  const double hx = d.size[0] / (nx - 1), hz = d.size[1] / (nz - 1), l = d.rupture_length, l2 = l * l;
  const int ix = i % nx, iz = i / nx;
  const int mx = (int)std::ceil(l / hx) + 1, mz = (int)std::ceil(l / hz) + 1;
  const btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  double m[6] = {0, 0, 0, 0, 0, 0};
  for (int qz = std::max(0, iz - mz); qz <= std::min(nz - 1, iz + mz); qz++)
    for (int qx = std::max(0, ix - mx); qx <= std::min(nx - 1, ix + mx); qx++) {
      const int q = qz * nx + qx;
      const int32_t* ls = &c->node_links[(size_t)q * 12];
      for (int k = 0; k < 12 && ls[k] >= 0; k++) {
        const link_info& li = c->info[(size_t)ls[k]];
        if (li.end[0] != q || li.slot < 0) continue; // each link once, from its first particle
        const double f = excess(c, ls[k]);
        if (f == 0) continue;
        const int o = li.end[1];
        // the link's middle in the rest grid, relative to particle i
        const double rx = (0.5 * (qx + o % nx) - ix) * hx, rz = (0.5 * (qz + o / nx) - iz) * hz;
        const double r2 = rx * rx + rz * rz;
        if (r2 >= l2) continue;
        const double w = (1 - r2 / l2) * (1 - r2 / l2);
        const btVector3 dv = nodes[o].m_x - nodes[q].m_x;
        const double len = dv.length();
        if (!(len > 0)) continue;
        const double s = w * f / len; // f L n n^T = f d d^T / L
        m[0] += s * dv[0] * dv[0], m[1] += s * dv[1] * dv[1], m[2] += s * dv[2] * dv[2];
        m[3] += s * dv[0] * dv[1], m[4] += s * dv[0] * dv[2], m[5] += s * dv[1] * dv[2];
      }
    }
  const double norm = 3 / (M_PI * l2);
  for (double& v : m) v *= norm;
  return largest_eigenvalue(m);
}

// the links' tensions after a substep's solve (the multipliers over h^2),
// the longest live stretch or shear link for the contact's reach and, with
// rupture on, each particle's sum of f L / 2 over its stretched links (one
// pass over the links for all three)
static void measure_links(tx_cloth* c, double h) {
  const btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  const btSoftBody::Node* base = &c->body->m_nodes[0];
  const bool sums = c->def.rupture_tension > 0;
  float* local = c->local.data();
  if (sums) std::fill(local, local + c->n, 0.0f);
  const double ih2 = 1 / (h * h);
  const bool implicit = c->def.solver == TX_CLOTH_IMPLICIT;
  btScalar longest = 0;
  for (int i = 0, ni = links.size(); i < ni; i++) {
    const btSoftBody::Link& l = links[i];
    const int id = (int)reinterpret_cast<intptr_t>(l.m_tag);
    float f;
    btScalar len;
    if (implicit) { // the spring's force at the end of the substep
      len = (l.m_n[1]->m_x - l.m_n[0]->m_x).length();
      const double k = l.m_material == c->bend_mat ? c->def.bend_stiffness : c->def.stretch_stiffness;
      f = (float)(k * ((double)len - (double)l.m_rl));
    } else {
      f = (float)(-c->lambda[(size_t)i] * ih2);
      len = c->length[(size_t)i]; // before the last correction and the contact: close enough
    }
    c->tension[(size_t)id] = f;
    if (len > longest && c->info[(size_t)id].kind != BEND) longest = len;
    const float fx = f - c->hanging[(size_t)id];
    if (sums && fx > 0) {
      const float fl = 0.5f * fx * len;
      local[l.m_n[0] - base] += fl;
      local[l.m_n[1] - base] += fl;
    }
  }
  if (c->max_edge > 0) c->reach_factor = std::max(2.0, 2 * (double)longest / c->max_edge);
}

// Where the membrane tension passes rupture_tension (within the HIP's reach
// when blunt_rupture_tension is set, which holds elsewhere), the most tensed
// stretch or shear link at that particle breaks, with its triangles and the
// bending links over it. Only particles whose own stretched links could
// reach it are averaged (the average over a disc is at most about the
// largest of its particles' own sums of f L / 2 over their area), so a
// step without a tear costs one pass over the links.
//
// With `near` (a fast HIP, before the solve): the links it dragged have no
// solved tension yet, so those with a particle within the contact's reach
// of it count with their spring's force k (length - rest) where that is
// larger, and only particles there are checked.
static void rupture(tx_cloth* c, const btVector3* near) {
  const double tip = c->def.rupture_tension, blunt = c->def.blunt_rupture_tension > 0 ? c->def.blunt_rupture_tension : tip;
  if (tip <= 0) return;
  const double rc = c->hip_radius + 0.5 * c->def.thickness;
  const btScalar at_hip = (btScalar)(rc + c->reach_factor * c->max_edge);
  const btVector3 hip((btScalar)c->hip_now[0], (btScalar)c->hip_now[1], (btScalar)c->hip_now[2]);
  // the tip's criterion holds where its contact moves the skin and the average over rupture_length sees it
  const btScalar tip_reach = at_hip + (btScalar)c->def.rupture_length, tip_reach2 = tip_reach * tip_reach;
  const btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  const btSoftBody::Node* base = &c->body->m_nodes[0];
  const btScalar reach = (btScalar)(c->hip_radius + 0.5 * c->def.thickness + 2 * c->max_edge), reach2 = reach * reach;
  if (near)
    for (int i = 0, ni = links.size(); i < ni; i++) {
      const btSoftBody::Link& l = links[i];
      if ((l.m_n[0]->m_x - *near).length2() > reach2 && (l.m_n[1]->m_x - *near).length2() > reach2) continue;
      const int id = (int)reinterpret_cast<intptr_t>(l.m_tag);
      const double k = c->info[(size_t)id].kind == BEND ? c->def.bend_stiffness : c->def.stretch_stiffness;
      const float f = (float)(k * ((l.m_n[1]->m_x - l.m_n[0]->m_x).length() - l.m_rl));
      if (f - c->hanging[(size_t)id] > excess(c, id)) c->tension[(size_t)id] = f;
    }
  float* local = c->local.data();
  if (near) { // the sums again, with the spring forces just put in (after a solve, measure_links made them)
    std::fill(local, local + c->n, 0.0f);
    for (int i = 0, ni = links.size(); i < ni; i++) {
      const btSoftBody::Link& l = links[i];
      const float f = excess(c, (int)(intptr_t)l.m_tag);
      if (!(f > 0)) continue;
      const float fl = 0.5f * f * (l.m_n[1]->m_x - l.m_n[0]->m_x).length();
      local[l.m_n[0] - base] += fl;
      local[l.m_n[1] - base] += fl;
    }
  }
  // a margin of 2 below the criterion: in a uniform field a particle's own
  // sum over its area is at least the largest principal tension, and the
  // kernel's average of a peaked field is at most its peak
  const float bar = (float)(std::min(tip, blunt) * c->area / 2);
  int nb = 0, most = 0;
  for (int p = 1; p < c->n; p++)
    if (local[p] > local[most]) most = p;
  for (int p = 0; p < c->n; p++) {
    if (local[p] < bar && p != most) continue; // the most loaded particle always, for tx_cloth_peak_tension
    if (near && (base[p].m_x - *near).length2() > reach2) continue;
    const double t = membrane_tension(c, p);
    if (t > c->peak_tension) c->peak_tension = t;
    if (t > c->sub_peak) c->sub_peak = t;
    const bool far = !(c->hip_radius > 0 && (base[p].m_x - hip).length2() <= tip_reach2);
    if (t < (far ? blunt : tip)) continue;
    int best = -1;
    float fbest = 0;
    const int32_t* ls = &c->node_links[(size_t)p * 12];
    for (int k = 0; k < 12 && ls[k] >= 0; k++) {
      const link_info& li = c->info[(size_t)ls[k]];
      if (li.slot < 0 || li.kind == BEND) continue;
      if (excess(c, ls[k]) > fbest) fbest = excess(c, ls[k]), best = ls[k];
    }
    if (best >= 0) c->breaking_far[(size_t)nb] = far, c->breaking[(size_t)nb++] = best;
  }
  bool at_contact = false; // a link torn where the HIP holds the skin: its puncture
  for (int k = 0; k < nb; k++) {
    int id = c->breaking[(size_t)k];
    link_info& li = c->info[(size_t)id];
    if (li.slot < 0) continue;
    if (c->hip_radius > 0 && c->touching)
      for (int e = 0; e < 2; e++) at_contact |= (base[li.end[e]].m_x - hip).length2() <= at_hip * at_hip;
    sever_link(c, id);
    c->torn++;
    c->torn_pulled += c->breaking_far[(size_t)k];
  }
  if (at_contact) pierce_start(c);
}

// whether p-q and a-b cross in x-z, each strictly between the other's ends
static bool crosses_xz(const float* p, const float* q, const double* a, const double* b) {
  auto side = [](double ox, double oz, double ux, double uz, double px, double pz) {
    return (ux - ox) * (pz - oz) - (uz - oz) * (px - ox);
  };
  const double d1 = side(a[0], a[2], b[0], b[2], p[0], p[2]), d2 = side(a[0], a[2], b[0], b[2], q[0], q[2]);
  const double d3 = side(p[0], p[2], q[0], q[2], a[0], a[2]), d4 = side(p[0], p[2], q[0], q[2], b[0], b[2]);
  return d1 * d2 < 0 && d3 * d4 < 0;
}

extern "C" int tx_cloth_cut(tx_cloth* c, const double a[3], const double b[3]) {
  int cut = 0;
  for (int id = 0; id < c->nlink; id++) {
    link_info& li = c->info[(size_t)id];
    if (li.slot < 0 || li.kind == BEND) continue;
    if (!crosses_xz(&c->rest_x[(size_t)li.end[0] * 3], &c->rest_x[(size_t)li.end[1] * 3], a, b)) continue;
    sever_link(c, id);
    cut++;
  }
  if (cut) tx_cloth_save(c); // a fault goes back to the cut skin, not the whole one
  return cut;
}

extern "C" int tx_cloth_remove_particle(tx_cloth* c, int i) {
  if (!c || i < 0 || i >= c->n || c->freed[(size_t)i]) return 0;
  const int before = c->body->m_links.size();
  const int32_t* ls = &c->node_links[(size_t)i * 12];
  for (int k = 0; k < 12 && ls[k] >= 0; k++) {
    if (c->info[(size_t)ls[k]].slot < 0) continue;
    if (c->info[(size_t)ls[k]].kind == BEND) remove_link(c, ls[k]), c->tension[(size_t)ls[k]] = 0;
    else sever_link(c, ls[k]); // its triangles and the bending links across it too
  }
  const int32_t* ts = &c->node_tris[(size_t)i * 8];
  for (int k = 0; k < 8 && ts[k] >= 0; k++)
    if (c->tri_alive[(size_t)ts[k]]) c->tri_alive[(size_t)ts[k]] = 0, c->live_dirty = true;
  // frozen as a freed particle: nothing holds it any more
  if (c->pinned[(size_t)i]) tx_cloth_unpin(c, i);
  btSoftBody::Node& nd = c->body->m_nodes[i];
  nd.m_im = 0;
  nd.m_v = btVector3(0, 0, 0);
  c->freed[(size_t)i] = 1;
  c->nfreed++;
  c->rim[(size_t)i] = 0;
  c->topology_dirty = c->detach_check = true;
  tx_cloth_save(c); // a fault goes back to the patch without it
  return before - c->body->m_links.size();
}

// Pieces cut off from the patch: particles with no path of live links to a
// fixed or pinned particle. Each is frozen where it is (no mass, no
// velocity), loses its links and its triangles, and keeps its index: what
// the readers of skin.x hold (puncture rows, the thread's points) stays a
// valid index, and nothing they draw or collide with (skin.tri) has it. A
// patch with no fixed particle (fixed_border off, no clamp) floats whole:
// nothing is cut off from it.
static void free_detached(tx_cloth* c) {
  c->detach_check = false;
  if (!c->anchored) return;
  int32_t* q = c->flood.data();
  int32_t* mark = c->piece_of.data(); // 0 not reached, 1 the patch, 2 a piece cut off
  std::fill(c->piece_of.begin(), c->piece_of.end(), 0);
  auto flood = [&](int tail, int32_t label) {
    for (int head = 0; head < tail; head++) {
      const int32_t* ls = &c->node_links[(size_t)q[head] * 12];
      for (int k = 0; k < 12 && ls[k] >= 0; k++) {
        const link_info& li = c->info[(size_t)ls[k]];
        if (li.slot < 0) continue;
        const int o = li.end[0] == q[head] ? li.end[1] : li.end[0];
        if (mark[o]) continue;
        mark[o] = label;
        q[tail++] = o;
      }
    }
  };
  int tail = 0;
  for (int i = 0; i < c->n; i++)
    if (!c->freed[(size_t)i] && (!(c->im0[(size_t)i] > 0) || c->pinned[(size_t)i])) mark[i] = 1, q[tail++] = i;
  flood(tail, 1);
  for (int i = 0; i < c->n; i++) {
    if (mark[i] || c->freed[(size_t)i]) continue;
    mark[i] = 2;
    q[0] = i;
    flood(1, 2);
    c->pieces++;
  }
  btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  for (int i = 0; i < c->n; i++) {
    if (mark[i] != 2) continue;
    c->freed[(size_t)i] = 1;
    c->nfreed++;
    nodes[i].m_im = 0;
    nodes[i].m_v = btVector3(0, 0, 0);
    c->rim[(size_t)i] = 0;
    const int32_t* ls = &c->node_links[(size_t)i * 12];
    for (int k = 0; k < 12 && ls[k] >= 0; k++)
      if (c->info[(size_t)ls[k]].slot >= 0) remove_link(c, ls[k]), c->tension[(size_t)ls[k]] = 0;
    const int32_t* ts = &c->node_tris[(size_t)i * 8];
    for (int k = 0; k < 8 && ts[k] >= 0; k++)
      if (c->tri_alive[(size_t)ts[k]]) c->tri_alive[(size_t)ts[k]] = 0, c->live_dirty = true;
    c->topology_dirty = true;
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
    c->good_freed = c->freed; // same size: a copy, no allocation
    c->good_nfreed = c->nfreed;
    c->good_pieces = c->pieces;
    c->topology_dirty = false;
  }
  if (c->pierce_dirty) {
    c->good_rim = c->rim;
    c->good_pierced = c->pierced;
    c->good_pierces = c->pierces;
    c->good_rim_radius = c->rim_radius;
    for (int a = 0; a < 3; a++) c->good_pierce_at[a] = c->pierce_at[a], c->good_pierce_dir[a] = c->pierce_dir[a];
    c->pierce_dirty = false;
  }
  c->good_torn = c->torn;
  c->good_torn_pulled = c->torn_pulled;
  std::memcpy(c->good_tension.data(), c->tension.data(), (size_t)c->nlink * sizeof(float));
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
    c->freed = c->good_freed;
    c->nfreed = c->good_nfreed;
    c->pieces = c->good_pieces;
    for (int i = 0; i < c->n; i++) // a particle freed in the faulty step gets its mass back
      nodes[i].m_im = c->freed[(size_t)i] || c->pinned[(size_t)i] ? 0 : c->im0[(size_t)i];
    c->topology_dirty = false;
  }
  if (c->pierce_dirty) {
    c->rim = c->good_rim;
    c->pierced = c->good_pierced;
    c->pierces = c->good_pierces;
    c->rim_radius = c->good_rim_radius;
    for (int a = 0; a < 3; a++) c->pierce_at[a] = c->good_pierce_at[a], c->pierce_dir[a] = c->good_pierce_dir[a];
    c->pierce_dirty = false;
  }
  c->detach_check = false;
  c->torn = c->good_torn;
  c->torn_pulled = c->good_torn_pulled;
  std::memcpy(c->tension.data(), c->good_tension.data(), (size_t)c->nlink * sizeof(float));
  for (int a = 0; a < 3; a++) c->hip_prev[a] = c->good_hip[a];
  for (int a = 0; a < 3; a++) c->contact_force[a] = 0;
  c->contact_depth = 0;
  c->contact_moves = 0;
  c->contact_held = 0;
}

// The force of the skin on the HIP: the springs of eq. 1 (k (l - l0) along each
// link, stretch and shear at stretch_stiffness, bending at bend_stiffness) pulling
// on the particles the contact holds, plus their weight, less what accelerates
// them (m a over the step): the HIP holds them against all of it. The contact's momentum
// is no measure of it here: a position solver's correction at 60 Hz is m/dt^2
// times what the links' last iterations left over, which the iteration count sets,
// not the material.
//
// The implicit solver takes the whole patch's momentum balance instead: the HIP's
// push is the one force on the skin not otherwise known, so the skin's reaction on
// the HIP is what holds the patch up at its kinematic particles (the border, the
// clamp, the jaws' grasps: the links' pull on them) less the backward Euler
// inertia M (x - y) / h^2 of the free particles over the last substep (y the
// prediction with gravity and the loads, so the weight is in it). The held
// particles' own imbalance, which the local sum reads, carries the part of the
// solve that has not converged yet (the CG stops at 1e-2, Newton at a tenth),
// and it sits where the contact is: at 1.25 mm the local sum read 234 mN where
// the patch's balance reads 198 mN, and with a HIP at rest it flipped between
// 11 and 136 mN as the contact's active set changed from step to step.
static int link_reaction(const tx_cloth* c, double dt, double h, double out[3]) {
  out[0] = out[1] = out[2] = 0;
  int held = 0;
  // pierced, the patch's balance would count the rim's push on the HIP too: what the skin beyond the
  // rim pushes (none, mostly) is read from the particles it holds
  const bool balance = c->def.solver == TX_CLOTH_IMPLICIT && c->def.reading == TX_CLOTH_BALANCE && !c->pierced;
  const double ih2 = 1 / (h * h);
  for (int i = 0; i < c->n; i++) {
    const btSoftBody::Node& nd = c->body->m_nodes[i];
    if (!(nd.m_im > 0)) continue;
    const bool in = c->in_contact[(size_t)i] != 0;
    held += in;
    double m = 1.0 / nd.m_im;
    if (balance) {
      for (int e = 0; e < 3; e++) out[e] -= m * ((double)nd.m_x[e] - c->y[(size_t)i * 3 + e]) * ih2;
      const double ks = c->sprung > 0 ? c->spring_k[(size_t)i] : 0; // a spring is an external force too, as a load in y
      for (int e = 0; e < 3 && ks > 0; e++) out[e] += ks * (c->spring_a[(size_t)i * 3 + e] - (double)nd.m_x[e]);
    }
    else if (in)
      for (int e = 0; e < 3; e++)
        out[e] += m * (c->world.m_gravity[e] - (nd.m_v[e] - c->good_v[(size_t)i * 3 + e]) / dt);
  }
  if (held == 0) {
    out[0] = out[1] = out[2] = 0;
    return 0;
  }
  const btAlignedObjectArray<btSoftBody::Link>& links = c->body->m_links;
  const btSoftBody::Node* base = &c->body->m_nodes[0];
  for (int i = 0, ni = links.size(); i < ni; i++) {
    const btSoftBody::Link& l = links[i];
    int a = (int)(l.m_n[0] - base), b = (int)(l.m_n[1] - base);
    bool ia, ib; // balance: the kinematic end, which the link pulls towards the other; else the held end
    if (balance) ia = !(l.m_n[0]->m_im > 0), ib = !(l.m_n[1]->m_im > 0);
    else ia = c->in_contact[(size_t)a] != 0, ib = c->in_contact[(size_t)b] != 0;
    if (ia == ib) continue; // none held, or both: a link inside the contact pulls both ways
    btVector3 d = l.m_n[1]->m_x - l.m_n[0]->m_x;
    double len = d.length();
    if (!(len > 0)) continue;
    bool bend = c->info[(size_t)(intptr_t)l.m_tag].kind == BEND;
    double k = bend ? c->def.bend_stiffness : c->def.stretch_stiffness;
    double s = k * (len - (double)l.m_rl) / len * (ia ? 1 : -1); // on the held (kinematic) end, toward the other
    for (int e = 0; e < 3; e++) out[e] += balance ? -s * d[e] : s * d[e]; // what holds the patch, or pulls the held
  }
  // a smooth sphere takes only the push along its contact normal: the rest is the held
  // particles' own imbalance, which the solver has not yet spread (no pull either).
  // Once the skin wraps the sphere (pushed on every side: their mean direction is under
  // half a push) that mean is no normal, and a few pushes above the centre turned it
  // over (the force fell to 0 with 30 N in the links, 2.7 cm down over a particle): the
  // links' reaction is then taken whole, a wrapped sphere taking a push from any side
  double n[3] = {-c->contact_dir[0], -c->contact_dir[1], -c->contact_dir[2]};
  double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (c->contact_pushes > 0 && nl < 0.5 * c->contact_pushes) return held;
  double along = nl > 0 ? (out[0] * n[0] + out[1] * n[1] + out[2] * n[2]) / nl : 0;
  for (int e = 0; e < 3; e++) out[e] = along > 0 ? along * n[e] / nl : 0;
  return held;
}

// the pinned particles where the jaws have them at fraction u of the step: after
// predict, before the contact and the solve, which move only what has mass
static void place_pinned(tx_cloth* c, double u) {
  btAlignedObjectArray<btSoftBody::Node>& nodes = c->body->m_nodes;
  for (int i = 0; i < c->n; i++) {
    if (!c->pinned[(size_t)i]) continue;
    const double* f = &c->pin_from[(size_t)i * 3];
    const double* t = &c->pin_to[(size_t)i * 3];
    if (u >= 1) nodes[i].m_x = btVector3((btScalar)t[0], (btScalar)t[1], (btScalar)t[2]); // exactly where asked
    else
      nodes[i].m_x = btVector3((btScalar)(f[0] + u * (t[0] - f[0])), (btScalar)(f[1] + u * (t[1] - f[1])),
                               (btScalar)(f[2] + u * (t[2] - f[2])));
  }
}

extern "C" tx_cloth_status tx_cloth_pin(tx_cloth* c, int i, const double x[3]) {
  if (i < 0 || i >= c->n) {
    tx_set_error("skin: pin on particle %d, there are %d", i, c->n);
    return TX_CLOTH_BAD;
  }
  if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]) && std::fabs(x[0]) <= 1e3 &&
        std::fabs(x[1]) <= 1e3 && std::fabs(x[2]) <= 1e3)) {
    tx_set_error("skin: pin of particle %d at (%g, %g, %g) m, must be finite and within 1 km", i, x[0], x[1], x[2]);
    return TX_CLOTH_BAD;
  }
  if (!(c->im0[(size_t)i] > 0)) {
    tx_set_error("skin: particle %d is fixed (border or clamp), it cannot be pinned", i);
    return TX_CLOTH_BAD;
  }
  if (c->freed[(size_t)i]) {
    tx_set_error("skin: particle %d is cut off from the patch, it cannot be pinned", i);
    return TX_CLOTH_BAD;
  }
  btSoftBody::Node& nd = c->body->m_nodes[i];
  if (!c->pinned[(size_t)i]) {
    c->pinned[(size_t)i] = 1;
    c->npinned++;
    nd.m_im = 0; // kinematic: the links and the contact move only what has mass
    nd.m_v = btVector3(0, 0, 0);
  }
  for (int a = 0; a < 3; a++) c->pin_to[(size_t)i * 3 + a] = x[a];
  return TX_CLOTH_OK;
}

extern "C" bool tx_cloth_unpin(tx_cloth* c, int i) {
  if (i < 0 || i >= c->n || !c->pinned[(size_t)i]) return false;
  c->pinned[(size_t)i] = 0;
  c->npinned--;
  c->body->m_nodes[i].m_im = c->im0[(size_t)i]; // it keeps the jaws' last velocity
  c->detach_check = true; // what only the jaws held is cut off
  return true;
}

extern "C" int tx_cloth_pinned(const tx_cloth* c) { return c->npinned; }

extern "C" tx_cloth_status tx_cloth_step(tx_cloth* c, double dt) {
  if (!(dt > 0 && dt <= 1)) {
    tx_set_error("skin: step dt = %g s, must be finite and in (0, 1]", dt);
    return TX_CLOTH_BAD;
  }
  int substeps = (int)std::ceil(dt / c->def.max_substep - 1e-9);
  if (substeps < 1) substeps = 1;
  const double h = dt / substeps;
  btSoftBody* b = c->body;
  c->peak_tension = 0;
  c->stats.cg_iterations = 0;
  c->stats.residual = 0;
  c->stats.released = 0;
  c->stats.newton = 0;
  const btScalar ih = (btScalar)(1 / h);
  c->contact_depth = 0;
  c->contact_moves = 0;
  c->contact_held = 0;
  const btVector3 start((btScalar)c->hip_prev[0], (btScalar)c->hip_prev[1], (btScalar)c->hip_prev[2]);
  const btVector3 end((btScalar)c->hip[0], (btScalar)c->hip[1], (btScalar)c->hip[2]);
  c->broke = false;
  if (c->npinned > 0)
    for (int i = 0; i < c->n; i++)
      if (c->pinned[(size_t)i])
        for (int a = 0; a < 3; a++) c->pin_from[(size_t)i * 3 + a] = c->body->m_nodes[i].m_x[a];
  for (int s = 0; s < substeps; s++) {
    btVector3 h0 = start.lerp(end, (btScalar)s / (btScalar)substeps);
    btVector3 h1 = start.lerp(end, (btScalar)(s + 1) / (btScalar)substeps);
    const int torn0 = c->torn, pulled0 = c->torn_pulled;
    c->sub_peak = 0;
    if (c->detach_check) free_detached(c);
    predict(c, h);
    if (c->npinned > 0) place_pinned(c, (double)(s + 1) / substeps);
    sweep_contact(c, h0, h1, h, true);
    if (c->def.solver == TX_CLOTH_IMPLICIT) solve_implicit(c, h);
    else solve_links(c, h);
    btAlignedObjectArray<btSoftBody::Node>& nodes = b->m_nodes;
    const btScalar vc = (btScalar)(ih * std::exp(-c->def.damping * h));
    for (int i = 0; i < c->n; i++) {
      nodes[i].m_v = (nodes[i].m_x - nodes[i].m_q) * vc;
      nodes[i].m_f = btVector3(0, 0, 0);
    }
    // the contact again after the links, with the velocities it implies
    std::fill(c->in_contact.begin(), c->in_contact.end(), 0);
    for (int a = 0; a < 3; a++) c->contact_dir[a] = 0;
    c->contact_pushes = 0;
    for (int a = 0; a < 3; a++) c->hip_now[a] = h1[a];
    project_contact(c, h1, h0, h, true, true);
    if (c->def.solver == TX_CLOTH_IMPLICIT) {
      // the solve's active set holds the HIP too: a vertex sliding across its sphere ends
      // a little off it (second order), beyond the touch test, and still pushes
      const btSoftBody::Node* base = &b->m_nodes[0];
      for (int i = 0; i < c->n; i++) {
        if (!c->held_solve[(size_t)i] || (c->pierced && c->rim[(size_t)i])) continue;
        c->in_contact[(size_t)i] = 1;
        const btVector3 r = base[i].m_x - h1;
        const btScalar rl = r.length();
        if (rl > 0)
          for (int a = 0; a < 3; a++) c->contact_dir[a] += r[a] / rl;
        if (rl > 0) c->contact_pushes++;
      }
    }
    if (!healthy(c)) {
      c->faults++;
      tx_cloth_restore(c);
      c->broke = false; // the tear, if any, is undone with the step
      // the HIP's move that led here is not replayed: it starts the next step where it is
      for (int a = 0; a < 3; a++) c->hip_prev[a] = c->hip[a];
      return TX_CLOTH_FAULT;
    }
    measure_links(c, h);
    rupture(c, nullptr);
    if (c->torn - torn0 > c->torn_pulled - pulled0 && !c->broke) {
      // the HIP tore a link (not a pull beyond its reach, whose place the HIP's path does not tell): the
      // criterion crossed between the last substep's check and this one's: where, linear in the tension
      const double tc = c->def.rupture_tension, d = c->sub_peak - c->prev_peak;
      double u = d > 0 ? (tc - c->prev_peak) / d : 1;
      u = u < 0 ? 0 : u > 1 ? 1 : u;
      for (int a = 0; a < 3; a++) c->broke_at[a] = (double)h0[a] + u * ((double)h1[a] - (double)h0[a]);
      c->broke = true;
    }
    c->prev_peak = c->sub_peak;
  }
  if (c->detach_check) free_detached(c); // the mesh published after this step has none of it
  c->contact_held = link_reaction(c, dt, h, c->contact_force);
  for (int a = 0; a < 3; a++) {
    c->contact_at[a] = c->hip[a];
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

extern "C" tx_cloth_status tx_cloth_set_load(tx_cloth* c, int i, const double f[3]) {
  if (i < 0 || i >= c->n) {
    tx_set_error("skin: load on particle %d, there are %d", i, c->n);
    return TX_CLOTH_BAD;
  }
  if (!(std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]) && std::fabs(f[0]) <= 1e6 &&
        std::fabs(f[1]) <= 1e6 && std::fabs(f[2]) <= 1e6)) {
    tx_set_error("skin: load (%g, %g, %g) N on particle %d, must be finite and within 1e6 N", f[0], f[1], f[2], i);
    return TX_CLOTH_BAD;
  }
  btVector3& l = c->load[(size_t)i];
  c->loaded -= l.length2() > 0;
  l = btVector3((btScalar)f[0], (btScalar)f[1], (btScalar)f[2]);
  c->loaded += l.length2() > 0;
  return TX_CLOTH_OK;
}

extern "C" tx_cloth_status tx_cloth_set_spring(tx_cloth* c, int i, const double anchor[3], double k) {
  if (i < 0 || i >= c->n) {
    tx_set_error("skin: spring on particle %d, there are %d", i, c->n);
    return TX_CLOTH_BAD;
  }
  bool finite = std::isfinite(anchor[0]) && std::isfinite(anchor[1]) && std::isfinite(anchor[2]);
  if (!(k >= 0 && k <= 1e9) || !finite) {
    tx_set_error("skin: spring of %g N/m to (%g, %g, %g) on particle %d, must be in [0, 1e9] N/m to a finite point", k,
                 anchor[0], anchor[1], anchor[2], i);
    return TX_CLOTH_BAD;
  }
  double& ks = c->spring_k[(size_t)i];
  c->sprung -= ks > 0;
  ks = k;
  c->sprung += ks > 0;
  for (int a = 0; a < 3; a++) c->spring_a[(size_t)i * 3 + a] = anchor[a];
  return TX_CLOTH_OK;
}

extern "C" int tx_cloth_link_total(const tx_cloth* c) { return c->nlink; }

extern "C" bool tx_cloth_link_ends(const tx_cloth* c, int link, int32_t ends[2]) {
  if (link < 0 || link >= c->nlink) return false;
  ends[0] = c->info[(size_t)link].end[0];
  ends[1] = c->info[(size_t)link].end[1];
  return true;
}

extern "C" double tx_cloth_link_tension(const tx_cloth* c, int link) {
  if (link < 0 || link >= c->nlink || c->info[(size_t)link].slot < 0) return 0;
  return c->tension[(size_t)link];
}

extern "C" double tx_cloth_membrane_tension(const tx_cloth* c, int i) {
  if (i < 0 || i >= c->n) return NAN;
  return membrane_tension(c, i);
}

extern "C" double tx_cloth_peak_tension(const tx_cloth* c) { return c->peak_tension; }

extern "C" bool tx_cloth_broke_at(const tx_cloth* c, double at[3]) {
  for (int a = 0; a < 3; a++) at[a] = c->broke ? c->broke_at[a] : 0;
  return c->broke;
}

extern "C" bool tx_cloth_pierced(const tx_cloth* c) { return c->pierced; }
extern "C" int tx_cloth_pierces(const tx_cloth* c) { return c->pierces; }
extern "C" bool tx_cloth_freed(const tx_cloth* c, int i) { return i >= 0 && i < c->n && c->freed[(size_t)i]; }
extern "C" int tx_cloth_freed_count(const tx_cloth* c) { return c->nfreed; }
extern "C" int tx_cloth_pieces_freed(const tx_cloth* c) { return c->pieces; }

extern "C" void tx_cloth_solve_stats(const tx_cloth* c, tx_cloth_solve_info* out) { *out = c->stats; }

extern "C" double tx_cloth_converged_substep(double stiffness, double particle_mass, double kwh2) {
  return std::sqrt(kwh2 / (stiffness * 2 / particle_mass));
}
