// A scenario's "view" object to a checked tx_view_def.
#include "view_def.h"

#include "../../controllers/system.h" // tx_json_kind, shared with the parameter readers
#include "../../model/error.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

tx_view_def tx_view_def_default(void) {
  tx_view_def d = {.camera = tx_camera_default(), .auto_camera = true, .width = 640, .height = 480, .frame_every = 10,
                   .background = {0.12f, 0.13f, 0.16f}, .light_dir = {-0.3f, -1.0f, -0.5f}};
  float l = sqrtf(d.light_dir[0] * d.light_dir[0] + d.light_dir[1] * d.light_dir[1] + d.light_dir[2] * d.light_dir[2]);
  for (int i = 0; i < 3; i++) d.light_dir[i] /= l;
  return d;
}

// the error at KEY (relative to the view): "KEY: message" in tx_error(), KEY in tx_error_key()
static int bad(const char* key, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static int bad(const char* key, const char* fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  tx_set_error_at(key, "%s%s%s", key, *key ? ": " : "", msg);
  return -1;
}

static int check_keys(const char* at, const json_t* obj, const char* const* known) {
  const char* k;
  json_t* v;
  json_object_foreach((json_t*)obj, k, v) {
    bool ok = false;
    for (const char* const* q = known; *q && !ok; q++) ok = strcmp(*q, k) == 0;
    if (ok) continue;
    char list[256] = "", key[160];
    for (const char* const* q = known; *q; q++) {
      size_t len = strlen(list);
      snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "", *q);
    }
    snprintf(key, sizeof key, "%s%s%s", at, *at ? "." : "", k);
    return bad(key, "unknown key (known: %s)", list);
  }
  return 0;
}

// n finite numbers in [lo, hi]
static int numbers(const char* key, const json_t* v, int n, double lo, double hi, double* out) {
  if (!json_is_array(v) || (int)json_array_size(v) != n)
    return bad(key, "expected an array of %d numbers, got %s", n, tx_json_kind(v));
  for (int i = 0; i < n; i++) {
    const json_t* e = json_array_get(v, (size_t)i);
    double x = json_number_value(e);
    if (!json_is_number(e) || !isfinite(x) || x < lo || x > hi)
      return bad(key, "entry %d: expected a number in [%g, %g]", i, lo, hi);
    out[i] = x;
  }
  return 0;
}

static int number(const char* key, const json_t* v, double lo, double hi, bool open_lo, double* out) {
  double x = json_number_value(v);
  if (!json_is_number(v) || !isfinite(x) || x < lo || x > hi || (open_lo && x == lo))
    return bad(key, "expected a number in %s%g, %g], got %s", open_lo ? "(" : "[", lo, hi,
               json_is_number(v) ? "an out-of-range number" : tx_json_kind(v));
  *out = x;
  return 0;
}

// an object's "point" and unit "normal" (defaults given in p and nrm) into out
// (6): the point, then the normal scaled to unit length
static int point_normal(const char* key, const json_t* v, double p[3], double nrm[3], float out[6]) {
  const json_t* q;
  char sub[128];
  snprintf(sub, sizeof sub, "%s.point", key);
  if ((q = json_object_get(v, "point")) && numbers(sub, q, 3, -1e4, 1e4, p)) return -1;
  snprintf(sub, sizeof sub, "%s.normal", key);
  if ((q = json_object_get(v, "normal")) && numbers(sub, q, 3, -1e4, 1e4, nrm)) return -1;
  double l = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
  if (!(l > 1e-6)) return bad(sub, "expected a non-zero direction");
  for (int c = 0; c < 3; c++) out[c] = (float)p[c], out[3 + c] = (float)(nrm[c] / l);
  return 0;
}

static int integer(const char* key, const json_t* v, int lo, int hi, int* out) {
  if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi)
    return bad(key, "expected an integer in [%d, %d]", lo, hi);
  *out = (int)json_integer_value(v);
  return 0;
}

// component prefixes: the model's name characters, short enough for a suffix
static bool plain_name(const char* s) {
  if (!*s || strlen(s) > TX_NAME_MAX - 10) return false;
  for (; *s; s++)
    if (!((*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '_' || *s == '.')) return false;
  return true;
}

static int read_camera(const json_t* cam, tx_view_def* d) {
  static const char* const keys[] = {"eye", "target", "up", "fov_deg", "near_m", "far_m", NULL};
  if (!json_is_object(cam)) return bad("camera", "expected an object, got %s", tx_json_kind(cam));
  if (check_keys("camera", cam, keys)) return -1;
  tx_camera* c = &d->camera;
  const json_t* v;
  if ((v = json_object_get(cam, "eye")) && numbers("camera.eye", v, 3, -1e4, 1e4, c->eye)) return -1;
  if ((v = json_object_get(cam, "target")) && numbers("camera.target", v, 3, -1e4, 1e4, c->target)) return -1;
  if ((v = json_object_get(cam, "up")) && numbers("camera.up", v, 3, -1e4, 1e4, c->up)) return -1;
  double deg = c->fov_y * 180 / M_PI;
  if ((v = json_object_get(cam, "fov_deg")) && number("camera.fov_deg", v, 1, 170, false, &deg)) return -1;
  c->fov_y = deg * M_PI / 180;
  if ((v = json_object_get(cam, "near_m")) && number("camera.near_m", v, 0, 100, true, &c->near_m)) return -1;
  if ((v = json_object_get(cam, "far_m")) && number("camera.far_m", v, 0, 1e5, true, &c->far_m)) return -1;
  double dx = c->target[0] - c->eye[0], dy = c->target[1] - c->eye[1], dz = c->target[2] - c->eye[2];
  c->convergence = sqrt(dx * dx + dy * dy + dz * dz); // the target is on the zero-parallax plane unless told otherwise
  d->auto_camera = false;
  if (tx_camera_check(c)) return bad("camera", "%s", tx_error());
  return 0;
}

// a laparoscope through a port, aimed at the camera's target; the camera's
// eye becomes the scope's tip
static int read_laparoscope(const json_t* lap, const json_t* cam, tx_view_def* d) {
  static const char* const keys[] = {"port", "insertion_m", NULL};
  if (!json_is_object(lap)) return bad("laparoscope", "expected an object, got %s", tx_json_kind(lap));
  if (check_keys("laparoscope", lap, keys)) return -1;
  if (!cam || !json_object_get(cam, "target")) return bad("laparoscope", "needs a camera with the target it is aimed at");
  double port[3], ins = 0.05, dist = 0;
  const json_t* v = json_object_get(lap, "port");
  if (!v) return bad("laparoscope.port", "missing: where the scope passes the abdominal wall");
  if (numbers("laparoscope.port", v, 3, -1e4, 1e4, port)) return -1;
  if ((v = json_object_get(lap, "insertion_m")) && number("laparoscope.insertion_m", v, 0, 1, false, &ins)) return -1;
  for (int i = 0; i < 3; i++) dist += pow(d->camera.target[i] - port[i], 2);
  if (!(sqrt(dist) > ins + 0.005))
    return bad("laparoscope.insertion_m", "the tip (%g m in) must stop short of the camera's target (%g m from the port)", ins,
               sqrt(dist));
  tx_laparoscope_aim(&d->laparoscope, port, d->camera.target, ins);
  tx_laparoscope_camera(&d->laparoscope, &d->camera);
  d->camera.convergence = d->laparoscope.focus;
  d->scope = true;
  if (tx_camera_check(&d->camera)) return bad("laparoscope", "%s", tx_error());
  return 0;
}

static int read_item(size_t i, const json_t* e, tx_draw_item* it) {
  static const char* const keys[] = {"mesh", "spheres", "segments", "tool", "plane", "instrument", "urdf", "colour",
                                     "colour_by", "range", "texture", "radius_m", "show_force", "force_scale_m_per_n",
                                     "proxy", "cut", "markers", NULL};
  char at[48], key[96];
  snprintf(at, sizeof at, "draw[%zu]", i);
  if (!json_is_object(e)) return bad(at, "expected an object, got %s", tx_json_kind(e));
  if (check_keys(at, e, keys)) return -1;
  static const struct { const char* key; tx_draw_kind kind; } kinds[] = {
      {"mesh", TX_DRAW_MESH}, {"spheres", TX_DRAW_SPHERES}, {"segments", TX_DRAW_SEGMENTS}, {"tool", TX_DRAW_TOOL},
      {"plane", TX_DRAW_PLANE}, {"instrument", TX_DRAW_INSTRUMENT}, {"markers", TX_DRAW_MARKERS}};
  *it = (tx_draw_item){.colour = {0.8f, 0.8f, 0.8f}, .range = {0, 1}, .radius = 0.005f, .force_scale = 0.01f};
  for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
    const json_t* v = json_object_get(e, kinds[k].key);
    if (!v) continue;
    if (it->kind) return bad(at, "expected exactly one of mesh, spheres, segments, tool, plane, instrument, markers");
    it->kind = kinds[k].kind;
    snprintf(key, sizeof key, "%s.%s", at, kinds[k].key);
    if (it->kind == TX_DRAW_PLANE) {
      static const char* const pkeys[] = {"point", "normal", "size_m", NULL};
      if (!json_is_object(v)) return bad(key, "expected an object, got %s", tx_json_kind(v));
      if (check_keys(key, v, pkeys)) return -1;
      double p[3] = {0, 0, 0}, nrm[3] = {0, 1, 0}, size = 0.2;
      if (point_normal(key, v, p, nrm, it->plane)) return -1;
      const json_t* q;
      char sub[128];
      snprintf(sub, sizeof sub, "%s.size_m", key);
      if ((q = json_object_get(v, "size_m")) && number(sub, q, 0, 1e4, true, &size)) return -1;
      it->plane[6] = (float)(size / 2);
      continue;
    }
    if (it->kind == TX_DRAW_MARKERS) { // the punctures, on the skin whose rows they name; grasps and knots by events
      static const char* const mkeys[] = {"punctures", "skin", "events", "thread", NULL};
      if (!json_is_object(v)) return bad(key, "expected an object, got %s", tx_json_kind(v));
      if (check_keys(key, v, mkeys)) return -1;
      char sub[128];
      const json_t* q = json_object_get(v, "punctures");
      snprintf(sub, sizeof sub, "%s.punctures", key);
      size_t n = json_is_string(q) ? strlen(json_string_value(q)) : 0;
      if (q && (!json_is_string(q) || !plain_name(json_string_value(q)) || n < 11 ||
                strcmp(json_string_value(q) + n - 10, ".punctures") != 0))
        return bad(sub, "expected a puncture list component such as needle.punctures");
      if (q) snprintf(it->name, sizeof it->name, "%s", json_string_value(q));
      const json_t* ev = json_object_get(v, "events");
      if (!q && !ev) return bad(sub, "expected a puncture list component such as needle.punctures, or events");
      q = json_object_get(v, "skin");
      snprintf(sub, sizeof sub, "%s.skin", key);
      if (*it->name && (!json_is_string(q) || !plain_name(json_string_value(q))))
        return bad(sub, "expected the skin's component prefix (SKIN.x holds the rows the punctures name), such as skin");
      if (!*it->name && q) return bad(sub, "a skin places punctures: give punctures too");
      if (q) snprintf(it->skin, sizeof it->skin, "%s", json_string_value(q));
      snprintf(sub, sizeof sub, "%s.events", key);
      if (ev && (!json_is_array(ev) || json_array_size(ev) == 0 || json_array_size(ev) > TX_MARKER_STREAMS))
        return bad(sub, "expected an array of 1 to %d event stream names, such as [\"instruments.events\"]", TX_MARKER_STREAMS);
      for (size_t j = 0; ev && j < json_array_size(ev); j++) {
        const json_t* name = json_array_get(ev, j);
        if (!json_is_string(name) || !plain_name(json_string_value(name)))
          return bad(sub, "entry %zu: expected an event stream name such as instruments.events", j);
        snprintf(it->events[it->nevents++], TX_NAME_MAX, "%s", json_string_value(name));
      }
      q = json_object_get(v, "thread");
      snprintf(sub, sizeof sub, "%s.thread", key);
      if (q && (!json_is_string(q) || !plain_name(json_string_value(q))))
        return bad(sub, "expected the thread's component prefix (THREAD.spheres: its nodes), such as thread");
      if (q && !ev) return bad(sub, "a thread places knots from events: give events too");
      if (q) snprintf(it->thread, sizeof it->thread, "%s", json_string_value(q));
      it->radius = 0.0015f;
      it->colour[0] = 0.9f, it->colour[1] = 0.15f, it->colour[2] = 0.85f; // magenta: apart from skin, steel and thread
      continue;
    }
    if (!json_is_string(v) || !plain_name(json_string_value(v)))
      return bad(key, "expected a component prefix of 1-%d characters of a-z 0-9 _ .", TX_NAME_MAX - 10);
    snprintf(it->name, sizeof it->name, "%s", json_string_value(v));
  }
  if (!it->kind) return bad(at, "expected one of mesh, spheres, segments, tool, plane, instrument, markers");
  double tmp[3];
  const json_t* v;
  snprintf(key, sizeof key, "%s.colour", at);
  if ((v = json_object_get(e, "colour"))) {
    if (numbers(key, v, 3, 0, 1, tmp)) return -1;
    for (int c = 0; c < 3; c++) it->colour[c] = (float)tmp[c];
  } else if (it->kind == TX_DRAW_TOOL) {
    it->colour[0] = 0.85f, it->colour[1] = 0.25f, it->colour[2] = 0.2f;
  } else if (it->kind == TX_DRAW_PLANE) {
    it->colour[0] = 0.45f, it->colour[1] = 0.5f, it->colour[2] = 0.6f;
  } else if (it->kind == TX_DRAW_MARKERS) { // set with the kind
  } else if (it->kind == TX_DRAW_INSTRUMENT) { // steel
    it->colour[0] = 0.72f, it->colour[1] = 0.74f, it->colour[2] = 0.78f;
  }
  snprintf(key, sizeof key, "%s.urdf", at);
  if ((v = json_object_get(e, "urdf"))) { // read and checked by the graphics view (it needs the readers)
    if (it->kind != TX_DRAW_INSTRUMENT) return bad(key, "only instruments take a urdf");
    const char* u = json_string_value(v);
    if (!u || !*u || strlen(u) >= sizeof it->urdf)
      return bad(key, "expected the hand's instruments: names or .urdf paths separated by spaces, at most %d characters",
                 (int)sizeof it->urdf - 1);
    snprintf(it->urdf, sizeof it->urdf, "%s", u);
  } else if (it->kind == TX_DRAW_INSTRUMENT) {
    return bad(key, "an instrument needs its urdf (as physics.instruments' handN or instrumentN)");
  }
  snprintf(key, sizeof key, "%s.colour_by", at);
  if ((v = json_object_get(e, "colour_by"))) {
    if (it->kind != TX_DRAW_SPHERES && it->kind != TX_DRAW_SEGMENTS && it->kind != TX_DRAW_MESH)
      return bad(key, "only meshes, spheres and segments take a colour map");
    if (!json_is_string(v) || !plain_name(json_string_value(v)))
      return bad(key, "expected a component name such as tissue.damage or liver.temperature");
    snprintf(it->scalar, sizeof it->scalar, "%s", json_string_value(v));
  }
  snprintf(key, sizeof key, "%s.range", at);
  if ((v = json_object_get(e, "range"))) {
    if (!*it->scalar) return bad(key, "a range needs colour_by");
    if (numbers(key, v, 2, -1e30, 1e30, tmp)) return -1;
    if (!(tmp[1] > tmp[0])) return bad(key, "expected [low, high] with low < high");
    it->range[0] = (float)tmp[0], it->range[1] = (float)tmp[1];
  }
  snprintf(key, sizeof key, "%s.texture", at);
  it->skin_texture = it->kind == TX_DRAW_MESH && !json_object_get(e, "colour");
  if ((v = json_object_get(e, "texture"))) {
    if (it->kind != TX_DRAW_MESH) return bad(key, "only meshes take a texture");
    const char* t = json_string_value(v);
    if (!t || (strcmp(t, "skin") != 0 && strcmp(t, "tissue") != 0 && strcmp(t, "none") != 0))
      return bad(key, "expected \"skin\", \"tissue\" or \"none\"");
    it->skin_texture = strcmp(t, "skin") == 0;
    it->tissue_texture = strcmp(t, "tissue") == 0;
  }
  double x = 0; // set by number() whenever it returns 0
  snprintf(key, sizeof key, "%s.radius_m", at);
  if ((v = json_object_get(e, "radius_m"))) {
    if (it->kind != TX_DRAW_TOOL && it->kind != TX_DRAW_MARKERS) return bad(key, "only tools and markers take a radius");
    if (number(key, v, 0, 1, true, &x)) return -1;
    it->radius = (float)x;
  }
  snprintf(key, sizeof key, "%s.show_force", at);
  if ((v = json_object_get(e, "show_force"))) {
    if (it->kind != TX_DRAW_TOOL) return bad(key, "only tools show a force");
    if (!json_is_boolean(v)) return bad(key, "expected true or false, got %s", tx_json_kind(v));
    it->show_force = json_is_true(v);
  }
  snprintf(key, sizeof key, "%s.force_scale_m_per_n", at);
  if ((v = json_object_get(e, "force_scale_m_per_n"))) {
    if (it->kind != TX_DRAW_TOOL) return bad(key, "only tools show a force");
    if (number(key, v, 0, 10, true, &x)) return -1;
    it->force_scale = (float)x;
  }
  // the proxy: where the force model's contact holds the tool on the surface (x0)
  snprintf(key, sizeof key, "%s.proxy", at);
  if ((v = json_object_get(e, "proxy"))) {
    if (it->kind != TX_DRAW_TOOL) return bad(key, "only tools show a proxy");
    if (!json_is_string(v) || !plain_name(json_string_value(v)) || !strstr(json_string_value(v), ".force_model"))
      return bad(key, "expected a force model component such as tool0.force_model");
    snprintf(it->proxy, sizeof it->proxy, "%s", json_string_value(v));
  }
  // a cutaway: the inside of a block of voxels, where a needle does its damage
  snprintf(key, sizeof key, "%s.cut", at);
  if ((v = json_object_get(e, "cut"))) {
    static const char* const ckeys[] = {"point", "normal", NULL};
    if (it->kind != TX_DRAW_SPHERES) return bad(key, "only spheres take a cut");
    if (!json_is_object(v)) return bad(key, "expected an object, got %s", tx_json_kind(v));
    if (check_keys(key, v, ckeys)) return -1;
    double p[3] = {0, 0, 0}, nrm[3] = {0, 0, 1};
    if (point_normal(key, v, p, nrm, it->cut)) return -1;
    it->has_cut = true;
  }
  return 0;
}

int tx_view_def_from_json(const json_t* view, tx_view_def* d) {
  static const char* const keys[] = {"rate_hz", "width", "height", "frame_every", "camera", "laparoscope", "stereo",
                                     "background", "light", "draw", NULL};
  if (!json_is_object(view)) return bad("", "expected an object, got %s", tx_json_kind(view));
  if (check_keys("", view, keys)) return -1;
  const json_t* v;
  if ((v = json_object_get(view, "rate_hz"))) {
    double hz;
    if (number("rate_hz", v, 0, 1000, true, &hz)) return -1;
  }
  if ((v = json_object_get(view, "width")) && integer("width", v, 16, TX_VIEW_SIDE_MAX, &d->width)) return -1;
  if ((v = json_object_get(view, "height")) && integer("height", v, 16, TX_VIEW_SIDE_MAX, &d->height)) return -1;
  if ((v = json_object_get(view, "frame_every")) && integer("frame_every", v, 1, 1000000, &d->frame_every))
    return -1;
  if ((v = json_object_get(view, "camera")) && read_camera(v, d)) return -1;
  if ((v = json_object_get(view, "laparoscope")) && read_laparoscope(v, json_object_get(view, "camera"), d)) return -1;
  if ((v = json_object_get(view, "stereo"))) {
    static const char* const skeys[] = {"interaxial_m", "convergence_m", NULL};
    if (!json_is_object(v)) return bad("stereo", "expected an object, got %s", tx_json_kind(v));
    if (check_keys("stereo", v, skeys)) return -1;
    const json_t* q;
    if ((q = json_object_get(v, "interaxial_m")) && number("stereo.interaxial_m", q, 0, 1, false, &d->camera.interaxial))
      return -1;
    d->interaxial_given = q != NULL;
    if ((q = json_object_get(v, "convergence_m")) &&
        number("stereo.convergence_m", q, 0, 1e4, true, &d->camera.convergence))
      return -1;
    d->convergence_given = q != NULL;
  }
  double c[3];
  if ((v = json_object_get(view, "background"))) {
    if (numbers("background", v, 3, 0, 1, c)) return -1;
    for (int i = 0; i < 3; i++) d->background[i] = (float)c[i];
  }
  if ((v = json_object_get(view, "light")) && json_is_string(v)) {
    if (strcmp(json_string_value(v), "headlight") != 0) return bad("light", "expected a direction or \"headlight\"");
    d->headlight = true;
  } else if (v) {
    if (numbers("light", v, 3, -1e4, 1e4, c)) return -1;
    double l = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (!(l > 1e-6)) return bad("light", "expected a non-zero direction");
    for (int i = 0; i < 3; i++) d->light_dir[i] = (float)(c[i] / l);
  }
  // the 1/30 rule of stereography: comfortable depth for a scene at the convergence distance
  if (!d->interaxial_given) d->camera.interaxial = d->camera.convergence / 30;
  if ((v = json_object_get(view, "draw"))) {
    if (!json_is_array(v) || json_array_size(v) == 0 || json_array_size(v) > TX_DRAW_MAX)
      return bad("draw", "expected an array of 1 to %d entries", TX_DRAW_MAX);
    d->nitems = 0;
    size_t i;
    json_t* e;
    json_array_foreach(v, i, e) {
      if (read_item(i, e, &d->items[d->nitems])) return -1;
      d->nitems++;
    }
  }
  return 0;
}

int tx_view_def_from_text(const char* text, tx_view_def* d) {
  json_error_t e;
  json_t* view = text ? json_loads(text, JSON_DECODE_ANY, &e) : NULL;
  if (!view) return bad("", "not JSON: %s", text ? e.text : "no text");
  int rc = tx_view_def_from_json(view, d);
  json_decref(view);
  return rc;
}

static bool has(const char* const* written, int count, const char* name) {
  for (int i = 0; i < count; i++)
    if (strcmp(written[i], name) == 0) return true;
  return false;
}

// NAME from "NAME.suffix" when the written name ends in that suffix
static bool prefix_of(const char* comp, const char* suffix, char out[TX_NAME_MAX]) {
  size_t n = strlen(comp), s = strlen(suffix);
  if (n <= s || strcmp(comp + n - s, suffix) != 0 || n - s >= TX_NAME_MAX - 10) return false;
  memcpy(out, comp, n - s);
  out[n - s] = 0;
  return true;
}

int tx_view_def_auto_draw(tx_view_def* d, const char* const* written, int count) {
  d->nitems = 0;
  static const char* const scalars[] = {"damage", "temperature", NULL};
  for (int i = 0; i < count && d->nitems < TX_DRAW_MAX; i++) {
    char name[TX_NAME_MAX], other[TX_NAME_MAX + 16];
    tx_draw_item it = {.colour = {0.8f, 0.8f, 0.8f}, .range = {0, 1}, .radius = 0.005f, .force_scale = 0.01f};
    if (prefix_of(written[i], ".x", name)) {
      snprintf(other, sizeof other, "%s.tri", name);
      if (!has(written, count, other)) continue;
      it.kind = TX_DRAW_MESH;
      it.skin_texture = true;
    } else if (prefix_of(written[i], ".spheres", name)) {
      it.kind = TX_DRAW_SPHERES;
      for (const char* const* q = scalars; *q && !*it.scalar; q++) {
        snprintf(other, sizeof other, "%s.%s", name, *q);
        if (has(written, count, other) && strlen(other) < sizeof it.scalar) memcpy(it.scalar, other, strlen(other) + 1);
      }
    } else if (prefix_of(written[i], ".segments", name)) {
      it.kind = TX_DRAW_SEGMENTS;
      it.colour[0] = 0.9f, it.colour[1] = 0.85f, it.colour[2] = 0.5f;
    } else if (prefix_of(written[i], ".pose", name) && strncmp(name, "device", 6) == 0) {
      it.kind = TX_DRAW_TOOL;
      it.colour[0] = 0.85f, it.colour[1] = 0.25f, it.colour[2] = 0.2f;
      snprintf(other, sizeof other, "%s.force", name);
      it.show_force = has(written, count, other);
      snprintf(other, sizeof other, "tool%s.force_model", name + 6); // deviceN's is toolN's, as the scenarios name them
      if (has(written, count, other) && strlen(other) < sizeof it.proxy) memcpy(it.proxy, other, strlen(other) + 1);
    } else {
      continue;
    }
    memcpy(it.name, name, sizeof it.name);
    d->items[d->nitems++] = it;
  }
  return d->nitems;
}

// prefix + suffix into a component name; prefixes are checked short enough on input
static void join(char out[TX_NAME_MAX], const char* prefix, const char* suffix) {
  size_t k = 0;
  for (; *prefix && k < TX_NAME_MAX - 1; prefix++) out[k++] = *prefix;
  for (; *suffix && k < TX_NAME_MAX - 1; suffix++) out[k++] = *suffix;
  out[k] = 0;
}

int tx_draw_item_components(const tx_draw_item* it, char out[3][TX_NAME_MAX]) {
  int n = 0;
  switch (it->kind) {
  case TX_DRAW_MESH:
    join(out[n++], it->name, ".x");
    join(out[n++], it->name, ".tri");
    break;
  case TX_DRAW_SPHERES: join(out[n++], it->name, ".spheres"); break;
  case TX_DRAW_SEGMENTS: join(out[n++], it->name, ".segments"); break;
  case TX_DRAW_TOOL:
    join(out[n++], it->name, ".pose");
    if (it->show_force) join(out[n++], it->name, ".force");
    if (*it->proxy) join(out[n++], it->proxy, "");
    break;
  case TX_DRAW_PLANE: break;
  case TX_DRAW_INSTRUMENT:
    join(out[n++], it->name, ".links");
    join(out[n++], it->name, ".held");
    break;
  case TX_DRAW_MARKERS: // the renderer finds them in this order by which are given
    if (*it->name) join(out[n++], it->name, ""), join(out[n++], it->skin, ".x");
    if (*it->thread) join(out[n++], it->thread, ".spheres");
    break;
  }
  if (*it->scalar) join(out[n++], it->scalar, "");
  return n;
}

void tx_marker_take(tx_marker_list* l, const tx_event* e) {
  if (e->kind == TX_EVENT_RELEASE) { // every grasp of that hand ends
    uint32_t k = 0;
    for (uint32_t i = 0; i < l->n; i++)
      if (!(l->m[i].kind == TX_EVENT_GRASP && l->m[i].source == e->source)) l->m[k++] = l->m[i];
    l->n = k;
    return;
  }
  tx_marker m = {.kind = e->kind, .source = e->source};
  if (e->kind == TX_EVENT_GRASP) {
    for (int c = 0; c < 3; c++) m.p[c] = (float)e->grasp.point[c];
    if (!(isfinite(m.p[0]) && isfinite(m.p[1]) && isfinite(m.p[2]))) return;
  } else if (e->kind == TX_EVENT_KNOT) { // value[0], value[1]: its first and last node
    double a = e->value[0], b = e->value[1];
    if (!(a >= 0 && b >= a && b < 1e9)) return;
    m.first = (uint32_t)a, m.last = (uint32_t)b;
  } else {
    return;
  }
  if (l->n == TX_MARKERS_MAX) {
    l->dropped++;
    return;
  }
  l->m[l->n++] = m;
}
