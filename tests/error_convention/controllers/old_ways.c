// A fixture for test_error_convention.sh --self-test: each old way to report
// an error once. Never compiled.
#include <stdio.h>
#include <stddef.h>

typedef struct tx_fault tx_fault;

int tx_fixture_open(const char* path, char* err, size_t n) {
  snprintf(err, n, "%s: no", path);
  return -1;
}

static void step(void* self) {
  (void)self;
  fprintf(stderr, "tactus: printed from a step\n");
}
