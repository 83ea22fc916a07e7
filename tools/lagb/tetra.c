// Tetrahedra by the tetgen program (see tetra.h).
#include "tools/lagb/tetra.h"

#include "model/error.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

enum { TETGEN_SECONDS = 60 };

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// the last line tetgen wrote that says something, for the one-line error
static void last_words(const char* log, char* out, size_t n) {
  out[0] = 0;
  FILE* f = fopen(log, "r");
  if (!f) return;
  char buf[512];
  while (fgets(buf, sizeof buf, f)) {
    buf[strcspn(buf, "\r\n")] = 0;
    char* s = buf;
    while (*s == ' ' || *s == '\t') s++;
    if (*s && strncmp(s, "Warning", 7) != 0 && snprintf(out, n, "%s", s) >= (int)n) out[n - 1] = 0;
  }
  fclose(f);
}

// runs tetgen SWITCHES surf.off in DIR with its output in DIR/log; its
// status, or -1. In DIR, so that the comment tetgen writes into its files
// names surf.off and not a temporary folder: the files are reproducible.
static int run_tetgen(const char* tetgen, const char* sw, const char* dir) {
  char exe[PATH_MAX];
  if (!realpath(tetgen, exe)) return -1;
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    if (chdir(dir) != 0) _exit(126);
    int fd = open("log", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, 1), dup2(fd, 2), close(fd);
    execl(exe, "tetgen", sw, "surf.off", (char*)NULL);
    _exit(127);
  }
  // a guard against a run that does not end
  double t0 = now();
  for (;;) {
    int status;
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    if (r < 0 && errno != EINTR) return -1;
    if (now() - t0 > TETGEN_SECONDS) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return 124;
    }
    nanosleep(&(struct timespec){0, 2000000}, NULL);
  }
}

// the count in the header of an .ele file, or -1
static int ele_count(const char* path) {
  FILE* f = fopen(path, "r");
  if (!f) return -1;
  char buf[256];
  int n = -1;
  while (n < 0 && fgets(buf, sizeof buf, f))
    if (buf[0] != '#' && sscanf(buf, "%d", &n) != 1) n = -1;
  fclose(f);
  return n;
}

// tetgen's working folder and all it wrote there (.off, .1.node, .1.smesh, ...)
static void remove_work(const char* dir) {
  DIR* d = opendir(dir);
  if (d) {
    struct dirent* e;
    char p[4400];
    while ((e = readdir(d)))
      if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && snprintf(p, sizeof p, "%s/%s", dir, e->d_name) < (int)sizeof p)
        remove(p);
    closedir(d);
  }
  rmdir(dir);
}

bool tx_lagb_tetgen(const tx_trimesh* s, const char* prefix, const char* switches, const char* tetgen, int* tets) {
  return tx_lagb_tetgen_sized(s, NULL, prefix, switches, tetgen, tets);
}

// surf.mtr: one size a vertex, which tetgen -m reads beside surf.off
static bool write_sizes(const char* path, const double* sizes, int n) {
  FILE* f = fopen(path, "w");
  if (!f) return tx_set_error("%s: cannot write: %s", path, strerror(errno)), false;
  fprintf(f, "%d 1\n", n);
  for (int i = 0; i < n; i++) fprintf(f, "%.9g\n", sizes[i]);
  if (fclose(f) != 0) return tx_set_error("%s: cannot write", path), false;
  return true;
}

bool tx_lagb_tetgen_sized(const tx_trimesh* s, const double* sizes, const char* prefix, const char* switches,
                          const char* tetgen, int* tets) {
  *tets = 0;
  if (!tetgen || access(tetgen, X_OK) != 0) {
    tx_set_error("the tetgen program was not found (%s): install the tetgen package",
                 tetgen && *tetgen ? tetgen : "none");
    return false;
  }
  char dir[4200], off[4300], log[4300], ele[4300];
  if (snprintf(dir, sizeof dir, "%s.tetgen.XXXXXX", prefix) >= (int)sizeof dir || !mkdtemp(dir)) {
    tx_set_error("%s: cannot make a working folder: %s", prefix, strerror(errno));
    return false;
  }
  snprintf(off, sizeof off, "%s/surf.off", dir);
  snprintf(log, sizeof log, "%s/log", dir);
  snprintf(ele, sizeof ele, "%s/surf.1.ele", dir);
  char mtr[4300];
  snprintf(mtr, sizeof mtr, "%s/surf.mtr", dir);
  if (!tx_trimesh_write_off(s, off) || (sizes && !write_sizes(mtr, sizes, s->nv))) {
    remove_work(dir);
    return false;
  }
  int rc = run_tetgen(tetgen, switches, dir);
  int n = rc == 0 ? ele_count(ele) : -1;
  if (n <= 0) {
    char words[300];
    last_words(log, words, sizeof words);
    tx_set_error("tetgen %s failed (%s%d)%s%s", switches, rc == 124 ? "timed out, " : "status ", rc,
                 *words ? ": " : "", words);
    remove_work(dir);
    return false;
  }
  // the three files appear together, or none
  const char* ext[] = {"node", "ele", "face"};
  char from[3][4300], to[3][4300];
  for (int i = 0; i < 3; i++) {
    snprintf(from[i], sizeof from[i], "%s/surf.1.%s", dir, ext[i]);
    if (snprintf(to[i], sizeof to[i], "%s.%s", prefix, ext[i]) >= (int)sizeof to[i]) {
      tx_set_error("%s: path too long", prefix);
      remove_work(dir);
      return false;
    }
  }
  for (int i = 0; i < 3; i++)
    if (rename(from[i], to[i]) != 0) {
      tx_set_error("%s: cannot write: %s", to[i], strerror(errno));
      for (int j = 0; j < i; j++) remove(to[j]);
      remove_work(dir);
      return false;
    }
  remove_work(dir);
  *tets = n;
  return true;
}
