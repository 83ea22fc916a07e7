// PNG files through libpng's simplified API.
#include "png_writer.h"

#include "../../model/error.h"

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int tx_png_write(const char* path, const uint8_t* rgba, int width, int height, bool bottom_up) {
  char tmp[4200];
  if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) return tx_set_error("%s: path too long", path), -1;
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = (png_uint_32)width;
  img.height = (png_uint_32)height;
  img.format = PNG_FORMAT_RGBA;
  // the fast setting (zlib level 1, plain filters): frames are written while
  // the view runs, and a default-compressed 1280 x 480 frame took ~40 ms
  img.flags = PNG_IMAGE_FLAG_FAST;
  // a negative stride walks the rows from the last: bottom-up buffers come out upright
  png_int_32 stride = (png_int_32)width * 4 * (bottom_up ? -1 : 1);
  if (!png_image_write_to_file(&img, tmp, 0, rgba, stride, NULL)) {
    tx_set_error("%s: %s", path, img.message);
    remove(tmp);
    return -1;
  }
  if (rename(tmp, path) != 0) {
    remove(tmp);
    return tx_set_error("%s: cannot be written", path), -1;
  }
  return 0;
}

int tx_png_read(const char* path, uint8_t** rgba, int* width, int* height) {
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  *rgba = NULL;
  if (!png_image_begin_read_from_file(&img, path)) return tx_set_error("%s: %s", path, img.message), -1;
  img.format = PNG_FORMAT_RGBA;
  *rgba = malloc(PNG_IMAGE_SIZE(img));
  if (!*rgba) {
    png_image_free(&img);
    return tx_set_error("%s: out of memory", path), -1;
  }
  if (!png_image_finish_read(&img, NULL, *rgba, 0, NULL)) {
    free(*rgba);
    *rgba = NULL;
    return tx_set_error("%s: %s", path, img.message), -1;
  }
  *width = (int)img.width;
  *height = (int)img.height;
  return 0;
}
