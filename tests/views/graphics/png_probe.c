// png_probe FILE [X Y W H]: prints "WIDTH HEIGHT RED" where RED counts the
// pixels that are clearly red (the tool's colour), for the shell tests of
// window mode. Given a region (px, from the top-left), it also prints SHADE:
// the pixels in it of the window overlay's backing colour (0.05, 0.05, 0.08),
// which nothing else in a frame has, to find the overlay in each eye.
#include "model/error.h"
#include "views/graphics/png_writer.h"

#include <stdio.h>
#include <stdlib.h>

static int near(int v, int want) { return v >= want - 2 && v <= want + 2; }

int main(int argc, char** argv) {
  if (argc != 2 && argc != 6) return fprintf(stderr, "usage: png_probe FILE [X Y W H]\n"), 2;
  uint8_t* img;
  int w, h;
  if (tx_png_read(argv[1], &img, &w, &h)) return fprintf(stderr, "png_probe: %s\n", tx_error()), 1;
  long red = 0;
  for (long i = 0; i < (long)w * h; i++)
    if (img[4 * i] > 120 && img[4 * i + 1] < 90 && img[4 * i + 2] < 90) red++;
  printf("%d %d %ld", w, h, red);
  if (argc == 6) {
    int x0 = atoi(argv[2]), y0 = atoi(argv[3]), rw = atoi(argv[4]), rh = atoi(argv[5]);
    long shade = 0;
    for (int y = y0 < 0 ? 0 : y0; y < y0 + rh && y < h; y++)
      for (int x = x0 < 0 ? 0 : x0; x < x0 + rw && x < w; x++) {
        const uint8_t* p = img + 4 * ((long)y * w + x);
        shade += near(p[0], 13) && near(p[1], 13) && near(p[2], 20);
      }
    printf(" %ld", shade);
  }
  printf("\n");
  free(img);
  return 0;
}
