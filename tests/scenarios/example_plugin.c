// An example plugin: a controller class added to tactus without rebuilding it.
//
// "example.sine" writes one f64 value, amplitude * sin(2 pi freq_hz t), where
// t is the simulation time of the step, so a lockstep run is deterministic.
// Built as a module against the public headers only, as a researcher would.
#include <tactus/tactus.h>

#include <math.h>
#include <stdlib.h>

typedef struct sine {
  double freq_hz;   // Hz
  double amplitude; // in the units of the written component
  tx_port out;      // 1 x 1 f64
} sine;

// the parameters: `tactus describe` lists them, configure reads them through here
static const tx_param_def params[] = {
    {"freq_hz", TX_PARAM_NUM, "Hz", 0.0, 1e5, 1.0, NULL, "the sine's frequency, at most half the rate"},
    {"amplitude", TX_PARAM_NUM, "1", -1e6, 1e6, 1.0, NULL, "its amplitude, in the units of the component"},
    {"write", TX_PARAM_STR, NULL, 0, 0, 0, "example.sine", "the component written (f64 1 x 1)"},
    {"units", TX_PARAM_STR, NULL, 0, 0, 0, "1", "its units"},
};

static int configure(tx_setup* s, void** self) {
  sine* c = calloc(1, sizeof *c);
  if (!c) return -1;
  *self = c; // fini frees it, even when a parameter below is wrong
  c->freq_hz = tx_table_num(s, "freq_hz");
  if (c->freq_hz > 0.5 * tx_setup_rate(s)) // no faster than Nyquist
    return tx_setup_fail(s, "freq_hz", "%g Hz is above half the rate, %g Hz", c->freq_hz, 0.5 * tx_setup_rate(s));
  c->amplitude = tx_table_num(s, "amplitude");
  const char* name = tx_table_str(s, "write");
  const char* units = tx_table_str(s, "units");
  c->out = tx_setup_write(s, &(tx_component_def){name, TX_F64, 1, 1, units});
  return 0;
}

static void step(tx_ctx* x, void* self) {
  sine* c = self;
  const double t = (double)tx_sim_ns(x) * 1e-9;
  double* out = tx_write(x, c->out);
  out[0] = c->amplitude * sin(2.0 * M_PI * c->freq_hz * t);
}

static void fini(void* self) { free(self); }

static const tx_controller_class sine_class = {
    .type = "example.sine",
    .summary = "writes amplitude * sin(2 pi freq_hz t) as one f64 (an example plugin)",
    .configure = configure,
    .step = step,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};

// the entry point the loader looks up; refuses a tactus it was not built for
__attribute__((visibility("default"))) int tx_plugin_register(int api_version) {
  if (api_version != TX_API_VERSION) return -1;
  return tx_register_controller(&sine_class);
}
