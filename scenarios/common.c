// What the subcommands share: errors, numbers, output folders, progress.
#include "command.h"

#include "../model/error.h"

#include <dirent.h>
#include <errno.h>
#include <ftw.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

const char* tx_program = "tactus";

int tx_bad_input(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  char line[2048];
  vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  // arguments are quoted in messages: keep the message one line
  for (char* c = line; *c; c++)
    if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = '?';
  fprintf(stderr, "%s: %s\n", tx_program, line);
  return TX_EXIT_BAD_INPUT;
}

bool tx_parse_num(const char* s, double min, double max, double* out) {
  char* end = NULL;
  errno = 0;
  double v = strtod(s, &end);
  if (!*s || *end || errno || !isfinite(v) || v < min || v > max) return false;
  *out = v;
  return true;
}

// mkdir -p; made receives the outermost folder it made ("" if none)
static int make_dirs(const char* path, char* made, size_t mn) {
  char p[4096];
  *made = 0;
  if (snprintf(p, sizeof p, "%s", path) >= (int)sizeof p || strlen(path) >= mn) return errno = ENAMETOOLONG, -1;
  for (char* c = *p ? p + 1 : p;; c++) { // an empty path has nothing past its NUL
    if (*c != '/' && *c) continue;
    char end = *c;
    *c = 0;
    if (mkdir(p, 0755) == 0) {
      if (!*made) snprintf(made, mn, "%s", p);
    } else if (errno != EEXIST) {
      return -1;
    }
    *c = end;
    if (!end) break;
  }
  struct stat st;
  if (stat(p, &st) != 0) return -1;
  if (!S_ISDIR(st.st_mode)) return errno = ENOTDIR, -1;
  return 0;
}

static int remove_one(const char* path, const struct stat* st, int flag, struct FTW* ftw) {
  (void)st, (void)flag, (void)ftw;
  remove(path);
  return 0;
}

// rm -r, never following links out of the folder
static void remove_tree(const char* path) { nftw(path, remove_one, 16, FTW_DEPTH | FTW_PHYS); }

static int no_dots(const struct dirent* e) { return strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0; }

int tx_out_check(const char* given, bool force) {
  if (!given || force) return 0;
  struct dirent** entries = NULL;
  int n = scandir(given, &entries, no_dots, alphasort);
  if (n <= 0) return free(entries), 0; // missing (made later) or empty; other faults are named when it is made
  char first[256];
  snprintf(first, sizeof first, "%s", entries[0]->d_name);
  for (int i = 0; i < n; i++) free(entries[i]);
  free(entries);
  return tx_bad_input("--out %s: not empty (it holds %s%s); choose a new folder, or add --force to write into it", given,
                      first, n > 1 ? ", ..." : "");
}

int tx_out_open(tx_out* o, const char* given, const char* stem) {
  *o = (tx_out){0};
  if (given) {
    snprintf(o->dir, sizeof o->dir, "%s", given);
  } else {
    char stamp[32];
    time_t now = time(NULL);
    strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", localtime(&now));
    snprintf(o->dir, sizeof o->dir, "out/%s-%s", stem, stamp);
    for (int k = 2; access(o->dir, F_OK) == 0 && k < 100; k++) snprintf(o->dir, sizeof o->dir, "out/%s-%s-%d", stem, stamp, k);
  }
  if (make_dirs(o->dir, o->made, sizeof o->made) != 0) {
    tx_set_error("--out %s: %s", o->dir, strerror(errno));
    return tx_out_discard(o), -1;
  }
  // what it held before (with --force): a failed run removes only what it added
  struct dirent** entries = NULL;
  int n = *o->made ? 0 : scandir(o->dir, &entries, no_dots, alphasort);
  if (n > 0 && (o->had = calloc(n, sizeof *o->had))) {
    for (int i = 0; i < n; i++) o->had[o->nhad++] = strdup(entries[i]->d_name);
  }
  for (int i = 0; i < n; i++) free(entries[i]);
  free(entries);
  // prove the folder takes files before any work is done
  char probe[4200];
  snprintf(probe, sizeof probe, "%s/.tactus-probe", o->dir);
  FILE* f = fopen(probe, "w");
  if (!f) {
    tx_set_error("--out %s: %s", o->dir, strerror(errno));
    return tx_out_discard(o), -1;
  }
  fclose(f);
  remove(probe);
  return 0;
}

static bool had(const tx_out* o, const char* name) {
  for (int i = 0; i < o->nhad; i++)
    if (o->had[i] && strcmp(o->had[i], name) == 0) return true;
  return false;
}

void tx_out_discard(tx_out* o) {
  if (*o->made) {
    remove_tree(o->made);
  } else if (*o->dir) {
    struct dirent** entries = NULL;
    int n = scandir(o->dir, &entries, no_dots, alphasort);
    for (int i = 0; i < n; i++) {
      char path[4400];
      snprintf(path, sizeof path, "%s/%s", o->dir, entries[i]->d_name);
      if (!had(o, entries[i]->d_name)) remove_tree(path);
      free(entries[i]);
    }
    free(entries);
  }
  tx_out_close(o);
}

void tx_out_close(tx_out* o) {
  for (int i = 0; i < o->nhad; i++) free(o->had[i]);
  free(o->had);
  o->had = NULL;
  o->nhad = 0;
  *o->made = 0;
}

bool tx_out_empty(const tx_out* o) {
  struct dirent** entries = NULL;
  int n = scandir(o->dir, &entries, no_dots, alphasort), added = 0;
  for (int i = 0; i < n; i++) {
    added += !had(o, entries[i]->d_name);
    free(entries[i]);
  }
  free(entries);
  return added == 0;
}

int tx_out_dir(const char* given, const char* stem, char* dir, size_t n) {
  tx_out o;
  if (tx_out_open(&o, given, stem)) return -1;
  snprintf(dir, n, "%s", o.dir);
  tx_out_close(&o);
  return 0;
}

tx_scenario* tx_load_for_command(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                 int ndevices) {
  return tx_load_for_command_view(name, sets, nsets, devices, ndevices, NULL, NULL, false);
}

tx_scenario* tx_load_for_command_view(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                      int ndevices, const char* view, const char* stereo, bool lockstep) {
  char path[PATH_MAX];
  if (tx_scenario_locate(name, path, sizeof path)) return tx_bad_input("%s", tx_error()), NULL;
  tx_load_options o = {sets, nsets, true, devices, ndevices, view, stereo, lockstep, NULL, NULL};
  tx_scenario* s = tx_scenario_load(path, &o);
  if (!s) tx_bad_input("%s", tx_error());
  return s;
}

static volatile sig_atomic_t stop_requested; // the signal, 0 for none
static volatile int64_t stop_first_ns;        // when it came

// The first signal stops the run cleanly. One more, a second or more later,
// ends the process at once, should a step never return; sooner it is the same
// request again (timeout(1) sends it to the child and to the process group).
static void on_stop(int sig) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  int64_t now = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
  if (!stop_requested) {
    stop_first_ns = now;
    stop_requested = sig;
  } else if (now - stop_first_ns > 1000000000) {
    signal(sig, SIG_DFL);
    raise(sig);
  }
}

void tx_catch_stop_signals(void) {
  struct sigaction sa = {.sa_handler = on_stop};
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

int tx_stop_signal(void) { return stop_requested; }

bool tx_progress(double elapsed_s, void* total_s) {
  if (isatty(STDERR_FILENO)) fprintf(stderr, "\r  %.1f / %.1f s ", elapsed_s, *(double*)total_s);
  return !stop_requested;
}
