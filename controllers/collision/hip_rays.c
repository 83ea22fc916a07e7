// The 26 or 98 unit ray directions of the HIP (the SutureHap journal paper,
// "Number of cast rays": 45 or 22.5 degrees between neighbours).
#include "hip_rays.h"

#include <math.h>
#include <stdlib.h>

int tx_hip_rays(int count, double dirs[][3]) {
  int h; // half the grid side: 1 for 3x3x3, 2 for 5x5x5
  if (count == 26) h = 1;
  else if (count == 98) h = 2;
  else return 0;
  int n = 0;
  // the cells on the outer shell of the (2h+1)^3 grid, normalised
  for (int i = -h; i <= h; i++)
    for (int j = -h; j <= h; j++)
      for (int k = -h; k <= h; k++) {
        if (abs(i) != h && abs(j) != h && abs(k) != h) continue; // inside the shell
        double l = sqrt((double)(i * i + j * j + k * k));
        dirs[n][0] = i / l;
        dirs[n][1] = j / l;
        dirs[n][2] = k / l;
        n++;
      }
  return n;
}
