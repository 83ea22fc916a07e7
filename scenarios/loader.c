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

// the i-th --device goes to the i-th controller of type "haptics"
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

static int add_controllers(const char* file, tx_system* sys, json_t* list, const set_origin* origins, int norigins) {
  if (!json_is_array(list) || json_array_size(list) == 0)
    return fail("%s: controllers: expected a non-empty array", file);
  static const char* const keys[] = {"name", "type", "rate_hz", "params", "thread", NULL};
  size_t i;
  json_t* c;
  json_array_foreach(list, i, c) {
    char where[48];
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

static tx_scenario* load_root(const char* file, const char* dir, json_t* root, const tx_load_options* o) {
  tx_register_builtin();
  if (!json_is_object(root)) return fail("%s: expected a JSON object at the top", file), NULL;
  static const char* const keys[] = {"name", "description", "duration_s", "model", "plugins", "controllers", "view", NULL};
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
  if (declare_model(file, s->system, json_object_get(root, "model")) ||
      add_controllers(file, s->system, json_object_get(root, "controllers"), origins, norigins) ||
      add_view(file, s->system, json_object_get(root, "view"), o)) {
    tx_scenario_free(s);
    return NULL;
  }
  if (tx_system_finalize(s->system)) {
    const char* key = tx_error_key(); // the instance at fault, if any
    int index = -1;
    for (int i = 0; i < tx_system_count(s->system); i++)
      if (strcmp(tx_system_name(s->system, i), key) == 0) index = i;
    bool is_view = index >= 0 && o && o->view && strcmp(o->view, "none") != 0 && index == tx_system_count(s->system) - 1 &&
                   strcmp(key, VIEW_INSTANCE) == 0;
    if (is_view) fail("%s: view.draw: %s", file, tx_error());
    else if (index >= 0) fail("%s: controllers[%d]: %s", file, index, tx_error());
    else fail("%s: %s", file, tx_error());
    tx_scenario_free(s);
    return NULL;
  }
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
  char copy[PATH_MAX];
  snprintf(copy, sizeof copy, "%s", path);
  tx_scenario* s = load_root(path, dirname(copy), root, o);
  json_decref(root);
  return s;
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
