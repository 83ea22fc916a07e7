// Counting allocations in a test program, to check that a step never calls
// malloc. Include it in one source file of the program; set `counting` to 1
// around the code under test and read `allocations`.
//
// It interposes glibc's malloc, calloc and realloc. Sanitizers bring their
// own allocator, so there TX_NO_ALLOC_COUNT is defined, nothing is counted,
// and the assertions on the count must be left out with #ifndef.
#ifndef TX_TESTS_ALLOC_COUNT_H
#define TX_TESTS_ALLOC_COUNT_H

#include <stddef.h>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define TX_NO_ALLOC_COUNT 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(__GLIBC__)
#define TX_NO_ALLOC_COUNT 1
#endif

static volatile int counting;     // 1 while allocations are counted
static volatile long allocations; // allocations seen while counting

#ifndef TX_NO_ALLOC_COUNT
extern void* __libc_malloc(size_t n);
extern void* __libc_calloc(size_t n, size_t size);
extern void* __libc_realloc(void* p, size_t n);
void* malloc(size_t n) {
  if (counting) allocations++;
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t size) {
  if (counting) allocations++;
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t n) {
  if (counting) allocations++;
  return __libc_realloc(p, n);
}
#endif

#endif
