// Contact sheets: box-filtered thumbnails in a grid.
#include "contact_sheet.h"

#include "../../model/error.h"
#include "png_writer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool tx_contact_sheet_init(tx_contact_sheet* s, int frame_w, int frame_h, int thumb_width, int cap) {
  memset(s, 0, sizeof *s);
  s->thumb_w = thumb_width < frame_w ? thumb_width : frame_w;
  s->thumb_h = (int)((long)frame_h * s->thumb_w / frame_w);
  if (s->thumb_h < 1) s->thumb_h = 1;
  s->cap = cap < 2 ? 2 : cap & ~1;
  s->stride = 1;
  s->pixels = calloc((size_t)s->cap * (size_t)s->thumb_w * (size_t)s->thumb_h, 4);
  return s->pixels != NULL;
}

void tx_contact_sheet_free(tx_contact_sheet* s) {
  free(s->pixels);
  s->pixels = NULL;
}

static void shrink(const tx_contact_sheet* s, const uint8_t* rgba, int w, int h, uint8_t* out) {
  for (int ty = 0; ty < s->thumb_h; ty++)
    for (int tx = 0; tx < s->thumb_w; tx++) {
      // the source box of this thumbnail pixel; the source is bottom-up
      int x0 = tx * w / s->thumb_w, x1 = (tx + 1) * w / s->thumb_w;
      int y0 = ty * h / s->thumb_h, y1 = (ty + 1) * h / s->thumb_h;
      if (x1 <= x0) x1 = x0 + 1;
      if (y1 <= y0) y1 = y0 + 1;
      unsigned sum[4] = {0, 0, 0, 0}, cnt = 0;
      for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++, cnt++)
          for (int c = 0; c < 4; c++) sum[c] += rgba[4 * ((size_t)(h - 1 - y) * w + x) + c];
      for (int c = 0; c < 4; c++) out[4 * (ty * s->thumb_w + tx) + c] = (uint8_t)(sum[c] / cnt);
    }
}

void tx_contact_sheet_add(tx_contact_sheet* s, const uint8_t* rgba, int w, int h, bool last) {
  if (!s->pixels) return;
  size_t one = (size_t)s->thumb_w * (size_t)s->thumb_h * 4;
  bool take = s->offered++ % s->stride == 0;
  if (!take && !last) return;
  if (s->count == s->cap) {
    if (last) { // the run's last frame replaces the newest thumbnail
      shrink(s, rgba, w, h, s->pixels + one * (size_t)(s->count - 1));
      return;
    }
    for (int i = 0; i < s->cap / 2; i++) memmove(s->pixels + one * i, s->pixels + one * (2 * i), one);
    s->count = s->cap / 2;
    s->stride *= 2;
    if ((s->offered - 1) % s->stride != 0) return;
  }
  shrink(s, rgba, w, h, s->pixels + one * (size_t)s->count++);
}

int tx_contact_sheet_write(const tx_contact_sheet* s, const char* path, int columns) {
  if (!s->count) return tx_set_error("%s: no frames to show", path), -1;
  const int gap = 4;
  int cols = s->count < columns ? s->count : columns, rows = (s->count + cols - 1) / cols;
  int W = cols * (s->thumb_w + gap) + gap, H = rows * (s->thumb_h + gap) + gap;
  uint8_t* sheet = malloc((size_t)W * (size_t)H * 4);
  if (!sheet) return tx_set_error("%s: out of memory", path), -1;
  for (size_t i = 0; i < (size_t)W * H; i++) sheet[4 * i] = sheet[4 * i + 1] = sheet[4 * i + 2] = 32, sheet[4 * i + 3] = 255;
  size_t one = (size_t)s->thumb_w * (size_t)s->thumb_h * 4;
  for (int k = 0; k < s->count; k++) {
    int ox = gap + (k % cols) * (s->thumb_w + gap), oy = gap + (k / cols) * (s->thumb_h + gap);
    for (int y = 0; y < s->thumb_h; y++)
      memcpy(sheet + 4 * ((size_t)(oy + y) * W + ox), s->pixels + one * k + (size_t)y * s->thumb_w * 4,
             (size_t)s->thumb_w * 4);
  }
  int rc = tx_png_write(path, sheet, W, H, false);
  free(sheet);
  return rc;
}
