// The device recorder and its reader: what a crash leaves on disk is whole
// blocks, a file cut short replays its whole blocks with a warning, a corrupt
// block or an implausible value is refused naming the block and record, a
// failed write is seen by the haptics thread, and version 1 files still read.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/haptics/recorder.h"
#include "scenarios/loader.h"
#include "views/trace_plot.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const tx_device_info touch = {.max_force = 3.3, .max_stiffness = 500, .workspace_min = {-0.5, -0.5, -0.5},
                                     .workspace_max = {0.5, 0.5, 0.5}};

static tx_record sample(size_t i) {
  tx_record r = {0};
  r.t_s = (double)i * 1e-3;
  r.pos[0] = 0.01 * sin((double)i * 0.01);
  r.pos[1] = -0.002 + 1e-6 * (double)i;
  r.quat[0] = 1;
  r.vel[2] = 0.005;
  r.force[1] = 1.5 * cos((double)i * 0.02);
  r.force_model[6] = -300;
  r.buttons = (double)(i % 4);
  return r;
}

static char dir[64];

static int make_dir(void** state) {
  (void)state;
  snprintf(dir, sizeof dir, "/tmp/tx-rec-XXXXXX");
  return mkdtemp(dir) ? 0 : -1;
}

static int remove_dir(void** state) {
  (void)state;
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  return system(cmd);
}

static const char* bin_path(void) {
  static char p[128];
  snprintf(p, sizeof p, "%s/device0.bin", dir);
  return p;
}

static void sleep_ms(int ms) { nanosleep(&(struct timespec){ms / 1000, (ms % 1000) * 1000000L}, NULL); }

// record n samples (with the given ones replaced), stopped so the file is whole
static void record(size_t n, const tx_record* special, size_t nspecial, size_t at) {
  tx_recorder* r = tx_recorder_start(dir, 0, 1000, &touch);
  assert_non_null(r);
  for (size_t i = 0; i < n; i++) {
    tx_record q = i >= at && i < at + nspecial ? special[i - at] : sample(i);
    while (!tx_recorder_push(r, &q)) sleep_ms(1);
  }
  int rc = tx_recorder_stop(r);
  (void)rc; // a file the reader refuses also fails the CSV export: the callers check the load
}

static long file_size(const char* path) {
  struct stat st;
  assert_int_equal(stat(path, &st), 0);
  return (long)st.st_size;
}

static unsigned char* slurp(const char* path, long* size) {
  *size = file_size(path);
  unsigned char* b = malloc((size_t)*size);
  FILE* f = fopen(path, "rb");
  assert_non_null(f);
  assert_int_equal(fread(b, 1, (size_t)*size, f), (size_t)*size);
  fclose(f);
  return b;
}

static void spill(const char* path, const unsigned char* b, long size) {
  FILE* f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(b, 1, (size_t)size, f), (size_t)size);
  fclose(f);
}

// 0 or -1 (the message in tx_error()); where a file cut short ends in warn
static int load(size_t* count, char* warn) {
  tx_record_file rf;
  int rc = tx_record_load(bin_path(), &rf);
  *count = rf.count;
  snprintf(warn, 512, "%s", rf.cut_short);
  free(rf.records);
  return rc;
}

// the error names the file and holds fragment; a "(block B)" in fragment
// matches any block, since the writer thread cuts blocks where its drains fall
static void expect_error(const char* fragment) {
  size_t count;
  char warn[512];
  assert_int_equal(load(&count, warn), -1);
  char head[256] = "";
  const char* tail = fragment;
  const char* block = strstr(fragment, "(block ");
  if (block) {
    snprintf(head, sizeof head, "%.*s", (int)(block - fragment + 7), fragment);
    tail = strchr(block, ')');
  }
  if (!strstr(tx_error(), bin_path()) || !strstr(tx_error(), head) || !strstr(tx_error(), tail))
    fail_msg("'%s' lacks the file or '%s'", tx_error(), fragment);
  assert_string_equal(warn, "");
}

static void records_read_back_bit_for_bit(void** state) {
  (void)state;
  record(3000, NULL, 0, 0);
  tx_record_file rf;
  assert_int_equal(tx_record_load(bin_path(), &rf), 0);
  assert_string_equal(rf.cut_short, "");
  const tx_record_header h = rf.header;
  tx_record* recs = rf.records;
  size_t count = rf.count;
  assert_int_equal(count, 3000);
  assert_int_equal(h.version, 2);
  assert_true(h.rate_hz == 1000 && h.device.max_force == 3.3);
  for (size_t i = 0; i < count; i++) {
    tx_record want = sample(i);
    if (memcmp(&recs[i], &want, sizeof want) != 0) fail_msg("record %zu differs", i);
  }
  free(recs);
}

// a crash (SIGSEGV, kill -9) at any moment finds the header and every record
// drained so far on disk: the writer flushes each drain (every 5 ms)
static void a_crash_leaves_whole_records_on_disk(void** state) {
  (void)state;
  char warn[512];
  tx_recorder* r = tx_recorder_start(dir, 0, 1000, &touch);
  assert_non_null(r);
  assert_int_equal(file_size(bin_path()), (long)sizeof(tx_record_header)); // the header is there at once
  for (size_t i = 0; i < 777; i++) {
    tx_record q = sample(i);
    assert_true(tx_recorder_push(r, &q));
  }
  sleep_ms(100); // many drains; the recorder is still running, as it would be at a crash
  size_t count = 0;
  int rc = load(&count, warn);
  if (rc) fail_msg("%s", tx_error());
  assert_string_equal(warn, ""); // no block cut short: nothing sits in a stdio buffer
  assert_int_equal(count, 777);
  assert_int_equal(tx_recorder_error(r, NULL), 0);
  assert_int_equal(tx_recorder_stop(r), 0);
}

// a killed run's file, cut anywhere: its whole blocks, and one warning
static void a_file_cut_short_gives_its_whole_blocks(void** state) {
  (void)state;
  record(1000, NULL, 0, 0);
  long size;
  unsigned char* b = slurp(bin_path(), &size);
  const long hdr = (long)sizeof(tx_record_header);
  // the blocks as the writer drained them
  long at[1000];
  size_t counts[1000], nblocks = 0;
  for (long off = hdr; off < size; nblocks++) {
    tx_record_block blk;
    memcpy(&blk, b + off, sizeof blk);
    at[nblocks] = off, counts[nblocks] = blk.count;
    off += (long)(sizeof blk + blk.count * sizeof(tx_record));
  }
  assert_true(nblocks >= 4); // 256 records a block at most
  size_t count;
  char warn[512], want[64];
  // inside the second block's header, inside its records, after three of its records
  long cuts[] = {at[1] + 7, at[1] + 16 + 100, at[1] + 16 + 3 * (long)sizeof(tx_record)};
  for (int k = 0; k < 3; k++) {
    spill(bin_path(), b, cuts[k]);
    assert_int_equal(load(&count, warn), 0);
    assert_int_equal(count, counts[0]);
    if (!strstr(warn, bin_path()) || !strstr(warn, "cut short in block 1")) fail_msg("warning: '%s'", warn);
  }
  // in the middle of the last record
  spill(bin_path(), b, size - 100);
  assert_int_equal(load(&count, warn), 0);
  assert_int_equal(count, 1000 - counts[nblocks - 1]);
  snprintf(want, sizeof want, "cut short in block %zu", nblocks - 1);
  assert_non_null(strstr(warn, want));
  // only the header: no records to replay
  spill(bin_path(), b, hdr);
  expect_error("holds no records");
  spill(bin_path(), b, hdr - 1);
  expect_error("cut short in its header");
  free(b);
}

static void a_corrupt_block_is_refused_by_name(void** state) {
  (void)state;
  record(1000, NULL, 0, 0);
  long size;
  unsigned char* b = slurp(bin_path(), &size);
  const long hdr = (long)sizeof(tx_record_header);
  tx_record_block first;
  memcpy(&first, b + hdr, sizeof first);
  long second = hdr + (long)(sizeof first + first.count * sizeof(tx_record));
  // one bit of a record in the second block
  b[second + 16 + 40] ^= 0x10;
  spill(bin_path(), b, size);
  expect_error("block 1 (records ");
  expect_error("checksum mismatch");
  b[second + 16 + 40] ^= 0x10;
  // the block header's count, made 256 more: past any block, however the
  // writer's drains cut them (a low bit could leave a count that still fits)
  b[second + 9] ^= 0x01;
  spill(bin_path(), b, size);
  expect_error("block 1 at byte");
  b[second + 9] ^= 0x01;
  // the header: its rate
  b[20] ^= 0x01;
  spill(bin_path(), b, size);
  expect_error("header checksum mismatch");
  b[20] ^= 0x01;
  // the repro: 2000 random bytes after offset 104
  srand(11);
  for (int i = 0; i < 2000; i++) b[hdr + rand() % (size - hdr)] = (unsigned char)rand();
  spill(bin_path(), b, size);
  expect_error("block");
  free(b);
}

// values with a good checksum that no device sends, nor the safety chain lets out
static void implausible_values_are_refused(void** state) {
  (void)state;
  tx_record bad = sample(300);
  bad.pos[1] = 1e300;
  record(1000, &bad, 1, 300);
  expect_error("record 300 (block 1): a position is not finite or beyond 10 m");
  bad = sample(5);
  bad.force[2] = NAN;
  record(10, &bad, 1, 5);
  expect_error("record 5 (block 0): the force sent is not finite");
  bad.force[2] = 3.4; // above the device's 3.3 N
  record(10, &bad, 1, 5);
  expect_error("record 5 (block 0): the force sent");
  bad = sample(5);
  bad.t_s = sample(4).t_s;
  record(10, &bad, 1, 5);
  expect_error("record 5 (block 0): time does not increase");
  bad = sample(5);
  bad.t_s = INFINITY;
  record(10, &bad, 1, 5);
  expect_error("record 5 (block 0): time is not in");
  bad = sample(5);
  bad.quat[0] = 0;
  record(10, &bad, 1, 5);
  expect_error("record 5 (block 0): the orientation is not a unit quaternion");
  bad = sample(5);
  bad.buttons = 0.5;
  record(10, &bad, 1, 5);
  expect_error("buttons");
  // the extremes of a double that a device may send: read back as they are
  tx_record fine[3] = {sample(5), sample(6), sample(7)};
  fine[0].pos[0] = 4.1e-312, fine[1].pos[1] = -0.0, fine[2].pos[2] = DBL_MIN;
  fine[0].force[0] = -4.1e-312, fine[1].force[1] = DBL_MIN, fine[2].force[2] = -0.0;
  fine[0].force_model[0] = DBL_MAX; // the model read is kept as it was, whatever it was
  record(10, fine, 3, 5);
  size_t count;
  char warn[512];
  assert_int_equal(load(&count, warn), 0);
  assert_int_equal(count, 10);
}

// the CSV export and the plots' reader agree on every bit of t, position and force
static void the_csv_reads_back_bit_for_bit(void** state) {
  (void)state;
  tx_record fine[4] = {sample(5), sample(6), sample(7), sample(8)};
  fine[0].pos[0] = 4.1e-312, fine[1].pos[1] = -0.0, fine[2].pos[2] = DBL_MIN, fine[3].pos[0] = 0x1p-1074;
  fine[0].force[0] = -4.1e-312, fine[1].force[1] = DBL_MIN, fine[2].force[2] = -0.0, fine[3].force[1] = 0.1;
  fine[3].t_s = nextafter(fine[3].t_s, 1);
  record(20, fine, 4, 5);
  char csv[128];
  snprintf(csv, sizeof csv, "%s/device0.csv", dir);
  tx_trace t;
  if (tx_trace_load(csv, &t)) fail_msg("%s", tx_error());
  assert_int_equal(t.n, 20);
  for (int i = 0; i < 20; i++) {
    tx_record want = i >= 5 && i < 9 ? fine[i - 5] : sample((size_t)i);
    assert_memory_equal(&t.t[i], &want.t_s, sizeof(double));
    for (int k = 0; k < 3; k++) {
      assert_memory_equal(&t.p[k][i], &want.pos[k], sizeof(double));
      assert_memory_equal(&t.f[k][i], &want.force[k], sizeof(double));
    }
  }
  tx_trace_free(&t);
}

// version 1: the records straight after the header, no checksums
static void version_1_files_still_read(void** state) {
  (void)state;
  tx_record_header h = {TX_RECORD_MAGIC, 1, sizeof(tx_record), 1000, 0, 0, touch};
  FILE* f = fopen(bin_path(), "wb");
  assert_non_null(f);
  fwrite(&h, sizeof h, 1, f);
  for (size_t i = 0; i < 50; i++) {
    tx_record r = sample(i);
    fwrite(&r, sizeof r, 1, f);
  }
  fwrite("partial", 7, 1, f); // a killed run's last record
  fclose(f);
  size_t count;
  char warn[512];
  assert_int_equal(load(&count, warn), 0);
  assert_int_equal(count, 50);
  assert_non_null(strstr(warn, "ends in the middle of a record"));
  h.version = 3;
  f = fopen(bin_path(), "r+b");
  fwrite(&h, sizeof h, 1, f);
  fclose(f);
  expect_error("version is neither 1 nor 2");
}

// a write that fails (here EFBIG past RLIMIT_FSIZE, as ENOSPC on a full disk)
// is seen by the haptics thread at once, and the stop reports it
static void a_failed_write_is_seen_at_once(void** state) {
  (void)state;
  struct rlimit old;
  assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
  void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = {20000, old.rlim_max};
  assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
  tx_recorder* r = tx_recorder_start(dir, 0, 1000, &touch);
  assert_non_null(r);
  const char* file = NULL;
  assert_int_equal(tx_recorder_error(r, &file), 0);
  int e = 0;
  for (size_t i = 0; i < 5000 && !e; i++) { // 1 ms apart, as at 1 kHz
    tx_record q = sample(i);
    assert_true(tx_recorder_push(r, &q)); // the ring is drained on, never full
    sleep_ms(1);
    e = tx_recorder_error(r, &file);
    if (e) print_message("  the write failed %zu records in: %s\n", i + 1, strerror(e));
  }
  assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
  signal(SIGXFSZ, was);
  assert_int_equal(e, EFBIG);
  assert_string_equal(file, bin_path());
  assert_int_equal(tx_recorder_stop(r), -1);
  assert_non_null(strstr(tx_error(), "device0.bin: File too large"));
}

// the haptics controller sees the failed write at its next step and stops the
// run with the reason, long before its duration (600 s; lockstep runs far
// faster than real time, so the bound is loose)
static void a_failed_write_stops_the_run(void** state) {
  (void)state;
  static const char text[] =
      "{\"name\":\"t\",\"controllers\":["
      "{\"name\":\"wall\",\"type\":\"collision.wall\",\"rate_hz\":60,\"params\":{\"stiffness\":300}},"
      "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":"
      "\"sim:hand_stiffness=200,hand=pierce-down\",\"force_model\":\"tool0.force_model\"}}]}";
  tx_scenario* sc = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!sc) fail_msg("%s", tx_error());
  struct rlimit old;
  assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
  void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = {20000, old.rlim_max};
  assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
  tx_run_options o = {.duration_s = 600, .lockstep = true, .record_dir = dir};
  tx_run_result r;
  int rc = tx_system_run(sc->system, &o, &r);
  assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
  signal(SIGXFSZ, was);
  if (rc) fail_msg("%s", tx_error());
  print_message("  %s at t = %.3f s of 600 s\n", r.halt_reason, r.halt_t_s);
  assert_true(r.halted);
  char want[256];
  snprintf(want, sizeof want, "haptics: %s: File too large", bin_path());
  assert_string_equal(r.halt_reason, want);
  assert_true(r.halt_t_s > 0 && r.halt_t_s < 300);
  tx_scenario_free(sc);
}

// the CSV is written in finish, after the last step: one that cannot be
// written (its temporary file is taken by a folder here) still stops the run,
// whose result then names the file, as a stop in a step does
static void a_recording_that_cannot_be_finished_stops_the_run(void** state) {
  (void)state;
  static const char text[] =
      "{\"name\":\"t\",\"controllers\":["
      "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:pierce-down\"}}]}";
  tx_scenario* sc = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!sc) fail_msg("%s", tx_error());
  char taken[128];
  snprintf(taken, sizeof taken, "%s/device0.csv.tmp", dir);
  assert_int_equal(mkdir(taken, 0755), 0);
  tx_run_options o = {.duration_s = 0.2, .lockstep = true, .record_dir = dir};
  tx_run_result r;
  if (tx_system_run(sc->system, &o, &r)) fail_msg("%s", tx_error());
  print_message("  %s at t = %.3f s\n", r.halt_reason, r.halt_t_s);
  assert_true(r.halted);
  char want[256];
  snprintf(want, sizeof want, "haptics: recording: %s: Is a directory", taken);
  assert_string_equal(r.halt_reason, want);
  assert_true(fabs(r.halt_t_s - 0.199) < 1e-9); // the last step's time
  tx_scenario_free(sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(records_read_back_bit_for_bit, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(a_crash_leaves_whole_records_on_disk, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(a_file_cut_short_gives_its_whole_blocks, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(a_corrupt_block_is_refused_by_name, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(implausible_values_are_refused, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(the_csv_reads_back_bit_for_bit, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(version_1_files_still_read, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(a_failed_write_is_seen_at_once, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(a_failed_write_stops_the_run, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(a_recording_that_cannot_be_finished_stops_the_run, make_dir, remove_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
