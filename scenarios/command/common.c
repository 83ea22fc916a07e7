// What the subcommands share: errors, numbers, output folders, progress.
#include "command.h"

#include <errno.h>
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

// mkdir -p
static int make_dirs(const char* path) {
  char p[4096];
  if (snprintf(p, sizeof p, "%s", path) >= (int)sizeof p) return errno = ENAMETOOLONG, -1;
  for (char* c = *p ? p + 1 : p; *c; c++) { // an empty path has nothing past its NUL
    if (*c != '/') continue;
    *c = 0;
    if (mkdir(p, 0755) != 0 && errno != EEXIST) return -1;
    *c = '/';
  }
  if (mkdir(p, 0755) != 0 && errno != EEXIST) return -1;
  struct stat st;
  if (stat(p, &st) != 0) return -1;
  if (!S_ISDIR(st.st_mode)) return errno = ENOTDIR, -1;
  return 0;
}

int tx_out_dir(const char* given, const char* stem, char* dir, size_t n, char* err, size_t en) {
  if (given) {
    snprintf(dir, n, "%s", given);
  } else {
    char stamp[32];
    time_t now = time(NULL);
    strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", localtime(&now));
    snprintf(dir, n, "out/%s-%s", stem, stamp);
    for (int k = 2; access(dir, F_OK) == 0 && k < 100; k++) snprintf(dir, n, "out/%s-%s-%d", stem, stamp, k);
  }
  if (make_dirs(dir) != 0) return snprintf(err, en, "--out %s: %s", dir, strerror(errno)), -1;
  // prove the folder takes files before any work is done
  char probe[4200];
  snprintf(probe, sizeof probe, "%s/.tactus-probe", dir);
  FILE* f = fopen(probe, "w");
  if (!f) return snprintf(err, en, "--out %s: %s", dir, strerror(errno)), -1;
  fclose(f);
  remove(probe);
  return 0;
}

tx_scenario* tx_load_for_command(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                 int ndevices) {
  return tx_load_for_command_view(name, sets, nsets, devices, ndevices, NULL, NULL, false);
}

tx_scenario* tx_load_for_command_view(const char* name, const char* const* sets, int nsets, const char* const* devices,
                                      int ndevices, const char* view, const char* stereo, bool lockstep) {
  char path[PATH_MAX], err[1024];
  if (tx_scenario_locate(name, path, sizeof path, err, sizeof err)) return tx_bad_input("%s", err), NULL;
  tx_load_options o = {sets, nsets, true, devices, ndevices, view, stereo, lockstep};
  tx_scenario* s = tx_scenario_load(path, &o, err, sizeof err);
  if (!s) tx_bad_input("%s", err);
  return s;
}

static volatile sig_atomic_t stop_requested;

static void on_stop(int sig) {
  (void)sig;
  stop_requested = 1;
}

void tx_catch_stop_signals(void) {
  struct sigaction sa = {0};
  sa.sa_handler = on_stop;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

bool tx_progress(double elapsed_s, void* total_s) {
  if (isatty(STDERR_FILENO)) fprintf(stderr, "\r  %.1f / %.1f s ", elapsed_s, *(double*)total_s);
  return !stop_requested;
}
