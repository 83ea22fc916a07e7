// tactus: the command line. Subcommands list, describe, run, bench and study.
#include "../scenarios/command.h"

#include <tactus/config.h>
#include <tactus/tactus.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: tactus COMMAND [ARGS]\n"
    "\n"
    "  list                       the scenarios on the search path, with their files; (shadowed) marks a\n"
    "                             name an earlier folder already gives\n"
    "  describe SCENARIO          controllers, rates, threads, reads and writes, and every parameter\n"
    "                             with its value\n"
    "  describe --class TYPE      a controller class's parameter table, as Markdown (docs/ holds it)\n"
    "  describe --classes         the controller types built in\n"
    "  describe --instrument FILE an instrument description (URDF): links, masses, shapes, meshes, jaws\n"
    "  run SCENARIO [OPTIONS]     run it; writes OUT/report.json (tactus run --help)\n"
    "  bench NAME [--out DIR]     a benchmark table (tactus bench lists them)\n"
    "  study NAME [--out DIR]     a study with plots (tactus study lists them)\n"
    "                             (--out refuses a folder that holds files, unless --force)\n"
    "  export FILE.bin [--out F]  the CSV of a device recording (one a killed run left)\n"
    "  version                    version and the optional parts built in\n"
    "\n"
    "SCENARIO is a name from `tactus list` or a path to a .json file.\n"
    "Scenarios are searched in $TACTUS_SCENARIO_PATH (':'-separated), then " TX_SCENARIO_DIR ".\n"
    "Bad input exits with status 2 and one line naming the file and key.\n";

// the names already listed: the first on the search path wins (tx_scenario_locate)
typedef struct listing {
  char (*names)[TX_NAME_MAX + 192];
  int count, cap;
} listing;

static void print_scenario(const char* name, const char* path, const char* description, void* user) {
  listing* l = user;
  bool shadowed = false;
  for (int i = 0; i < l->count && !shadowed; i++) shadowed = strcmp(l->names[i], name) == 0;
  if (!shadowed && l->count == l->cap) {
    int cap = l->cap ? 2 * l->cap : 32;
    void* grown = realloc(l->names, cap * sizeof *l->names);
    if (grown) l->names = grown, l->cap = cap;
  }
  if (!shadowed && l->count < l->cap) snprintf(l->names[l->count++], sizeof l->names[0], "%s", name);
  char label[TX_NAME_MAX + 16];
  snprintf(label, sizeof label, "%s%s", name, shadowed ? " (shadowed)" : "");
  printf("%-24s %s\n%-24s %s\n", label, path, "", description);
}

int tx_cmd_list(int argc, char** argv) {
  (void)argv;
  if (argc > 1) return tx_bad_input("list: takes no arguments");
  listing l = {0};
  tx_scenario_list(print_scenario, &l);
  free(l.names);
  printf("\nNames are looked up in this order: where two scenarios share a name, the first is run and a later one is\n"
         "(shadowed).\n");
  return 0;
}

static const char* kind_text(tx_param_kind k) {
  switch (k) {
  case TX_PARAM_NUM: return "number";
  case TX_PARAM_INT: return "integer";
  case TX_PARAM_BOOL: return "boolean";
  case TX_PARAM_STR: return "string";
  case TX_PARAM_STRS: return "strings";
  case TX_PARAM_JSON: return "JSON";
  }
  return "?";
}

static const char* range_text(const tx_param_def* d, char* buf, size_t n) {
  char lo[32], hi[32];
  if (d->kind == TX_PARAM_NUM || d->kind == TX_PARAM_INT)
    return snprintf(buf, n, "[%s, %s]", tx_param_num_text(d->min, lo, sizeof lo), tx_param_num_text(d->max, hi, sizeof hi)), buf;
  if (d->kind == TX_PARAM_STRS) return snprintf(buf, n, "at most %s", tx_param_num_text(d->max, hi, sizeof hi)), buf;
  return "-";
}

// the Markdown table of a class's parameters; the docs hold it between
// <!-- params TYPE --> and <!-- /params --> (tests/docs/test_param_tables.sh)
static int describe_class(const char* type) {
  const tx_controller_class* cls = tx_find_controller(type);
  if (!cls) return tx_bad_input("describe --class %s: unknown controller type (tactus describe --classes lists them)", type);
  if (!cls->params) return printf("%s: no parameter table\n", cls->type), 0;
  printf("| key | kind | default | units | range | meaning |\n|---|---|---|---|---|---|\n");
  for (int k = 0; k < cls->nparams; k++) {
    const tx_param_def* d = &cls->params[k];
    char def[128], range[96];
    printf("| `%s` | %s | %s | %s | %s | %s |\n", d->key, kind_text(d->kind), tx_param_default_text(d, true, def, sizeof def),
           d->units ? d->units : "-", range_text(d, range, sizeof range), d->meaning);
  }
  return 0;
}

// one controller's parameters: value in this scenario (or the default), units, range, meaning
static void describe_params(tx_system* s, int i) {
  const tx_controller_class* cls = tx_system_class(s, i);
  printf("\n%s (%s):", tx_system_name(s, i), cls->type);
  if (!cls->params) return (void)printf(" no parameter table\n");
  if (!cls->nparams) return (void)printf(" no parameters\n");
  printf("\n  %-20s %-30s %-8s %-22s %s\n", "parameter", "value", "units", "range", "meaning");
  json_t* given = tx_system_params(s, i);
  for (int k = 0; k < cls->nparams; k++) {
    const tx_param_def* d = &cls->params[k];
    char value[64], range[96];
    tx_param_value_text(d, given, 30, value, sizeof value);
    printf("  %-20s %-30s %-8s %-22s %s\n", d->key, value, d->units ? d->units : "-", range_text(d, range, sizeof range),
           d->meaning);
  }
}

int tx_cmd_describe(int argc, char** argv) {
  if (argc == 2 && strcmp(argv[1], "--classes") == 0) {
    for (int i = 0; tx_controller_class_at(i); i++) printf("%s\n", tx_controller_class_at(i)->type);
    return 0;
  }
  if (argc >= 2 && strcmp(argv[1], "--class") == 0) {
    if (argc != 3) return tx_bad_input("describe --class: expected one TYPE (tactus describe --class collision.wall)");
    return describe_class(argv[2]);
  }
  if (argc != 2) return tx_bad_input("describe: expected one SCENARIO (tactus describe rates)");
  tx_scenario* sc = tx_load_for_command(argv[1], NULL, 0, NULL, 0);
  if (!sc) return TX_EXIT_BAD_INPUT;
  tx_system* s = sc->system;
  printf("%s: %s\nfile: %s\ndefault duration: %g s\n\nthreads:\n", sc->name, sc->description, sc->path,
         sc->duration_s);
  for (int t = 0; t < tx_system_threads(s); t++) {
    const char* tn = tx_system_thread_name(s, t);
    printf("  t%d%s%s%s%s:", t, tn ? " (" : "", tn ? tn : "", tn ? ")" : "",
           tx_system_thread_own(s, t) ? " (haptics: alone, top priority)" : "");
    for (int i = 0; i < tx_system_count(s); i++)
      if (tx_system_thread(s, i) == t) printf(" %s @ %g Hz", tx_system_name(s, i), tx_system_rate(s, i));
    printf("\n");
  }
  printf("\n%-14s %-18s %10s %-6s %-6s %s\n", "controller", "type", "rate Hz", "thread", "access", "component");
  for (int i = 0; i < tx_system_count(s); i++) {
    printf("%-14s %-18s %10g t%-5d", tx_system_name(s, i), tx_system_class(s, i)->type, tx_system_rate(s, i),
           tx_system_thread(s, i));
    if (tx_system_ports(s, i) == 0) printf(" (reads and writes nothing)\n");
    for (int p = 0; p < tx_system_ports(s, i); p++) {
      tx_port_info pi = tx_system_port(s, i, p);
      if (p) printf("%-14s %-18s %10s %-6s", "", "", "", "");
      if (pi.stream) printf(" %-6s %s (event stream)\n", pi.stream == 1 ? "emits" : "listens", pi.component);
      else printf(" %-6s %s (%s %ux%u, %s)\n", pi.write ? "writes" : "reads", pi.component, tx_type_name(pi.def->type),
                  pi.def->rows, pi.def->cols, pi.def->units);
    }
  }
  printf("\n");
  for (int i = 0; i < tx_system_count(s); i++) {
    const tx_controller_class* cls = tx_system_class(s, i);
    bool shown = false;
    for (int j = 0; j < i && !shown; j++) shown = tx_system_class(s, j) == cls;
    if (!shown) printf("%s: %s\n", cls->type, cls->summary ? cls->summary : "");
  }
  printf("\nparameters (the value in this scenario, or the default):\n");
  for (int i = 0; i < tx_system_count(s); i++) describe_params(s, i);
  tx_scenario_free(sc);
  return 0;
}

static int version(void) {
  printf("tactus %s (%s%s%s)\noptional parts:", TX_VERSION, TX_BUILD_TYPE, *TX_SANITIZE ? ", sanitize=" : "",
         TX_SANITIZE);
  const struct { const char* name; int on; } parts[] = {
      {"bullet", TX_WITH_BULLET}, {"ode", TX_WITH_ODE}, {"assimp", TX_WITH_ASSIMP}, {"urdfdom", TX_WITH_URDFDOM}, {"osmesa", TX_WITH_OSMESA}, {"glfw", TX_WITH_GLFW},
      {"dds", TX_WITH_DDS}, {"plplot", TX_WITH_PLPLOT}};
  for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) printf(" %s=%s", parts[i].name, parts[i].on ? "on" : "off");
  printf("\n");
  return 0;
}

int main(int argc, char** argv) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  tx_register_builtin();
  if (argc < 2) return tx_bad_input("expected a command: list, describe, run, bench, study (tactus --help)");
  const char* cmd = argv[1];
  if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) return fputs(usage, stdout), 0;
  if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) return version();
  if (!strcmp(cmd, "list")) return tx_cmd_list(argc - 1, argv + 1);
  if (!strcmp(cmd, "describe") && argc >= 3 && !strcmp(argv[2], "--instrument"))
    return argc == 4 ? tx_cmd_describe_instrument(argv[3])
                     : tx_bad_input("describe --instrument: expected one FILE.urdf (assets/instruments/)");
  if (!strcmp(cmd, "describe")) return tx_cmd_describe(argc - 1, argv + 1);
  if (!strcmp(cmd, "run")) return tx_cmd_run(argc - 1, argv + 1);
  if (!strcmp(cmd, "bench")) return tx_cmd_bench(argc - 1, argv + 1);
  if (!strcmp(cmd, "study")) return tx_cmd_study(argc - 1, argv + 1);
  if (!strcmp(cmd, "export")) return tx_cmd_export(argc - 1, argv + 1);
  return tx_bad_input("unknown command '%s' (tactus --help lists them)", cmd);
}
