// A plugin whose parameter table cannot be trusted (a key twice): loading a
// scenario that names it must stop at load with one line naming the plugin
// and the entry, before any controller is configured.
#include <tactus/tactus.h>

#include <stdlib.h>

static const tx_param_def params[] = {
    {"gain", TX_PARAM_NUM, "1", 0, 10, 1, NULL, "a gain"},
    {"gain", TX_PARAM_NUM, "1", 0, 10, 2, NULL, "the same key again"},
};

static int configure(tx_setup* s, void** self) {
  (void)s;
  *self = NULL;
  return 0;
}

static void step(tx_ctx* c, void* self) { (void)c, (void)self; }

static const tx_controller_class cls = {.type = "test.bad_table", .summary = "a table with a key twice",
                                        .configure = configure, .step = step, .params = params,
                                        .nparams = TX_PARAMS_COUNT(params)};

__attribute__((visibility("default"))) int tx_plugin_register(int api_version) {
  if (api_version != TX_API_VERSION) return -1;
  return tx_register_controller(&cls);
}
