// A plugin whose controller fails in init, after the others have started
// (opened recordings, made folders): a run that fails before its first step
// must keep nothing and say why in one line.
#include <tactus/tactus.h>

#include <stdlib.h>

static int configure(tx_setup* s, void** self) {
  (void)s;
  *self = NULL;
  return 0;
}

static int init(tx_ctx* c, void* self) {
  (void)self;
  tx_stop_run(c, "no device here (a test)");
  return -1;
}

static void step(tx_ctx* c, void* self) {
  (void)c, (void)self;
}

static const tx_controller_class cls = {
    .type = "test.fails_init", .summary = "fails in init", .configure = configure, .init = init, .step = step};

__attribute__((visibility("default"))) int tx_plugin_register(int api_version) {
  if (api_version != TX_API_VERSION) return -1;
  return tx_register_controller(&cls);
}
