// scripted: a device that follows waypoints, for headless and repeatable runs.
//
// "scripted:NAME" plays a built-in motion of the suturing skin tests, or
// "insert" of the needle-insertion scenario;
// "scripted:FILE.csv" plays a waypoint file, one row per waypoint:
//   t_s, x_m, y_m, z_m [, qw, qx, qy, qz] [, grip_rad [, buttons]]
// (buttons: the bits held from that row until the next, not interpolated)
// A relative FILE that is not there from the working folder is looked up on
// the scenario search path ($TACTUS_SCENARIO_PATH, then the source tree's
// scenarios/), where a scenario keeps its files beside its JSON:
// "scripted:instruments/hand0.csv" is scenarios/instruments/hand0.csv. Last,
// the assets' folder, where a procedure's waypoints live:
// "scripted:procedures/lagb/hand0.csv" is assets/procedures/lagb/hand0.csv.
// Rows are interpolated linearly (orientation by normalised lerp); after the
// last row the device holds still. Lines starting with '#' and a first line
// of column names are skipped. Forces written to it are ignored.
#include "device.h"

#include "../../model/error.h"
#include "device_scripted.h"

#if defined(__has_include) // the fuzzer builds this file alone, without the generated config
#if __has_include(<tactus/config.h>)
#include <tactus/config.h> // TX_SCENARIO_DIR
#endif
#endif

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ROWS_MAX 1000000

typedef struct waypoint {
  double t;       // s
  double pos[3];  // m
  double quat[4]; // w, x, y, z
  double grip;    // rad
  double buttons; // bits held from this row on
} waypoint;

struct tx_device {
  waypoint* w;
  size_t count;
};

// The skin tests of the suturing journal paper, in metres: the skin's
// mid-plane is y = 0; a 0.4 cm skin and a 0.05 cm HIP touch at |y| = 2.5 mm,
// so the sliding motions run at |y| = 2 mm, 0.5 mm into the skin.
// Piercing moves at 5 mm/s along y, sliding at 10 mm/s along x or z.
static const tx_hand_motion motions[] = {
    {"pierce-down", 4, {{0, 0, 0.010, 0}, {0.5, 0, 0.010, 0}, {4.5, 0, -0.010, 0}, {5.0, 0, -0.010, 0}}},
    {"pierce-up", 4, {{0, 0, -0.010, 0}, {0.5, 0, -0.010, 0}, {4.5, 0, 0.010, 0}, {5.0, 0, 0.010, 0}}},
    {"slide-x-over", 5, {{0, -0.03, 0.010, 0}, {1.0, -0.03, 0.002, 0}, {7.0, 0.03, 0.002, 0}, {8.0, 0.03, 0.010, 0}, {8.5, 0.03, 0.010, 0}}},
    {"slide-x-under", 5, {{0, -0.03, -0.010, 0}, {1.0, -0.03, -0.002, 0}, {7.0, 0.03, -0.002, 0}, {8.0, 0.03, -0.010, 0}, {8.5, 0.03, -0.010, 0}}},
    {"slide-z-over", 5, {{0, 0, 0.010, -0.03}, {1.0, 0, 0.002, -0.03}, {7.0, 0, 0.002, 0.03}, {8.0, 0, 0.010, 0.03}, {8.5, 0, 0.010, 0.03}}},
    {"slide-z-under", 5, {{0, 0, -0.010, -0.03}, {1.0, 0, -0.002, -0.03}, {7.0, 0, -0.002, 0.03}, {8.0, 0, -0.010, 0.03}, {8.5, 0, -0.010, 0.03}}},
    // the voxel needle-insertion scenario: from 1 mm above the surface y = 0
    // straight down at 3 mm/s to 4 mm deep, then straight back out at 3 mm/s
    {"insert", 5, {{0, 0, 0.001, 0}, {0.2, 0, 0.001, 0}, {0.2 + 5.0 / 3, 0, -0.004, 0}, {0.2 + 10.0 / 3, 0, 0.001, 0}, {3.8, 0, 0.001, 0}}},
    // tactus study skin-paper: the pierce motions start 3 cm away; under
    // gravity the 42 x 42 skin hangs about 3 cm (docs/skin.md), so its pierce
    // starts 6 cm below (5 mm/s)
    {"paper-pierce-up", 4, {{0, 0, -0.030, 0}, {0.2, 0, -0.030, 0}, {9.2, 0, 0.015, 0}, {9.5, 0, 0.015, 0}}},
    {"paper-pierce-up-hanging", 4, {{0, 0, -0.060, 0}, {0.2, 0, -0.060, 0}, {12.2, 0, 0.0, 0}, {12.5, 0, 0.0, 0}}},
    {"paper-pierce-down", 4, {{0, 0, 0.030, 0}, {0.2, 0, 0.030, 0}, {9.2, 0, -0.015, 0}, {9.5, 0, -0.015, 0}}},
    // tactus study skin-accuracy: down through the skin at 1 cm/s
    {"accuracy-pierce-down", 4, {{0, 0, 0.010, 0}, {0.2, 0, 0.010, 0}, {2.7, 0, -0.015, 0}, {3.0, 0, -0.015, 0}}},
    // scenario thread-knot: the thread lies along +x to its pinned tail at
    // x = 0.2 m; the head doubles back above it (a bight), crosses over the
    // standing part, back under it, up through the bight and over its upper
    // strand (an overhand knot), then pulls along +y until the bight closes
    {"thread-overhand", 10, {{0, 0, 0, 0}, {0.5, 0, 0.005, 0}, {2.0, 0.14, 0.005, 0}, {2.3, 0.15, -0.005, 0.003},
                             {2.6, 0.125, -0.005, -0.003}, {2.9, 0.125, 0.0025, -0.003}, {3.1, 0.125, 0.0025, 0.003},
                             {3.4, 0.125, 0.012, 0.003}, {5.0, 0.125, 0.072, 0}, {5.5, 0.125, 0.072, 0}}},
    // the same knot, then pulled on along +y until the thread is taut from
    // the head to the pinned tail (0.186 m apart: the knot takes the rest)
    {"thread-overhand-tight", 11, {{0, 0, 0, 0}, {0.5, 0, 0.005, 0}, {2.0, 0.14, 0.005, 0}, {2.3, 0.15, -0.005, 0.003},
                                   {2.6, 0.125, -0.005, -0.003}, {2.9, 0.125, 0.0025, -0.003}, {3.1, 0.125, 0.0025, 0.003},
                                   {3.4, 0.125, 0.012, 0.003}, {5.0, 0.125, 0.072, 0}, {6.0, 0.125, 0.17, 0}, {6.5, 0.125, 0.17, 0}}},
};

const tx_hand_motion* tx_hand_motion_find(const char* name) {
  for (size_t i = 0; i < sizeof motions / sizeof motions[0]; i++)
    if (strcmp(name, motions[i].name) == 0) return &motions[i];
  return NULL;
}

static tx_device* with_rows(size_t count) {
  tx_device* d = calloc(1, sizeof *d);
  if (d && !(d->w = calloc(count, sizeof *d->w))) {
    free(d);
    d = NULL;
  }
  if (d) d->count = count;
  return d;
}

static tx_device* from_motion(const tx_hand_motion* m) {
  tx_device* d = with_rows((size_t)m->count);
  for (int i = 0; d && i < m->count; i++)
    d->w[i] = (waypoint){m->t_pos[i][0], {m->t_pos[i][1], m->t_pos[i][2], m->t_pos[i][3]}, {1, 0, 0, 0}, 0, 0};
  return d;
}

// parse one row of 4, 5, 8, 9 or 10 numbers; returns a message or NULL
static const char* parse_row(char* line, waypoint* w) {
  double v[11];
  int n = 0;
  for (char* p = line; n < 11;) {
    char* end;
    errno = 0;
    v[n] = strtod(p, &end);
    if (end == p || errno || !isfinite(v[n])) return "expected a finite number";
    n++;
    while (*end == ' ' || *end == '\t') end++;
    if (*end == ',') p = end + 1;
    else if (*end == 0 || *end == '\n' || *end == '\r') break;
    else return "expected ',' between numbers";
  }
  if (n != 4 && n != 5 && n != 8 && n != 9 && n != 10)
    return "expected 4, 5, 8 or 9 columns: t, x, y, z [, qw, qx, qy, qz] [, grip] (or a 10th: buttons)";
  *w = (waypoint){v[0], {v[1], v[2], v[3]}, {1, 0, 0, 0}, 0, 0};
  if (n >= 8) {
    // scaled by the largest component first, so that a huge one cannot overflow the norm
    double m = fmax(fmax(fabs(v[4]), fabs(v[5])), fmax(fabs(v[6]), fabs(v[7])));
    if (!(m > 1e-9)) return "the quaternion is zero";
    double q = 0;
    for (int i = 0; i < 4; i++) q += (v[4 + i] / m) * (v[4 + i] / m);
    for (int i = 0; i < 4; i++) w->quat[i] = v[4 + i] / m / sqrt(q);
  }
  if (n == 5 || n == 9) w->grip = v[n - 1];
  if (n == 10) w->grip = v[8], w->buttons = v[9];
  if (n == 10 && (v[9] < 0 || v[9] >= 4294967296.0 || v[9] != floor(v[9]))) return "buttons: an integer in [0, 2^32)";
  for (int i = 0; i < 3; i++)
    if (fabs(w->pos[i]) > 10) return "a position beyond 10 m (the file must be in metres)";
  return NULL;
}

tx_device* tx_scripted_read_csv(FILE* f, const char* path) {
  size_t cap = 256, count = 0;
  tx_device* d = with_rows(cap);
  char line[1024];
  int lineno = 0;
  const char* problem = NULL;
  while (d && !problem && fgets(line, sizeof line, f)) {
    lineno++;
    if (!strchr(line, '\n') && !feof(f)) problem = "line longer than 1023 characters";
    else if (line[0] == '#' || line[strspn(line, " \t\r\n")] == 0) continue;
    else if (lineno == 1 && !strchr("+-.0123456789", line[strspn(line, " \t")])) continue; // column names
    else if (count == ROWS_MAX) problem = "more than 1000000 waypoints";
    else {
      if (count == cap) {
        waypoint* grown = realloc(d->w, 2 * cap * sizeof *grown);
        if (!grown) {
          problem = "out of memory";
          break;
        }
        d->w = grown, cap *= 2;
      }
      problem = parse_row(line, &d->w[count]);
      if (!problem && d->w[count].t < 0) problem = "time must not be negative";
      // rows closer than 1 us would make the velocity between them overflow
      if (!problem && count && !(d->w[count].t - d->w[count - 1].t >= 1e-6))
        problem = "time must increase by at least 1 us from row to row";
      count++;
    }
  }
  if (!problem && d && count == 0) problem = "no waypoints", lineno = 0;
  if (problem || !d) {
    if (lineno) tx_set_error("%s:%d: %s", path, lineno, problem ? problem : "out of memory");
    else tx_set_error("%s: %s", path, problem ? problem : "out of memory");
    if (d) free(d->w);
    free(d);
    return NULL;
  }
  d->count = count;
  return d;
}

static tx_device* open_scripted(const char* arg, double period_s) {
  (void)period_s;
  const tx_hand_motion* m = tx_hand_motion_find(arg);
  if (m) return from_motion(m);
  size_t len = strlen(arg);
  if (len > 4 && strcmp(arg + len - 4, ".csv") == 0) {
    FILE* f = fopen(arg, "r");
    int err = errno;
    char path[PATH_MAX];
    const char* env = getenv("TACTUS_SCENARIO_PATH");
    for (const char* dir = env; !f && arg[0] != '/' && dir && *dir;) { // the scenario search path, in order
      size_t n = strcspn(dir, ":");
      if (n > 0 && snprintf(path, sizeof path, "%.*s/%s", (int)n, dir, arg) < (int)sizeof path) f = fopen(path, "r");
      dir += n + (dir[n] == ':');
    }
#ifdef TX_SCENARIO_DIR
    if (!f && arg[0] != '/' && snprintf(path, sizeof path, "%s/%s", TX_SCENARIO_DIR, arg) < (int)sizeof path)
      f = fopen(path, "r");
#endif
#ifdef TX_ASSET_DIR
    if (!f && arg[0] != '/' && snprintf(path, sizeof path, "%s/%s", TX_ASSET_DIR, arg) < (int)sizeof path) f = fopen(path, "r");
#endif
    if (!f) return tx_set_error("%s: %s", arg, strerror(err)), NULL;
    tx_device* d = tx_scripted_read_csv(f, arg);
    fclose(f);
    return d;
  }
  char names[512] = "";
  for (size_t i = 0; i < sizeof motions / sizeof motions[0]; i++) {
    size_t used = strlen(names);
    snprintf(names + used, sizeof names - used, "%s%s", i ? ", " : "", motions[i].name);
  }
  tx_set_error("device 'scripted:%s': expected a .csv file or one of %s", arg, names);
  return NULL;
}

static void info_scripted(const tx_device* d, tx_device_info* out) {
  // a scripted hand has no device limits of its own: those of a Touch-class device
  (void)d;
  *out = (tx_device_info){.max_force = 3.3, .max_stiffness = 500, .damping = 0,
                          .workspace_min = {-0.5, -0.5, -0.5}, .workspace_max = {0.5, 0.5, 0.5}};
}

static bool read_scripted(tx_device* d, double t, tx_device_state* s) {
  size_t i = 0; // the segment w[i]..w[i+1] holding t (few rows: a linear search is fine)
  while (i + 1 < d->count && d->w[i + 1].t <= t) i++;
  const waypoint* a = &d->w[i];
  const waypoint* b = i + 1 < d->count ? &d->w[i + 1] : a;
  double span = b->t - a->t;
  double u = span > 0 ? fmin(fmax((t - a->t) / span, 0), 1) : 0;
  double q = 0;
  for (int k = 0; k < 3; k++) {
    s->pos[k] = a->pos[k] + u * (b->pos[k] - a->pos[k]);
    s->vel[k] = span > 0 && t >= a->t && t < b->t ? (b->pos[k] - a->pos[k]) / span : 0;
  }
  // q and -q are one orientation: interpolate along the short way
  double dot = 0;
  for (int k = 0; k < 4; k++) dot += a->quat[k] * b->quat[k];
  double sign = dot < 0 ? -1 : 1;
  for (int k = 0; k < 4; k++) {
    s->quat[k] = a->quat[k] + u * (sign * b->quat[k] - a->quat[k]);
    q += s->quat[k] * s->quat[k];
  }
  for (int k = 0; k < 4; k++) s->quat[k] /= sqrt(q);
  s->grip = a->grip + u * (b->grip - a->grip);
  s->buttons = (uint32_t)a->buttons; // held until the next row
  s->t_ns = (int64_t)llround(t * 1e9);
  return true;
}

static void write_scripted(tx_device* d, const double force[3]) { (void)d, (void)force; }

static void close_scripted(tx_device* d) {
  free(d->w);
  free(d);
}

const tx_device_backend tx_device_scripted = {"scripted", open_scripted, info_scripted, read_scripted, write_scripted,
                                              close_scripted, NULL, NULL};
