// Model stress: a writer at 4 kHz, readers at 1 kHz and 20 Hz, checksummed
// payloads. Then the same without pauses, to maximise interleavings. Any torn
// snapshot shows as a checksum mismatch; under ThreadSanitizer any unordered
// access shows as a report.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/model.h>

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct shared {
  tx_model* model;
  tx_comp comp;
  size_t words;          // payload u32 words; the last is the checksum
  double writer_hz;      // 0: as fast as possible
  _Atomic bool done;
} shared;

typedef struct reader_args {
  shared* sh;
  tx_reader reader;
  double hz;             // 0: as fast as possible
  uint64_t reads, checked, torn, stale_back;
} reader_args;

static uint32_t sum_of(const uint32_t* v, size_t n) {
  uint64_t h = tx_hash(TX_HASH_SEED, v, n * sizeof *v);
  return (uint32_t)(h ^ (h >> 32));
}

static void pause_until(int64_t ns) {
  struct timespec ts = {ns / 1000000000, ns % 1000000000};
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
}

static void* writer_main(void* arg) {
  shared* sh = arg;
  int64_t t0 = tx_mono_ns();
  for (uint64_t k = 1; !atomic_load(&sh->done); k++) {
    if (sh->writer_hz > 0) pause_until(t0 + (int64_t)(k * 1e9 / sh->writer_hz));
    uint32_t* v = tx_model_back(sh->model, sh->comp);
    for (size_t i = 0; i + 1 < sh->words; i++) v[i] = (uint32_t)(k * 2654435761u + i);
    v[sh->words - 1] = sum_of(v, sh->words - 1);
    tx_model_publish(sh->model, sh->comp, (int64_t)k);
  }
  return NULL;
}

static void* reader_main(void* arg) {
  reader_args* a = arg;
  shared* sh = a->sh;
  int64_t t0 = tx_mono_ns();
  uint64_t last_seq = 0;
  for (uint64_t k = 1; !atomic_load(&sh->done); k++) {
    if (a->hz > 0) pause_until(t0 + (int64_t)(k * 1e9 / a->hz));
    tx_snapshot s = tx_model_acquire(sh->model, a->reader);
    a->reads++;
    if (s.seq < last_seq) a->stale_back++; // a newer acquire never returns an older publish
    last_seq = s.seq;
    if (s.seq == 0) continue;
    const uint32_t* v = s.data;
    // read the whole payload twice, slowly: a writer reusing this buffer would show
    uint32_t first = sum_of(v, sh->words - 1);
    if (first != v[sh->words - 1] || sum_of(v, sh->words - 1) != first) a->torn++;
    if (s.sim_ns != (int64_t)s.seq) a->torn++; // header and payload belong together
    a->checked++;
  }
  return NULL;
}

static void run(size_t words, double writer_hz, const double* reader_hz, int nreaders, double seconds) {
  shared sh = {.words = words, .writer_hz = writer_hz};
  sh.model = tx_model_create();
  sh.comp = tx_model_add(sh.model, &(tx_component_def){"stress.payload", TX_U32, (uint32_t)words, 1, "1"});
  reader_args args[4];
  for (int r = 0; r < nreaders; r++) args[r] = (reader_args){.sh = &sh, .reader = tx_model_add_reader(sh.model, sh.comp), .hz = reader_hz[r]};
  assert_true(tx_model_commit(sh.model));

  pthread_t w, rd[4];
  assert_int_equal(pthread_create(&w, NULL, writer_main, &sh), 0);
  for (int r = 0; r < nreaders; r++) assert_int_equal(pthread_create(&rd[r], NULL, reader_main, &args[r]), 0);
  pause_until(tx_mono_ns() + (int64_t)(seconds * 1e9));
  atomic_store(&sh.done, true);
  pthread_join(w, NULL);
  for (int r = 0; r < nreaders; r++) pthread_join(rd[r], NULL);

  uint64_t published = tx_model_latest(sh.model, sh.comp).seq;
  print_message("  %zu words, writer %g Hz: %llu publishes\n", words, writer_hz, (unsigned long long)published);
  for (int r = 0; r < nreaders; r++) {
    print_message("  reader %g Hz: %llu reads, %llu checked, %llu torn\n", reader_hz[r],
                  (unsigned long long)args[r].reads, (unsigned long long)args[r].checked,
                  (unsigned long long)args[r].torn);
    assert_int_equal(args[r].torn, 0);
    assert_int_equal(args[r].stale_back, 0);
    assert_true(args[r].checked > 0); // the check really ran
  }
  assert_true(published > 0);
  tx_model_destroy(sh.model);
}

// the spine's case: 4 kHz writer of a mesh, haptic and physics-rate readers
static void paced_4khz_writer_1khz_and_20hz_readers(void** state) {
  (void)state;
  const double hz[] = {1000, 20};
  run(10404 * 3, 4000, hz, 2, 2.0);
}

// no pauses at all: the writer reuses buffers as fast as readers release them
static void unpaced_hammering(void** state) {
  (void)state;
  const double hz[] = {0, 0, 0};
  run(1024, 0, hz, 3, 1.0);
}

// the checksum used above does catch a change of one word
static void checksum_detects_a_torn_payload(void** state) {
  (void)state;
  uint32_t v[64];
  for (int i = 0; i < 63; i++) v[i] = (uint32_t)i;
  v[63] = sum_of(v, 63);
  v[17] ^= 1u << 5;
  assert_true(sum_of(v, 63) != v[63]);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(checksum_detects_a_torn_payload),
      cmocka_unit_test(paced_4khz_writer_1khz_and_20hz_readers),
      cmocka_unit_test(unpaced_hammering),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
