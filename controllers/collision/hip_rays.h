// Internal: the ray directions a haptic interaction point (HIP) casts.
//
// The suturing papers' HIP casts 26 or 98 rays from its centre, 45 or 22.5
// degrees apart. The 26 directions are the cells around the centre of a
// 3 x 3 x 3 grid, the 98 those on the surface of a 5 x 5 x 5 grid (5^3 - 3^3),
// each normalised. Both sets are symmetric (d and -d are both in it), so on a
// flat plane the tangential parts of the rays cancel.
//
//     double dirs[98][3];
//     int n = tx_hip_rays(98, dirs); // 98, or 0 for a count other than 26 or 98
#ifndef TX_CONTROLLERS_COLLISION_HIP_RAYS_H
#define TX_CONTROLLERS_COLLISION_HIP_RAYS_H

#define TX_HIP_RAYS_MAX 98

// fill dirs with count unit directions; returns count, or 0 if count is not 26 or 98
int tx_hip_rays(int count, double dirs[][3]);

#endif
