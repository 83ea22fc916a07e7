// view.force_curve: records a tool's force and position at its rate into
// memory taken at configure, and writes a CSV and a force-displacement PNG
// once the run is over.
#include "force_curve.h"

#include "aside.h"
#include "plot.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { COLS = 11 }; // t, x y z, fx fy fz, contacts, pierced, torn, skin_t

typedef struct curve {
  tx_port pose, force, state, torn; // reads; state and torn may be invalid (id 0)
  int axis;                         // 0, 1, 2: x, y, z
  char file[64];                    // base name of the CSV and PNG
  bool png;                         // draw the PNG too
  double* rows;                     // (cap x COLS) the samples
  uint64_t cap, n;                  // capacity and samples taken
  tx_warning w_full;                // the recording filled up
  tx_result r_samples;
} curve;

static const tx_param_def params[] = {
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the tool pose read (f64 1 x 7)"},
    {"force", TX_PARAM_STR, NULL, 0, 0, 0, "device0.force", "the force read (f64 1 x 3)"},
    {"state", TX_PARAM_STR, NULL, 0, 0, 0, "hip0.state", "the HIP state read (f64 1 x 8)"},
    {"torn", TX_PARAM_STR, NULL, 0, 0, 0, "skin.torn", "the torn-link count read (i32 1 x 1)"},
    {"axis", TX_PARAM_STR, NULL, 0, 0, 0, "y", "the axis plotted: x, y or z"},
    {"file", TX_PARAM_STR, NULL, 0, 0, 0, "force_displacement", "base name of OUT/FILE.csv and OUT/FILE.png"},
    {"max_samples", TX_PARAM_INT, "1", 1, 10000000, 600000, NULL, "rows kept, allocated at configure"},
    {"png", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "also plot OUT/FILE.png"},
};

static int configure(tx_setup* s, void** self) {
  curve* c = calloc(1, sizeof *c);
  if (!c) return -1;
  *self = c;
  const char* pose = tx_table_str(s, "pose");
  const char* force = tx_table_str(s, "force");
  const char* state = tx_table_str(s, "state");
  const char* torn = tx_table_str(s, "torn");
  const char* axis = tx_table_str(s, "axis");
  const char* file = tx_table_str(s, "file");
  c->cap = (uint64_t)tx_table_int(s, "max_samples");
  c->png = tx_table_bool(s, "png");
  if (!pose || !force || !state || !torn || !axis || !file) return -1;
  if (strlen(axis) != 1 || axis[0] < 'x' || axis[0] > 'z') return tx_setup_fail(s, "axis", "expected x, y or z, got \"%s\"", axis);
  c->axis = axis[0] - 'x';
  size_t len = strlen(file);
  if (len == 0 || len >= sizeof c->file || strspn(file, "abcdefghijklmnopqrstuvwxyz0123456789_-") != len)
    return tx_setup_fail(s, "file", "expected a base name of letters, digits, _ and - (at most 63), got \"%s\"", file);
  memcpy(c->file, file, len + 1);
  c->rows = malloc(sizeof(double) * COLS * c->cap);
  if (!c->rows) return tx_setup_fail(s, "max_samples", "%llu samples do not fit in memory", (unsigned long long)c->cap);
  c->pose = TX_READ_OF(s, pose, tx_pose);
  c->force = TX_READ_OF(s, force, tx_force);
  if (*state) c->state = TX_READ_OF(s, state, tx_hip_state);
  if (*torn) c->torn = TX_READ_OF(s, torn, tx_torn);
  c->w_full = tx_setup_warning(s, "recording_full");
  c->r_samples = tx_setup_result(s, "samples");
  return 0;
}

// every page of the samples is mapped before the first 1 kHz step
static int init(tx_ctx* ctx, void* self) {
  curve* c = self;
  tx_prefault(c->rows, sizeof(double) * COLS * c->cap);
  return 0;
}

static void step(tx_ctx* ctx, void* self) {
  curve* c = self;
  if (c->n == c->cap) {
    tx_warn(ctx, c->w_full);
    return;
  }
  double* r = c->rows + COLS * c->n++;
  const tx_pose* p = tx_read(ctx, c->pose).data;
  const tx_force* f = tx_read(ctx, c->force).data;
  r[0] = tx_sim_ns(ctx) * 1e-9;
  memcpy(r + 1, p->pos, 3 * sizeof *r);
  memcpy(r + 4, f->f, 3 * sizeof *r);
  r[7] = r[8] = r[9] = r[10] = 0;
  if (c->state.id) {
    const tx_hip_state* st = tx_read(ctx, c->state).data;
    r[7] = st->contacts, r[8] = st->pierced, r[10] = st->skin_t;
  }
  if (c->torn.id) r[9] = ((const tx_torn*)tx_read(ctx, c->torn).data)->links;
}

static void finish(tx_ctx* ctx, void* self) {
  curve* c = self;
  tx_set_result(ctx, c->r_samples, (double)c->n);
  const char* dir = tx_record_dir(ctx);
  if (!dir || c->n == 0) return;
  char name[80], path[4200];
  snprintf(name, sizeof name, "%s.csv", c->file);
  tx_aside a;
  if (!tx_aside_open(ctx, &a, dir, name)) return;
  fprintf(a.f, "t_s,x_m,y_m,z_m,fx_n,fy_n,fz_n,contacts,pierced,torn,skin_t_s\n");
  for (uint64_t i = 0; i < c->n; i++) {
    const double* r = c->rows + COLS * i;
    fprintf(a.f, "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.0f,%.0f,%.0f,%.6f\n", r[0], r[1], r[2], r[3], r[4], r[5], r[6],
            r[7], r[8], r[9], r[10]);
  }
  if (!tx_aside_commit(ctx, &a) || !c->png) return;
  // the papers' plot: force along the axis (N) against the position along it, in the plots' length unit
  double* xs = malloc(sizeof(double) * c->n);
  double* ys = malloc(sizeof(double) * c->n);
  if (!xs || !ys) {
    free(xs), free(ys);
    tx_stop_run(ctx, "%s.png: out of memory", c->file);
    return;
  }
  for (uint64_t i = 0; i < c->n; i++) {
    xs[i] = tx_plot_length(c->rows[COLS * i + 1 + c->axis]);
    ys[i] = c->rows[COLS * i + 4 + c->axis];
  }
  char xl[64], yl[64];
  snprintf(xl, sizeof xl, "HIP %c (" TX_PLOT_LENGTH_UNIT ")", 'x' + c->axis);
  snprintf(yl, sizeof yl, "force F%c on the device (N)", 'x' + c->axis);
  tx_plot_series s = {"force", xs, ys, (int)(c->n > 2147483647u ? 2147483647u : c->n), false, 1};
  tx_plot p = {"force against displacement", xl, yl, false, false, &s, 1};
  snprintf(path, sizeof path, "%s/%s.png", dir, c->file);
  if (tx_plot_png(path, &p)) tx_stop_run(ctx, "%s", tx_error());
  free(xs);
  free(ys);
}

static void fini(void* self) {
  curve* c = self;
  if (!c) return;
  free(c->rows);
  free(c);
}

const tx_controller_class tx_view_force_curve = {
    .type = "view.force_curve",
    .summary = "records a tool's force against its position; writes NAME.csv and a force-displacement NAME.png",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
    .view = true,
};
