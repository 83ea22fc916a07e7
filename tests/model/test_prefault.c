// tx_prefault: every page of a fresh, lazily mapped buffer is resident
// afterwards (mincore), and its contents are still zeros.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/model.h>

#include <stdint.h>
#include <sys/mman.h>
#include <unistd.h>

static size_t resident_pages(void* p, size_t n, size_t page) {
  unsigned char vec[(8u << 20) / 4096];
  assert_true(n / page <= sizeof vec);
  assert_int_equal(mincore(p, n, vec), 0);
  size_t k = 0;
  for (size_t i = 0; i < n / page; i++) k += vec[i] & 1;
  return k;
}

static void every_page_is_mapped_and_still_zero(void** state) {
  (void)state;
  size_t page = (size_t)sysconf(_SC_PAGESIZE), n = 4u << 20; // 4 MB, like the recorder's ring
  // an anonymous mapping, as calloc makes for a buffer this large: no page is there yet
  unsigned char* p = mmap(NULL, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  assert_true(p != MAP_FAILED);
  assert_int_equal(resident_pages(p, n, page), 0);
  tx_prefault(p, n);
  assert_int_equal(resident_pages(p, n, page), n / page);
  for (size_t i = 0; i < n; i++)
    if (p[i]) fail_msg("byte %zu is %d", i, p[i]);
  tx_prefault(p + 1, page); // an unaligned range
  tx_prefault(NULL, 10);    // nothing to do
  tx_prefault(p, 0);
  munmap(p, n);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_page_is_mapped_and_still_zero),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
