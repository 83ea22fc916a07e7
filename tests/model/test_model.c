// Model: schema checks, publish/acquire semantics, and the hazard rule that a
// held snapshot never changes under its reader.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/model.h>

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

static void rejects_bad_definitions_and_keeps_state(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp ok = tx_model_add(m, &(tx_component_def){"skin.x", TX_F32, 4, 3, "m"});
  assert_int_equal(ok.id, 1);
  const tx_component_def bad[] = {
      {"skin.x", TX_F32, 4, 3, "m"},      // duplicate
      {"Skin", TX_F32, 4, 3, "m"},        // upper case
      {"", TX_F32, 4, 3, "m"},            // empty
      {NULL, TX_F32, 4, 3, "m"},          // missing
      {"a", (tx_type)99, 4, 3, "m"},      // unknown type
      {"a", TX_F32, 0, 3, "m"},           // no rows
      {"a", TX_F32, 4, 0, "m"},           // no cols
      {"a", TX_F64, 1u << 31, 4, "m"},    // larger than 4 GiB
      {"a", TX_F32, 4, 3, "0123456789abcdefXYZ"}, // units too long
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_comp c = tx_model_add(m, &bad[i]);
    assert_int_equal(c.id, 0);
    assert_true(strlen(tx_error()) > 0);
    assert_int_equal(tx_model_count(m), 1);
  }
  assert_int_equal(tx_model_add_reader(m, (tx_comp){7}).id, 0);
  assert_true(tx_model_commit(m));
  assert_int_equal(tx_model_add(m, &(tx_component_def){"late", TX_F32, 1, 1, "1"}).id, 0);
  assert_int_equal(tx_model_add_reader(m, ok).id, 0);
  assert_string_equal(tx_model_def(m, ok)->units, "m");
  assert_int_equal(tx_model_bytes(m, ok), 4 * 3 * 4);
  tx_model_destroy(m);
}

static void model_size_is_bounded(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  // 200 MiB is allowed for one component, but not six buffers of it (four readers)
  tx_comp c = tx_model_add(m, &(tx_component_def){"big", TX_U8, 200u << 20, 1, "1"});
  assert_int_not_equal(c.id, 0);
  for (int r = 0; r < 4; r++) assert_int_not_equal(tx_model_add_reader(m, c).id, 0);
  assert_false(tx_model_commit(m));
  assert_non_null(strstr(tx_error(), "MiB"));
  assert_int_equal(tx_model_add(m, &(tx_component_def){"huge", TX_U8, (256u << 20) + 1, 1, "1"}).id, 0);
  tx_model_destroy(m);
}

static void type_names_round_trip(void** state) {
  (void)state;
  for (tx_type t = TX_F32; t <= TX_U8; t++) assert_int_equal(tx_type_from_name(tx_type_name(t)), t);
  assert_null(tx_type_name((tx_type)0));
  assert_int_equal(tx_type_from_name("f16"), 0);
  assert_int_equal(tx_type_from_name(NULL), 0);
  assert_int_equal(tx_type_size(TX_F64), 8);
  assert_int_equal(tx_type_size((tx_type)42), 0);
}

static void publish_then_acquire(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &(tx_component_def){"tool.pose", TX_F64, 1, 7, "m"});
  tx_reader r = tx_model_add_reader(m, c);
  assert_true(tx_model_commit(m));

  tx_snapshot s = tx_model_acquire(m, r);
  assert_int_equal(s.seq, 0); // never published: zeros
  assert_true(((const double*)s.data)[0] == 0.0);

  for (int k = 1; k <= 5; k++) {
    double* back = tx_model_back(m, c);
    for (int i = 0; i < 7; i++) back[i] = k * 10 + i;
    int64_t before = tx_mono_ns();
    assert_int_equal(tx_model_publish(m, c, k * 1000), k);
    s = tx_model_acquire(m, r);
    assert_int_equal(s.seq, k);
    assert_int_equal(s.sim_ns, k * 1000);
    assert_true(s.mono_ns >= before);
    assert_int_equal(s.rows, 1);
    assert_int_equal(s.cols, 7);
    assert_true(((const double*)s.data)[6] == k * 10 + 6);
  }
  tx_model_destroy(m);
}

static void held_snapshot_never_changes(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &(tx_component_def){"skin.x", TX_I32, 64, 1, "1"});
  tx_reader slow = tx_model_add_reader(m, c), fast = tx_model_add_reader(m, c);
  assert_true(tx_model_commit(m));

  int32_t* back = tx_model_back(m, c);
  for (int i = 0; i < 64; i++) back[i] = 1;
  tx_model_publish(m, c, 0);
  tx_snapshot held = tx_model_acquire(m, slow);
  for (int k = 2; k < 100; k++) { // many publishes while the slow reader holds seq 1
    back = tx_model_back(m, c);
    assert_ptr_not_equal(back, held.data);
    for (int i = 0; i < 64; i++) back[i] = k;
    tx_model_publish(m, c, k);
    tx_snapshot s = tx_model_acquire(m, fast);
    assert_int_equal(((const int32_t*)s.data)[63], k);
  }
  for (int i = 0; i < 64; i++) assert_int_equal(((const int32_t*)held.data)[i], 1);
  assert_int_equal(held.seq, 1);
  tx_model_release(m, slow);
  tx_model_destroy(m);
}

static void back_copy_and_rows(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &(tx_component_def){"skin.tris", TX_U32, 10, 3, "1"});
  tx_reader r = tx_model_add_reader(m, c);
  assert_true(tx_model_commit(m));
  uint32_t* back = tx_model_back(m, c);
  for (int i = 0; i < 30; i++) back[i] = (uint32_t)i;
  tx_model_set_rows(m, c, 4);
  tx_model_publish(m, c, 1);
  uint32_t* copy = tx_model_back_copy(m, c); // an incremental writer starts from the latest
  for (int i = 0; i < 30; i++) assert_int_equal(copy[i], i);
  copy[0] = 99;
  tx_model_publish(m, c, 2);
  tx_snapshot s = tx_model_acquire(m, r);
  assert_int_equal(s.rows, 4); // rows carry over with the copy
  assert_int_equal(((const uint32_t*)s.data)[0], 99);
  assert_int_equal(((const uint32_t*)s.data)[29], 29);
  tx_model_set_rows(m, c, 1000); // clamped to capacity
  tx_model_publish(m, c, 3);
  assert_int_equal(tx_model_acquire(m, r).rows, 10);
  assert_int_equal(tx_model_latest(m, c).seq, 3);
  tx_model_destroy(m);
}

static void null_and_invalid_ids_are_harmless(void** state) {
  (void)state;
  assert_null(tx_model_back(NULL, (tx_comp){1}));
  assert_int_equal(tx_model_publish(NULL, (tx_comp){1}, 0), 0);
  assert_null(tx_model_acquire(NULL, (tx_reader){1}).data);
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &(tx_component_def){"a", TX_U8, 1, 1, "1"});
  assert_null(tx_model_back(m, c)); // not committed: no buffers yet
  assert_true(tx_model_commit(m));
  assert_null(tx_model_back(m, (tx_comp){2}));
  assert_null(tx_model_acquire(m, (tx_reader){1}).data); // no such reader
  assert_int_equal(tx_model_find(m, "b").id, 0);
  assert_int_equal(tx_model_find(m, "a").id, 1);
  tx_model_destroy(m);
  tx_model_destroy(NULL);
}

static void hash_is_stable_and_sensitive(void** state) {
  (void)state;
  const char a[] = "0123456789abcdefXYZ", b[] = "0123456789abcdefXYz";
  assert_true(tx_hash(TX_HASH_SEED, a, sizeof a) == tx_hash(TX_HASH_SEED, a, sizeof a));
  assert_true(tx_hash(TX_HASH_SEED, a, sizeof a) != tx_hash(TX_HASH_SEED, b, sizeof b));
  assert_true(tx_hash(TX_HASH_SEED, a, 8) != tx_hash(TX_HASH_SEED, a + 1, 8));
  // a fixed value: traces hashed today must hash the same tomorrow
  assert_true(tx_hash(TX_HASH_SEED, "tactus model", 12) == 0xd652d00d1b99ea17ull);
  assert_true(tx_hash(TX_HASH_SEED, "", 0) == TX_HASH_SEED);
}

static void stamp_is_the_latest_publish(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &(tx_component_def){"a", TX_F32, 2, 1, "1"});
  assert_true(tx_model_commit(m));
  tx_stamp t = tx_model_stamp(m, c);
  assert_true(t.seq == 0 && t.sim_ns == 0 && t.mono_ns == 0); // never published
  int64_t before = tx_mono_ns();
  tx_model_publish(m, c, 1234);
  tx_model_publish(m, c, 5678);
  t = tx_model_stamp(m, c);
  tx_snapshot s = tx_model_latest(m, c);
  assert_int_equal(t.seq, 2);
  assert_int_equal(t.sim_ns, 5678);
  assert_true(t.mono_ns == s.mono_ns && t.mono_ns >= before && t.mono_ns <= tx_mono_ns());
  t = tx_model_stamp(m, (tx_comp){2});
  assert_true(t.seq == 0 && t.sim_ns == 0 && t.mono_ns == 0);
  t = tx_model_stamp(NULL, c);
  assert_true(t.seq == 0);
  tx_model_destroy(m);
}

// a writer publishing as fast as it can, sim_ns = 10 x seq: every stamp read
// beside it is whole (never one publish's seq with another's times) and none goes back
typedef struct stamp_race {
  tx_model* m;
  tx_comp c;
  atomic_bool done;
} stamp_race;

static void* stamp_writer(void* arg) {
  stamp_race* r = arg;
  for (int64_t i = 1; i <= 200000; i++) tx_model_publish(r->m, r->c, 10 * i);
  atomic_store(&r->done, true);
  return NULL;
}

static void stamp_is_whole_beside_a_writer(void** state) {
  (void)state;
  stamp_race r = {.m = tx_model_create()};
  r.c = tx_model_add(r.m, &(tx_component_def){"a", TX_F32, 2, 1, "1"});
  assert_true(tx_model_commit(r.m));
  pthread_t w;
  assert_int_equal(pthread_create(&w, NULL, stamp_writer, &r), 0);
  tx_stamp last = {0};
  uint64_t reads = 0, torn = 0, back = 0;
  while (!atomic_load(&r.done)) {
    tx_stamp t = tx_model_stamp(r.m, r.c);
    reads++;
    torn += t.sim_ns != (int64_t)(10 * t.seq) || (t.seq && !t.mono_ns);
    back += t.seq < last.seq || t.mono_ns < last.mono_ns;
    last = t;
  }
  pthread_join(w, NULL);
  assert_true(reads > 0);
  assert_int_equal(torn, 0);
  assert_int_equal(back, 0);
  assert_int_equal(tx_model_stamp(r.m, r.c).seq, 200000);
  tx_model_destroy(r.m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(rejects_bad_definitions_and_keeps_state),
      cmocka_unit_test(model_size_is_bounded),
      cmocka_unit_test(type_names_round_trip),
      cmocka_unit_test(publish_then_acquire),
      cmocka_unit_test(held_snapshot_never_changes),
      cmocka_unit_test(back_copy_and_rows),
      cmocka_unit_test(null_and_invalid_ids_are_harmless),
      cmocka_unit_test(hash_is_stable_and_sensitive),
      cmocka_unit_test(stamp_is_the_latest_publish),
      cmocka_unit_test(stamp_is_whole_beside_a_writer),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
