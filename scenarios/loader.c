// Scenario files: JSON (jansson) to a checked, finalized controller system.
#include "loader.h"

#include "../model/error.h"
#include "../views/graphics/view_def.h"
#include "../views/graphics/window_input.h"

#include <tactus/config.h>

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define SETS_MAX 64

// sets tx_error() and returns -1
static int fail(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
static int fail(const char* fmt, ...) {
  char line[1024]; // the message may quote tx_error() itself
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  // keys and values from the file are quoted in messages: keep the message one line
  for (char* c = line; *c; c++)
    if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = '?';
  tx_set_error("%s", line);
  return -1;
}

// every key of obj must be one of known (NULL-terminated)
static int check_keys(const char* file, const char* where, json_t* obj, const char* const* known) {
  const char* key;
  json_t* v;
  json_object_foreach(obj, key, v) {
    bool ok = false;
    for (const char* const* k = known; *k && !ok; k++) ok = strcmp(*k, key) == 0;
    if (ok) continue;
    char list[256] = "";
    for (const char* const* k = known; *k; k++) {
      size_t len = strlen(list);
      snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "", *k);
    }
    return fail("%s: %s%s%s: unknown key (known: %s)", file, where, *where ? "." : "", key, list);
  }
  return 0;
}

// list[i] must be an object with known keys only; where receives "list[i]"
static int check_entry(const char* file, const char* list, size_t i, json_t* entry, const char* const* known,
                       char* where, size_t wn) {
  snprintf(where, wn, "%s[%zu]", list, i);
  if (!json_is_object(entry)) return fail("%s: %s: expected an object, got %s", file, where, tx_json_kind(entry));
  return check_keys(file, where, entry, known);
}

// a --set or --device that changed one controller value, to name it when that value is wrong
typedef struct set_origin {
  int controller;
  char key[128];    // "params.X" or "rate_hz"
  const char* flag; // "--set" or "--device"
  const char* text;
} set_origin;

static int apply_sets(const char* file, json_t* root, const tx_load_options* o, set_origin* origins, int* norigins) {
  *norigins = 0;
  for (int i = 0; o && i < o->nsets; i++) {
    const char* text = o->sets[i];
    const char* eq = strchr(text, '=');
    if (!eq || eq == text) return fail("--set %s: expected KEY=VALUE", text);
    char key[128];
    if ((size_t)(eq - text) >= sizeof key) return fail("--set %s: key too long", text);
    memcpy(key, text, eq - text);
    key[eq - text] = 0;
    json_error_t je;
    json_t* value = json_loads(eq + 1, JSON_DECODE_ANY, &je);
    // a number past a double's range is not a bare word
    if (!value && strstr(je.text, "real number overflow"))
      return fail("--set %s: the number is out of range (beyond +-1.8e308)", text);
    if (!value) value = json_string(eq + 1); // bare words are strings
    if (!value) return fail("--set %s: value is not valid UTF-8", text);

    char* dot = strchr(key, '.');
    if (!dot) {
      if (strcmp(key, "duration_s") != 0) {
        json_decref(value);
        return fail("--set %s: unknown key '%s' (use duration_s or CONTROLLER.PARAM)", text, key);
      }
      // checked here, so that a bad value names the --set rather than the file
      if (!json_is_number(value) || !(json_number_value(value) >= TX_DURATION_MIN_S && json_number_value(value) <= TX_DURATION_MAX_S)) {
        json_decref(value);
        return fail("--set %s: expected a number in [%g, %g]", text, TX_DURATION_MIN_S, TX_DURATION_MAX_S);
      }
      json_object_set_new(root, key, value);
      continue;
    }
    *dot = 0;
    const char* param = dot + 1;
    json_t* controllers = json_object_get(root, "controllers");
    size_t index;
    json_t* c;
    int found = -1;
    json_array_foreach(controllers, index, c) {
      if (json_is_string(json_object_get(c, "name")) && strcmp(json_string_value(json_object_get(c, "name")), key) == 0)
        found = (int)index;
    }
    if (found < 0 && *param && strcmp(key, "net") == 0) { // the net section: net.domain, net.peers, ...
      json_t* net = json_object_get(root, "net");
      if (!net) json_object_set_new(root, "net", net = json_object());
      if (!json_is_object(net)) return json_decref(value), fail("%s: net: expected an object", file);
      json_object_set_new(net, param, value);
      continue;
    }
    if (found < 0 || !*param) {
      json_decref(value);
      if (!*param) return fail("--set %s: expected CONTROLLER.PARAM=VALUE", text);
      return fail("--set %s: no controller named '%s' in %s", text, key, file);
    }
    c = json_array_get(controllers, found);
    set_origin* so = &origins[(*norigins)++];
    so->controller = found;
    so->flag = "--set";
    so->text = text;
    if (strcmp(param, "rate_hz") == 0) {
      json_object_set_new(c, "rate_hz", value);
      snprintf(so->key, sizeof so->key, "rate_hz");
    } else {
      json_t* params = json_object_get(c, "params");
      if (!params) json_object_set_new(c, "params", params = json_object());
      if (!json_is_object(params)) {
        json_decref(value);
        return fail("%s: controllers[%d].params: expected an object", file, found);
      }
      json_object_set_new(params, param, value);
      snprintf(so->key, sizeof so->key, "params.%s", param);
    }
  }
  return 0;
}

// plugin libraries stay loaded for the life of the process: their classes live
// there, even those of a plugin that failed half-way, which is not run again
typedef struct loaded_plugin {
  char path[PATH_MAX];
  char failure[256]; // "" when it registered
} loaded_plugin;
static loaded_plugin loaded_plugins[32];
static int nloaded_plugins;

static int load_plugins(const char* file, const char* dir, json_t* plugins, const tx_load_options* o) {
  if (!plugins) return 0;
  if (!json_is_array(plugins)) return fail("%s: plugins: expected an array of paths", file);
  size_t i;
  json_t* p;
  json_array_foreach(plugins, i, p) {
    if (!json_is_string(p)) return fail("%s: plugins[%zu]: expected a path, got %s", file, i, tx_json_kind(p));
    if (!o || !o->allow_plugins) return fail("%s: plugins[%zu]: plugins are not allowed here", file, i);
    char path[PATH_MAX], real[PATH_MAX];
    const char* name = json_string_value(p);
    snprintf(path, sizeof path, "%s%s%s", name[0] == '/' ? "" : dir, name[0] == '/' ? "" : "/", name);
    if (!realpath(path, real)) return fail("%s: plugins[%zu]: %s: %s", file, i, path, strerror(errno));
    const loaded_plugin* seen = NULL;
    for (int k = 0; k < nloaded_plugins && !seen; k++)
      if (strcmp(loaded_plugins[k].path, real) == 0) seen = &loaded_plugins[k];
    if (seen && *seen->failure) return fail("%s: plugins[%zu]: %s refused to register: %s", file, i, real, seen->failure);
    if (seen) continue;
    if (nloaded_plugins == 32) return fail("%s: plugins[%zu]: more than 32 plugins", file, i);
    void* lib = dlopen(real, RTLD_NOW | RTLD_LOCAL);
    if (!lib) return fail("%s: plugins[%zu]: %s", file, i, dlerror());
    int (*entry)(int) = (int (*)(int))dlsym(lib, "tx_plugin_register");
    if (!entry) {
      dlclose(lib);
      return fail("%s: plugins[%zu]: %s has no tx_plugin_register", file, i, real);
    }
    loaded_plugin* lp = &loaded_plugins[nloaded_plugins++];
    strcpy(lp->path, real);
    if (entry(TX_API_VERSION) != 0) {
      snprintf(lp->failure, sizeof lp->failure, "%s", *tx_error() ? tx_error() : "it returned an error");
      return fail("%s: plugins[%zu]: %s refused to register: %s", file, i, real, lp->failure);
    }
  }
  return 0;
}

static int declare_model(const char* file, tx_system* sys, json_t* model) {
  if (!model) return 0;
  if (!json_is_array(model)) return fail("%s: model: expected an array of components", file);
  static const char* const keys[] = {"name", "type", "rows", "cols", "units", NULL};
  size_t i;
  json_t* c;
  json_array_foreach(model, i, c) {
    char where[48];
    if (check_entry(file, "model", i, c, keys, where, sizeof where)) return -1;
    json_t *name = json_object_get(c, "name"), *type = json_object_get(c, "type"), *rows = json_object_get(c, "rows"),
           *cols = json_object_get(c, "cols"), *units = json_object_get(c, "units");
    if (!json_is_string(name)) return fail("%s: %s.name: expected a string", file, where);
    tx_type t = tx_type_from_name(json_string_value(type));
    if (!t) return fail("%s: %s.type: expected one of f32, f64, i32, u32, u8", file, where);
    if (!json_is_integer(rows) || json_integer_value(rows) < 1 || json_integer_value(rows) > (1 << 26))
      return fail("%s: %s.rows: expected an integer in [1, %d]", file, where, 1 << 26);
    if (cols && (!json_is_integer(cols) || json_integer_value(cols) < 1 || json_integer_value(cols) > 1024))
      return fail("%s: %s.cols: expected an integer in [1, 1024]", file, where);
    if (units && !json_is_string(units)) return fail("%s: %s.units: expected a string", file, where);
    tx_component_def d = {json_string_value(name), t, (uint32_t)json_integer_value(rows),
                          cols ? (uint32_t)json_integer_value(cols) : 1, units ? json_string_value(units) : "1"};
    if (tx_system_declare(sys, &d)) return fail("%s: %s.%s: %s", file, where, tx_error_key(), tx_error());
  }
  return 0;
}

// the i-th --device goes to the i-th controller of type "haptics"; "scenario"
// keeps the file's own device for that hand
static int apply_devices(const char* file, json_t* root, const tx_load_options* o, set_origin* origins, int* norigins) {
  json_t* controllers = json_object_get(root, "controllers");
  size_t index = 0, used = 0;
  json_t* c;
  json_array_foreach(controllers, index, c) {
    if (used == (size_t)o->ndevices) break;
    json_t* type = json_object_get(c, "type");
    if (!json_is_string(type) || strcmp(json_string_value(type), "haptics") != 0) continue;
    json_t* params = json_object_get(c, "params");
    if (!params) json_object_set_new(c, "params", params = json_object());
    if (!json_is_object(params)) return fail("%s: controllers[%zu].params: expected an object", file, index);
    if (strcmp(o->devices[used], "scenario") == 0) {
      used++;
      continue;
    }
    json_object_set_new(params, "device", json_string(o->devices[used]));
    origins[*norigins] = (set_origin){(int)index, "params.device", "--device", o->devices[used]};
    (*norigins)++;
    used++;
  }
  if (used < (size_t)o->ndevices)
    return fail("--device %s: %s has %zu haptics controller%s, so it takes at most %zu --device", o->devices[used],
                file, used, used == 1 ? "" : "s", used);
  return 0;
}

// map[i]: the index in the file of list[i] (a role runs a part of the list), NULL when the same
static int add_controllers(const char* file, tx_system* sys, json_t* list, const set_origin* origins, int norigins,
                           const int* map) {
  // a role's part (map) may be empty: a display host runs only its --view
  if (!json_is_array(list) || (json_array_size(list) == 0 && !map))
    return fail("%s: controllers: expected a non-empty array", file);
  static const char* const keys[] = {"name", "type", "rate_hz", "params", "thread", NULL};
  size_t index;
  json_t* c;
  json_array_foreach(list, index, c) {
    char where[48];
    size_t i = map ? (size_t)map[index] : index;
    if (check_entry(file, "controllers", i, c, keys, where, sizeof where)) return -1;
    json_t *name = json_object_get(c, "name"), *type = json_object_get(c, "type"), *rate = json_object_get(c, "rate_hz");
    if (!json_is_string(name)) return fail("%s: %s.name: expected a string", file, where);
    if (!json_is_string(type)) return fail("%s: %s.type: expected a string", file, where);
    json_t* thread = json_object_get(c, "thread");
    if (thread && !json_is_string(thread))
      return fail("%s: %s.thread: expected a thread name (a string), got %s", file, where, tx_json_kind(thread));
    if (!json_is_number(rate))
      tx_set_error_at("rate_hz", "expected a number in Hz, got %s", rate ? tx_json_kind(rate) : "nothing");
    else if (tx_system_add(sys, json_string_value(name), json_string_value(type), json_number_value(rate),
                           json_object_get(c, "params")) == 0) {
      if (!thread || tx_system_set_thread(sys, tx_system_count(sys) - 1, json_string_value(thread)) == 0) continue;
    }
    char key[128]; // fail() replaces the key with the message
    snprintf(key, sizeof key, "%s", tx_error_key());
    for (int k = norigins - 1; k >= 0; k--) // the last --set of a key is the one in effect
      if (origins[k].controller == (int)i && strcmp(origins[k].key, key) == 0)
        return fail("%s %s: %s", origins[k].flag, origins[k].text, tx_error());
    return fail("%s: %s%s%s: %s", file, where, *key ? "." : "", key, tx_error());
  }
  return 0;
}

#define VIEW_INSTANCE "view" // the graphics view's name in the report

// the scenario's "view" is always checked; a graphics view is added only when the run draws
static int add_view(const char* file, tx_system* sys, json_t* view, const tx_load_options* o) {
  tx_view_def d = tx_view_def_default();
  if (view && tx_view_def_from_json(view, &d))
    return fail("%s: view%s%s", file, *tx_error_key() ? "." : ": ", tx_error()); // tx_error() starts with the key
  // the clocks' lower bound, checked even when nothing draws
  json_t* vr = view ? json_object_get(view, "rate_hz") : NULL;
  if (json_is_number(vr) && json_number_value(vr) < TX_RATE_MIN_HZ)
    return fail("%s: view.rate_hz: %g Hz is below the least rate, %g Hz", file, json_number_value(vr), TX_RATE_MIN_HZ);
  if (!o || !o->view || strcmp(o->view, "none") == 0) return 0;
  // a window's mouse and keyboard reach the model through a controller of
  // their own (the view only reads): window.pointer, for the mouse device
  if (strcmp(o->view, "window") == 0 && tx_find_controller("input.window")) {
    if (tx_system_add(sys, "window_input", "input.window", TX_WINDOW_INPUT_HZ, NULL))
      return fail("%s: view: %s", file, tx_error());
  }
  json_t* rate = view ? json_object_get(view, "rate_hz") : NULL;
  json_t* params = json_object();
  json_t* available = json_array();
  if (!params || !available) return json_decref(params), json_decref(available), fail("%s: out of memory", file);
  // what the model holds, for the draw list made from the naming conventions
  for (int i = 0; i < tx_system_count(sys); i++)
    for (int p = 0; p < tx_system_ports(sys, i) && json_array_size(available) < 256; p++)
      if (tx_system_port(sys, i, p).write) json_array_append_new(available, json_string(tx_system_port(sys, i, p).component));
  if (view) json_object_set(params, "view", view);
  json_object_set_new(params, "available", available);
  json_object_set_new(params, "target", json_string(o->view));
  json_object_set_new(params, "stereo_mode", json_string(o->stereo ? o->stereo : "mono"));
  json_object_set_new(params, "wait", json_boolean(o->view_wait));
  int rc = tx_system_add(sys, VIEW_INSTANCE, "views.graphics", rate ? json_number_value(rate) : 30, params);
  json_decref(params);
  if (rc == 0) return 0;
  char key[128];
  snprintf(key, sizeof key, "%s", tx_error_key());
  const char* k = strncmp(key, "params.", 7) == 0 ? key + 7 : key;
  if (strcmp(k, "view") == 0 || strcmp(k, "name") == 0) k = "";
  return fail("%s: view%s%s: %s", file, *k ? "." : "", k, tx_error());
}


#define PROBE_INSTANCE "probe" // --probe's view.probe in the report

// --probe: a view.probe of the components named, every EVERY_S (0.1 s by default)
static int add_probe(tx_system* sys, const tx_load_options* o) {
  if (!o || !o->probe) return 0;
  char spec[1024];
  if (snprintf(spec, sizeof spec, "%s", o->probe) >= (int)sizeof spec) return fail("--probe: longer than %zu characters", sizeof spec - 1);
  double every = 0.1;
  char* at = strchr(spec, '@');
  if (at) {
    char* end;
    *at = 0;
    every = strtod(at + 1, &end);
    if (end == at + 1 || *end || !isfinite(every) || every < 0)
      return fail("--probe %s: expected @ a time in seconds, 0 or more, after the components", o->probe);
  }
  json_t* params = json_object();
  json_t* list = json_array();
  if (!params || !list) return json_decref(params), json_decref(list), fail("--probe: out of memory");
  for (char* save = NULL, *c = strtok_r(spec, ",", &save); c; c = strtok_r(NULL, ",", &save)) json_array_append_new(list, json_string(c));
  json_object_set_new(params, "components", list);
  json_object_set_new(params, "every_s", json_real(every));
  int rc = tx_system_add(sys, PROBE_INSTANCE, "view.probe", every > 0 && every < 0.01 ? 1000 : 100, params);
  json_decref(params);
  if (rc) return fail("--probe %s: %s%s%s", o->probe, tx_error_key(), *tx_error_key() ? ": " : "", tx_error());
  return 0;
}

// ---- roles and the net section: one scenario split over processes (docs/distributed.md)

#define ROLES_MAX 16
#define NET_INSTANCE "net" // the bridge's name in the report
#define NET_DOMAIN_MAX 232 // DDS domain ids with the standard port mapping
#define NET_PEERS_MAX 32

static bool plain_name(const char* n, size_t max, bool dot) {
  size_t len = strlen(n);
  if (len == 0 || len >= max) return false;
  for (const char* c = n; *c; c++)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_' || (dot ? *c == '.' : *c == '-'))) return false;
  return true;
}

// "roles": {ROLE: [CONTROLLER, ...]}: every controller in exactly one role;
// a role may be empty (a display host: only the --view it runs with).
// role_of[i] receives the role index of controllers[i]; *nroles the count
static int check_roles(const char* file, json_t* roles, json_t* controllers, int* role_of, int* nroles) {
  *nroles = 0;
  if (!roles) return 0;
  if (!json_is_object(roles) || json_object_size(roles) == 0)
    return fail("%s: roles: expected an object of ROLE: [CONTROLLER, ...]", file);
  if (json_object_size(roles) > ROLES_MAX) return fail("%s: roles: at most %d", file, ROLES_MAX);
  size_t n = json_is_array(controllers) ? json_array_size(controllers) : 0;
  for (size_t i = 0; i < n; i++) role_of[i] = -1;
  const char* role;
  json_t* list;
  int r = 0;
  json_object_foreach(roles, role, list) {
    if (!plain_name(role, 32, false)) return fail("%s: roles.%s: a role name is 1-31 characters of a-z 0-9 _ -", file, role);
    if (!json_is_array(list)) return fail("%s: roles.%s: expected an array of controller names", file, role);
    size_t k;
    json_t* name;
    json_array_foreach(list, k, name) {
      size_t found = n;
      for (size_t i = 0; i < n && found == n; i++) {
        json_t* cn = json_object_get(json_array_get(controllers, i), "name");
        if (json_is_string(name) && json_is_string(cn) && strcmp(json_string_value(cn), json_string_value(name)) == 0) found = i;
      }
      if (found == n) return fail("%s: roles.%s[%zu]: no controller named %s%s%s", file, role, k, json_is_string(name) ? "'" : "",
                                  json_is_string(name) ? json_string_value(name) : tx_json_kind(name), json_is_string(name) ? "'" : "");
      if (role_of[found] >= 0) return fail("%s: roles.%s[%zu]: '%s' already has a role", file, role, k, json_string_value(name));
      role_of[found] = r;
    }
    r++;
  }
  for (size_t i = 0; i < n; i++)
    if (role_of[i] < 0) {
      json_t* cn = json_object_get(json_array_get(controllers, i), "name");
      return fail("%s: controllers[%zu]: '%s' has no role (every controller of a scenario with roles has one)", file, i,
                  json_is_string(cn) ? json_string_value(cn) : "?");
    }
  *nroles = r;
  return 0;
}

// "net": {domain, peers, rate_hz, fast, state, streams}, checked on every load
static int check_net(const char* file, json_t* net) {
  if (!net) return 0;
  if (!json_is_object(net)) return fail("%s: net: expected an object", file);
  static const char* const keys[] = {"domain", "peers", "rate_hz", "poll_us", "fast", "state", "streams", NULL};
  if (check_keys(file, "net", net, keys)) return -1;
  json_t* domain = json_object_get(net, "domain");
  if (domain && (!json_is_integer(domain) || json_integer_value(domain) < 0 || json_integer_value(domain) > NET_DOMAIN_MAX))
    return fail("%s: net.domain: expected an integer in [0, %d] (a DDS domain id)", file, NET_DOMAIN_MAX);
  json_t* poll = json_object_get(net, "poll_us");
  if (poll && (!json_is_integer(poll) || json_integer_value(poll) < 0 || json_integer_value(poll) > 100000))
    return fail("%s: net.poll_us: expected an integer in [0, 100000] (us; 0: send from the bridge's step)", file);
  json_t* rate = json_object_get(net, "rate_hz");
  if (rate && (!json_is_number(rate) || !(json_number_value(rate) >= 1 && json_number_value(rate) <= TX_RATE_MAX_HZ)))
    return fail("%s: net.rate_hz: expected a number in [1, %g]", file, TX_RATE_MAX_HZ);
  json_t* peers = json_object_get(net, "peers");
  if (peers && (!json_is_array(peers) || json_array_size(peers) > NET_PEERS_MAX))
    return fail("%s: net.peers: expected an array of at most %d addresses", file, NET_PEERS_MAX);
  size_t i;
  json_t* v;
  json_array_foreach(peers, i, v) {
    const char* p = json_string_value(v);
    bool ok = p && *p && strlen(p) <= 253 && p[0] != '-' && p[0] != '.' && !strstr(p, "..");
    bool digits = true;
    for (const char* c = p; ok && *c; c++) {
      ok = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '-' || *c == '.';
      if (!(*c >= '0' && *c <= '9') && *c != '.') digits = false;
    }
    if (ok && digits) { // all digits and dots: it must be a dotted quad of bytes
      unsigned a, b, c, d;
      char end;
      ok = sscanf(p, "%u.%u.%u.%u%c", &a, &b, &c, &d, &end) == 4 && a < 256 && b < 256 && c < 256 && d < 256;
    }
    if (!ok) return fail("%s: net.peers[%zu]: expected an IPv4 address or a host name", file, i);
  }
  static const char* const lists[] = {"fast", "state", "streams"};
  for (int l = 0; l < 3; l++) {
    json_t* a = json_object_get(net, lists[l]);
    if (a && !json_is_array(a)) return fail("%s: net.%s: expected an array of names", file, lists[l]);
    json_array_foreach(a, i, v)
      if (!json_is_string(v) || !plain_name(json_string_value(v), TX_NAME_MAX, true))
        return fail("%s: net.%s[%zu]: expected a component name (a-z 0-9 _ .)", file, lists[l], i);
  }
  return 0;
}

// the writer of a component (or stream) in a finalized system: its instance, or -1
static int writer_of(tx_system* sys, const char* name, bool stream, const tx_component_def** def) {
  for (int i = 0; i < tx_system_count(sys); i++)
    for (int p = 0; p < tx_system_ports(sys, i); p++) {
      tx_port_info pi = tx_system_port(sys, i, p);
      if (strcmp(pi.component, name) != 0) continue;
      if (stream ? pi.stream == 1 : (pi.stream == 0 && pi.write)) {
        if (def) *def = pi.def;
        return i;
      }
    }
  return -1;
}

// every name in net.fast, net.state and net.streams is in the model
static int check_net_names(const char* file, json_t* net, tx_system* sys) {
  static const char* const lists[] = {"fast", "state", "streams"};
  for (int l = 0; net && l < 3; l++) {
    size_t i;
    json_t* v;
    json_array_foreach(json_object_get(net, lists[l]), i, v)
      if (writer_of(sys, json_string_value(v), l == 2, NULL) < 0)
        return fail("%s: net.%s[%zu]: '%s' is not %s", file, lists[l], i, json_string_value(v),
                    l == 2 ? "an event stream any controller emits" : "in the model (no controller writes it)");
  }
  return 0;
}

static bool in_list(json_t* a, const char* name) {
  size_t i;
  json_t* v;
  json_array_foreach(a, i, v)
    if (strcmp(json_string_value(v), name) == 0) return true;
  return false;
}

// the bridge's parameters for one role: what its controllers write and others
// read goes out, what they read and others write comes in with the writer's
// schema; a read across roles that the net section does not name is an error
static json_t* bridge_params(const char* file, const char* scenario, json_t* net, tx_system* full, int ncontrollers,
                             const int* role_of, int role, bool* any) {
  json_t *fast = json_object_get(net, "fast"), *state = json_object_get(net, "state"), *streams = json_object_get(net, "streams");
  json_t *send = json_array(), *receive = json_array(), *send_streams = json_array(), *receive_streams = json_array(),
         *best = json_array();
  json_t* params = json_object();
  *any = false;
  for (int i = 0; i < tx_system_count(full); i++) {
    if (role_of[i] != role) continue;
    for (int p = 0; p < tx_system_ports(full, i); p++) {
      tx_port_info pi = tx_system_port(full, i, p);
      bool stream = pi.stream != 0;
      const tx_component_def* def = NULL;
      if (pi.write || pi.stream == 1) { // written here: sent when it crosses
        bool crosses = stream ? in_list(streams, pi.component) : in_list(fast, pi.component) || in_list(state, pi.component);
        if (crosses && !in_list(stream ? send_streams : send, pi.component))
          json_array_append_new(stream ? send_streams : send, json_string(pi.component));
        if (crosses && !stream && in_list(fast, pi.component) && !in_list(best, pi.component))
          json_array_append_new(best, json_string(pi.component));
        continue;
      }
      int w = writer_of(full, pi.component, stream, &def);
      if (w < 0 || role_of[w] == role) continue;
      bool crosses = stream ? in_list(streams, pi.component) : in_list(fast, pi.component) || in_list(state, pi.component);
      if (!crosses) {
        json_decref(params), json_decref(send), json_decref(receive), json_decref(send_streams);
        json_decref(receive_streams), json_decref(best);
        char who[32]; // a controller of the file, or the --view added after them
        if (i < ncontrollers) snprintf(who, sizeof who, "controllers[%d]", i);
        else snprintf(who, sizeof who, "view");
        return fail("%s: %s: %s '%s', which controller '%s' of another role writes: name it in net.%s", file, who,
                    stream ? "listens to" : "reads", pi.component, tx_system_name(full, w), stream ? "streams" : "fast or net.state"),
               NULL;
      }
      bool seen = false;
      size_t k;
      json_t* e;
      json_array_foreach(stream ? receive_streams : receive, k, e) seen |= strcmp(json_string_value(json_object_get(e, "name")), pi.component) == 0;
      if (seen) continue;
      if (stream) {
        uint32_t capacity = 0;
        for (int s = 0; s < tx_system_streams(full); s++)
          if (strcmp(tx_system_stream(full, s).name, pi.component) == 0) capacity = tx_system_stream(full, s).capacity;
        json_array_append_new(receive_streams, json_pack("{s:s, s:I}", "name", pi.component, "capacity", (json_int_t)capacity));
      } else {
        json_array_append_new(receive, json_pack("{s:s, s:s, s:I, s:I, s:s}", "name", pi.component, "type", tx_type_name(def->type),
                                                 "rows", (json_int_t)def->rows, "cols", (json_int_t)def->cols, "units", def->units));
        if (in_list(fast, pi.component) && !in_list(best, pi.component)) json_array_append_new(best, json_string(pi.component));
      }
    }
  }
  *any = json_array_size(send) + json_array_size(receive) + json_array_size(send_streams) + json_array_size(receive_streams) > 0;
  json_t* domain = json_object_get(net, "domain");
  json_object_set_new(params, "domain", json_integer(domain ? json_integer_value(domain) : 0));
  json_t* peers = json_object_get(net, "peers");
  json_object_set_new(params, "peers", peers ? json_deep_copy(peers) : json_array());
  json_object_set_new(params, "session", json_string(scenario));
  json_t* poll = json_object_get(net, "poll_us");
  json_object_set_new(params, "poll_us", json_integer(poll ? json_integer_value(poll) : 0));
  json_object_set_new(params, "send", send);
  json_object_set_new(params, "receive", receive);
  json_object_set_new(params, "send_streams", send_streams);
  json_object_set_new(params, "receive_streams", receive_streams);
  json_object_set_new(params, "best_effort", best);
  return params;
}


// finalize, naming the controller at fault by its place in the file
static int finalize(const char* file, tx_system* sys, json_t* root, const tx_load_options* o) {
  if (tx_system_finalize(sys) == 0) return 0;
  const char* key = tx_error_key(); // the instance at fault, if any
  int index = -1;
  size_t i;
  json_t* c;
  json_array_foreach(json_object_get(root, "controllers"), i, c) {
    json_t* n = json_object_get(c, "name");
    if (json_is_string(n) && strcmp(json_string_value(n), key) == 0) index = (int)i;
  }
  bool is_view = index < 0 && o && o->view && strcmp(o->view, "none") != 0 && strcmp(key, VIEW_INSTANCE) == 0;
  if (is_view) return fail("%s: view.draw: %s", file, tx_error());
  if (index < 0 && strcmp(key, NET_INSTANCE) == 0) return fail("%s: net: %s", file, tx_error());
  if (index < 0 && o && o->probe && strcmp(key, PROBE_INSTANCE) == 0) return fail("--probe %s: %s", o->probe, tx_error());
  if (index >= 0) return fail("%s: controllers[%d]: %s", file, index, tx_error());
  return fail("%s: %s", file, tx_error());
}

// a role declares only the model components its own controllers write; the
// bridge makes those it mirrors in, with the writer's schema
static int declare_role_model(const char* file, tx_system* sys, json_t* model, tx_system* full, const int* role_of, int role) {
  if (!model) return 0;
  json_t* mine = json_array();
  size_t i;
  json_t* c;
  json_array_foreach(model, i, c) {
    int w = writer_of(full, json_string_value(json_object_get(c, "name")), false, NULL);
    if (w >= 0 && role_of[w] == role) json_array_append(mine, c);
  }
  int rc = declare_model(file, sys, mine);
  json_decref(mine);
  return rc;
}

static tx_scenario* load_root(const char* file, const char* dir, json_t* root, const tx_load_options* o) {
  tx_register_builtin();
  if (!json_is_object(root)) return fail("%s: expected a JSON object at the top", file), NULL;
  static const char* const keys[] = {"name", "description", "duration_s", "model", "plugins", "controllers", "view", "roles", "net", NULL};
  if (check_keys(file, "", root, keys)) return NULL;
  set_origin origins[SETS_MAX + 2];
  int norigins = 0;
  if (o && o->nsets > SETS_MAX) return fail("--set: more than %d", SETS_MAX), NULL;
  if (o && (o->ndevices < 0 || o->ndevices > 2)) return fail("--device: at most two (one per hand)"), NULL;
  if (apply_sets(file, root, o, origins, &norigins)) return NULL;
  if (o && o->ndevices && apply_devices(file, root, o, origins, &norigins)) return NULL;

  json_t *name = json_object_get(root, "name"), *desc = json_object_get(root, "description"),
         *duration = json_object_get(root, "duration_s");
  // the name becomes part of the default output folder: keep it a plain file name
  const char* nm = json_is_string(name) ? json_string_value(name) : "";
  bool plain = *nm && strlen(nm) < TX_NAME_MAX;
  for (const char* c = nm; *c && plain; c++) plain = (*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_' || *c == '-';
  if (!plain) return fail("%s: name: expected 1-%d characters of a-z 0-9 _ -", file, TX_NAME_MAX - 1), NULL;
  if (desc && !json_is_string(desc)) return fail("%s: description: expected a string", file), NULL;
  double seconds = 10;
  if (duration) {
    seconds = json_number_value(duration);
    if (!json_is_number(duration) || !(seconds >= TX_DURATION_MIN_S && seconds <= TX_DURATION_MAX_S))
      return fail("%s: duration_s: expected a number in [%g, %g]", file, TX_DURATION_MIN_S, TX_DURATION_MAX_S), NULL;
  }
  if (load_plugins(file, dir, json_object_get(root, "plugins"), o)) return NULL;

  tx_scenario* s = calloc(1, sizeof *s);
  if (!s || !(s->system = tx_system_create())) {
    free(s);
    return fail("%s: out of memory", file), NULL;
  }
  snprintf(s->path, sizeof s->path, "%s", file);
  snprintf(s->name, sizeof s->name, "%s", json_string_value(name));
  snprintf(s->description, sizeof s->description, "%s", desc ? json_string_value(desc) : "");
  s->duration_s = seconds;
  json_t *controllers = json_object_get(root, "controllers"), *roles = json_object_get(root, "roles"),
         *net = json_object_get(root, "net");
  int role_of[1024 + 8], nroles = 0, role = -1; // the file's controllers, then what --view adds
  if (json_is_array(controllers) && json_array_size(controllers) > 1024)
    return tx_scenario_free(s), fail("%s: controllers: at most 1024", file), NULL;
  if (check_roles(file, roles, controllers, role_of, &nroles) || check_net(file, net)) return tx_scenario_free(s), NULL;
  if (o && o->role) {
    char have[256] = "";
    const char* rn;
    json_t* rv;
    int r = 0;
    json_object_foreach(roles, rn, rv) {
      if (strcmp(rn, o->role) == 0) role = r;
      size_t len = strlen(have);
      snprintf(have + len, sizeof have - len, "%s%s", r++ ? ", " : "", rn);
    }
    if (!roles) return tx_scenario_free(s), fail("--role %s: %s has no roles", o->role, file), NULL;
    if (role < 0) return tx_scenario_free(s), fail("--role %s: unknown role (%s has: %s)", o->role, file, have), NULL;
  }
  // a role: the whole scenario is built first, for the schema of every
  // component that crosses; then only the role's controllers, and the bridge
  tx_system* full = s->system;
  json_t* part = NULL;
  int map[1024];
  if (role >= 0) {
    // the role's --view too, so that what it draws is mirrored in like any read
    if (declare_model(file, full, json_object_get(root, "model")) || add_controllers(file, full, controllers, origins, norigins, NULL) ||
        add_view(file, full, json_object_get(root, "view"), o) || finalize(file, full, root, o) || check_net_names(file, net, full))
      return tx_scenario_free(s), NULL;
    for (int i = (int)json_array_size(controllers); i < tx_system_count(full) && i < 1024 + 8; i++) role_of[i] = role;
    bool drawn = o->view && strcmp(o->view, "none") != 0;
    bool alone = true;
    for (size_t i = 0; i < json_array_size(controllers); i++) alone &= role_of[i] != role;
    if (alone && !drawn)
      return tx_scenario_free(s), fail("--role %s: this role of %s runs no controller: give it a view (--view png or --view window)", o->role, file), NULL;
    part = json_array();
    for (size_t i = 0; i < json_array_size(controllers); i++)
      if (role_of[i] == role) map[json_array_size(part)] = (int)i, json_array_append(part, json_array_get(controllers, i));
    if (!(s->system = tx_system_create())) {
      tx_system_destroy(full), json_decref(part), free(s);
      return fail("%s: out of memory", file), NULL;
    }
  }
  bool bridge = false;
  json_t* bp = role >= 0 ? bridge_params(file, s->name, net, full, (int)json_array_size(controllers), role_of, role, &bridge) : NULL;
  int rc = role >= 0 && !bp ? -1 : 0;
  if (!rc && role < 0) rc = declare_model(file, s->system, json_object_get(root, "model"));
  else if (!rc) rc = declare_role_model(file, s->system, json_object_get(root, "model"), full, role_of, role);
  if (!rc) rc = add_controllers(file, s->system, part ? part : controllers, origins, norigins, part ? map : NULL);
  if (!rc && bridge && !tx_find_controller("net.dds"))
    rc = fail("--role %s: %s crosses processes, and this build has no DDS bridge (configure with -DTX_WITH_DDS=ON)", o->role, file);
  if (!rc && bridge) {
    json_t* rate = json_object_get(net, "rate_hz");
    rc = tx_system_add(s->system, NET_INSTANCE, "net.dds", rate ? json_number_value(rate) : 1000, bp);
    if (rc) fail("%s: net: %s%s%s", file, tx_error_key(), *tx_error_key() ? ": " : "", tx_error());
    else if ((rc = tx_system_set_thread(s->system, tx_system_count(s->system) - 1, NET_INSTANCE))) fail("%s: net: %s", file, tx_error());
  }
  if (!rc) rc = add_view(file, s->system, json_object_get(root, "view"), o);
  if (!rc) rc = add_probe(s->system, o);
  if (!rc) rc = finalize(file, s->system, root, o);
  if (!rc && role < 0) rc = check_net_names(file, net, s->system);
  json_decref(bp);
  json_decref(part);
  if (full != s->system) tx_system_destroy(full);
  if (rc) return tx_scenario_free(s), NULL;
  return s;
}

static void format_parse_error(const char* file, const json_error_t* e) {
  if (e->line > 0) fail("%s:%d:%d: %s", file, e->line, e->column, e->text);
  else fail("%s: %s", file, e->text);
}

tx_scenario* tx_scenario_load(const char* path, const tx_load_options* o) {
  struct stat st;
  if (stat(path, &st) != 0) return fail("%s: %s", path, strerror(errno)), NULL;
  if (!S_ISREG(st.st_mode)) return fail("%s: not a regular file", path), NULL;
  json_error_t e;
  json_t* root = json_load_file(path, JSON_REJECT_DUPLICATES, &e);
  if (!root) return format_parse_error(path, &e), NULL;
  tx_scenario* s = tx_scenario_load_json(path, root, o);
  json_decref(root);
  return s;
}

tx_scenario* tx_scenario_load_json(const char* path, json_t* root, const tx_load_options* o) {
  char copy[PATH_MAX];
  snprintf(copy, sizeof copy, "%s", path);
  return load_root(path, dirname(copy), root, o);
}

tx_scenario* tx_scenario_load_text(const char* label, const char* text, size_t len, const tx_load_options* o) {
  json_error_t e;
  json_t* root = json_loadb(text, len, JSON_REJECT_DUPLICATES, &e);
  if (!root) return format_parse_error(label, &e), NULL;
  tx_scenario* s = load_root(label, ".", root, o);
  json_decref(root);
  return s;
}

void tx_scenario_free(tx_scenario* s) {
  if (!s) return;
  tx_system_destroy(s->system);
  free(s);
}

// the directories scenarios are searched in, in order
static int search_dirs(char dirs[][PATH_MAX], int max) {
  int count = 0;
  const char* env = getenv("TACTUS_SCENARIO_PATH");
  if (env) {
    char copy[4096];
    snprintf(copy, sizeof copy, "%s", env);
    char* save = NULL;
    for (char* d = strtok_r(copy, ":", &save); d && count < max - 1; d = strtok_r(NULL, ":", &save))
      snprintf(dirs[count++], PATH_MAX, "%s", d);
  }
  snprintf(dirs[count++], PATH_MAX, "%s", TX_SCENARIO_DIR);
  return count;
}

int tx_scenario_locate(const char* name, char* path, size_t size) {
  size_t len = strlen(name);
  if (strchr(name, '/') || (len > 5 && strcmp(name + len - 5, ".json") == 0)) {
    if (access(name, R_OK) != 0) return fail("%s: %s", name, strerror(errno));
    snprintf(path, size, "%s", name);
    return 0;
  }
  char dirs[16][PATH_MAX];
  int count = search_dirs(dirs, 16);
  for (int d = 0; d < count; d++) {
    snprintf(path, size, "%s/%s/%s.json", dirs[d], name, name);
    if (access(path, R_OK) == 0) return 0;
  }
  return fail("%s: unknown scenario (tactus list shows them; a file needs a .json ending)", name);
}

int tx_asset_locate(const char* given, char* path, size_t size) {
  if (access(given, R_OK) == 0 || given[0] == '/') return snprintf(path, size, "%s", given), access(given, R_OK);
  // the source tree holds scenarios/ and assets/ side by side
  const char* prefixes[] = {TX_SCENARIO_DIR "/..", TX_SCENARIO_DIR "/../assets"};
  for (size_t i = 0; i < sizeof prefixes / sizeof prefixes[0]; i++) {
    if (snprintf(path, size, "%s/%s", prefixes[i], given) >= (int)size) continue;
    if (access(path, R_OK) == 0) return 0;
  }
  snprintf(path, size, "%s", given);
  return -1;
}

void tx_scenario_list(tx_scenario_visit visit, void* user) {
  char dirs[16][PATH_MAX];
  int count = search_dirs(dirs, 16);
  for (int d = 0; d < count; d++) {
    struct dirent** entries = NULL;
    int ne = scandir(dirs[d], &entries, NULL, alphasort);
    for (int i = 0; i < ne; i++) {
      char path[PATH_MAX];
      int len = snprintf(path, sizeof path, "%s/%s/%s.json", dirs[d], entries[i]->d_name, entries[i]->d_name);
      json_t* root = entries[i]->d_name[0] != '.' && len < (int)sizeof path ? json_load_file(path, 0, NULL) : NULL;
      if (root) {
        const char* desc = json_string_value(json_object_get(root, "description"));
        visit(entries[i]->d_name, path, desc ? desc : "", user);
        json_decref(root);
      }
      free(entries[i]);
    }
    free(entries);
  }
}
