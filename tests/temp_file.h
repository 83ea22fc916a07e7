// A temporary file with the given text, for tests that feed files to readers.
// Include after cmocka.h. The path lives until the next call.
#ifndef TX_TESTS_TEMP_FILE_H
#define TX_TESTS_TEMP_FILE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

// write text to a new /tmp/tx-test-XXXXXX.csv and return its path
static inline char* write_file(const char* text) {
  static char path[64];
  snprintf(path, sizeof path, "/tmp/tx-test-XXXXXX.csv");
  int fd = mkstemps(path, 4);
  assert_true(fd >= 0);
  assert_int_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
  close(fd);
  return path;
}

#endif
