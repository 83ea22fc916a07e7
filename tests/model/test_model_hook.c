// Publish hooks: called once per publish of their own component, on the
// writer's thread, with the new seq, after the publish is visible to readers;
// a full table is refused; a removal waits for a call under way, so its user
// data may be freed at once; no allocation on the publish path.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/model.h>

#include <pthread.h>
#include <stdatomic.h>
#include <string.h>
#include <unistd.h>

typedef struct seen {
  tx_model* m;
  tx_reader r;      // to check the publish is visible when the hook runs
  uint32_t comp;
  uint64_t last_seq;
  int calls;
  bool visible;     // every call saw its publish as the latest
} seen;

static void record(void* user, tx_comp c, uint64_t seq) {
  seen* s = user;
  s->calls++;
  s->comp = c.id;
  s->last_seq = seq;
  tx_snapshot snap = tx_model_acquire(s->m, s->r);
  if (snap.seq != seq) s->visible = false;
  tx_model_release(s->m, s->r);
}

static void hooks_run_on_their_component_only(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp a = tx_model_add(m, &(tx_component_def){"a", TX_F64, 1, 1, "1"});
  tx_comp b = tx_model_add(m, &(tx_component_def){"b", TX_F64, 1, 1, "1"});
  tx_reader ra = tx_model_add_reader(m, a), rb = tx_model_add_reader(m, b);
  seen sa = {.m = m, .r = ra, .visible = true}, sb = {.m = m, .r = rb, .visible = true};
  int ha = tx_model_add_hook(m, a, record, &sa); // before commit
  assert_true(ha > 0);
  assert_true(tx_model_commit(m));
  int hb = tx_model_add_hook(m, b, record, &sb); // and after it
  assert_true(hb > 0 && hb != ha);
  for (int i = 0; i < 5; i++) tx_model_publish(m, a, i);
  tx_model_publish(m, b, 0);
  assert_int_equal(sa.calls, 5);
  assert_int_equal(sa.comp, a.id);
  assert_int_equal(sa.last_seq, 5);
  assert_true(sa.visible);
  assert_int_equal(sb.calls, 1);
  assert_int_equal(sb.comp, b.id);
  tx_model_remove_hook(m, ha);
  tx_model_publish(m, a, 9);
  assert_int_equal(sa.calls, 5); // removed: not called again
  tx_model_remove_hook(m, ha);   // twice, and nonsense ids: nothing happens
  tx_model_remove_hook(m, 0);
  tx_model_remove_hook(m, 99);
  // the freed slot is given again, to b: a's publishes must not reach it
  seen sc = {.m = m, .r = rb, .visible = true};
  int hc = tx_model_add_hook(m, b, record, &sc);
  assert_int_equal(hc, ha);
  tx_model_publish(m, a, 10);
  assert_int_equal(sc.calls, 0);
  tx_model_publish(m, b, 10);
  assert_int_equal(sc.calls, 1);
  assert_int_equal(sb.calls, 2);
  assert_int_equal(tx_model_add_hook(m, (tx_comp){0}, record, &sa), 0);
  assert_int_equal(tx_model_add_hook(m, a, NULL, &sa), 0);
  tx_model_destroy(m);
}

static void count(void* user, tx_comp c, uint64_t seq) {
  (void)c, (void)seq;
  (*(int*)user)++;
}

static void a_full_table_is_refused(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp a = tx_model_add(m, &(tx_component_def){"a", TX_F64, 1, 1, "1"});
  assert_true(tx_model_commit(m));
  int n = 0;
  for (int i = 0; i < TX_PUBLISH_HOOKS_MAX; i++) assert_int_equal(tx_model_add_hook(m, a, count, &n), i + 1);
  assert_int_equal(tx_model_add_hook(m, a, count, &n), 0);
  assert_non_null(strstr(tx_error(), "publish hooks"));
  tx_model_publish(m, a, 0);
  assert_int_equal(n, TX_PUBLISH_HOOKS_MAX);
  tx_model_destroy(m);
}

// a writer thread publishes without pause while the main thread adds and
// removes a hook whose user data it frees (poisons) right after each removal:
// no call may see poisoned data (TSan and ASan check the rest)
typedef struct slow {
  _Atomic int alive; // 1 until poisoned
  _Atomic int calls;
  _Atomic int after_free;
} slow;

static void slow_hook(void* user, tx_comp c, uint64_t seq) {
  (void)c, (void)seq;
  slow* s = user;
  for (volatile int i = 0; i < 200; i++) {}
  if (atomic_load(&s->alive) != 1) atomic_fetch_add(&s->after_free, 1);
  atomic_fetch_add(&s->calls, 1);
}

typedef struct writer {
  tx_model* m;
  tx_comp c;
  _Atomic bool stop;
} writer;

static void* write_loop(void* arg) {
  writer* w = arg;
  for (int64_t t = 0; !atomic_load(&w->stop); t++) tx_model_publish(w->m, w->c, t);
  return NULL;
}

static void removal_waits_for_a_call_under_way(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp a = tx_model_add(m, &(tx_component_def){"a", TX_F64, 1, 1, "1"});
  assert_true(tx_model_commit(m));
  writer w = {.m = m, .c = a};
  pthread_t t;
  assert_int_equal(pthread_create(&t, NULL, write_loop, &w), 0);
  int total = 0, bad = 0;
  for (int round = 0; round < 100; round++) {
    slow s = {.alive = 1};
    int id = tx_model_add_hook(m, a, slow_hook, &s);
    assert_true(id > 0);
    while (atomic_load(&s.calls) < 3) sched_yield();
    tx_model_remove_hook(m, id);
    atomic_store(&s.alive, 0); // as if freed
    int calls = atomic_load(&s.calls);
    for (volatile int i = 0; i < 2000; i++) {}
    assert_int_equal(atomic_load(&s.calls), calls); // no call after the removal returned
    total += calls;
    bad += atomic_load(&s.after_free);
  }
  atomic_store(&w.stop, true);
  pthread_join(t, NULL);
  assert_int_equal(bad, 0);
  assert_true(total >= 300);
  tx_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(hooks_run_on_their_component_only),
      cmocka_unit_test(a_full_table_is_refused),
      cmocka_unit_test(removal_waits_for_a_call_under_way),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
