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
  btSoftBodyWorldInfo info;  // the links body's world
  btSoftBody* body;
  std::vector<double> mass;  // (nv) kg, lumped
  bool has_plate;
  double plate;              // m, the plate's underside
  double plate_force;        // N, upward, averaged over the last tx_fem_step
  int contacts;              // nodes on the plate after the last step
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
  return d;
}

static double tet_volume(const double* a, const double* b, const double* c, const double* d) {
  double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
         ad[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (ab[0] * (ac[1] * ad[2] - ac[2] * ad[1]) + ab[1] * (ac[2] * ad[0] - ac[0] * ad[2]) +
          ab[2] * (ac[0] * ad[1] - ac[1] * ad[0])) /
         6.0;
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
      !(d->link_stiffness > 0 && d->link_stiffness <= 1) || !(d->volume_stiffness >= 0)) {
    tx_set_error("soft body: density > 0, damping >= 0, dt >= 0, iterations >= 1, 0 < kLST <= 1 and kVC >= 0 needed");
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
    for (int t = 0; t < ne; t++) {
      double rho = d->density;
      if (d->mass_scaling) rho = std::max(rho, modulus * std::pow(b->dt / (0.3 * alt[(size_t)t]), 2));
      for (int k = 0; k < 4; k++) b->mass[(size_t)tets[4 * t + k]] += rho * vol[(size_t)t] / 4;
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
      b->world->getWorldInfo().m_gravity.setValue(0, 0, 0);
      b->world->getWorldInfo().m_sparsesdf.Initialize();
      b->world->setImplicit(false);
      b->body = new btSoftBody(&b->world->getWorldInfo(), nv, x.data(), m.data());
    } else {
      b->info.m_gravity.setValue(0, 0, 0);
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
      } else {
        // Smith et al.'s stable Neo-Hookean matches linear elasticity at rest
        // with mu' = 4/3 mu and lambda' = lambda + 5/6 mu
        b->force = new btDeformableNeoHookeanForce((btScalar)(4.0 / 3.0 * mu), (btScalar)(lambda + 5.0 / 6.0 * mu), 0);
      }
      b->world->addForce(s, b->force);
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
  return b;
}

extern "C" void tx_fem_fix(tx_fem* b, int node) {
  if (node >= 0 && node < b->nv) b->body->setMass(node, 0);
}

extern "C" void tx_fem_set_plate(tx_fem* b, double y) {
  b->has_plate = true;
  b->plate = y;
}

// one step of the links body: Bullet's own order, without collisions
static void links_step(tx_fem* b) {
  btSoftBody* s = b->body;
  s->predictMotion((btScalar)b->dt);
  s->solveConstraints();
  s->integrateMotion();
}

extern "C" bool tx_fem_step(tx_fem* b, int steps) {
  btAlignedObjectArray<btSoftBody::Node>& nodes = b->body->m_nodes;
  const double keep = std::exp(-b->def.damping * b->dt);
  double impulse = 0;  // N s, what the plate took over these steps
  for (int k = 0; k < steps; k++) {
    if (b->world) b->world->stepSimulation((btScalar)b->dt, 0);
    else links_step(b);
    int on = 0;
    for (int i = 0; i < b->nv; i++) {
      btSoftBody::Node& n = nodes[i];
      if (n.m_im <= 0) continue;
      n.m_v *= (btScalar)keep;
      if (b->has_plate && n.m_x.getY() > b->plate) {
        // frictionless: only the normal motion is stopped; the momentum the
        // plate takes is its force times the step
        double moved = (n.m_x.getY() - b->plate) / b->dt;
        double up = std::max((double)n.m_v.getY(), moved);
        impulse += b->mass[(size_t)i] * up;
        n.m_x.setY((btScalar)b->plate);
        if (n.m_v.getY() > 0) n.m_v.setY(0);
        on++;
      }
      if (!std::isfinite(n.m_x.getX() + n.m_x.getY() + n.m_x.getZ() + n.m_v.getX() + n.m_v.getY() + n.m_v.getZ()))
        return false;
    }
    b->contacts = on;
  }
  b->plate_force = steps > 0 ? impulse / (steps * b->dt) : 0;
  return true;
}

extern "C" double tx_fem_dt(const tx_fem* b) { return b->dt; }
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
