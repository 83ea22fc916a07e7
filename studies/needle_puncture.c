// tactus study needle-puncture: the force along the curved needle against
// its tip's depth while it punctures the skin, and the puncture force. The
// real controllers in lockstep: a scripted hand (this study's class, 1 kHz)
// holds the needle holder, which holds a 3/8-circle needle 30 mm long from
// the start (physics.instruments, 1 kHz); physics.skin (60 Hz, its defaults)
// takes the needle's tip as its HIP. The hand lowers the needle until its
// circle's centre is 5.5 mm above the skin and turns it about that centre
// at 0.5 rad/s, so that the tip goes down into the skin along its own arc.
// Each millisecond the study's class samples the skin's force on the tip
// along the tip's direction of travel, the tip's depth below where it first
// meets the skin (the HIP radius plus half the thickness above the skin's
// rest plane), and the force on the hand, until 0.3 s after the entry
// puncture. Writes needle-puncture.csv, .json and .png.
#include "studies.h"

#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <tactus/config.h>

#include <stdio.h>

#if TX_WITH_ODE && TX_WITH_URDFDOM && TX_WITH_ASSIMP && TX_WITH_BULLET
#include "../scenarios/loader.h"
#include "../controllers/system.h"

#include <tactus/components.h>
#include <tactus/events.h>

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NEEDLE_LENGTH 0.03 // m: a 3/8 circle of radius 12.7 mm
#define GRASP_D 0.03       // m ahead of the jaws' pivot
#define GRASP_PHI 0.2      // rad from the swage
#define CENTRE_Y 0.0055    // m above the skin's rest plane
#define TURN_RATE 0.5      // rad/s
#define SAMPLES_MAX 8000
#define HIP_R 0.0005 // m, physics.skin's default HIP
#define SKIN_T 0.004 // m, physics.skin's default thickness

typedef struct sample {
  double t, depth, along, force, hand;
} sample;

typedef struct probe {
  tx_port pose, vel, grip, tip, npose, contact, hand, events;
  sample* s;
  int n;
  double punct_t; // the entry's time, or -1
  tx_event entry;
  double th0, turn_start;
} probe;
static probe the_probe;

static double radius(void) { return NEEDLE_LENGTH / (0.75 * M_PI); }

static int probe_configure(tx_setup* s, void** self) {
  probe* p = &the_probe;
  *self = p;
  p->pose = tx_setup_write(s, &TX_COMPONENT_OF("device0.pose", tx_pose, 1));
  p->vel = tx_setup_write(s, &TX_COMPONENT_OF("device0.velocity", tx_velocity, 1));
  p->grip = tx_setup_write(s, &TX_COMPONENT_OF("device0.grip", tx_device_grip, 1));
  p->tip = TX_READ_OF(s, "needle.tip", tx_pose);
  p->npose = TX_READ_OF(s, "needle.pose", tx_pose);
  p->contact = TX_READ_OF(s, "skin.contact", tx_skin_contact);
  p->hand = TX_READ_OF(s, "instrument0.force_model", tx_force_model);
  p->events = tx_setup_listen(s, "instruments.events");
  return 0;
}

// the hand: 7 cm up while the root turns to the hand's orientation (it starts
// unturned), down to the centre at CENTRE_Y, then turning about the centre
static void hand_at(const probe* p, double t, double pos[3], double q[4], double v[3]) {
  double R = radius(), cy = 0.07, th = p->th0, vy = 0, om = 0;
  if (t > 0.5) cy = 0.07 - (0.07 - CENTRE_Y) * fmin(1, (t - 0.5) / 1.0), vy = t < 1.5 ? -(0.07 - CENTRE_Y) : 0;
  if (t > p->turn_start) th = p->th0 - TURN_RATE * (t - p->turn_start), om = -TURN_RATE;
  pos[0] = cos(th) * (R - GRASP_D), pos[1] = cy + sin(th) * (R - GRASP_D), pos[2] = 0;
  v[0] = -om * sin(th) * (R - GRASP_D), v[1] = vy + om * cos(th) * (R - GRASP_D), v[2] = 0;
  // turned about z by th, flipped about x: the arc curves down
  q[0] = 0, q[1] = cos(th / 2), q[2] = sin(th / 2), q[3] = 0;
}

static void probe_init_pose(tx_ctx* c, probe* p) {
  tx_pose* pose = tx_write(c, p->pose);
  tx_velocity* v = tx_write(c, p->vel);
  hand_at(p, (double)tx_sim_ns(c) * 1e-9, pose->pos, pose->quat, v->v);
  tx_device_grip* g = tx_write(c, p->grip);
  g->grip = 0, g->buttons = 0;
}

static int probe_init(tx_ctx* c, void* self) {
  probe_init_pose(c, self);
  return 0;
}

static void probe_step(tx_ctx* c, void* self) {
  probe* p = self;
  double t = (double)tx_sim_ns(c) * 1e-9;
  probe_init_pose(c, p);
  tx_event e;
  while (tx_next_event(c, p->events, &e))
    if (e.kind == TX_EVENT_PUNCTURE && p->punct_t < 0) p->punct_t = t, p->entry = e;
  if (t < p->turn_start || p->n >= SAMPLES_MAX) return;
  tx_snapshot tip = tx_read(c, p->tip), np = tx_read(c, p->npose), ct = tx_read(c, p->contact), hf = tx_read(c, p->hand);
  if (!tip.seq || !np.seq || !ct.seq || !hf.seq) return;
  // the tip's direction of travel: the arc's tangent at the tip, (-sin a, cos a, 0) in the needle frame
  const double* q = ((const tx_pose*)np.data)->quat;
  double a = 0.75 * M_PI, u[3] = {-sin(a), cos(a), 0}, d[3];
  double tt[3] = {2 * (q[2] * u[2] - q[3] * u[1]), 2 * (q[3] * u[0] - q[1] * u[2]), 2 * (q[1] * u[1] - q[2] * u[0])};
  d[0] = u[0] + q[0] * tt[0] + q[2] * tt[2] - q[3] * tt[1];
  d[1] = u[1] + q[0] * tt[1] + q[3] * tt[0] - q[1] * tt[2];
  d[2] = u[2] + q[0] * tt[2] + q[1] * tt[1] - q[2] * tt[0];
  const tx_skin_contact* sc = ct.data;
  const tx_force_model* fm = hf.data;
  sample* s = &p->s[p->n++];
  s->t = t;
  s->depth = HIP_R + SKIN_T / 2 - ((const tx_pose*)tip.data)->pos[1];
  s->along = -(sc->f[0] * d[0] + sc->f[1] * d[1] + sc->f[2] * d[2]); // against the travel: positive
  s->force = sqrt(sc->f[0] * sc->f[0] + sc->f[1] * sc->f[1] + sc->f[2] * sc->f[2]);
  s->hand = sqrt(fm->f0[0] * fm->f0[0] + fm->f0[1] * fm->f0[1] + fm->f0[2] * fm->f0[2]);
}

static const tx_controller_class probe_class = {.type = "study.needle_hand",
                                                .summary = "the needle-puncture study's scripted hand and probe",
                                                .configure = probe_configure,
                                                .init = probe_init,
                                                .step = probe_step};

int tx_study_needle_puncture(const tx_study_args* a) {
  bool quick = false;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
  if (!tx_find_controller(probe_class.type) && tx_register_controller(&probe_class))
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  probe* p = &the_probe;
  *p = (probe){.punct_t = -1, .th0 = 0.75 * M_PI - GRASP_PHI + 5 * M_PI / 180, .turn_start = 1.6};
  p->s = calloc(SAMPLES_MAX, sizeof *p->s);
  if (!p->s) return fprintf(stderr, "tactus: out of memory\n"), 1;
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"needle-puncture\",\"controllers\":["
           "{\"name\":\"hand\",\"type\":\"study.needle_hand\",\"rate_hz\":1000},"
           "{\"name\":\"instruments\",\"type\":\"physics.instruments\",\"rate_hz\":1000,\"params\":{"
           "\"instrument0\":\"needle_holder\",\"needle\":true,\"needle_in_jaws\":0,\"needle_length_m\":%g,"
           "\"needle_grasp_m\":%g,\"needle_grasp_rad\":%g,\"table_height_m\":-1,\"skin\":\"skin\"}},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":60,\"params\":{\"pose\":\"needle.tip\"}}]}",
           NEEDLE_LENGTH, GRASP_D, GRASP_PHI);
  tx_scenario* sc = tx_scenario_load_text("needle-puncture", text, strlen(text), NULL);
  if (!sc) return free(p->s), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  // the tip meets the skin some 35 degrees into the turn and tears within
  // about 40 more: 2.5 s of turning (1.25 rad) is room for both
  tx_run_options o = {.duration_s = p->turn_start + (quick ? 2.0 : 2.5), .lockstep = true};
  tx_run_result r;
  int rc = tx_system_run(sc->system, &o, &r) ? 1 : 0;
  if (rc) fprintf(stderr, "tactus: %s\n", tx_error());
  tx_scenario_free(sc);
  if (rc) return free(p->s), 1;
  if (p->punct_t < 0) return free(p->s), fprintf(stderr, "tactus: study needle-puncture: the needle never punctured the skin\n"), 1;

  // from first contact to 0.3 s after the entry; the puncture force is the
  // largest force along the needle before the tear, and where it was
  int first = -1, last = 0, peak = -1;
  for (int i = 0; i < p->n; i++) {
    if (first < 0 && p->s[i].force > 0) first = i;
    if (p->s[i].t <= p->punct_t + 0.3) last = i;
    if (first >= 0 && p->s[i].t < p->punct_t && (peak < 0 || p->s[i].along > p->s[peak].along)) peak = i;
  }
  if (first < 0 || peak < 0) return free(p->s), fprintf(stderr, "tactus: study needle-puncture: the tip never touched the skin\n"), 1;
  // after the tear: the largest force along from 50 ms (3 skin steps) after it to the end
  double after = 0, flaps = 0;
  for (int i = first; i <= last; i++)
    if (p->s[i].t > p->punct_t + 0.05) after = fmax(after, fabs(p->s[i].along));
    else if (p->s[i].t >= p->punct_t) flaps = fmax(flaps, fabs(p->s[i].along));
  int n = last - first + 1;
  double* depth = malloc(2 * (size_t)n * sizeof *depth);
  if (!depth) return free(p->s), fprintf(stderr, "tactus: out of memory\n"), 1;
  double* along = depth + n;

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "needle-puncture.csv")) return free(depth), free(p->s), tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "t_s,tip_depth_m,force_along_needle_n,skin_force_n,hand_force_n,torn_after\n");
  for (int i = first; i <= last; i++) {
    const sample* q = &p->s[i];
    fprintf(csv, "%.4f,%.6g,%.6g,%.6g,%.6g,%d\n", q->t, q->depth, q->along, q->force, q->hand, q->t >= p->punct_t);
    depth[i - first] = tx_plot_length(q->depth), along[i - first] = q->along;
  }
  if (!tx_aside_end(&out))
    return free(depth), free(p->s), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  const sample* pk = &p->s[peak];
  json_t* doc = json_pack("{s:s,s:{s:f,s:f,s:f,s:f},s:f,s:f,s:f,s:f,s:f,s:f,s:f,s:i}", "study", "needle-puncture", "needle",
                          "length_m", NEEDLE_LENGTH, "radius_m", radius(), "centre_above_skin_m", CENTRE_Y, "turn_rad_s",
                          TURN_RATE, "puncture_force_n", pk->along, "puncture_depth_m", pk->depth, "puncture_time_s",
                          p->punct_t, "event_force_n", p->entry.puncture.force, "hand_force_at_puncture_n", pk->hand,
                          "force_along_after_n", after, "force_along_first_50ms_after_n", flaps, "triangle", (int)p->entry.source);
  if (!doc || tx_report_save(doc, a->out_dir, "needle-puncture.json"))
    fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "out of memory"), rc = 1;
  json_decref(doc);
  int before = 0; // samples before the tear: a line; after it, markers
  while (before < n && p->s[first + before].t < p->punct_t) before++;
  tx_plot_series ser[2] = {{"before the tear", depth, along, before, false, 1},
                           {"0.3 s after it", depth + before, along + before, n - before, true, 2}};
  char png[4200], title[200];
  snprintf(title, sizeof title, "Needle puncture: %.3f N at %.2f mm, back to %.3f N after", pk->along,
           tx_plot_length(pk->depth), after);
  tx_plot pl = {title, "tip depth below first contact (" TX_PLOT_LENGTH_UNIT ")", "force along the needle (N)", false, false, ser, before < n ? 2 : 1};
  snprintf(png, sizeof png, "%s/needle-puncture.png", a->out_dir);
  if (rc == 0 && tx_plot_png(png, &pl) != 0) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("needle-puncture: a 3/8-circle needle %g mm long (R = %.2f mm) in the needle holder, turned at %g rad/s about "
         "its centre %g mm above the skin (physics.skin defaults, 60 Hz)\n",
         NEEDLE_LENGTH * 1e3, radius() * 1e3, TURN_RATE, CENTRE_Y * 1e3);
  printf("  puncture force along the needle: %.3f N at %.2f mm below first contact (t = %.3f s); the event's |f| %.3f N\n",
         pk->along, pk->depth * 1e3, p->punct_t, p->entry.puncture.force);
  printf("  the hand felt %.3f N then; along the needle in the first 50 ms after the tear at most %.3f N (the torn "
         "flaps, which no longer push the pierced tip), from 50 ms on at most %.3f N\n",
         pk->hand, flaps, after);
  free(depth);
  free(p->s);
  return rc;
}
#else
int tx_study_needle_puncture(const tx_study_args* a) {
  (void)a;
  return tx_bad_input("study needle-puncture: built without ODE, urdfdom, assimp or Bullet (TX_WITH_ODE, TX_WITH_URDFDOM, "
                      "TX_WITH_ASSIMP, TX_WITH_BULLET)");
}
#endif
