// The contact sheet keeps an even spread of frames and always the last one.
#include "model/error.h"
#include "views/graphics/contact_sheet.h"
#include "views/graphics/png_writer.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

// a frame whose every pixel holds its number, so a thumbnail says which frame it is
static void offer(tx_contact_sheet* s, int index, bool last) {
  uint8_t img[8 * 6 * 4];
  for (int i = 0; i < 8 * 6; i++) img[4 * i] = (uint8_t)index, img[4 * i + 1] = 0, img[4 * i + 2] = 0, img[4 * i + 3] = 255;
  tx_contact_sheet_add(s, img, 8, 6, last);
}

static int frame_of(const tx_contact_sheet* s, int k) { return s->pixels[(size_t)k * s->thumb_w * s->thumb_h * 4]; }

static void spread_and_last(void** state) {
  (void)state;
  tx_contact_sheet s;
  assert_true(tx_contact_sheet_init(&s, 8, 6, 4, 8));
  assert_int_equal(s.thumb_w, 4);
  assert_int_equal(s.thumb_h, 3);
  for (int i = 0; i < 20; i++) offer(&s, i, false);
  // 8 kept, then halved twice: every 4th frame
  assert_int_equal(s.stride, 4);
  assert_int_equal(s.count, 5);
  for (int k = 0; k < s.count; k++) assert_int_equal(frame_of(&s, k), 4 * k);
  offer(&s, 20, false);
  offer(&s, 21, true); // the last frame is kept whatever the stride
  assert_int_equal(frame_of(&s, s.count - 1), 21);
  assert_int_equal(frame_of(&s, s.count - 2), 20);
  char path[] = "/tmp/tx_sheet_XXXXXX";
  int fd = mkstemp(path);
  close(fd);
  assert_int_equal(tx_contact_sheet_write(&s, path, 3), 0);
  uint8_t* img;
  int w, h;
  assert_int_equal(tx_png_read(path, &img, &w, &h), 0);
  assert_int_equal(w, 3 * (4 + 4) + 4); // 3 columns of 4 px with 4 px gaps
  assert_int_equal(h, 3 * (3 + 4) + 4); // 7 thumbnails in rows of 3
  assert_int_equal(img[4 * (4 * w + 4)], 0); // the first thumbnail's first pixel: frame 0
  free(img);
  remove(path);
  tx_contact_sheet_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(spread_and_last)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
