// A tetrahedral soft body on Bullet: the C interface of fem.h over Bullet's
// FEM deformables (btDeformableMultiBodyDynamicsWorld) or its classic soft
// body (links and volume conservation).
#include "fem.h"

extern "C" {
#include "../../../model/error.h"
}

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableCorotatedForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btDeformableNeoHookeanForce.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <new>
#include <set>
#include <utility>
#include <vector>

struct tx_fem {
  tx_fem_def def;
  int nv;
  double dt;
  // FEM: a deformable world; links: a body of its own
  btSoftBodyRigidBodyCollisionConfiguration* config;
  btCollisionDispatcher* dispatcher;
  btDbvtBroadphase* broadphase;
  btDeformableBodySolver* body_solver;
  btDeformableMultiBodyConstraintSolver* solver;
  btDeformableMultiBodyDynamicsWorld* world;
  btDeformableLagrangianForce* force;
  btAlignedObjectArray<btVector3> elastic;  // (nv) N, the elastic force of the explicit step
  double volume_modulus;     // Pa, the force's lambda: the volume term the nodal pressure averages; 0: per element
  std::vector<double> node_rest, node_now;  // (nv) m^3, a quarter of each live tetrahedron's volume, at rest and now (then J)
  btSoftBodyWorldInfo info;  // the links body's world
  btSoftBody* body;
  std::vector<double> mass;  // (nv) kg, lumped
  std::vector<double> weight;  // (nv) true mass over mass (1 without mass scaling)
  bool has_plate;
  double plate;              // m, the plate's underside; with ball_r > 0, the ball's centre height
  double ball_x, ball_z, ball_r;  // m, a ball in place of the plate (tx_fem_set_ball); r 0: the plate
  double plate_force;        // N, upward, averaged over the last tx_fem_step
  int ncaps;                 // rigid capsules nodes are kept out of (tx_fem_set_capsules)
  double caps[TX_FEM_CAPSULES_MAX][7];  // each: one end, the other, the radius (m)
  double cap_box[TX_FEM_CAPSULES_MAX][6];  // each capsule's bounding box (low, high), m: most nodes are outside it
  int contacts;              // nodes on the plate after the last step
  double added_mass;         // mass scaling's, over the true mass
  std::vector<btVector3> before;  // (nv) m, the nodes after the last step in which the tool touched nothing
  std::vector<int> hull;     // (nh x 3) the tetrahedra's boundary faces, outward
  std::vector<btVector3> saved_x, saved_v;  // tx_fem_save's state
  // kinematic nodes (tx_fem_set_kinematic)
  std::vector<char> kinematic;          // (nv) 1: moved by its holder
  std::vector<btVector3> kin_from, kin_to;  // (nv) m, this tx_fem_step's move (or this spread move's)
  std::vector<int> kin_span, kin_done;  // (nv) substeps a move is spread over (0: this tx_fem_step's), taken of it
  std::vector<btVector3> kin_force;     // (nv) N, elastic force summed over the substeps
  int kin_count;                        // kinematic nodes now
  int kin_steps;                        // substeps kin_force sums
  // removal (tx_fem_remove_tet); every array sized at create
  int ne, live_ne;
  std::vector<int> tets;       // (ne x 4) as created
  std::vector<double> rest;    // (nv x 3) m, the nodes as created (faces are turned outward by them)
  std::vector<char> tet_live;  // (ne)
  std::vector<int> slot, slot_tet;  // (ne) tetrahedron -> its row in the body's m_tetras, and back
  std::vector<int> nbr;        // (ne x 4) the tetrahedron across face k (opposite node k), -1: none
  std::vector<int> hull_at;    // (ne x 4) face k of t: its row in hull, -1: not boundary
  std::vector<int> hull_owner; // (hull rows) 4 t + k of each boundary face
  std::vector<char> fresh;     // (ne x 4) laid open by a removal inside the tool: not pushed until the tool leaves it
  std::vector<int> node_tets;  // (nv) live tetrahedra at each node; 0: out of the solve
  std::vector<double> tet_mass, tet_true;  // (ne) kg, the mass it lumps (scaled), its true mass
  std::vector<double> true_mass;           // (nv) kg, the true mass at each node
  std::vector<char> fixed;     // (nv) tx_fem_fix
  std::vector<int> tet_edge;   // links: (ne x 6) the edge ids of each tetrahedron
  std::vector<int> edge_count; // links: live tetrahedra on each edge
  std::vector<std::pair<int, int>> edge_nodes;  // links: the nodes of each edge
  bool has_tool;
  double tool_c[3], tool_r;
  double tool_prev[3];  // m, the centre at the last tx_fem_step: a face it has gone behind since is pushed back
  tx_fem_tool_info tool;
};

extern "C" tx_fem_def tx_fem_def_default(void) {
  tx_fem_def d;
  d.model = TX_FEM_COROTATED;
  d.young = 5e3;
  d.poisson = 0.45;
  d.density = 1000;
  d.damping = 0;
  d.dt = 0;
  d.mass_scaling = false;
  d.iterations = 10;
  d.link_stiffness = 1;
  d.volume_stiffness = 0;
  d.gravity[0] = d.gravity[1] = d.gravity[2] = 0;
  d.max_speed = 0;
  d.nodal_pressure = true;
  return d;
}

static double tet_volume(const double* a, const double* b, const double* c, const double* d) {
  double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
         ad[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (ab[0] * (ac[1] * ad[2] - ac[2] * ad[1]) + ab[1] * (ac[2] * ad[0] - ac[0] * ad[2]) +
          ab[2] * (ac[0] * ad[1] - ac[1] * ad[0])) /
         6.0;
}

// face k of tetrahedron t (opposite its node k) made boundary, turned
// outward: the fourth node behind it (the order the first build used)
static void hull_add(tx_fem* b, int t, int k) {
  const int* e = &b->tets[4 * (size_t)t];
  int f[3] = {e[(k + 1) % 4], e[(k + 2) % 4], e[(k + 3) % 4]};
  std::sort(f, f + 3);
  int a = f[0], c = f[1], g = f[2], o = e[k];
  const double* x = b->rest.data();
  if (tet_volume(x + 3 * a, x + 3 * c, x + 3 * g, x + 3 * o) > 0) std::swap(c, g);
  b->hull_at[4 * (size_t)t + (size_t)k] = (int)b->hull_owner.size();
  b->hull_owner.push_back(4 * t + k);
  b->hull.push_back(a), b->hull.push_back(c), b->hull.push_back(g);
}

// face k of t no longer boundary: the last row takes its place
static void hull_drop(tx_fem* b, int t, int k) {
  size_t at = (size_t)b->hull_at[4 * (size_t)t + (size_t)k], last = b->hull_owner.size() - 1;
  b->hull_at[4 * (size_t)t + (size_t)k] = -1;
  if (at != last) {
    int owner = b->hull_owner[last];
    b->hull_owner[at] = owner;
    b->hull_at[(size_t)owner] = (int)at;
    for (int q = 0; q < 3; q++) b->hull[3 * at + (size_t)q] = b->hull[3 * last + (size_t)q];
  }
  b->hull_owner.pop_back();
  b->hull.resize(3 * last);
}

extern "C" void tx_fem_destroy(tx_fem* b) {
  if (!b) return;
  if (b->world) {
    if (b->body) b->world->removeSoftBody(b->body);
    delete b->world;
  }
  delete b->body;
  delete b->force;
  delete b->solver;
  delete b->body_solver;
  delete b->broadphase;
  delete b->dispatcher;
  delete b->config;
  delete b;
}

extern "C" tx_fem* tx_fem_create(const tx_fem_def* d, const double* nodes, int nv, const int* tets, int ne) {
  bool fem = d->model == TX_FEM_COROTATED || d->model == TX_FEM_NEOHOOKEAN;
  if (d->model != TX_FEM_COROTATED && d->model != TX_FEM_NEOHOOKEAN && d->model != TX_FEM_LINKS) {
    tx_set_error("soft body: unknown model %d", (int)d->model);
    return NULL;
  }
  if (fem && !(d->young > 0 && d->poisson >= 0 && d->poisson < 0.5)) {
    tx_set_error("soft body: E = %g Pa and nu = %g: need E > 0 and 0 <= nu < 0.5", d->young, d->poisson);
    return NULL;
  }
  if (!(d->density > 0) || !(d->damping >= 0) || !(d->dt >= 0) || d->iterations < 1 ||
      !(d->link_stiffness > 0 && d->link_stiffness <= 1) || !(d->volume_stiffness >= 0) || !(d->max_speed >= 0) ||
      !std::isfinite(d->gravity[0] + d->gravity[1] + d->gravity[2])) {
    tx_set_error("soft body: density > 0, damping >= 0, dt >= 0, iterations >= 1, 0 < kLST <= 1, kVC >= 0, max speed >= 0 "
                 "and a finite gravity needed");
    return NULL;
  }
  if (nv < 4 || ne < 1) {
    tx_set_error("soft body: %d nodes and %d tetrahedra: need a tetrahedron at least", nv, ne);
    return NULL;
  }
  tx_fem* b = new (std::nothrow) tx_fem();
  if (!b) {
    tx_set_error("soft body: out of memory");
    return NULL;
  }
  b->def = *d;
  b->nv = nv;
  try {
    // each tetrahedron's shortest altitude (3 V / largest face), which sets
    // the explicit step: the P-wave crosses it in more than 3 steps
    std::vector<double> alt((size_t)ne), vol((size_t)ne);
    for (int t = 0; t < ne; t++) {
      const int* e = tets + 4 * t;
      for (int k = 0; k < 4; k++)
        if (e[k] < 0 || e[k] >= nv) {
          tx_set_error("soft body: tetrahedron %d names node %d of %d", t, e[k], nv);
          tx_fem_destroy(b);
          return NULL;
        }
      double v = tet_volume(nodes + 3 * e[0], nodes + 3 * e[1], nodes + 3 * e[2], nodes + 3 * e[3]);
      if (!(v > 0)) {
        tx_set_error("soft body: tetrahedron %d is inverted or flat (volume %g m^3)", t, v);
        tx_fem_destroy(b);
        return NULL;
      }
      double a = INFINITY;
      for (int k = 0; k < 4; k++) {
        const double *p = nodes + 3 * e[(k + 1) % 4], *q = nodes + 3 * e[(k + 2) % 4], *r = nodes + 3 * e[(k + 3) % 4];
        double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
        double c[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        a = std::min(a, 3 * v / (0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])));
      }
      alt[(size_t)t] = a, vol[(size_t)t] = v;
    }
    double mu = d->young / (2 * (1 + d->poisson));
    double lambda = d->young * d->poisson / ((1 + d->poisson) * (1 - 2 * d->poisson));
    double modulus = lambda + 2 * mu;  // P-wave modulus, Pa
    std::vector<double> sorted = alt;
    std::sort(sorted.begin(), sorted.end());
    double ref = d->mass_scaling ? sorted[sorted.size() / 2] : sorted[0];
    b->dt = d->dt > 0 ? d->dt : 0.3 * ref * std::sqrt(d->density / modulus);
    // lumped masses; with mass scaling a thin element is given the density
    // that makes its own stable step b->dt
    b->mass.assign((size_t)nv, 0.0);
    b->weight.assign((size_t)nv, 0.0);
    double true_mass = 0, mass = 0;
    b->tet_mass.resize((size_t)ne), b->tet_true.resize((size_t)ne);
    for (int t = 0; t < ne; t++) {
      double rho = d->density;
      if (d->mass_scaling && fem) rho = std::max(rho, modulus * std::pow(b->dt / (0.3 * alt[(size_t)t]), 2));
      b->tet_mass[(size_t)t] = rho * vol[(size_t)t], b->tet_true[(size_t)t] = d->density * vol[(size_t)t];
      for (int k = 0; k < 4; k++) {
        b->mass[(size_t)tets[4 * t + k]] += rho * vol[(size_t)t] / 4;
        b->weight[(size_t)tets[4 * t + k]] += d->density * vol[(size_t)t] / 4;
      }
      true_mass += d->density * vol[(size_t)t], mass += rho * vol[(size_t)t];
    }
    b->added_mass = mass / true_mass - 1;
    b->true_mass = b->weight;
    for (int i = 0; i < nv; i++) b->weight[(size_t)i] /= b->mass[(size_t)i];  // the fraction of each node's mass that gravity pulls
    b->before.resize((size_t)nv);
    for (int i = 0; i < nv; i++)
      b->before[(size_t)i] = btVector3((btScalar)nodes[3 * i], (btScalar)nodes[3 * i + 1], (btScalar)nodes[3 * i + 2]);
    b->saved_x.resize((size_t)nv);
    b->saved_v.resize((size_t)nv);
    b->kinematic.assign((size_t)nv, 0);
    b->kin_from.resize((size_t)nv);
    b->kin_to.resize((size_t)nv);
    b->kin_span.assign((size_t)nv, 0);
    b->kin_done.assign((size_t)nv, 0);
    b->kin_force.resize((size_t)nv);
    b->kin_count = b->kin_steps = 0;
    // removal's bookkeeping, sized once
    b->ne = b->live_ne = ne;
    b->tets.assign(tets, tets + 4 * (size_t)ne);
    b->rest.assign(nodes, nodes + 3 * (size_t)nv);
    b->tet_live.assign((size_t)ne, 1);
    b->slot.resize((size_t)ne), b->slot_tet.resize((size_t)ne);
    for (int t = 0; t < ne; t++) b->slot[(size_t)t] = b->slot_tet[(size_t)t] = t;
    b->nbr.assign(4 * (size_t)ne, -1);
    b->hull_at.assign(4 * (size_t)ne, -1);
    b->fresh.assign(4 * (size_t)ne, 0);
    b->hull.reserve(12 * (size_t)ne);
    b->hull_owner.reserve(4 * (size_t)ne);
    b->node_tets.assign((size_t)nv, 0);
    for (int t = 0; t < 4 * ne; t++) b->node_tets[(size_t)tets[t]]++;
    b->fixed.assign((size_t)nv, 0);
    // the boundary: faces that belong to one tetrahedron only, turned outward;
    // the others give each tetrahedron its neighbour across them
    {
      std::vector<std::array<int, 6>> keyed;  // sorted face, the tetrahedron's fourth node, the tetrahedron, the face
      keyed.reserve(4 * (size_t)ne);
      for (int t = 0; t < ne; t++)
        for (int k = 0; k < 4; k++) {
          std::array<int, 3> f = {tets[4 * t + (k + 1) % 4], tets[4 * t + (k + 2) % 4], tets[4 * t + (k + 3) % 4]};
          std::sort(f.begin(), f.end());
          keyed.push_back({f[0], f[1], f[2], tets[4 * t + k], t, k});
        }
      std::sort(keyed.begin(), keyed.end());
      for (size_t i = 0; i < keyed.size(); i++) {
        bool next = i + 1 < keyed.size() && std::equal(keyed[i].begin(), keyed[i].begin() + 3, keyed[i + 1].begin());
        bool prev = i > 0 && std::equal(keyed[i].begin(), keyed[i].begin() + 3, keyed[i - 1].begin());
        if (next) b->nbr[(size_t)(4 * keyed[i][4] + keyed[i][5])] = keyed[i + 1][4];
        if (prev) b->nbr[(size_t)(4 * keyed[i][4] + keyed[i][5])] = keyed[i - 1][4];
        if (!next && !prev) hull_add(b, keyed[i][4], keyed[i][5]);
      }
    }

    std::vector<btVector3> x((size_t)nv);
    std::vector<btScalar> m((size_t)nv);
    for (int i = 0; i < nv; i++) {
      x[(size_t)i] = btVector3((btScalar)nodes[3 * i], (btScalar)nodes[3 * i + 1], (btScalar)nodes[3 * i + 2]);
      m[(size_t)i] = (btScalar)b->mass[(size_t)i];
    }
    if (fem) {
      b->config = new btSoftBodyRigidBodyCollisionConfiguration();
      b->dispatcher = new btCollisionDispatcher(b->config);
      b->broadphase = new btDbvtBroadphase();
      b->body_solver = new btDeformableBodySolver();
      b->solver = new btDeformableMultiBodyConstraintSolver();
      b->solver->setDeformableSolver(b->body_solver);
      b->world = new btDeformableMultiBodyDynamicsWorld(b->dispatcher, b->broadphase, b->solver, b->config, b->body_solver);
      b->world->setGravity(btVector3(0, 0, 0));
      b->world->getWorldInfo().m_gravity.setValue((btScalar)d->gravity[0], (btScalar)d->gravity[1], (btScalar)d->gravity[2]);
      b->world->getWorldInfo().m_sparsesdf.Initialize();
      b->world->setImplicit(false);
      b->body = new btSoftBody(&b->world->getWorldInfo(), nv, x.data(), m.data());
    } else {
      b->info.m_gravity.setValue((btScalar)d->gravity[0], (btScalar)d->gravity[1], (btScalar)d->gravity[2]);
      b->info.air_density = 0;
      b->info.m_sparsesdf.Initialize();
      b->body = new btSoftBody(&b->info, nv, x.data(), m.data());
    }
    btSoftBody* s = b->body;
    for (int t = 0; t < ne; t++) s->appendTetra(tets[4 * t], tets[4 * t + 1], tets[4 * t + 2], tets[4 * t + 3]);
    s->m_cfg.collisions = 0;  // the plate is ours
    s->m_cfg.kDP = 0;
    s->m_sleepingThreshold = 0;
    if (fem) {
      s->initializeDmInverse();
      // the deformation scratch of each tetrahedron, at rest (the solver
      // fills it every step; filled here so that nothing is read uninitialised)
      btSoftBody::TetraScratch rest;
      rest.m_F.setIdentity();
      rest.m_cofF.setIdentity();
      rest.m_corotation.setIdentity();
      rest.m_trace = 3;
      rest.m_J = 1;
      s->m_tetraScratches.resize(s->m_tetras.size(), rest);
      s->m_tetraScratchesTn.resize(s->m_tetras.size(), rest);
      b->world->addSoftBody(s);
      if (d->model == TX_FEM_COROTATED) {
        b->force = new btDeformableCorotatedForce((btScalar)mu, (btScalar)lambda);
        b->volume_modulus = lambda;
      } else {
        // Smith et al.'s stable Neo-Hookean matches linear elasticity at rest
        // with mu' = 4/3 mu and lambda' = lambda + 5/6 mu
        b->force = new btDeformableNeoHookeanForce((btScalar)(4.0 / 3.0 * mu), (btScalar)(lambda + 5.0 / 6.0 * mu), 0);
        b->volume_modulus = lambda + 5.0 / 6.0 * mu;
      }
      if (!d->nodal_pressure) b->volume_modulus = 0;
      b->node_rest.resize((size_t)nv);
      b->node_now.resize((size_t)nv);
      b->world->addForce(s, b->force);
      // the force reads the nodes by index; the world, which is never stepped (fem_step), would number them so
      for (int i = 0; i < nv; i++) s->m_nodes[i].index = i;
      b->elastic.resize(nv);
      // gravity is applied in tx_fem_step, to the true mass only: mass
      // scaling must not make the organs heavier
      b->world->getWorldInfo().m_gravity.setValue(0, 0, 0);
    } else {
      // a link on every edge of the tetrahedra, once
      std::set<std::pair<int, int>> edges;
      for (int t = 0; t < ne; t++)
        for (int i = 0; i < 4; i++)
          for (int j = i + 1; j < 4; j++) {
            int a = tets[4 * t + i], c = tets[4 * t + j];
            edges.insert(std::make_pair(std::min(a, c), std::max(a, c)));
          }
      s->m_materials[0]->m_kLST = (btScalar)d->link_stiffness;
      for (const auto& e : edges) s->appendLink(e.first, e.second, s->m_materials[0], false);
      // each tetrahedron's edges by id, for removal
      b->edge_nodes.assign(edges.begin(), edges.end());
      b->edge_count.assign(b->edge_nodes.size(), 0);
      b->tet_edge.resize(6 * (size_t)ne);
      for (int t = 0; t < ne; t++) {
        int q = 0;
        for (int i = 0; i < 4; i++)
          for (int j = i + 1; j < 4; j++) {
            int a = tets[4 * t + i], c = tets[4 * t + j];
            std::pair<int, int> key(std::min(a, c), std::max(a, c));
            int id = (int)(std::lower_bound(b->edge_nodes.begin(), b->edge_nodes.end(), key) - b->edge_nodes.begin());
            b->tet_edge[6 * (size_t)t + (size_t)q++] = id;
            b->edge_count[(size_t)id]++;
          }
      }
      s->m_cfg.piterations = d->iterations;
      s->m_cfg.kVC = (btScalar)d->volume_stiffness;
      s->setPose(d->volume_stiffness > 0, false);
      b->dt = d->dt > 0 ? d->dt : 1e-3;
    }
  } catch (const std::bad_alloc&) {
    tx_set_error("soft body: out of memory for %d nodes and %d tetrahedra", nv, ne);
    tx_fem_destroy(b);
    return NULL;
  }
  tx_fem_save(b);
  return b;
}

extern "C" void tx_fem_fix(tx_fem* b, int node) {
  if (node >= 0 && node < b->nv) b->body->setMass(node, 0), b->fixed[(size_t)node] = 1;
}

extern "C" void tx_fem_set_kinematic_over(tx_fem* b, int node, const double p[3], int substeps) {
  if (node < 0 || node >= b->nv || !std::isfinite(p[0] + p[1] + p[2]) || b->node_tets[(size_t)node] == 0) return;
  size_t i = (size_t)node;
  btSoftBody::Node& n = b->body->m_nodes[node];
  if (!b->kinematic[i]) {
    if (!(n.m_im > 0)) return;  // fixed: it stays where tx_fem_fix left it
    b->body->setMass(node, 0);
    b->kinematic[i] = 1, b->kin_count++;
    b->kin_force[i].setZero();
  }
  b->kin_from[i] = n.m_x;
  b->kin_to[i] = btVector3((btScalar)p[0], (btScalar)p[1], (btScalar)p[2]);
  b->kin_span[i] = substeps > 1 ? substeps : 0;
  b->kin_done[i] = 0;
}

extern "C" void tx_fem_set_kinematic(tx_fem* b, int node, const double p[3]) { tx_fem_set_kinematic_over(b, node, p, 0); }

extern "C" void tx_fem_release(tx_fem* b, int node) {
  if (node < 0 || node >= b->nv || !b->kinematic[(size_t)node]) return;
  if (b->node_tets[(size_t)node] > 0) b->body->setMass(node, (btScalar)b->mass[(size_t)node]);
  b->kinematic[(size_t)node] = 0, b->kin_count--;
}

extern "C" bool tx_fem_is_kinematic(const tx_fem* b, int node) {
  return node >= 0 && node < b->nv && b->kinematic[(size_t)node];
}

extern "C" bool tx_fem_kinematic_force(const tx_fem* b, int node, double f[3]) {
  f[0] = f[1] = f[2] = 0;
  if (!b->world || !tx_fem_is_kinematic(b, node) || b->kin_steps == 0) return false;
  const btVector3& s = b->kin_force[(size_t)node];
  for (int a = 0; a < 3; a++) f[a] = (double)s[a] / b->kin_steps;
  return true;
}

// each kinematic node to its place after substep k of steps (k + 1 parts of
// its move; a spread move: its substeps taken so far + 1 of its span); links:
// to its place before the substep, at the move's speed, since Bullet's
// prediction moves every node, massless or not
static void place_kinematic(tx_fem* b, int k, int steps) {
  const btScalar h = (btScalar)b->dt;
  for (int i = 0; i < b->nv && b->kin_count > 0; i++) {
    if (!b->kinematic[(size_t)i]) continue;
    btSoftBody::Node& n = b->body->m_nodes[i];
    const btVector3 move = b->kin_to[(size_t)i] - b->kin_from[(size_t)i];
    int span = steps, part = b->world ? k + 1 : k;
    bool moving = true;
    if (b->kin_span[(size_t)i] > 0) {  // spread: substep `done` of its span, and still at its end after it
      int& done = b->kin_done[(size_t)i];
      span = b->kin_span[(size_t)i];
      moving = done < span;
      part = std::min(b->world ? done + 1 : done, span);
      done++;
    }
    n.m_q = n.m_x;
    n.m_x = b->kin_from[(size_t)i] + move * ((btScalar)part / (btScalar)span);
    n.m_v = moving ? move / ((btScalar)span * h) : btVector3(0, 0, 0);
  }
}

extern "C" void tx_fem_set_plate(tx_fem* b, double y) {
  b->has_plate = true;
  b->plate = y;
  b->ball_r = 0;
}

// one step of the links body: Bullet's own order, without collisions
static void links_step(tx_fem* b) {
  btSoftBody* s = b->body;
  s->predictMotion((btScalar)b->dt);
  s->solveConstraints();
  s->integrateMotion();
}

// The average nodal pressure tetrahedron (Bonet and Burton, Commun. Numer.
// Meth. Engng 14, 1998): linear tetrahedra lock when nearly incompressible,
// as every element's own volume change is penalised. Here each node's
// volume ratio J is taken over all the tetrahedra around it, and each
// tetrahedron's volume term uses the mean of its nodes' J in place of its
// own. Both models' volume terms are lambda (J - c) cof(F), so the change is
// lambda (Jbar - J) cof(F), added to the force Bullet computed.
static void nodal_pressure(tx_fem* b) {
  btSoftBody* s = b->body;
  std::fill(b->node_rest.begin(), b->node_rest.end(), 0.0);
  std::fill(b->node_now.begin(), b->node_now.end(), 0.0);
  btSoftBody::Node* first = &s->m_nodes[0];
  for (int t = 0; t < s->m_tetras.size(); t++) {
    const btSoftBody::Tetra& e = s->m_tetras[t];
    double v = e.m_element_measure / 4, j = s->m_tetraScratches[t].m_J;
    for (int k = 0; k < 4; k++) {
      size_t n = (size_t)(e.m_n[k] - first);
      b->node_rest[n] += v, b->node_now[n] += v * j;
    }
  }
  // each node's J (a node in no live tetrahedron keeps 0: none reads it)
  for (int i = 0; i < b->nv; i++)
    if (b->node_rest[(size_t)i] > 0) b->node_now[(size_t)i] /= b->node_rest[(size_t)i];
  for (int t = 0; t < s->m_tetras.size(); t++) {
    const btSoftBody::Tetra& e = s->m_tetras[t];
    const btSoftBody::TetraScratch& sc = s->m_tetraScratches[t];
    double jbar = 0;
    for (int k = 0; k < 4; k++) jbar += b->node_now[(size_t)(e.m_n[k] - first)] / 4;
    // the change in first Piola stress, lambda (Jbar - J) cof(F), gives node
    // k the force -V (that) Dm^-T grad N_k, which is -(lambda (Jbar - J) / 6)
    // times column k of cof(Ds): the area vector of the face opposite it
    const btVector3 c1 = e.m_n[1]->m_x - e.m_n[0]->m_x, c2 = e.m_n[2]->m_x - e.m_n[0]->m_x,
                    c3 = e.m_n[3]->m_x - e.m_n[0]->m_x;
    const btScalar k = (btScalar)(-b->volume_modulus * (jbar - sc.m_J) / 6);
    const btVector3 f1 = c2.cross(c3) * k, f2 = c3.cross(c1) * k, f3 = c1.cross(c2) * k;
    b->elastic[(int)(e.m_n[1] - first)] += f1;
    b->elastic[(int)(e.m_n[2] - first)] += f2;
    b->elastic[(int)(e.m_n[3] - first)] += f3;
    const btVector3 f0 = -(f1 + f2 + f3);
    b->elastic[(int)(e.m_n[0] - first)] += f0;
  }
}

// One explicit step of the FEM body: Bullet's elastic force (the model's, on
// each tetrahedron's deformation gradient), then symplectic Euler, as the
// deformable world's explicit path does (v += dt f / m, then x += dt v). The
// world itself is not stepped: its step recomputes every tetrahedron's
// rotation (btSoftBody::updateDeformation, an iterative extraction started
// from the identity each time) that neither the Neo-Hookean nor the
// corotated force reads, and refits collision trees that are not used here;
// together over half of the step's time.
static void fem_step(tx_fem* b) {
  btSoftBody* s = b->body;
  for (int t = 0; t < s->m_tetras.size(); t++) {
    btSoftBody::Tetra& e = s->m_tetras[t];
    const btVector3 c1 = e.m_n[1]->m_x - e.m_n[0]->m_x, c2 = e.m_n[2]->m_x - e.m_n[0]->m_x,
                    c3 = e.m_n[3]->m_x - e.m_n[0]->m_x;
    btMatrix3x3 ds(c1.getX(), c2.getX(), c3.getX(), c1.getY(), c2.getY(), c3.getY(), c1.getZ(), c2.getZ(), c3.getZ());
    e.m_F = ds * e.m_Dm_inverse;
    btSoftBody::TetraScratch& sc = s->m_tetraScratches[t];
    sc.m_F = e.m_F;
    sc.m_J = e.m_F.determinant();
    const btMatrix3x3 c = e.m_F.transpose() * e.m_F;
    sc.m_trace = c[0].getX() + c[1].getY() + c[2].getZ();
    sc.m_cofF = e.m_F.adjoint().transpose();
  }
  for (int i = 0; i < b->nv; i++) b->elastic[i].setZero();
  b->force->addScaledExplicitForce(1, b->elastic);
  if (b->volume_modulus > 0) nodal_pressure(b);
  const btScalar dt = (btScalar)b->dt;
  for (int i = 0; i < b->nv; i++) {
    btSoftBody::Node& n = s->m_nodes[i];
    if (!(n.m_im > 0)) continue;
    n.m_v += b->elastic[i] * (n.m_im * dt);
    n.m_q = n.m_x;
    n.m_x += n.m_v * dt;
  }
}

// the point of triangle abc closest to p, as barycentric weights (Ericson,
// Real-Time Collision Detection, 5.1.5)
static void closest_on_triangle(const btVector3& p, const btVector3& a, const btVector3& b, const btVector3& c, double w[3]) {
  btVector3 ab = b - a, ac = c - a, ap = p - a;
  double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) { w[0] = 1, w[1] = w[2] = 0; return; }
  btVector3 bp = p - b;
  double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) { w[1] = 1, w[0] = w[2] = 0; return; }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) { double v = d1 / (d1 - d3); w[0] = 1 - v, w[1] = v, w[2] = 0; return; }
  btVector3 cp = p - c;
  double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) { w[2] = 1, w[0] = w[1] = 0; return; }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) { double v = d2 / (d2 - d6); w[0] = 1 - v, w[2] = v, w[1] = 0; return; }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w[1] = 1 - v, w[2] = v, w[0] = 0;
    return;
  }
  double den = 1 / (va + vb + vc);
  w[1] = vb * den, w[2] = vc * den, w[0] = 1 - w[1] - w[2];
}

// how far a sphere (c, r) reaches past triangle abc along the face's outward
// normal side: r minus the signed distance to its closest point (> 0: overlap);
// n, the unit direction the face must move to leave the sphere. A face the
// centre is behind is pushed back only if the centre was in front of it at
// pc, the last step's: it went through. Otherwise it is a face of the far
// side, or one a removal laid open beside the tool, which the tool has not
// touched from outside (pushed by r + dist in one step, it would turn
// elements inside out).
static double overlap(const btVector3& c, const btVector3& pc, double r, const btVector3& a, const btVector3& b,
                      const btVector3& d, double w[3], btVector3& n) {
  closest_on_triangle(c, a, b, d, w);
  btVector3 q = a * (btScalar)w[0] + b * (btScalar)w[1] + d * (btScalar)w[2];
  btVector3 face = (b - a).cross(d - a);
  double fl = face.length();
  if (!(fl > 0)) return 0;
  face /= (btScalar)fl;
  btVector3 cq = q - c;
  double dist = cq.length();
  double side = (c - q).dot(face);  // > 0: the centre is outside
  if (side > 0 && dist > 1e-12) {
    n = cq / (btScalar)dist;
    return r - dist;
  }
  if (dist >= r) return 0;  // behind and out of reach: a face of the far side
  if (!((pc - q).dot(face) > 0)) return 0;  // behind before too: not met from outside
  n = -face;                // the centre went past the face: push it back behind the centre
  return r + dist;
}

// the tool against the boundary; returns the momentum taken (N s, on the body)
static btVector3 tool_contact(tx_fem* b, int& touched) {
  btAlignedObjectArray<btSoftBody::Node>& nodes = b->body->m_nodes;
  btVector3 c((btScalar)b->tool_c[0], (btScalar)b->tool_c[1], (btScalar)b->tool_c[2]);
  btVector3 pc((btScalar)b->tool_prev[0], (btScalar)b->tool_prev[1], (btScalar)b->tool_prev[2]);
  double r = b->tool_r;
  btVector3 impulse(0, 0, 0);
  touched = 0;
  for (size_t f = 0; f < b->hull.size(); f += 3) {
    btSoftBody::Node* v[3] = {&nodes[b->hull[f]], &nodes[b->hull[f + 1]], &nodes[b->hull[f + 2]]};
    if ((v[0]->m_x - c).length2() > (btScalar)(16 * r * r) + 2 * ((v[1]->m_x - v[0]->m_x).length2() + (v[2]->m_x - v[0]->m_x).length2()))
      continue;  // far: no face edge is long enough to reach the sphere
    double w[3];
    btVector3 n(0, 0, 0);
    double p = overlap(c, pc, r, v[0]->m_x, v[1]->m_x, v[2]->m_x, w, n);
    // a face a removal laid open where the tool already was (the cavity the
    // burn left around the tip) is not thrown out of it in one step, which
    // would turn its tetrahedron inside out: it is met once the tool has left it
    char& fresh = b->fresh[(size_t)b->hull_owner[f / 3]];
    if (fresh && p > 0) continue;
    fresh = 0;
    if (!(p > 0)) continue;
    // at most a tenth of the radius a step: a face met edge-on or far in (a
    // ragged surface after removals) is eased out over a few steps rather
    // than thrown out at once past the elements behind it
    p = std::min(p, 0.1 * r);
    // move the face's closest point by p along n: each free node by w_i p / sum(w^2)
    double ww = 0;
    for (int k = 0; k < 3; k++)
      if (v[k]->m_im > 0) ww += w[k] * w[k];
    if (!(ww > 0)) continue;
    touched++;
    for (int k = 0; k < 3; k++) {
      if (!(v[k]->m_im > 0) || w[k] == 0) continue;
      double move = w[k] * p / ww;
      v[k]->m_x += n * (btScalar)move;
      // the velocity into the tool is stopped; the momentum that takes is the
      // larger of the velocity and the push (as for the plate)
      double vn = -(double)v[k]->m_v.dot(n);
      double took = std::max(vn, move / b->dt);
      if (vn > 0) v[k]->m_v += n * (btScalar)vn;
      impulse += n * (btScalar)(b->mass[(size_t)(v[k] - &nodes[0])] * took);
    }
  }
  return impulse;
}

// a node inside the capsule goes out along its normal, and loses the speed
// it had into it (frictionless, as the ball)
static void keep_out_of_capsule(btSoftBody::Node& n, const double cap[7]) {
  const btVector3 a((btScalar)cap[0], (btScalar)cap[1], (btScalar)cap[2]), e((btScalar)cap[3], (btScalar)cap[4], (btScalar)cap[5]);
  const btVector3 ab = e - a;
  const double l2 = ab.length2();
  double t = l2 > 0 ? (double)(n.m_x - a).dot(ab) / l2 : 0;
  t = std::min(std::max(t, 0.0), 1.0);
  const btVector3 r = n.m_x - (a + ab * (btScalar)t);
  const double len = r.length();
  if (!(len < cap[6] && len > 0)) return;
  const btVector3 nn = r / (btScalar)len;
  n.m_x += nn * (btScalar)(cap[6] - len);
  const double vin = -(double)n.m_v.dot(nn);
  if (vin > 0) n.m_v += nn * (btScalar)vin;
}

extern "C" bool tx_fem_step(tx_fem* b, int steps) {
  btAlignedObjectArray<btSoftBody::Node>& nodes = b->body->m_nodes;
  const double keep = std::exp(-b->def.damping * b->dt);
  const double vmax2 = b->def.max_speed * b->def.max_speed;
  double impulse = 0;  // N s, what the plate took over these steps
  btVector3 tool(0, 0, 0);
  int touched = 0;
  const btVector3 dv((btScalar)(b->def.gravity[0] * b->dt), (btScalar)(b->def.gravity[1] * b->dt),
                    (btScalar)(b->def.gravity[2] * b->dt));
  const bool heavy = b->world && !dv.isZero();
  for (int i = 0; i < b->nv && b->kin_count > 0; i++) b->kin_force[(size_t)i].setZero();
  b->kin_steps = steps;
  for (int k = 0; k < steps; k++) {
    if (heavy)
      for (int i = 0; i < b->nv; i++)
        if (nodes[i].m_im > 0) nodes[i].m_v += dv * (btScalar)b->weight[(size_t)i];
    place_kinematic(b, k, steps);
    if (b->world) {
      fem_step(b);
      for (int i = 0; i < b->nv && b->kin_count > 0; i++)
        if (b->kinematic[(size_t)i]) b->kin_force[(size_t)i] += b->elastic[i];
    } else {
      links_step(b);
    }
    if (b->has_tool) tool += tool_contact(b, touched);
    int on = 0;
    for (int i = 0; i < b->nv; i++) {
      btSoftBody::Node& n = nodes[i];
      if (n.m_im <= 0) continue;
      n.m_v *= (btScalar)keep;
      if (b->has_plate && b->ball_r > 0) {
        // the ball: a node inside goes out along the ball's normal; the ball's
        // upward force is the normal momentum this takes, projected on y
        btVector3 c((btScalar)b->ball_x, (btScalar)b->plate, (btScalar)b->ball_z), r = n.m_x - c;
        double len = r.length();
        if (len < b->ball_r && len > 0) {
          btVector3 nn = r / (btScalar)len;
          double moved = (b->ball_r - len) / b->dt, vin = -(double)n.m_v.dot(nn);
          impulse += b->mass[(size_t)i] * std::max(vin, moved) * -(double)nn.getY();
          n.m_x = c + nn * (btScalar)b->ball_r;
          if (vin > 0) n.m_v += nn * (btScalar)vin;
          on++;
        }
      } else if (b->has_plate && n.m_x.getY() > b->plate) {
        // frictionless: only the normal motion is stopped; the momentum the
        // plate takes is its force times the step
        double moved = (n.m_x.getY() - b->plate) / b->dt;
        double up = std::max((double)n.m_v.getY(), moved);
        impulse += b->mass[(size_t)i] * up;
        n.m_x.setY((btScalar)b->plate);
        if (n.m_v.getY() > 0) n.m_v.setY(0);
        on++;
      }
      for (int c = 0; c < b->ncaps; c++) {
        const double* box = b->cap_box[c];
        const btVector3& x = n.m_x;
        if (x.getX() < box[0] || x.getY() < box[1] || x.getZ() < box[2] || x.getX() > box[3] || x.getY() > box[4] || x.getZ() > box[5])
          continue;
        keep_out_of_capsule(n, b->caps[c]);
      }
      if (!std::isfinite(n.m_x.getX() + n.m_x.getY() + n.m_x.getZ() + n.m_v.getX() + n.m_v.getY() + n.m_v.getZ()))
        return false;
      if (vmax2 > 0 && n.m_v.length2() > vmax2) return false;
    }
    b->contacts = on;
  }
  for (int i = 0; i < b->nv && b->kin_count > 0; i++)  // held there until moved again
    if (b->kinematic[(size_t)i] && (b->kin_span[(size_t)i] == 0 || b->kin_done[(size_t)i] >= b->kin_span[(size_t)i]))
      b->kin_from[(size_t)i] = b->kin_to[(size_t)i], b->kin_span[(size_t)i] = 0;
  b->plate_force = steps > 0 ? impulse / (steps * b->dt) : 0;
  // the body's force on the tool is minus the momentum the tool gave it
  double span = steps > 0 ? steps * b->dt : 1;
  for (int a = 0; a < 3; a++) b->tool.f[a] = -(double)tool[a] / span;
  b->tool.faces = touched;
  b->tool.depth = 0;
  if (touched == 0) {
    for (int i = 0; i < b->nv; i++) b->before[(size_t)i] = nodes[i].m_x;
  } else {
    // the indentation: how far the sphere reaches past the boundary as it
    // lay before the tool touched it
    // lay before the tool touched it: r minus the centre's signed distance to
    // that boundary (the nearest face's side gives the sign)
    btVector3 c((btScalar)b->tool_c[0], (btScalar)b->tool_c[1], (btScalar)b->tool_c[2]);
    double nearest = INFINITY, signed_dist = 0;
    for (size_t f = 0; f < b->hull.size(); f += 3) {
      const btVector3 &a = b->before[(size_t)b->hull[f]], &e = b->before[(size_t)b->hull[f + 1]],
                      &g = b->before[(size_t)b->hull[f + 2]];
      double w[3];
      closest_on_triangle(c, a, e, g, w);
      btVector3 q = a * (btScalar)w[0] + e * (btScalar)w[1] + g * (btScalar)w[2];
      double d = (c - q).length();
      if (d < nearest) nearest = d, signed_dist = (c - q).dot((e - a).cross(g - a)) >= 0 ? d : -d;
    }
    b->tool.depth = std::max(0.0, b->tool_r - signed_dist);
  }
  return true;
}

extern "C" void tx_fem_set_tool(tx_fem* b, const double c[3], double r) {
  bool had = b->has_tool;
  b->has_tool = r > 0 && std::isfinite(c[0] + c[1] + c[2] + r);
  if (!b->has_tool) return;
  for (int a = 0; a < 3; a++) b->tool_prev[a] = had ? b->tool_c[a] : c[a];
  for (int a = 0; a < 3; a++) b->tool_c[a] = c[a];
  b->tool_r = r;
}

extern "C" void tx_fem_tool(const tx_fem* b, tx_fem_tool_info* out) { *out = b->tool; }

extern "C" void tx_fem_save(tx_fem* b) {
  for (int i = 0; i < b->nv; i++) b->saved_x[(size_t)i] = b->body->m_nodes[i].m_x, b->saved_v[(size_t)i] = b->body->m_nodes[i].m_v;
}

extern "C" void tx_fem_restore(tx_fem* b) {
  for (int i = 0; i < b->nv; i++) {
    btSoftBody::Node& n = b->body->m_nodes[i];
    n.m_x = n.m_q = b->saved_x[(size_t)i];
    n.m_v = n.m_vn = b->saved_v[(size_t)i];
  }
  b->tool = tx_fem_tool_info();
}

extern "C" int tx_fem_node_count(const tx_fem* b) { return b->nv; }
extern "C" double tx_fem_added_mass(const tx_fem* b) { return b->added_mass; }

extern "C" double tx_fem_dt(const tx_fem* b) { return b->dt; }
extern "C" void tx_fem_set_ball(tx_fem* b, const double c[3], double r) {
  b->has_plate = r > 0;
  b->ball_x = c[0], b->plate = c[1], b->ball_z = c[2], b->ball_r = r;
}

extern "C" bool tx_fem_set_capsules(tx_fem* b, const double* caps, int n) {
  if (n < 0 || n > TX_FEM_CAPSULES_MAX) return false;
  for (int c = 0; c < 7 * n; c++)
    if (!std::isfinite(caps[c])) return false;
  for (int c = 0; c < n; c++)
    if (!(caps[7 * c + 6] > 0)) return false;
  b->ncaps = n;
  for (int c = 0; c < n; c++) {
    for (int k = 0; k < 7; k++) b->caps[c][k] = caps[7 * c + k];
    for (int a = 0; a < 3; a++) {
      b->cap_box[c][a] = std::min(caps[7 * c + a], caps[7 * c + 3 + a]) - caps[7 * c + 6];
      b->cap_box[c][3 + a] = std::max(caps[7 * c + a], caps[7 * c + 3 + a]) + caps[7 * c + 6];
    }
  }
  return true;
}

extern "C" double tx_fem_plate_force(const tx_fem* b) { return b->plate_force; }
extern "C" int tx_fem_plate_contacts(const tx_fem* b) { return b->contacts; }

extern "C" double tx_fem_kinetic(const tx_fem* b) {
  double e = 0;
  for (int i = 0; i < b->nv; i++) e += 0.5 * b->mass[(size_t)i] * b->body->m_nodes[i].m_v.length2();
  return e;
}

extern "C" void tx_fem_positions(const tx_fem* b, double* out) {
  for (int i = 0; i < b->nv; i++) {
    const btVector3& x = b->body->m_nodes[i].m_x;
    out[3 * i] = x.getX(), out[3 * i + 1] = x.getY(), out[3 * i + 2] = x.getZ();
  }
}

// --- removal -------------------------------------------------------------------

extern "C" bool tx_fem_remove_tet(tx_fem* b, int t) {
  if (t < 0 || t >= b->ne || !b->tet_live[(size_t)t] || b->live_ne <= 1) return false;
  btSoftBody* s = b->body;
  // its force goes: the body's last tetrahedron takes its row (the force
  // reads m_tetras and m_tetraScratches by the same row)
  int at = b->slot[(size_t)t], last = s->m_tetras.size() - 1;
  if (at != last) {
    s->m_tetras.swap(at, last);
    if (s->m_tetraScratches.size() > last) s->m_tetraScratches.swap(at, last);
    if (s->m_tetraScratchesTn.size() > last) s->m_tetraScratchesTn.swap(at, last);
    int moved = b->slot_tet[(size_t)last];
    b->slot[(size_t)moved] = at, b->slot_tet[(size_t)at] = moved;
  }
  s->m_tetras.pop_back();
  if (s->m_tetraScratches.size() > last) s->m_tetraScratches.pop_back();
  if (s->m_tetraScratchesTn.size() > last) s->m_tetraScratchesTn.pop_back();
  b->slot[(size_t)t] = -1;
  b->tet_live[(size_t)t] = 0, b->live_ne--;
  // the boundary: its boundary faces go, the faces it shared come out
  for (int k = 0; k < 4; k++) {
    if (b->hull_at[4 * (size_t)t + (size_t)k] >= 0) hull_drop(b, t, k);
    int n = b->nbr[4 * (size_t)t + (size_t)k];
    if (n < 0 || !b->tet_live[(size_t)n]) continue;
    for (int q = 0; q < 4; q++)
      if (b->nbr[4 * (size_t)n + (size_t)q] == t) hull_add(b, n, q), b->fresh[4 * (size_t)n + (size_t)q] = 1;
  }
  // links: the edges no live tetrahedron has
  if (!b->world)
    for (int q = 0; q < 6; q++) {
      int id = b->tet_edge[6 * (size_t)t + (size_t)q];
      if (--b->edge_count[(size_t)id] > 0) continue;
      const btSoftBody::Node *p0 = &s->m_nodes[b->edge_nodes[(size_t)id].first], *p1 = &s->m_nodes[b->edge_nodes[(size_t)id].second];
      for (int l = 0; l < s->m_links.size(); l++) {
        const btSoftBody::Link& k = s->m_links[l];
        if ((k.m_n[0] == p0 && k.m_n[1] == p1) || (k.m_n[0] == p1 && k.m_n[1] == p0)) {
          s->m_links.swap(l, s->m_links.size() - 1);
          s->m_links.pop_back();
          break;
        }
      }
    }
  // its mass leaves its nodes; a node in no live tetrahedron leaves the solve
  for (int k = 0; k < 4; k++) {
    size_t i = (size_t)b->tets[4 * (size_t)t + (size_t)k];
    btSoftBody::Node& n = s->m_nodes[(int)i];
    if (--b->node_tets[i] == 0) {
      if (b->kinematic[i]) b->kinematic[i] = 0, b->kin_count--;
      b->mass[i] = b->true_mass[i] = 0, b->weight[i] = 0;
      s->setMass((int)i, 0);
      n.m_v.setZero(), n.m_vn.setZero();
      continue;
    }
    b->mass[i] = std::max(b->mass[i] - b->tet_mass[(size_t)t] / 4, 0.0);
    b->true_mass[i] = std::max(b->true_mass[i] - b->tet_true[(size_t)t] / 4, 0.0);
    b->weight[i] = b->mass[i] > 0 ? b->true_mass[i] / b->mass[i] : 0;
    if (!b->fixed[i] && !b->kinematic[i]) s->setMass((int)i, (btScalar)b->mass[i]);
  }
  return true;
}

extern "C" bool tx_fem_tet_live(const tx_fem* b, int t) { return t >= 0 && t < b->ne && b->tet_live[(size_t)t]; }
extern "C" int tx_fem_tet_count(const tx_fem* b) { return b->ne; }
extern "C" int tx_fem_live_tet_count(const tx_fem* b) { return b->live_ne; }
extern "C" const int* tx_fem_tets(const tx_fem* b) { return b->tets.data(); }
extern "C" bool tx_fem_node_live(const tx_fem* b, int node) {
  return node >= 0 && node < b->nv && b->node_tets[(size_t)node] > 0;
}

extern "C" bool tx_fem_hull_is_live_boundary(const tx_fem* b) {
  // every live tetrahedron's faces, as sorted triples; those seen once are the boundary
  std::vector<std::array<int, 3>> all, once, kept;
  for (int t = 0; t < b->ne; t++) {
    if (!b->tet_live[(size_t)t]) continue;
    const int* e = &b->tets[4 * (size_t)t];
    for (int k = 0; k < 4; k++) {
      std::array<int, 3> f = {e[(k + 1) % 4], e[(k + 2) % 4], e[(k + 3) % 4]};
      std::sort(f.begin(), f.end());
      all.push_back(f);
    }
  }
  std::sort(all.begin(), all.end());
  for (size_t i = 0; i < all.size();) {
    size_t j = i + 1;
    while (j < all.size() && all[j] == all[i]) j++;
    if (j - i == 1) once.push_back(all[i]);
    i = j;
  }
  int nf;
  const int* hull = tx_fem_hull(b, &nf);
  for (int i = 0; i < nf; i++) {
    std::array<int, 3> f = {hull[3 * i], hull[3 * i + 1], hull[3 * i + 2]};
    std::sort(f.begin(), f.end());
    kept.push_back(f);
  }
  std::sort(kept.begin(), kept.end());
  return kept == once;
}

extern "C" double tx_fem_tet_volume(const tx_fem* b, int t) {
  if (!tx_fem_tet_live(b, t)) return 0;
  const int* e = &b->tets[4 * (size_t)t];
  double p[4][3];
  for (int k = 0; k < 4; k++) {
    const btVector3& x = b->body->m_nodes[e[k]].m_x;
    p[k][0] = x.getX(), p[k][1] = x.getY(), p[k][2] = x.getZ();
  }
  return tet_volume(p[0], p[1], p[2], p[3]);
}

extern "C" const int* tx_fem_hull(const tx_fem* b, int* faces) {
  *faces = (int)b->hull_owner.size();
  return b->hull.data();
}
