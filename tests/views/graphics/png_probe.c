// png_probe FILE: prints "WIDTH HEIGHT RED" where RED counts the pixels that
// are clearly red (the tool's colour), for the shell tests of window mode.
#include "views/graphics/png_writer.h"

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char** argv) {
  if (argc != 2) return fprintf(stderr, "usage: png_probe FILE\n"), 2;
  uint8_t* img;
  int w, h;
  char err[512];
  if (tx_png_read(argv[1], &img, &w, &h, err, sizeof err)) return fprintf(stderr, "png_probe: %s\n", err), 1;
  long red = 0;
  for (long i = 0; i < (long)w * h; i++)
    if (img[4 * i] > 120 && img[4 * i + 1] < 90 && img[4 * i + 2] < 90) red++;
  printf("%d %d %ld\n", w, h, red);
  free(img);
  return 0;
}
