// Tests of include/tactus/components.h against the shipped scenarios: every
// component a built-in controller writes in a shipped scenario has the layout
// of its struct (element type, columns = the struct's size, units), and a
// component that crosses controllers without a named layout fails the test.
#include "scenarios/loader.h"

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

typedef struct layout {
  const char* name; // a whole component name, or a suffix starting with '.'
  tx_type type;
  uint32_t cols;    // T_COLS
  size_t bytes;     // sizeof(T), per row
  const char* units;
} layout;

#define L(name, T) {name, T##_TYPE, T##_COLS, sizeof(T), T##_UNITS}
// whole names first: they win over a suffix
static const layout layouts[] = {
    L("needle.force", tx_needle_force), L("instrument0.pose", tx_instrument_pose),
    L("instrument1.pose", tx_instrument_pose), L("liver.damage", tx_organ_damage), L("stomach.damage", tx_organ_damage),
    L("band.state", tx_band_state),     L("procedure.step", tx_procedure_step), L("procedure.step_names", tx_procedure_step),
    L("procedure.steps", tx_procedure_step_state), L("procedure.suture", tx_suture_measures),
    L("cautery.tissue", tx_tissue_damage), L("band.centre", tx_vertex), L("pars_flaccida.state", tx_membrane_state),
    L("his.state", tx_membrane_state), L("procedure.lagb", tx_lagb_measures), L("procedure.step_paths", tx_step_path),
    L(".temperature", tx_temperature),  L(".links", tx_pose), L(".swage", tx_pose), L(".grip", tx_device_grip),
    L(".force_model", tx_force_model), L(".pose", tx_pose),
    L(".velocity", tx_velocity),        L(".force", tx_force),             L(".energy", tx_device_energy),
    L(".state", tx_hip_state),          L(".spheres", tx_sphere),          L(".segments", tx_segment),
    L(".x", tx_vertex),                 L(".tri", tx_triangle),            L(".thickness", tx_thickness),
    L(".torn", tx_torn),                L(".damage", tx_damage),           L(".nodes", tx_thread_node),
    L(".pointer", tx_pointer),          L(".contact", tx_skin_contact),    L(".rupture", tx_skin_rupture),
    L(".tip", tx_pose),                 L(".punctures", tx_puncture),      L(".cut_links", tx_thread_link),
    L(".puncture_loads", tx_puncture_load),
    L(".held", tx_instrument_held),     L(".grasp", tx_organ_grasp),     L(".surface_node", tx_surface_node),
    L(".capsules", tx_capsule),
};
#undef L

static const layout* layout_of(const char* comp) {
  size_t n = strlen(comp);
  for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++) {
    const char* k = layouts[i].name;
    size_t m = strlen(k);
    if (k[0] != '.' ? strcmp(comp, k) == 0 : (n > m && strcmp(comp + n - m, k) == 0)) return &layouts[i];
  }
  return NULL;
}

// the layouts themselves: columns times the element size is the struct's size
static void every_layout_is_its_columns(void** state) {
  (void)state;
  for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++)
    assert_int_equal(layouts[i].bytes, layouts[i].cols * tx_type_size(layouts[i].type));
  assert_int_equal(sizeof(tx_instrument_pose), tx_instrument_pose_COLS * sizeof(double));
  // the force model's fields lie where the papers' order puts them: F0, x0, K
  assert_int_equal(offsetof(tx_force_model, x0), 3 * sizeof(double));
  assert_int_equal(offsetof(tx_force_model, k), 6 * sizeof(double));
  assert_int_equal(offsetof(tx_hip_state, skin_t), 7 * sizeof(double));
  // event payloads share the event's value[] and keep it one cache line
  tx_event e = {.kind = TX_EVENT_PUNCTURE, .puncture = {.point = {1, 2, 3}, .force = 4, .depth = 5}};
  assert_true(e.value[3] == 4 && e.value[4] == 5);
  assert_int_equal(sizeof(tx_event), 64);
}

typedef struct seen {
  int scenarios, loaded, checked;
  char fail[1024];
} seen;

static void check_scenario(const char* name, const char* path, const char* description, void* user) {
  (void)description;
  seen* s = user;
  if (*s->fail) return;
  s->scenarios++;
  tx_load_options o = {0};
  tx_scenario* sc = tx_scenario_load(path, &o);
  if (!sc) {
    // a build without Bullet cannot load the skin; every other failure is a defect
    if (!TX_WITH_BULLET && strstr(tx_error(), "physics.")) return;
    snprintf(s->fail, sizeof s->fail, "%.100s: %.400s", name, tx_error());
    return;
  }
  s->loaded++;
  const tx_system* sys = sc->system;
  for (int i = 0; i < tx_system_count(sys) && !*s->fail; i++) {
    // the rates workers write components of any shape that only other workers read
    if (strcmp(tx_system_class(sys, i)->type, "rates.worker") == 0) continue;
    for (int p = 0; p < tx_system_ports(sys, i); p++) {
      tx_port_info pi = tx_system_port(sys, i, p);
      if (!pi.write) continue;
      const layout* l = layout_of(pi.component);
      if (!l) {
        snprintf(s->fail, sizeof s->fail, "%s: %s writes %s, which has no layout in <tactus/components.h>", name,
                 tx_system_name(sys, i), pi.component);
        break;
      }
      if (pi.def->type != l->type || pi.def->cols * tx_type_size(pi.def->type) != l->bytes ||
          strcmp(pi.def->units, l->units) != 0) {
        snprintf(s->fail, sizeof s->fail, "%s: %s writes %s as %s x %u in %s, its layout is %s x %u in %s", name,
                 tx_system_name(sys, i), pi.component, tx_type_name(pi.def->type), pi.def->cols, pi.def->units,
                 tx_type_name(l->type), l->cols, l->units);
        break;
      }
      s->checked++;
    }
  }
  tx_scenario_free(sc);
}

static void shipped_writers_use_the_layouts(void** state) {
  (void)state;
  seen s = {0};
  tx_scenario_list(check_scenario, &s);
  if (*s.fail) fail_msg("%s", s.fail);
  assert_true(s.scenarios >= 4); // haptics-wall, needle-voxel, rates, suturing-skin
  // the wall alone writes the device's pose, velocity, force, energy and the force model
  assert_true(s.checked >= 5);
  if (TX_WITH_BULLET) assert_int_equal(s.loaded, s.scenarios);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_layout_is_its_columns),
      cmocka_unit_test(shipped_writers_use_the_layouts),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
