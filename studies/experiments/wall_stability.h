// Internal: the virtual-wall experiment behind `tactus study haptic-stability`.
//
// A one-axis wall occupies x > 0 and is rendered at the servo period T by
//
//     F(k) = -K x(k) - B (x(k) - x(k-1)) / T   when x(k) > 0, else 0
//
// on the simulated device (sim_device.h), through the force path of the
// `haptics` controller (tx_haptic_tick in passivity.h: passivity observer and
// controller, then the safety chain with the limits the device gives), so
// what is measured is what the controller ships. Colgate's passivity
// condition for this sampled wall is b > K T / 2 + |B|: the zero-order hold
// delays the spring by about T/2, which acts as a negative damping K T / 2
// that the device's own damping b must absorb. Hence the bound
// K_max = 2 (b - |B|) / T.
//
// That is a passivity bound: it holds against every passive hand. The exact
// stability boundary of this loop (tx_wall_exact_bound) is where the
// eigenvalues of its discretisation leave the unit circle: the device's exact
// zero-order-hold transition over T (hand spring included), the wall
// computed from the sample x(k) and held over the next period (no further
// delay), the velocity a backward difference. The two agree near B = 0; with
// B > 0 the boundary lies well above 2 (b - B) / T, near 2 (b + B) / T for
// small B, since a damper that is one period late still mostly damps.
//
// One case: the hand presses the device into the wall with push_force and
// holds it there; the device starts at the resting depth x_eq = push_force/K
// with an inward velocity that gives an oscillation of amplitude kick * x_eq.
// The energy of that oscillation about x_eq,
//
//     E = m v^2 / 2 + (K + kh) (x - x_eq)^2 / 2     (true state, not the encoder's)
//
// is what a stable wall dissipates and an unstable one feeds. The case is
// stable when E averaged over the last quarter of the run is below E0, its
// value at the start: a small push dies out. The threshold is not a knob: a
// passive loop can only lose this energy, an unstable one grows (until the
// device bounces off the wall or the motors saturate), and a limit cycle that
// does not decay holds its own level, above E0 whenever it is larger than the
// push. The push is small (kick 1/4) so that such a limit cycle counts as
// unstable, yet several encoder quanta wide so that the loop can see it. Near
// the boundary the answer changes where the net damping of the loop changes
// sign; the run length sets how close (10 s: to within about 1%).
//
// With the passivity controller, two references for it (passivity.h):
// - port: the energy absorbed at the device port. It lets the wall give back
//   the spring energy stored by the push, so above 2b/T the oscillation
//   grows until it has spent that store and then stays: bounded, but not
//   decaying, so by the criterion above not stable.
// - spring: the same energy less what the wall's spring holds at the
//   measured depth (tx_spring_energy, as the controller computes it from a
//   published force model). What is left is the energy the sampling
//   generates, and the controller removes it as it appears.
//
//     tx_wall_case c = tx_wall_case_default();
//     c.device.period = 0.25e-3;
//     tx_wall_search s = tx_wall_largest_stable(&c, 10, 1e5, 0.01);
//     printf("%g N/m measured, %g N/m bound\n", s.k,
//            tx_wall_colgate_bound(c.device.damping, c.damping, c.device.period));
#ifndef TX_CONTROLLERS_HAPTICS_WALL_STABILITY_H
#define TX_CONTROLLERS_HAPTICS_WALL_STABILITY_H

#include <stdbool.h>
#include <stdint.h>

#include "../../controllers/haptics/sim_device.h"

// how the passivity controller (passivity.h) is wired in
typedef enum tx_wall_pc {
  TX_WALL_PC_OFF = 0, // the wall force goes to the device as it is; the observer still watches
  TX_WALL_PC_PORT,    // the controller keeps the energy absorbed at the device port >= 0
  TX_WALL_PC_SPRING,  // ... that energy less what an ideal continuous spring would hold: >= 0
} tx_wall_pc;

typedef struct tx_wall_case {
  tx_sim_device_def device; // m, b, T, quantum, max force; its hand fields are the operator (defaults below)
  double stiffness;         // N/m, wall stiffness K; 500: the device's nominal stiffness
  double damping;           // N s/m, wall damping B in [-1e3, 1e3]; 0: the bound is then the device's own, 2b/T
  tx_wall_pc passivity;     // passivity control, off by default
  double push_force;        // N, how hard the hand presses at rest; 1: a firm touch, a third of max force
  double kick;              // initial amplitude as a fraction of x_eq, in (0, 1); 0.25: small, see above
  double duration;          // s, simulated time; 10: 65 times m/b, so a 2% damping margin changes E by e
} tx_wall_case;

typedef struct tx_wall_result {
  bool stable;              // E over the last quarter below E at the start
  double energy_start;      // J, oscillation energy at the start
  double energy_end;        // J, mean oscillation energy over the last quarter
  double growth_rate;       // 1/s, least-squares slope of log E over eight windows; < 0 decays
  double depth_rest;        // m, x_eq = push_force / K
  double depth_max;         // m, deepest true penetration
  double outside_s;         // s the device spent outside the wall
  double observed_min;      // J, lowest energy the passivity observer saw (it runs with control off too)
  uint64_t control_ticks;   // ticks on which the passivity controller added damping
  uint64_t clamped_ticks;   // ticks on which the safety chain (or the device) clamped the force
  uint64_t rate_limited_ticks; // ticks on which the safety chain's impulse limit held the force back
} tx_wall_result;

typedef struct tx_wall_search {
  double k;          // N/m, the largest stiffness found stable; k_lo if even that was unstable
  double k_unstable; // N/m, the smallest stiffness found unstable above k; 0 if k_hi was still stable
  bool lo_unstable;  // the lower bound itself was unstable
  bool hi_stable;    // every stiffness up to k_hi was stable: the answer is "at least k_hi"
  int cases;         // runs it took
} tx_wall_search;

// the defaults above; the device is tx_sim_device_def_default() held by a
// soft, lossless hand (hand_stiffness 20 N/m, hand_damping 0): it adds no
// damping, so the stability measured is the device's own (a real hand's
// damping adds to b and allows a stiffer wall)
tx_wall_case tx_wall_case_default(void);

// 0 when every field is finite and in range, otherwise -1 with one line in tx_error() naming it
int tx_wall_case_check(const tx_wall_case* c);

#define TX_WALL_DELAY_MAX 512 // round-trip delay, servo periods

// the simulation side of one tick: the wall's force (N, along x) and the
// energy its spring holds (J) for the reading x (m), v (m/s)
void tx_wall_force(double K, double B, double x, double v, double* force, double* stored);

// carries tick k's reading to the simulation side and its answer back; 0, or
// -1 with tx_error() set (the run then fails)
typedef struct tx_wall_link {
  int (*exchange)(void* user, uint64_t k, double K, double B, double x, double v, double* force, double* stored);
  void* user;
} tx_wall_link;

// one case with a round trip of delay_ticks servo periods, in [0,
// TX_WALL_DELAY_MAX]; link NULL: the wall in this process. false with
// tx_error() on bad input or a failed exchange. Allocates nothing.
bool tx_wall_run_delayed(const tx_wall_case* c, int delay_ticks, const tx_wall_link* link, tx_wall_result* out);

// tx_wall_largest_stable's sweep and bisection, for the delayed wall (in this process)
tx_wall_search tx_wall_largest_stable_delayed(const tx_wall_case* c, int delay_ticks, double k_lo, double k_hi, double rel_tol);

// one case for c->duration seconds of simulated time, the wall in this
// process with no delay (tx_wall_run_delayed's delay 0); false (with
// tx_error() set, *out untouched) on bad input. Allocates nothing.
bool tx_wall_run(const tx_wall_case* c, tx_wall_result* out);

// the largest stable wall stiffness K (N/m) of the case between k_lo and
// k_hi (N/m): a sweep up from k_lo in steps of x1.25 to the first unstable K,
// then bisection on log K until the bracket is narrower than rel_tol (e.g.
// 0.01). c->stiffness is ignored. Bad input (not 0 < k_lo <= k_hi <= 1e7,
// rel_tol > 0, or a bad case) sets tx_error() and lo_unstable. The sweep, not bisection alone, because a
// limit cycle can make a stiffer wall look stable again.
tx_wall_search tx_wall_largest_stable(const tx_wall_case* c, double k_lo, double k_hi, double rel_tol);

// whether the wall K (N/m), B (N s/m) in contact on this device (its exact
// transition, dev->phi and dev->gam) is asymptotically stable: Jury's test on
// the closed loop's characteristic cubic, in the state (x(k), v(k), x(k-1))
bool tx_wall_exact_stable(const tx_sim_device* dev, double K, double B);

// the exact stability boundary: the largest K (N/m) that tx_wall_exact_stable
// accepts, to 1e-12 relative, for the device d (no quantisation: the encoder
// is linearised away) and the wall's damping B (N s/m); 0 if even 1 mN/m is
// unstable, NaN for a bad device (tx_error() set) or B
double tx_wall_exact_bound(const tx_sim_device_def* d, double B);

// Colgate's passivity bound K_max = 2 (b - B) / T, N/m, for the device's
// damping b (N s/m), the wall's damping B (N s/m) and the period T (s);
// 0 when b <= B (no stiffness is passive), NaN for T <= 0
double tx_wall_colgate_bound(double b, double B, double T);

#endif
