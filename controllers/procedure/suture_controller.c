// procedure.suture: steps A-H of a simple interrupted suture and the measures
// of its scorecard, from what the instruments and the thread publish
// (suture_controller.h, docs/suturing.md).
#include "suture_controller.h"

#include "suture_steps.h"
#include "../system.h" // tx_param_point

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HANDS 2
#define PUNCTURES_MAX 64 // rows of the punctures component read
#define SKIN_PARTICLES_MAX 16384 // the wound gap is measured on skins up to this many particles (102 x 102 at 1 mm)

typedef struct suture {
  tx_suture_steps steps;
  double wound_a[3], wound_b[3]; // m, the wound line on the skin (Y up)
  double wrap_reach;             // m, thread nodes this near the holder's jaw axis count for the wrap
  double wrap_length;            // m, how far along the jaws from the pivot
  tx_port instrument_events, thread_events, punctures, nodes, tension, thread_loads, holder, hand[HANDS];
  int nhands;
  tx_port out_step, out_steps, out_names, out_measures, out_events;
  tx_result done_r, step_r[TX_SUTURE_STEPS];
  tx_warning lost_w;
  // what has been seen
  int punctures_seen;      // puncture events taken
  int punctures_placed;    // of them, matched with their row (side) in punctures
  double puncture_at[PUNCTURES_MAX][3]; // m, each puncture event's point
  bool have_entry;
  double entry[3];         // m, the stitch's entry (its bite on the near edge)
  bool have_exit;
  double exit[3];          // m, its exit, on the far edge
  int stitch_punctures;    // the punctures up to the stitch's exit, in the needle's order
  tx_suture_measures m;
  double last_hand[HANDS][3];
  bool hand_seen[HANDS];
  uint32_t holding;        // bit h: hand h's jaws hold something
  bool cut;
  // the skin (skin: SKIN.x, SKIN.contact and SKIN.torn), for the wound gap, the force on the tissue and the tears
  tx_port skin_x, skin_contact, skin_torn;
  float* rest;             // (SKIN_PARTICLES_MAX x 3) m, SKIN.x as the run found it
  uint32_t nrest;          // its particles, 0 until the first publish
  tx_warning skin_too_large;
} suture;

static const tx_param_def params[] = {
    {"wound_a_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: one end of the wound line on the skin; [-0.015, 0, 0] by default"},
    {"wound_b_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: its other end; [0.015, 0, 0] by default (a 3 cm wound along x)"},
    {"instrument_events", TX_PARAM_STR, NULL, 0, 0, 0, "instruments.events",
     "the instruments' event stream: punctures (their points), grasps and releases; empty: none"},
    {"punctures", TX_PARAM_STR, NULL, 0, 0, 0, "needle.punctures",
     "tx_puncture rows in the order the needle made them: whether each entered or came out; empty: every puncture an entry"},
    {"thread_events", TX_PARAM_STR, NULL, 0, 0, 0, "thread.events", "the thread's event stream: knots and cuts; empty: none"},
    {"thread", TX_PARAM_STR, NULL, 0, 0, 0, "thread",
     "the thread's prefix: THREAD.nodes (the tail), THREAD.force_model (the tension) and THREAD.puncture_loads (the punctures it runs through); empty: none"},
    {"holder", TX_PARAM_STR, NULL, 0, 0, 0, "instrument0.pose", "the needle holder's pose (tx_instrument_pose), whose jaws the thread is wrapped around; empty: none"},
    {"hands", TX_PARAM_STRS, NULL, 0, HANDS, 0, NULL, "each hand's pose (tx_pose) for its path length; [\"device0.pose\", \"device1.pose\"] by default"},
    {"tail_m", TX_PARAM_NUM, "m", 0.001, 1, 0.03, NULL,
     "B is done once the thread runs through the stitch's punctures and beyond the entry is at most this long"},
    {"wrap_turns", TX_PARAM_NUM, "1", 0.25, 10, 1, NULL, "C is done once the thread winds around the holder's jaws this many times"},
    {"wrap_reach_m", TX_PARAM_NUM, "m", 0.001, 0.1, 0.008, NULL, "thread nodes within this distance of the jaws' axis count for the wrap"},
    {"wrap_length_m", TX_PARAM_NUM, "m", 0.005, 0.3, 0.03, NULL, "the jaws' length ahead of the pivot, along which a wrap counts"},
    {"skin", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "the skin's prefix: SKIN.x for the wound gap at the stitch, SKIN.contact for the force on the tissue, SKIN.torn for the tears and those a pull tore; empty: none"},
};

// a read that the scenario may leave out with an empty name
static tx_port optional_read(tx_setup* s, const char* name, tx_type type, uint32_t cols) {
  return name && *name ? tx_setup_read_as(s, name, type, cols) : (tx_port){0};
}

static int configure(tx_setup* s, void** self) {
  suture* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  if (tx_param_point(s, "wound_a_m", (const double[3]){-0.015, 0, 0}, k->wound_a) ||
      tx_param_point(s, "wound_b_m", (const double[3]){0.015, 0, 0}, k->wound_b))
    return -1;
  double dx = k->wound_b[0] - k->wound_a[0], dz = k->wound_b[2] - k->wound_a[2];
  if (!(dx * dx + dz * dz > 1e-8)) return tx_setup_fail(s, "wound_b_m", "the wound line is under 0.1 mm long across the skin (x-z)");
  tx_suture_rules r = {.tail_m = tx_table_num(s, "tail_m"), .wrap_turns = tx_table_num(s, "wrap_turns")};
  tx_suture_steps_start(&k->steps, &r, 0);
  k->wrap_reach = tx_table_num(s, "wrap_reach_m");
  k->wrap_length = tx_table_num(s, "wrap_length_m");

  const char* ie = tx_table_str(s, "instrument_events");
  const char* te = tx_table_str(s, "thread_events");
  const char* thread = tx_table_str(s, "thread");
  if (ie && *ie) k->instrument_events = tx_setup_listen(s, ie);
  if (te && *te) k->thread_events = tx_setup_listen(s, te);
  k->punctures = optional_read(s, tx_table_str(s, "punctures"), tx_puncture_TYPE, tx_puncture_COLS);
  if (thread && *thread) {
    char name[TX_NAME_MAX + 16];
    snprintf(name, sizeof name, "%s.nodes", thread);
    k->nodes = TX_READ_OF(s, name, tx_thread_node);
    snprintf(name, sizeof name, "%s.force_model", thread);
    k->tension = TX_READ_OF(s, name, tx_force_model);
    snprintf(name, sizeof name, "%s.puncture_loads", thread);
    k->thread_loads = TX_READ_OF(s, name, tx_puncture_load);
  }
  k->holder = optional_read(s, tx_table_str(s, "holder"), tx_instrument_pose_TYPE, tx_instrument_pose_COLS);
  const char* hands[HANDS];
  k->nhands = tx_table_strs(s, "hands", hands, HANDS);
  if (k->nhands == 0) hands[0] = "device0.pose", hands[1] = "device1.pose", k->nhands = HANDS;
  for (int h = 0; h < k->nhands; h++) k->hand[h] = optional_read(s, hands[h], tx_pose_TYPE, tx_pose_COLS);

  const char* me = tx_setup_name(s);
  char name[TX_NAME_MAX + 16];
  snprintf(name, sizeof name, "%s.step", me);
  k->out_step = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_procedure_step, 1));
  snprintf(name, sizeof name, "%s.steps", me);
  k->out_steps = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_procedure_step_state, TX_SUTURE_STEPS));
  snprintf(name, sizeof name, "%s.step_names", me);
  k->out_names = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_procedure_step, TX_SUTURE_STEPS));
  snprintf(name, sizeof name, "%s.suture", me);
  k->out_measures = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_suture_measures, 1));
  snprintf(name, sizeof name, "%s.events", me);
  k->out_events = tx_setup_emit(s, name, 64);
  k->done_r = tx_setup_result(s, "steps_done");
  for (int i = 0; i < TX_SUTURE_STEPS; i++) {
    snprintf(name, sizeof name, "step_%s", tx_suture_step_id(i));
    k->step_r[i] = tx_setup_result(s, name);
  }
  k->lost_w = tx_setup_warning(s, "punctures_unmatched");
  const char* skin = tx_table_str(s, "skin");
  if (skin && *skin) {
    snprintf(name, sizeof name, "%s.x", skin);
    k->skin_x = TX_READ_OF(s, name, tx_vertex);
    snprintf(name, sizeof name, "%s.contact", skin);
    k->skin_contact = TX_READ_OF(s, name, tx_skin_contact);
    snprintf(name, sizeof name, "%s.torn", skin);
    k->skin_torn = TX_READ_OF(s, name, tx_torn);
    k->rest = malloc(sizeof(float) * 3 * SKIN_PARTICLES_MAX);
    if (!k->rest) return tx_setup_fail(s, NULL, "out of memory");
    k->skin_too_large = tx_setup_warning(s, "skin_too_large");
  }
  return 0;
}

// a run starts with nothing seen (a reset runs init again)
static int init(tx_ctx* c, void* self) {
  (void)c;
  suture* k = self;
  tx_suture_rules r = k->steps.rules;
  tx_suture_steps_start(&k->steps, &r, 0);
  k->punctures_seen = k->punctures_placed = 0;
  k->have_entry = k->have_exit = k->cut = false;
  k->stitch_punctures = 0;
  k->holding = 0;
  memset(k->hand_seen, 0, sizeof k->hand_seen);
  k->nrest = 0;
  k->m = (tx_suture_measures){.bite_entry_m = NAN, .bite_exit_m = NAN, .wound_gap_before_m = NAN, .wound_gap_after_m = NAN};
  return 0;
}

// the signed distance of p from the wound line, across the skin (x-z, Y up):
// its sign is the wound edge p is on
static double wound_offset(const suture* k, const double p[3]) {
  double dx = k->wound_b[0] - k->wound_a[0], dz = k->wound_b[2] - k->wound_a[2];
  double px = p[0] - k->wound_a[0], pz = p[2] - k->wound_a[2];
  return (dz * px - dx * pz) / sqrt(dx * dx + dz * dz);
}

// a step's text for the window: "2/8 B pull the thread"
static void write_step_text(tx_ctx* c, suture* k) {
  tx_procedure_step* t = tx_write(c, k->out_step);
  int i = k->steps.current;
  if (i < TX_SUTURE_STEPS) snprintf(t->text, sizeof t->text, "%d/%d %s %s", i + 1, TX_SUTURE_STEPS, tx_suture_step_id(i), tx_suture_step_name(i));
  else snprintf(t->text, sizeof t->text, "done: %d of %d steps", tx_suture_steps_done(&k->steps), TX_SUTURE_STEPS);
}

// a TX_EVENT_STEP for each step whose status changed
static void emit_changes(tx_ctx* c, suture* k, const tx_procedure_step_state* before) {
  for (int i = 0; i < TX_SUTURE_STEPS; i++) {
    if (before[i].status == k->steps.step[i].status) continue;
    tx_event e = {.kind = TX_EVENT_STEP, .source = (uint32_t)i};
    e.value[0] = k->steps.step[i].status;
    tx_emit(c, k->out_events, &e);
  }
}

// punctures whose side (entry or exit) is known: a puncture event's row of
// the punctures component may be published after the event is taken
static void place_punctures(tx_ctx* c, suture* k, double t) {
  const tx_puncture* rows = NULL;
  uint32_t n = 0;
  if (k->punctures.id) {
    tx_snapshot s = tx_read(c, k->punctures);
    rows = s.data, n = s.seq ? s.rows : 0;
  }
  while (k->punctures_placed < k->punctures_seen && k->punctures_placed < PUNCTURES_MAX) {
    int i = k->punctures_placed;
    int side = 1; // without the component every puncture counts as an entry
    if (rows) {
      if ((uint32_t)i >= n || rows[i].v[0] < 0) return; // not published yet
      side = rows[i].side < 0 ? -1 : 1;
    }
    const double* p = k->puncture_at[i];
    double off = wound_offset(k, p);
    int edge = off >= 0 ? 1 : -1;
    if (side > 0 && k->steps.current == TX_SUTURE_A && !k->have_entry) {
      k->have_entry = true;
      memcpy(k->entry, p, sizeof k->entry);
      k->m.bite_entry_m = fabs(off);
    }
    if (tx_suture_steps_puncture(&k->steps, t, side, edge)) {
      k->stitch_punctures = i + 1;
      k->m.bite_exit_m = fabs(off);
      k->have_exit = true;
      memcpy(k->exit, p, sizeof k->exit);
    }
    k->punctures_placed++;
  }
}

static void take_events(tx_ctx* c, suture* k, double t) {
  tx_event e;
  if (k->instrument_events.id)
    while (tx_next_event(c, k->instrument_events, &e)) {
      if (e.kind == TX_EVENT_PUNCTURE) {
        if (k->punctures_seen < PUNCTURES_MAX) memcpy(k->puncture_at[k->punctures_seen], e.puncture.point, 3 * sizeof(double));
        else tx_warn(c, k->lost_w);
        k->punctures_seen++;
        k->m.punctures = k->punctures_seen;
      } else if (e.kind == TX_EVENT_GRASP && e.source < 32) {
        k->holding |= 1u << e.source;
      } else if (e.kind == TX_EVENT_RELEASE && e.source < 32) {
        k->holding &= ~(1u << e.source);
      }
    }
  place_punctures(c, k, t);
  if (k->thread_events.id)
    while (tx_next_event(c, k->thread_events, &e)) {
      if (e.kind == TX_EVENT_KNOT) {
        bool fixed = e.value[2] > 0.5;
        if (fixed) k->m.knots_fixed++;
        else k->m.knots++;
        tx_suture_steps_knot(&k->steps, t, (int)e.source, fixed);
      } else if (e.kind == TX_EVENT_CUT) {
        k->cut = true;
        tx_suture_steps_cut(&k->steps, t);
      }
    }
}

// the thread beyond the entry: from the node nearest the entry to the tail
static double tail_length(const tx_thread_node* n, uint32_t rows, const double entry[3]) {
  uint32_t near = 0;
  double best = INFINITY;
  for (uint32_t i = 0; i < rows; i++) {
    double d = 0;
    for (int a = 0; a < 3; a++) d += (n[i].x[a] - entry[a]) * (n[i].x[a] - entry[a]);
    if (d < best) best = d, near = i;
  }
  double len = 0;
  for (uint32_t i = near; i + 1 < rows; i++) {
    double d = 0;
    for (int a = 0; a < 3; a++) d += (n[i + 1].x[a] - n[i].x[a]) * (n[i + 1].x[a] - n[i].x[a]);
    len += sqrt(d);
  }
  return len;
}

// whether the thread runs through every puncture of the stitch: its loads'
// rows (one a puncture it went through, in the needle's order) reach the exit
static bool threaded(tx_ctx* c, const suture* k) {
  tx_snapshot s = tx_read(c, k->thread_loads);
  const tx_puncture_load* ld = s.data;
  uint32_t through = 0;
  while (s.seq && through < s.rows && ld[through].v[0] >= 0) through++;
  return k->stitch_punctures > 0 && through >= (uint32_t)k->stitch_punctures;
}

// turns of the thread around the holder's jaws: the angle its nodes sweep
// about the jaws' axis (the root's x, to the tip), over the runs of
// consecutive nodes within reach of it, ahead of the pivot
static double wrap_turns(const suture* k, const tx_thread_node* n, uint32_t rows, const tx_instrument_pose* h) {
  const double* q = h->quat; // w, x, y, z
  double ax[3] = {1 - 2 * (q[2] * q[2] + q[3] * q[3]), 2 * (q[1] * q[2] + q[0] * q[3]), 2 * (q[1] * q[3] - q[0] * q[2])};
  // two directions across the axis, for the angle
  double u[3] = {0, 0, 0};
  u[fabs(ax[0]) < 0.9 ? 0 : 1] = 1;
  double d = u[0] * ax[0] + u[1] * ax[1] + u[2] * ax[2];
  for (int a = 0; a < 3; a++) u[a] -= d * ax[a];
  double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (int a = 0; a < 3; a++) u[a] /= ul;
  double w[3] = {ax[1] * u[2] - ax[2] * u[1], ax[2] * u[0] - ax[0] * u[2], ax[0] * u[1] - ax[1] * u[0]};
  double swept = 0, prev = 0;
  bool inside = false;
  for (uint32_t i = 0; i < rows; i++) {
    double r[3] = {n[i].x[0] - h->pos[0], n[i].x[1] - h->pos[1], n[i].x[2] - h->pos[2]};
    double along = r[0] * ax[0] + r[1] * ax[1] + r[2] * ax[2];
    double cu = r[0] * u[0] + r[1] * u[1] + r[2] * u[2], cw = r[0] * w[0] + r[1] * w[1] + r[2] * w[2];
    bool near = along >= 0 && along <= k->wrap_length && cu * cu + cw * cw <= k->wrap_reach * k->wrap_reach;
    double angle = atan2(cw, cu);
    if (near && inside) {
      double step = angle - prev;
      if (step > M_PI) step -= 2 * M_PI;
      if (step < -M_PI) step += 2 * M_PI;
      swept += step;
    }
    inside = near, prev = angle;
  }
  return swept / (2 * M_PI);
}

// Across the wound at the stitch: the point of the wound line nearest the
// middle of the stitch's entry and exit (the entry alone before the exit,
// the wound's middle before either), and on each side of the line the
// particle nearest it at rest: the wound's two edges there (false: a side
// has none)
static bool wound_edges(const suture* k, int edge[2]) {
  double ux = k->wound_b[0] - k->wound_a[0], uz = k->wound_b[2] - k->wound_a[2], len = sqrt(ux * ux + uz * uz);
  ux /= len, uz /= len;
  double at[3];
  for (int a = 0; a < 3; a++) at[a] = 0.5 * (k->wound_a[a] + k->wound_b[a]);
  if (k->have_entry) memcpy(at, k->entry, sizeof at);
  if (k->have_exit)
    for (int a = 0; a < 3; a++) at[a] = 0.5 * (k->entry[a] + k->exit[a]);
  double s = (at[0] - k->wound_a[0]) * ux + (at[2] - k->wound_a[2]) * uz;
  s = fmin(fmax(s, 0), len);
  double best[2] = {INFINITY, INFINITY};
  edge[0] = edge[1] = -1;
  for (uint32_t i = 0; i < k->nrest; i++) {
    const float* r = k->rest + 3 * i;
    double along = (r[0] - k->wound_a[0]) * ux + (r[2] - k->wound_a[2]) * uz - s;
    double off = wound_offset(k, (const double[3]){r[0], r[1], r[2]});
    int e = off >= 0;
    double d = along * along + off * off;
    if (d < best[e]) best[e] = d, edge[e] = (int)i;
  }
  return edge[0] >= 0 && edge[1] >= 0;
}

// the distance of particles i and j of x (m)
static double particle_distance(const float* x, int i, int j) {
  const float *p = x + 3 * i, *q = x + 3 * j;
  return sqrt((double)(p[0] - q[0]) * (p[0] - q[0]) + (double)(p[1] - q[1]) * (p[1] - q[1]) + (double)(p[2] - q[2]) * (p[2] - q[2]));
}

// the skin: kept as the run found it, the gap on it and on the latest, the tip's force, the tears
static void read_skin(tx_ctx* c, suture* k) {
  tx_snapshot x = tx_read(c, k->skin_x);
  if (x.seq && k->nrest == 0) {
    if (x.rows > SKIN_PARTICLES_MAX) {
      tx_warn(c, k->skin_too_large);
    } else {
      memcpy(k->rest, x.data, sizeof(float) * 3 * x.rows);
      k->nrest = x.rows;
    }
  }
  int edge[2];
  if (x.seq && k->nrest == x.rows && wound_edges(k, edge)) {
    k->m.wound_gap_before_m = particle_distance(k->rest, edge[0], edge[1]);
    k->m.wound_gap_after_m = particle_distance(x.data, edge[0], edge[1]);
  }
  tx_snapshot f = tx_read(c, k->skin_contact);
  if (f.seq) {
    const tx_skin_contact* sc = f.data;
    k->m.tissue_force_max_n = fmax(k->m.tissue_force_max_n, sqrt(sc->f[0] * sc->f[0] + sc->f[1] * sc->f[1] + sc->f[2] * sc->f[2]));
  }
  tx_snapshot t = tx_read(c, k->skin_torn); // both counts from one publish: the pulled ones are some of the torn
  if (t.seq) k->m.tears = ((const tx_torn*)t.data)->links, k->m.tears_pulled = ((const tx_torn*)t.data)->pulled;
}

static void step(tx_ctx* c, void* self) {
  suture* k = self;
  double t = (double)tx_sim_ns(c) * 1e-9;
  tx_procedure_step_state before[TX_SUTURE_STEPS];
  memcpy(before, k->steps.step, sizeof before);
  // A begins with the run: its start is sent with the first step
  if (tx_step_index(c) == 0) k->steps.step[TX_SUTURE_A].t_start_s = t, before[TX_SUTURE_A].status = TX_STEP_NOT_REACHED;
  take_events(c, k, t);
  if (k->nodes.id) {
    tx_snapshot s = tx_read(c, k->nodes);
    if (s.seq && s.rows > 1) {
      if (k->steps.current == TX_SUTURE_B && k->have_entry)
        tx_suture_steps_tail(&k->steps, t, tail_length(s.data, s.rows, k->entry), threaded(c, k));
      if (k->steps.current == TX_SUTURE_C && k->holder.id) {
        tx_snapshot h = tx_read(c, k->holder);
        if (h.seq) tx_suture_steps_wrap(&k->steps, t, wrap_turns(k, s.data, s.rows, h.data));
      }
    }
    tx_snapshot f = tx_read(c, k->tension);
    if (f.seq) {
      const double* f0 = ((const tx_force_model*)f.data)->f0;
      k->m.peak_tension_n = fmax(k->m.peak_tension_n, sqrt(f0[0] * f0[0] + f0[1] * f0[1] + f0[2] * f0[2]));
    }
  }
  if (k->skin_x.id) read_skin(c, k);
  if (k->holding == 0 && k->cut) tx_suture_steps_hands_free(&k->steps, t);
  for (int h = 0; h < k->nhands; h++) {
    if (!k->hand[h].id) continue;
    tx_snapshot s = tx_read(c, k->hand[h]);
    if (!s.seq) continue;
    const double* p = ((const tx_pose*)s.data)->pos;
    if (k->hand_seen[h])
      k->m.path_m[h] += sqrt((p[0] - k->last_hand[h][0]) * (p[0] - k->last_hand[h][0]) + (p[1] - k->last_hand[h][1]) * (p[1] - k->last_hand[h][1]) +
                             (p[2] - k->last_hand[h][2]) * (p[2] - k->last_hand[h][2]));
    memcpy(k->last_hand[h], p, sizeof k->last_hand[h]);
    k->hand_seen[h] = true;
  }
  emit_changes(c, k, before);
  write_step_text(c, k);
  memcpy(tx_write(c, k->out_steps), k->steps.step, sizeof k->steps.step);
  tx_procedure_step* names = tx_write(c, k->out_names);
  for (int i = 0; i < TX_SUTURE_STEPS; i++)
    snprintf(names[i].text, sizeof names[i].text, "%s %s", tx_suture_step_id(i), tx_suture_step_name(i));
  *(tx_suture_measures*)tx_write(c, k->out_measures) = k->m;
}

static void finish(tx_ctx* c, void* self) {
  suture* k = self;
  tx_set_result(c, k->done_r, tx_suture_steps_done(&k->steps));
  for (int i = 0; i < TX_SUTURE_STEPS; i++) tx_set_result(c, k->step_r[i], k->steps.step[i].status);
}

static void fini(void* self) {
  suture* k = self;
  if (k) free(k->rest);
  free(k);
}

const tx_controller_class tx_procedure_suture = {
    .type = "procedure.suture",
    .summary = "steps A-H of a simple interrupted suture and its scorecard's measures, from the instruments' and the thread's events",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
