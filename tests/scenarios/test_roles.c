// Tests of the loader's roles and net section (docs/scenario-format.md,
// docs/distributed.md): a role runs only its controllers, every bad input is
// one line naming the file and key. Runs in every build: what crosses needs
// the DDS bridge, and a build without it says so.
#include "model/error.h"
#include "scenarios/loader.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#define W "\"type\": \"rates.worker\""
// p writes p.x; q reads it; r writes r.y alone
#define CONTROLLERS                                                                                                   \
  "\"controllers\": [{\"name\": \"p\", " W ", \"rate_hz\": 10, \"params\": {\"write\": \"p.x\", \"rows\": 2, \"cols\": 3}},"  \
  "{\"name\": \"q\", " W ", \"rate_hz\": 20, \"params\": {\"reads\": [\"p.x\"], \"write\": \"q.z\"}},"                        \
  "{\"name\": \"r\", " W ", \"rate_hz\": 30, \"params\": {\"write\": \"r.y\"}}]"

static tx_scenario* load_role(const char* text, const char* role, const char* set) {
  tx_set_error("%s", "");
  const char* sets[1] = {set};
  tx_load_options o = {.role = role, .sets = sets, .nsets = set ? 1 : 0};
  return tx_scenario_load_text("s.json", text, strlen(text), &o);
}

static void expect(const char* text, const char* role, const char* set, const char* message) {
  tx_scenario* s = load_role(text, role, set);
  if (s) {
    tx_scenario_free(s);
    fail_msg("loaded; expected '%s'", message);
  }
  if (strcmp(tx_error(), message) != 0) fail_msg("got '%s', expected '%s'", tx_error(), message);
}

static const char good[] = "{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"q\"], \"two\": [\"r\"]},"
                           " \"net\": {\"state\": [\"p.x\"]}, " CONTROLLERS "}";

static void without_role_the_whole_scenario_runs(void** state) {
  (void)state;
  tx_scenario* s = load_role(good, NULL, NULL);
  assert_non_null(s);
  assert_int_equal(tx_system_count(s->system), 3);
  tx_scenario_free(s);
}

static void a_role_runs_only_its_controllers(void** state) {
  (void)state;
  tx_scenario* s = load_role(good, "two", NULL); // r alone: nothing crosses, no bridge
  assert_non_null(s);
  assert_int_equal(tx_system_count(s->system), 1);
  assert_string_equal(tx_system_name(s->system, 0), "r");
  assert_int_equal(tx_model_find(tx_system_model(s->system), "p.x").id, 0);
  tx_scenario_free(s);
  // p writes p.x, which net names: the bridge sends it, for whichever process reads it
  s = load_role(good, "one", NULL);
  if (!tx_find_controller("net.dds")) return assert_null(s);
  assert_non_null(s);
  assert_int_equal(tx_system_count(s->system), 3);
  assert_string_equal(tx_system_name(s->system, 2), "net");
  assert_int_equal(json_array_size(json_object_get(tx_system_params(s->system, 2), "send")), 1);
  tx_scenario_free(s);
}

static void a_read_across_roles_needs_the_bridge(void** state) {
  (void)state;
  static const char split[] = "{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"r\"], \"two\": [\"q\"]},"
                              " \"net\": {\"state\": [\"p.x\"]}, " CONTROLLERS "}";
  tx_scenario* s = load_role(split, "two", NULL);
  if (!tx_find_controller("net.dds")) { // a build without DDS says so
    assert_null(s);
    assert_string_equal(tx_error(), "--role two: s.json crosses processes, and this build has no DDS bridge (configure with -DTX_WITH_DDS=ON)");
    return;
  }
  assert_non_null(s);
  assert_int_equal(tx_system_count(s->system), 2); // q and the bridge, which mirrors p.x in
  assert_string_equal(tx_system_name(s->system, 1), "net");
  tx_comp c = tx_model_find(tx_system_model(s->system), "p.x");
  assert_true(c.id != 0);
  assert_int_equal(tx_model_def(tx_system_model(s->system), c)->rows, 2);
  assert_int_equal(tx_model_def(tx_system_model(s->system), c)->cols, 3);
  tx_scenario_free(s);
  // the same read, but p.x not named in net
  static const char unnamed[] = "{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"r\"], \"two\": [\"q\"]}, " CONTROLLERS "}";
  expect(unnamed, "two", NULL,
         "s.json: controllers[1]: reads 'p.x', which controller 'p' of another role writes: name it in net.fast or net.state");
}

static void bad_roles(void** state) {
  (void)state;
  expect(good, "three", NULL, "--role three: unknown role (s.json has: one, two)");
  expect("{\"name\": \"t\", " CONTROLLERS "}", "one", NULL, "--role one: s.json has no roles");
  expect("{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"q\"]}, " CONTROLLERS "}", NULL, NULL,
         "s.json: controllers[2]: 'r' has no role (every controller of a scenario with roles has one)");
  expect("{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"q\", \"r\"], \"two\": [\"r\"]}, " CONTROLLERS "}", NULL, NULL,
         "s.json: roles.two[0]: 'r' already has a role");
  expect("{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"q\", \"r\", \"s\"]}, " CONTROLLERS "}", NULL, NULL,
         "s.json: roles.one[3]: no controller named 's'");
  expect("{\"name\": \"t\", \"roles\": {\"One\": [\"p\", \"q\", \"r\"]}, " CONTROLLERS "}", NULL, NULL,
         "s.json: roles.One: a role name is 1-31 characters of a-z 0-9 _ -");
  expect("{\"name\": \"t\", \"roles\": [], " CONTROLLERS "}", NULL, NULL,
         "s.json: roles: expected an object of ROLE: [CONTROLLER, ...]");
  expect("{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"q\", \"r\"], \"two\": \"p\"}, " CONTROLLERS "}", NULL, NULL,
         "s.json: roles.two: expected an array of controller names");
  // an empty role is a display host: it runs only the view it is given
  static const char display[] = "{\"name\": \"t\", \"roles\": {\"one\": [\"p\", \"q\", \"r\"], \"show\": []}, " CONTROLLERS "}";
  tx_scenario* s = load_role(display, NULL, NULL);
  assert_non_null(s);
  tx_scenario_free(s);
  expect(display, "show", NULL,
         "--role show: this role of s.json runs no controller: give it a view (--view png or --view window)");
}

static void bad_net(void** state) {
  (void)state;
  expect(good, "one", "net.domain=233", "s.json: net.domain: expected an integer in [0, 232] (a DDS domain id)");
  expect(good, NULL, "net.domain=-1", "s.json: net.domain: expected an integer in [0, 232] (a DDS domain id)");
  expect(good, NULL, "net.peers=[\"10.0.0.300\"]", "s.json: net.peers[0]: expected an IPv4 address or a host name");
  expect(good, NULL, "net.peers=[\"a b\"]", "s.json: net.peers[0]: expected an IPv4 address or a host name");
  expect(good, NULL, "net.peers=\"10.0.0.2\"", "s.json: net.peers: expected an array of at most 32 addresses");
  expect(good, NULL, "net.fast=[\"skin.x\"]", "s.json: net.fast[0]: 'skin.x' is not in the model (no controller writes it)");
  expect(good, "one", "net.fast=[\"skin.x\"]", "s.json: net.fast[0]: 'skin.x' is not in the model (no controller writes it)");
  expect(good, NULL, "net.streams=[\"p.x\"]", "s.json: net.streams[0]: 'p.x' is not an event stream any controller emits");
  expect(good, NULL, "net.rate_hz=0", "s.json: net.rate_hz: expected a number in [1, 100000]");
  expect(good, NULL, "net.poll_us=-5", "s.json: net.poll_us: expected an integer in [0, 100000] (us; 0: send from the bridge's step)");
  expect(good, NULL, "net.port=1", "s.json: net.port: unknown key (known: domain, peers, rate_hz, poll_us, fast, state, streams)");
  tx_scenario* s = load_role(good, NULL, "net.peers=[\"10.0.0.2\", \"sim-host\"]");
  assert_non_null(s);
  tx_scenario_free(s);
}

int main(void) {
  tx_register_builtin();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(without_role_the_whole_scenario_runs),
      cmocka_unit_test(a_role_runs_only_its_controllers),
      cmocka_unit_test(a_read_across_roles_needs_the_bridge),
      cmocka_unit_test(bad_roles),
      cmocka_unit_test(bad_net),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
