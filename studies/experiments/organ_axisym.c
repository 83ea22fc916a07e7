// The hemisphere's continuum reference, axisymmetric (see organ_axisym.h).
#include "organ_axisym.h"

#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct tx_axisym {
  double radius;
  int n, m, nodes, dofs, kd;  // elements and nodes per side, nodes, dofs, half bandwidth
  double* r;                  // node positions (nodes)
  double* z;
  double* l;                  // the stiffness's Cholesky factor (band)
  int nc;                     // candidate contact nodes: the top surface's i = 0 .. nc-1
  double* w;                  // their compliance to vertical forces (nc x nc), m/N
  double* q;                  // work: gaps at rest, pressures, residual gaps
  double* p;
  double* g;
  double* chol;  // work: the active block's factor
  int* act;      // active (in contact) flags
  int* idx;
  int in_contact;
  double* u;  // the displacement of the last indent (dofs)
};

bool tx_band_cholesky(double* a, int n, int kd) {
  int w = kd + 1;
  for (int i = 0; i < n; i++) {
    int j0 = i - kd > 0 ? i - kd : 0;
    for (int j = j0; j <= i; j++) {
      int k0 = j - kd > j0 ? j - kd : j0;
      const double* li = a + (size_t)i * w + kd - i;  // li[k] = L(i, k)
      const double* lj = a + (size_t)j * w + kd - j;
      double s = li[j];
      for (int k = k0; k < j; k++) s -= li[k] * lj[k];
      if (j < i) {
        a[(size_t)i * w + kd - i + j] = s / lj[j];
      } else {
        if (!(s > 0)) return false;
        a[(size_t)i * w + kd] = sqrt(s);
      }
    }
  }
  return true;
}

void tx_band_solve(const double* l, int n, int kd, double* b) {
  int w = kd + 1;
  for (int i = 0; i < n; i++) {
    const double* li = l + (size_t)i * w + kd - i;
    int k0 = i - kd > 0 ? i - kd : 0;
    double s = b[i];
    for (int k = k0; k < i; k++) s -= li[k] * b[k];
    b[i] = s / li[i];
  }
  for (int i = n - 1; i >= 0; i--) {
    const double* li = l + (size_t)i * w + kd - i;
    int k0 = i - kd > 0 ? i - kd : 0;
    b[i] /= li[i];
    for (int k = k0; k < i; k++) b[k] -= li[k] * b[i];
  }
}

void tx_axisym_destroy(tx_axisym* a) {
  if (!a) return;
  free(a->r), free(a->z), free(a->l), free(a->w), free(a->q), free(a->p), free(a->g), free(a->chol), free(a->act),
      free(a->idx), free(a->u);
  free(a);
}

// 1-D quadratic shape functions on [-1, 1] at nodes -1, 0, 1, and derivatives
static void shape1(double x, double n[3], double d[3]) {
  n[0] = x * (x - 1) / 2, n[1] = 1 - x * x, n[2] = x * (x + 1) / 2;
  d[0] = x - 0.5, d[1] = -2 * x, d[2] = x + 0.5;
}

// the element (ei, ej)'s 18 x 18 stiffness, weighted by 2 pi r (whole rings);
// false where the map folds
static bool element(const tx_axisym* a, int ei, int ej, double lambda, double mu, double ke[18][18]) {
  static const double gx[3] = {-0.774596669241483377, 0, 0.774596669241483377};
  static const double gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  int ids[9];
  for (int b = 0; b < 3; b++)
    for (int c = 0; c < 3; c++) ids[3 * b + c] = (2 * ej + b) * a->m + 2 * ei + c;
  memset(ke, 0, sizeof(double) * 18 * 18);
  for (int qa = 0; qa < 3; qa++)
    for (int qb = 0; qb < 3; qb++) {
      double nx[3], dx[3], ny[3], dy[3];
      shape1(gx[qa], nx, dx);
      shape1(gx[qb], ny, dy);
      double nn[9], dxi[9], deta[9], rr = 0, j00 = 0, j01 = 0, j10 = 0, j11 = 0;
      for (int b = 0; b < 3; b++)
        for (int c = 0; c < 3; c++) {
          int k = 3 * b + c;
          nn[k] = nx[c] * ny[b], dxi[k] = dx[c] * ny[b], deta[k] = nx[c] * dy[b];
          double r = a->r[ids[k]], z = a->z[ids[k]];
          rr += nn[k] * r;
          j00 += dxi[k] * r, j01 += deta[k] * r, j10 += dxi[k] * z, j11 += deta[k] * z;
        }
      double det = j00 * j11 - j01 * j10;
      if (!(det > 0) || !(rr > 0)) return false;
      double bm[4][18] = {{0}};
      for (int k = 0; k < 9; k++) {
        double dr = (j11 * dxi[k] - j10 * deta[k]) / det, dz = (-j01 * dxi[k] + j00 * deta[k]) / det;
        bm[0][2 * k] = dr;  // e_rr
        bm[1][2 * k + 1] = dz;  // e_zz
        bm[2][2 * k] = nn[k] / rr;  // e_tt (hoop)
        bm[3][2 * k] = dz, bm[3][2 * k + 1] = dr;  // g_rz
      }
      double wgt = gw[qa] * gw[qb] * det * 2 * M_PI * rr;
      double db[4][18];
      for (int c = 0; c < 18; c++) {
        double e0 = bm[0][c], e1 = bm[1][c], e2 = bm[2][c];
        db[0][c] = (lambda + 2 * mu) * e0 + lambda * (e1 + e2);
        db[1][c] = (lambda + 2 * mu) * e1 + lambda * (e0 + e2);
        db[2][c] = (lambda + 2 * mu) * e2 + lambda * (e0 + e1);
        db[3][c] = mu * bm[3][c];
      }
      for (int u = 0; u < 18; u++)
        for (int v = 0; v < 18; v++)
          ke[u][v] += wgt * (bm[0][u] * db[0][v] + bm[1][u] * db[1][v] + bm[2][u] * db[2][v] + bm[3][u] * db[3][v]);
    }
  return true;
}

tx_axisym* tx_axisym_create(double radius, double young, double nu, int n, double grade) {
  if (!(radius > 0 && radius < 10) || !(young > 0) || !(nu >= 0 && nu < 0.5) || n < 2 || n > 128 ||
      !(grade >= 1 && grade <= 3)) {
    tx_set_error("axisymmetric hemisphere: R %g m, E %g Pa, nu %g, %d elements, grading %g: need 0 < R < 10 m, E > 0, "
                 "0 <= nu < 0.5, 2 to 128 elements, grading 1 to 3",
                 radius, young, nu, n, grade);
    return NULL;
  }
  tx_axisym* a = calloc(1, sizeof *a);
  if (!a) goto oom;
  a->radius = radius, a->n = n, a->m = 2 * n + 1;
  a->nodes = a->m * a->m, a->dofs = 2 * a->nodes;
  a->kd = 2 * (2 * a->m + 2) + 1;  // a 9-node element spans node indices j m + i .. (j + 2) m + i + 2
  a->r = malloc(sizeof(double) * a->nodes);
  a->z = malloc(sizeof(double) * a->nodes);
  a->l = calloc((size_t)a->dofs * (a->kd + 1), sizeof(double));
  if (!a->r || !a->z || !a->l) goto oom;
  for (int j = 0; j < a->m; j++)
    for (int i = 0; i < a->m; i++) {
      double s = pow((double)i / (a->m - 1), grade), t = 1 - pow(1 - (double)j / (a->m - 1), grade);
      a->r[j * a->m + i] = radius * s * sqrt(fmax(0, 1 - t * t / 2));
      a->z[j * a->m + i] = radius * t * sqrt(fmax(0, 1 - s * s / 2));
    }
  // assemble; base nodes (j = 0) and the axis's radial dofs (i = 0) are held
  double lambda = young * nu / ((1 + nu) * (1 - 2 * nu)), mu = young / (2 * (1 + nu));
  int w = a->kd + 1;
  double(*ke)[18] = malloc(sizeof(double[18][18]));
  if (!ke) goto oom;
  for (int ej = 0; ej < n; ej++)
    for (int ei = 0; ei < n; ei++) {
      if (!element(a, ei, ej, lambda, mu, ke)) {
        free(ke), tx_axisym_destroy(a);
        tx_set_error("axisymmetric hemisphere: element (%d, %d) of %d x %d is folded", ei, ej, n, n);
        return NULL;
      }
      int dof[18];
      for (int b = 0; b < 3; b++)
        for (int c = 0; c < 3; c++) {
          int node = (2 * ej + b) * a->m + 2 * ei + c, k = 3 * b + c;
          dof[2 * k] = (2 * ej + b == 0 || 2 * ei + c == 0) ? -1 : 2 * node;
          dof[2 * k + 1] = 2 * ej + b == 0 ? -1 : 2 * node + 1;
        }
      for (int u = 0; u < 18; u++)
        for (int v = 0; v < 18; v++)
          if (dof[u] >= 0 && dof[v] >= 0 && dof[v] <= dof[u])
            a->l[(size_t)dof[u] * w + a->kd - dof[u] + dof[v]] += ke[u][v];
    }
  free(ke);
  for (int node = 0; node < a->nodes; node++) {
    bool base = node < a->m, axis = node % a->m == 0;
    if (base || axis) a->l[(size_t)(2 * node) * w + a->kd] = 1;
    if (base) a->l[(size_t)(2 * node + 1) * w + a->kd] = 1;
  }
  if (!tx_band_cholesky(a->l, a->dofs, a->kd)) {
    tx_axisym_destroy(a);
    tx_set_error("axisymmetric hemisphere: the stiffness is not positive definite (%d elements)", n);
    return NULL;
  }
  // the top surface (j = m - 1) out to 0.6 R, and its compliance: one solve per node
  int top = (a->m - 1) * a->m;
  while (a->nc < a->m && a->r[top + a->nc] <= 0.6 * radius) a->nc++;
  int nc = a->nc;
  a->w = malloc(sizeof(double) * nc * nc);
  a->q = malloc(sizeof(double) * nc);
  a->p = calloc(nc, sizeof(double));
  a->g = malloc(sizeof(double) * nc);
  a->chol = malloc(sizeof(double) * nc * nc);
  a->act = calloc(nc, sizeof(int));
  a->idx = malloc(sizeof(int) * nc);
  a->u = calloc(a->dofs, sizeof(double));
  double* x = malloc(sizeof(double) * a->dofs);
  if (!a->w || !a->q || !a->p || !a->g || !a->chol || !a->act || !a->idx || !a->u || !x) {
    free(x);
    goto oom;
  }
  for (int k = 0; k < nc; k++) {
    memset(x, 0, sizeof(double) * a->dofs);
    x[2 * (top + k) + 1] = 1;
    tx_band_solve(a->l, a->dofs, a->kd, x);
    for (int c = 0; c < nc; c++) a->w[c * nc + k] = x[2 * (top + c) + 1];
  }
  free(x);
  return a;
oom:
  tx_axisym_destroy(a);
  tx_set_error("axisymmetric hemisphere: out of memory for %d elements per side", n);
  return NULL;
}

int tx_axisym_dofs(const tx_axisym* a) { return a->dofs; }
int tx_axisym_contact_nodes(const tx_axisym* a) { return a->in_contact; }

// dense Cholesky of the active block of W and the solve for its pressures
static bool active_solve(tx_axisym* a) {
  int nc = a->nc, na = 0;
  for (int k = 0; k < nc; k++)
    if (a->act[k]) a->idx[na++] = k;
  double* c = a->chol;
  for (int i = 0; i < na; i++)
    for (int j = 0; j <= i; j++) {
      double s = a->w[a->idx[i] * nc + a->idx[j]];
      for (int k = 0; k < j; k++) s -= c[i * na + k] * c[j * na + k];
      if (j < i) c[i * na + j] = s / c[j * na + j];
      else if (s > 0) c[i * na + i] = sqrt(s);
      else return false;
    }
  // W_AA p_A = -q_A (the active nodes' gaps closed)
  for (int k = 0; k < nc; k++) a->p[k] = 0;
  double* y = a->g;
  for (int i = 0; i < na; i++) {
    double s = -a->q[a->idx[i]];
    for (int k = 0; k < i; k++) s -= c[i * na + k] * y[k];
    y[i] = s / c[i * na + i];
  }
  for (int i = na - 1; i >= 0; i--) {
    double s = y[i];
    for (int k = i + 1; k < na; k++) s -= c[k * na + i] * a->p[a->idx[k]];
    a->p[a->idx[i]] = s / c[i * na + i];
  }
  return true;
}

bool tx_axisym_indent(tx_axisym* a, double depth, double indenter, double* force) {
  int nc = a->nc, top = (a->m - 1) * a->m;
  if (!(indenter >= 0)) {
    tx_set_error("axisymmetric hemisphere: indenter radius %g m: need >= 0 (0: a flat)", indenter);
    return false;
  }
  // gap at rest to the indenter's underside, at z = R - d on the axis (a
  // flat, or the sphere's lower cap, which rises as r^2 / 2 Ri near the axis);
  // a pressure p (downward force) moves the surface by -W p, so the gap is q + W p
  for (int k = 0; k < nc; k++) {
    double r = a->r[top + k], under = a->radius - depth;
    if (indenter > 0) under += r < indenter ? indenter - sqrt(indenter * indenter - r * r) : a->radius;
    a->q[k] = under - a->z[top + k];
  }
  double tol = 1e-12 * a->radius;
  for (int it = 0; it < 20 * nc + 20; it++) {
    if (!active_solve(a)) break;
    double pmax = 0;
    for (int k = 0; k < nc; k++) pmax = fmax(pmax, a->p[k]);
    int flip = -1;
    for (int k = 0; k < nc && flip < 0; k++) {
      double gap = a->q[k];
      for (int c = 0; c < nc; c++) gap += a->w[k * nc + c] * a->p[c];
      a->g[k] = gap;
      if (a->act[k] ? a->p[k] < -1e-12 * pmax : gap < -tol) flip = k;
    }
    if (flip < 0) {
      double f = 0;
      a->in_contact = 0;
      for (int k = 0; k < nc; k++) f += a->p[k], a->in_contact += a->act[k];
      if (a->act[nc - 1]) {
        tx_set_error("axisymmetric hemisphere: the contact at d = %g m reaches past 0.6 R", depth);
        return false;
      }
      *force = f;
      // the whole field: the pressures as downward forces, one solve
      memset(a->u, 0, sizeof(double) * a->dofs);
      for (int k = 0; k < nc; k++) a->u[2 * (top + k) + 1] = -a->p[k];
      tx_band_solve(a->l, a->dofs, a->kd, a->u);
      return true;
    }
    a->act[flip] = !a->act[flip];
  }
  tx_set_error("axisymmetric hemisphere: the contact at d = %g m did not settle", depth);
  return false;
}

// the outer surface's node s from the pole: the top edge (j = m - 1) outward,
// then the side edge (i = m - 1) down to the base
static int surface_node(const tx_axisym* a, int s) {
  return s < a->m ? (a->m - 1) * a->m + s : (2 * a->m - 2 - s) * a->m + a->m - 1;
}

double tx_axisym_surface_uz(const tx_axisym* a, double phi) {
  int ns = 2 * a->m - 1;
  double prev = 0;
  for (int s = 1; s < ns; s++) {
    int n0 = surface_node(a, s - 1), n1 = surface_node(a, s);
    double here = atan2(a->r[n1], a->z[n1]);
    if (here >= phi || s == ns - 1) {
      double t = fmin(1, fmax(0, (phi - prev) / (here - prev)));
      return a->u[2 * n0 + 1] + (a->u[2 * n1 + 1] - a->u[2 * n0 + 1]) * t;
    }
    prev = here;
  }
  return NAN;
}
