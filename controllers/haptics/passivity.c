// Passivity observer and controller for one impedance-type device port, and
// the force path of a haptic tick.
#include "passivity.h"

#include <math.h>
#include <string.h>

void tx_passivity_observe(tx_passivity* p, const double sent[3], const double vel[3], double dt) {
  double power = sent[0] * vel[0] + sent[1] * vel[1] + sent[2] * vel[2]; // into the hand
  double energy = p->energy - power * dt;
  if (!isfinite(energy)) return;
  p->energy = energy;
  if (energy < p->min_energy) p->min_energy = energy;
}

static double damping_for(double energy, const double vel[3], double dt, double max_force) {
  double v2 = vel[0] * vel[0] + vel[1] * vel[1] + vel[2] * vel[2];
  if (!(energy < 0 && v2 > 1e-12 && dt > 0 && isfinite(v2))) return 0;
  return fmin(-energy / (v2 * dt), max_force / sqrt(v2));
}

double tx_passivity_damping(tx_passivity* p, const double vel[3], double dt, double max_force) {
  double a = damping_for(p->energy, vel, dt, max_force);
  if (a > 0) p->activations++;
  return a;
}

// eigen-decomposition of a symmetric 3x3 by cyclic Jacobi rotations: a
// fixed, small amount of work, no allocation
static void sym3_eigen(double a[3][3], double vec[3][3]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) vec[i][j] = i == j;
  for (int sweep = 0; sweep < 12; sweep++) {
    double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
    if (off == 0) return;
    for (int p = 0; p < 2; p++)
      for (int q = p + 1; q < 3; q++) {
        if (a[p][q] == 0) continue;
        double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
        double c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; k++) { // a <- a J
          double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq, a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; k++) { // a <- J^T a
          double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk, a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; k++) {
          double vkp = vec[k][p], vkq = vec[k][q];
          vec[k][p] = c * vkp - s * vkq, vec[k][q] = s * vkp + c * vkq;
        }
      }
  }
}

double tx_spring_energy(const double k[9], const double f[3]) {
  double s[3][3], vec[3][3], top = 0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) s[i][j] = -(k[3 * i + j] + k[3 * j + i]) / 2;
  for (int i = 0; i < 9; i++)
    if (!isfinite(k[i])) return 0;
  if (!(isfinite(f[0]) && isfinite(f[1]) && isfinite(f[2]))) return 0;
  sym3_eigen(s, vec);
  for (int i = 0; i < 3; i++) top = fmax(top, s[i][i]);
  double u = 0;
  for (int i = 0; i < 3; i++) {
    // a direction far softer than the stiffest is no spring: its pseudo-inverse is 0
    if (!(s[i][i] > 1e-9 * top)) continue;
    double along = vec[0][i] * f[0] + vec[1][i] * f[1] + vec[2][i] * f[2];
    u += along * along / s[i][i];
  }
  return u / 2;
}

void tx_haptic_path_init(tx_haptic_path* p, const tx_safety_limits* limits, bool control, tx_passivity_ref reference,
                         double device_damping) {
  *p = (tx_haptic_path){.control = control, .reference = reference, .limits = *limits,
                        .device_damping = isfinite(device_damping) && device_damping > 0 ? device_damping : 0};
  tx_safety_init(&p->safety);
}

void tx_haptic_tick(tx_haptic_path* p, double dt, const tx_haptic_input* in, const double pos[3], const double vel[3],
                    double out[3]) {
  tx_passivity* o = &p->passivity;
  tx_passivity_observe(o, p->held, vel, dt);
  // what the spring holds now is not energy the loop made, and what the
  // device's own damping took the port never saw
  if (p->reference == TX_PASSIVITY_REF_SPRING) {
    if (isfinite(in->stored)) p->stored = in->stored;
    double v2 = vel[0] * vel[0] + vel[1] * vel[1] + vel[2] * vel[2];
    if (isfinite(v2)) p->absorbed += p->device_damping * v2 * dt; // unseen at the port
  }
  p->reference_energy = o->energy - (p->reference == TX_PASSIVITY_REF_SPRING ? p->stored - p->absorbed : 0);
  if (p->reference_energy < p->reference_min) p->reference_min = p->reference_energy;
  double v_dot = p->damped_vel[0] * vel[0] + p->damped_vel[1] * vel[1] + p->damped_vel[2] * vel[2];
  if (isfinite(v_dot)) o->dissipated += p->damping * v_dot * dt; // last tick's damping, over this period
  // the controller damps the force about to be rendered; the safety chain
  // after it still bounds what is sent, and the observer measures that
  double alpha = p->control ? damping_for(p->reference_energy, vel, dt, p->limits.max_force) : 0;
  if (alpha > 0) o->activations++;
  double f[3];
  for (int i = 0; i < 3; i++) {
    f[i] = in->mute ? 0 : in->force[i] - alpha * vel[i];
    p->damped_vel[i] = alpha && !in->mute ? vel[i] : 0;
  }
  p->damping = in->mute ? 0 : alpha;
  tx_safety_apply(&p->safety, &p->limits, dt, f, pos, in->model_age_s, in->silent_s, out);
  memcpy(p->held, out, sizeof p->held);
}
