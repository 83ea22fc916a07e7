// png_probe FILE [X Y W H [R G B]]: prints "WIDTH HEIGHT RED" where RED counts the
// pixels that are clearly red (the tool's colour), for the shell tests of
// window mode. Given a region (px, from the top-left), it also prints SHADE:
// the pixels in it of the window overlay's backing colour (0.05, 0.05, 0.08),
// which nothing else in a frame has, to find the overlay in each eye; or,
// given R G B (0-255), of that colour (within 3), e.g. a panel's title bar.
#include "model/error.h"
#include "views/graphics/png_writer.h"

#include <stdio.h>
#include <stdlib.h>

static int near(int v, int want, int tol) { return v >= want - tol && v <= want + tol; }

int main(int argc, char** argv) {
  if (argc != 2 && argc != 6 && argc != 9) return fprintf(stderr, "usage: png_probe FILE [X Y W H [R G B]]\n"), 2;
  int want[3] = {13, 13, 20}, tol = 2;
  if (argc == 9) want[0] = atoi(argv[6]), want[1] = atoi(argv[7]), want[2] = atoi(argv[8]), tol = 3;
  uint8_t* img;
  int w, h;
  if (tx_png_read(argv[1], &img, &w, &h)) return fprintf(stderr, "png_probe: %s\n", tx_error()), 1;
  long red = 0;
  for (long i = 0; i < (long)w * h; i++)
    if (img[4 * i] > 120 && img[4 * i + 1] < 90 && img[4 * i + 2] < 90) red++;
  printf("%d %d %ld", w, h, red);
  if (argc >= 6) {
    int x0 = atoi(argv[2]), y0 = atoi(argv[3]), rw = atoi(argv[4]), rh = atoi(argv[5]);
    long shade = 0;
    for (int y = y0 < 0 ? 0 : y0; y < y0 + rh && y < h; y++)
      for (int x = x0 < 0 ? 0 : x0; x < x0 + rw && x < w; x++) {
        const uint8_t* p = img + 4 * ((long)y * w + x);
        shade += near(p[0], want[0], tol) && near(p[1], want[1], tol) && near(p[2], want[2], tol);
      }
    printf(" %ld", shade);
  }
  printf("\n");
  free(img);
  return 0;
}
