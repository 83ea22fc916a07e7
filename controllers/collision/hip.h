// Internal: the simplified ray-casting method of the suturing papers, the
// force of a deformable skin on a haptic interaction point (HIP).
//
// The HIP is a sphere of radius r at c that casts 26 or 98 rays d_n. A ray
// comes into contact when it meets the skin's mid-plane (the triangle mesh)
// at a distance t_n < r + h/2 (h: skin thickness), and stays in contact up to
// r + h/2 + hold. For each ray in contact:
//   P_in  where the ray crossed the HIP's radius when its contact began: c + r d_n.
//         A ray joining a contact already made takes the contact's anchor A,
//         the mean of (P_in - r d) over the rays in contact: P_in = A + r d_n,
//         so that it measures the skin's displacement since the contact began
//         (the first ray's onset, moved by eq. 8) instead of starting at zero
//         and pulling the mean down (join_anchor; false: c + r d_n)
//   P_n   where it meets the mid-plane now:                            c + t_n d_n
//   R_n = P_n - P_in                                  (the conference paper, eq. 5)
//   F   = -alpha sum(R_n) / N, N the rays in contact    (eq. 7; journal eq. 3)
// When the part of R_n across the approach (the direction toward the skin in
// which the contact began) grows past slide_max, P_in follows the hand by
// eq. 8, P_in = P_n - k R_n, applied to that tangential part only: the push is
// kept and a slide becomes a steady drag. Once the HIP has gone through the
// skin (the ray toward the skin along which contact began finds no skin any
// more) the force is zero until no ray touches the skin and the HIP is clear
// of the pierce: back on the side it came from, or pierce_range away from
// where it went through, so a torn flap that swings back never pushes as if
// the skin were whole. Rays that all lose an untorn skin at once (it wraps
// the HIP between them) while the skin is still ahead along the approach and
// the HIP is past where the contact began do not end the contact: the force
// goes on as -alpha ((c - A) . a) a (the rays' common part, A the anchor),
// and rays that meet the skin again measure from A.
//
// Mechanics mode (tx_hip_query_reaction) keeps the rays for contact and
// pierce, but the force is the skin's own reaction as the physics computed
// it (tx_skin_contact): F = f + K (c - x), K = -k n n^T, the move from x
// along n taken at most r + h/2 deep (past that the linearisation is not
// trusted: the force holds and K is 0), and never a pull. A pierce there
// also needs links torn since the contact began: without a tear the HIP is
// still in the skin, however far it got past the frozen skin.
//
//     tx_hip h;  tx_hip_init(&h, &def);         // def from tx_hip_def_default()
//     tx_hip_out o;  tx_hip_query(&h, &bvh, x, thickness, c, &o); // o.f, o.k
//     tx_hip_query_reaction(&h, &bvh, x, thickness, c, &contact, &o); // mechanics
#ifndef TX_CONTROLLERS_COLLISION_HIP_H
#define TX_CONTROLLERS_COLLISION_HIP_H

#include "hip_rays.h"
#include "tri_bvh.h"

#include <stdbool.h>

typedef struct tx_hip_def {
  double radius;        // m, HIP sphere (the papers: 0.05 to 0.1 cm)
  int rays;             // 26 or 98
  double alpha;         // N/m, force per mean displacement (the papers' 0.2 N per cm = 20 N/m)
  double k;             // 1, eq. 8 factor, < 1 (the papers' maximum-distance constant 0.3)
  double slide_max;     // m, tangential displacement that triggers eq. 8 (the papers' 0.3 units = 3 mm)
  double pierce_range;  // m, how far along the approach the skin is looked for before the HIP counts as through,
                        // and how far from where it went through a pierced HIP stays so
  double hold;          // m, a ray in contact stays so up to r + h/2 + hold: the physics leaves the skin
                        // at r + h/2 from the HIP it last saw, which may lead the HIP of now by its
                        // speed over one physics period
  bool join_anchor;     // a ray that comes into contact while others are takes their anchor (below);
                        // false: its P_in is its own point at the HIP's radius at its own onset
} tx_hip_def;

tx_hip_def tx_hip_def_default(void);
// 0 when every field is valid, else -1 and tx_error() names the field
int tx_hip_def_check(const tx_hip_def* d);

typedef struct tx_hip {
  tx_hip_def def;
  int nrays;                          // rays cast
  double dir[TX_HIP_RAYS_MAX][3];     // 1, unit ray directions
  bool on[TX_HIP_RAYS_MAX];           // ray in contact
  double p_in[TX_HIP_RAYS_MAX][3];    // m, first contact point of each ray in contact
  double t0[TX_HIP_RAYS_MAX];         // m, its hit distance at that first contact
  bool touching;                      // some ray was in contact at the last query
  bool pierced;                       // through the skin: no force until contact ends
  double approach[3];                 // 1, toward the skin when contact began
  double pierce_at[3];                // m, the HIP centre when it went through
  double anchor[3];                   // m, the contact's anchor at the last query in contact
  double torn_at_touch;               // links torn when the contact began (mechanics mode)
  uint64_t resets;                    // eq. 8 updates so far
} tx_hip;

typedef struct tx_hip_out {
  double f[3];   // N, force of the skin on the HIP
  double k[9];   // N/m, row-major dF/dc. Paper: each R_n moves with the HIP while the skin is held at its
                 // surface, so -alpha I in contact (0 without); mechanics: -k n n^T of the reaction
  int contacts;  // N, rays in contact (0 once pierced)
  bool pierced;  // the HIP is through the skin
  double depth;  // m, r + h/2 - the shortest contact distance (0 without contact)
  double x0[3];  // m, where f holds. Paper: where the HIP would just touch this skin along the approach
                 // (c without contact): the skin is frozen between physics publishes, the hand is not;
                 // mechanics: c
} tx_hip_out;

void tx_hip_init(tx_hip* h, const tx_hip_def* def); // def must pass tx_hip_def_check
void tx_hip_reset(tx_hip* h);                        // forget every contact
// one query of the HIP at c against the skin in b (built or refitted over x);
// thickness in m. Allocates nothing.
void tx_hip_query(tx_hip* h, tx_tri_bvh* b, const float* x, double thickness, const double c[3], tx_hip_out* out);

struct tx_skin_contact; // <tactus/components.h>
// the same in mechanics mode: contact and pierce from the rays, the force from r
void tx_hip_query_reaction(tx_hip* h, tx_tri_bvh* b, const float* x, double thickness, const double c[3],
                           const struct tx_skin_contact* r, tx_hip_out* out);

#endif
