// tactus run: one scenario, real time or lockstep, ending in a report.
#include "command.h"
#include "run.h"

#include "../views/report.h"
#include "../views/trace_plot.h"

#include <tactus/config.h>

#include "loader.h"
#if TX_WITH_GLFW
#include "../views/graphics/glfw_window.h"
#endif

#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char run_usage[] =
    "usage: tactus run SCENARIO [OPTIONS]\n"
    "       (with --view window and no SCENARIO, a window lists them to choose from)\n"
    "\n"
    "  --duration S        run length in seconds (default: the scenario's duration_s)\n"
    "  --lockstep          one thread on a virtual clock: deterministic, writes OUT/trace.csv\n"
    "  --set KEY=VALUE     override CONTROLLER.PARAM, CONTROLLER.rate_hz or duration_s (repeatable)\n"
    "  --device SPEC       a haptic device per hand, in turn: scripted:NAME|FILE.csv, replay:FILE, sim, udp:HOST:PORT,\n"
    "                      mouse, dds:DOMAIN[:NAME], or scenario (this hand keeps the scenario's own device)\n"
    "  --view SPEC         none|png|window (default none): png writes OUT/frames/ (OSMesa), window needs DISPLAY\n"
    "  --stereo MODE       mono|sbs|tb|anaglyph|lr (default mono): side by side, top-bottom, red-cyan, or left and right files\n"
    "  --out DIR           output folder (default out/SCENARIO-TIMESTAMP); one that holds files is refused\n"
    "  --force             write into a --out that holds files (same names are replaced)\n"
    "  --no-record         no device recordings (OUT/deviceN.bin and .csv are written by default)\n"
    "  --quiet             no summary table\n"
    "  --role NAME         only the controllers of this role, and the bridge to the other roles' processes\n"
    "                      (a session: one process per role, docs/distributed.md)\n"
    "  --probe C,...@S     record components C of any type (thread.nodes, needle.pose) every S seconds\n"
    "                      (@S left out: 0.1) into OUT/probe.csv, one line per row (docs/views.md)\n"
    "\n"
    "Writes OUT/report.json: per controller achieved rate, missed deadlines, period jitter and step time,\n"
    "and OUT/device0.png (force and position traces) when a haptics device was recorded.\n"
    "Ctrl-C (SIGINT) or SIGTERM stops the run early, still writes the report and exits 130 or 143;\n"
    "another, a second later, ends it at once. A run that fails before its first step exits 2 and keeps nothing.\n";

static bool one_of(const char* s, const char* const* options) {
  for (; *options; options++)
    if (strcmp(s, *options) == 0) return true;
  return false;
}

// "SIGINT" for 2, ...: the signals that stop a run
static const char* signal_name(int sig) { return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "a signal"; }

int tx_run_scenario(tx_scenario* sc, const tx_run_config* cfg, json_t** report_out) {
  char err[1024]; // tx_error(), kept across the clean-up that follows a failure
  double duration = cfg->duration_s > 0 ? cfg->duration_s : sc->duration_s;
  // output is bounded: a lockstep trace that could pass the cap is refused before anything is written
  if (cfg->lockstep) {
    double bytes = tx_system_trace_bytes(sc->system, duration);
    if (bytes > TX_TRACE_MAX_BYTES)
      return tx_bad_input("run %s --lockstep: %g s would write a trace of up to %.1f GB, over the %.0f GB cap; "
                          "shorten --duration, or run in real time",
                          sc->name, duration, bytes * 1e-9, TX_TRACE_MAX_BYTES / (1024.0 * 1024 * 1024));
  }
  tx_out out;
  if (tx_out_open(&out, cfg->out, sc->name)) return tx_bad_input("%s", tx_error());
  const char* dir = out.dir;
  // the report's room first: a run that fills the disk still leaves its report
  if (tx_report_reserve(sc->system, dir, "report.json")) {
    snprintf(err, sizeof err, "%s", tx_error());
    tx_out_discard(&out);
    return tx_bad_input("--out %s", err);
  }
  FILE* trace = NULL;
  char trace_path[4200] = "", trace_tmp[4300];
  if (cfg->lockstep) { // written aside and renamed once the run is whole
    snprintf(trace_path, sizeof trace_path, "%s/trace.csv", dir);
    snprintf(trace_tmp, sizeof trace_tmp, "%s.tmp", trace_path);
    trace = fopen(trace_tmp, "w");
    if (!trace) {
      int e = errno;
      tx_out_discard(&out);
      return tx_bad_input("--out %s: cannot write trace.csv: %s", dir, strerror(e));
    }
    fprintf(trace, "sim_ns,controller,component,seq,rows,hash\n");
  }
  tx_catch_stop_signals();
  tx_run_options o = {.duration_s = duration, .lockstep = cfg->lockstep, .trace = trace, .trace_name = trace_path,
                      .realtime_priority = true, .pin_threads = true, .keep_cpus_awake = true,
                      .record_dir = cfg->no_record ? NULL : dir, .out_dir = dir, .progress = tx_progress,
                      .progress_user = &duration};
  tx_run_result r;
  int rc = tx_system_run(sc->system, &o, &r);
  if (isatty(2)) fprintf(stderr, "\r%40s\r", "");
  if (rc) { // before the first step: nothing of this run is kept
    snprintf(err, sizeof err, "%s", tx_error());
    if (trace) fclose(trace);
    // fini first, so that no controller writes into the folder after it is cleared
    tx_system_destroy(sc->system);
    sc->system = NULL;
    tx_out_discard(&out);
    return tx_bad_input("run %s: %s", sc->name, err);
  }
  tx_out_close(&out);
  // the trace is whole, or gone with the reason
  char trace_err[4400] = "";
  if (trace) {
    errno = 0;
    bool bad = ferror(trace) != 0;
    if (fclose(trace) != 0 || bad)
      snprintf(trace_err, sizeof trace_err, "%s: %s", trace_path, strerror(errno ? errno : EIO));
    else if (rename(trace_tmp, trace_path) != 0)
      snprintf(trace_err, sizeof trace_err, "%s: %s", trace_path, strerror(errno));
    if (*trace_err) remove(trace_tmp);
  }
  json_t* report = tx_report_json(&(tx_report){sc->name, cfg->lockstep, &r, sc->system});
  if (!report || tx_report_save(report, dir, "report.json")) {
    snprintf(err, sizeof err, "%s", report ? tx_error() : "out of memory for the report");
    json_decref(report);
    tx_report_unreserve(dir, "report.json");
    fprintf(stderr, "tactus: run %s: %s\n", sc->name, err);
    return 1;
  }
  // force and position traces of every device recorded in this run; not after a fault, which may be the disk
  for (int hand = 0; hand < 2 && !cfg->no_record && !r.halted; hand++) {
    char csv[4200], png[4200];
    snprintf(csv, sizeof csv, "%s/device%d.csv", dir, hand);
    snprintf(png, sizeof png, "%s/device%d.png", dir, hand);
    if (access(csv, R_OK) == 0 && tx_trace_plot_png(csv, png) != 0 && TX_WITH_PLPLOT)
      fprintf(stderr, "tactus: %s\n", tx_error());
  }
  if (!cfg->quiet) {
    tx_report_print(stdout, report);
    printf("report: %s/report.json%s\n", dir, cfg->lockstep && !*trace_err ? " (and trace.csv)" : "");
  }
  int status = 0;
  if (r.halted) {
    fprintf(stderr, "tactus: run %s stopped at t = %.3f s: %s\n", sc->name, r.halt_t_s, r.halt_reason);
    status = 1;
  } else if (*trace_err) {
    fprintf(stderr, "tactus: run %s: %s\n", sc->name, trace_err);
    status = 1;
  } else if (r.stopped_early) {
    int sig = tx_stop_signal();
    fprintf(stderr, "tactus: run %s stopped early at t = %.3f s by %s; the report covers that much\n", sc->name,
            r.duration_s, signal_name(sig));
    status = 128 + (sig ? sig : SIGINT);
  }
  if (report_out && status == 0) *report_out = report;
  else json_decref(report);
  return status;
}

// the scenario picker (docs/trainer.md): `tactus run --view window` with no
// scenario lists those on the search path in a window; the chosen one's path
// is written to path, and hand 0 becomes the mouse where that was chosen
#if TX_WITH_GLFW
#define PICK_MAX 64
typedef struct pick_list {
  char* names[PICK_MAX];
  char* about[PICK_MAX];
  char* paths[PICK_MAX];
  int n;
} pick_list;

static void pick_visit(const char* name, const char* path, const char* description, void* user) {
  pick_list* l = user;
  if (l->n == PICK_MAX) return;
  l->names[l->n] = strdup(name), l->paths[l->n] = strdup(path), l->about[l->n] = strdup(description ? description : "");
  l->n++;
}
#endif

static int pick_scenario(char* path, size_t size, const char** devices, int* ndevices) {
#if TX_WITH_GLFW
  pick_list l = {0};
  tx_scenario_list(pick_visit, &l);
  static char chosen[2][128]; // the devices' specs live as long as the run's arguments
  int k = tx_window_pick((const char* const*)l.names, (const char* const*)l.about, l.n, chosen);
  int rc = 0;
  if (k >= 0 && k < l.n) snprintf(path, size, "%s", l.paths[k]);
  else if (k == -1) rc = tx_bad_input("run: no scenario chosen (the picker was closed)");
  else rc = tx_bad_input("run: the scenario picker: %s", tx_error());
  // each hand's choice, up to the last hand given one; a hand left to the scenario keeps the file's device
  int last = chosen[1][0] ? 2 : chosen[0][0] ? 1 : 0;
  if (k >= 0 && *ndevices == 0)
    for (int h = 0; h < last; h++) devices[(*ndevices)++] = chosen[h][0] ? chosen[h] : "scenario";
  for (int i = 0; i < l.n; i++) free(l.names[i]), free(l.about[i]), free(l.paths[i]);
  return rc;
#else
  (void)path, (void)size, (void)devices, (void)ndevices;
  return tx_bad_input("run: expected a SCENARIO (tactus list shows them)");
#endif
}

int tx_cmd_run(int argc, char** argv) {
  static const struct option longs[] = {
      {"duration", required_argument, 0, 'd'}, {"lockstep", no_argument, 0, 'l'}, {"set", required_argument, 0, 's'},
      {"device", required_argument, 0, 'D'},   {"view", required_argument, 0, 'v'}, {"stereo", required_argument, 0, 'S'},
      {"out", required_argument, 0, 'o'},      {"quiet", no_argument, 0, 'q'},   {"help", no_argument, 0, 'h'},
      {"no-record", no_argument, 0, 'R'},      {"role", required_argument, 0, 'r'},      {"force", no_argument, 0, 'F'},
      {"probe", required_argument, 0, 'p'},    {0, 0, 0, 0}};
  static const char* const views[] = {"none", "png", "window", NULL};
  static const char* const stereo[] = {"mono", "sbs", "tb", "anaglyph", "lr", NULL};
  tx_run_config cfg = {0};
  const char* sets[64];
  const char* devices[2];
  int nsets = 0, ndevices = 0;
  const char* view = "none";
  const char* stereo_mode = "mono";
  bool force = false;
  const char* role = NULL;
  const char* probe = NULL;
  optind = 1;
  opterr = 0;
  // GNU getopt moves operands behind the options, so SCENARIO may stand anywhere
  for (int c; (c = getopt_long(argc, argv, "", longs, NULL)) != -1;) {
    switch (c) {
    case 'd':
      if (!tx_parse_num(optarg, 1e-3, 86400, &cfg.duration_s))
        return tx_bad_input("--duration %s: expected seconds in [0.001, 86400]", optarg);
      break;
    case 'l': cfg.lockstep = true; break;
    case 's':
      if (nsets == 64) return tx_bad_input("--set: at most 64");
      sets[nsets++] = optarg;
      break;
    case 'D':
      if (++ndevices > 2) return tx_bad_input("--device %s: at most two devices (one per hand)", optarg);
      devices[ndevices - 1] = optarg;
      break;
    case 'v':
      if (!one_of(optarg, views)) return tx_bad_input("--view %s: expected none, png or window", optarg);
      view = optarg;
      break;
    case 'S':
      if (!one_of(optarg, stereo)) return tx_bad_input("--stereo %s: expected mono, sbs, tb, anaglyph or lr", optarg);
      stereo_mode = optarg;
      break;
    case 'o': cfg.out = optarg; break;
    case 'q': cfg.quiet = true; break;
    case 'R': cfg.no_record = true; break;
    case 'F': force = true; break;
    case 'r': role = optarg; break;
    case 'p': probe = optarg; break;
    case 'h': return fputs(run_usage, stdout), 0;
    default:
      // inside a group of short options argv[optind - 1] is not the option; optopt is
      if (optopt && strncmp(argv[optind - 1], "--", 2) != 0)
        return tx_bad_input("run: unknown option '-%c' (tactus run --help)", optopt);
      return tx_bad_input("run: unknown or incomplete option '%s' (tactus run --help)", argv[optind - 1]);
    }
  }
  if (cfg.duration_s == 0) cfg.duration_s = tx_replay_duration(devices, ndevices, sets, nsets); // ends with the recording
  if (optind < argc) cfg.scenario = argv[optind++];
  if (optind < argc) return tx_bad_input("run: unexpected argument '%s'", argv[optind]);
  char picked[PATH_MAX];
  if (!cfg.scenario && strcmp(view, "window") == 0 && getenv("DISPLAY") && *getenv("DISPLAY")) {
    int rc = pick_scenario(picked, sizeof picked, devices, &ndevices);
    if (rc) return rc;
    cfg.scenario = picked;
  }
  if (!cfg.scenario) return tx_bad_input("run: expected a SCENARIO (tactus list shows them)");
  if (strcmp(view, "png") == 0 && !TX_WITH_OSMESA)
    return tx_bad_input("--view png: this build has no OSMesa (configure with -DTX_WITH_OSMESA=ON)");
  if (strcmp(view, "window") == 0 && !TX_WITH_GLFW)
    return tx_bad_input("--view window: this build has no GLFW (configure with -DTX_WITH_GLFW=ON)");
  if (strcmp(view, "window") == 0 && !(getenv("DISPLAY") && *getenv("DISPLAY")))
    return tx_bad_input("--view window: no display (DISPLAY is not set); use --view png for frames without one");
  if (strcmp(stereo_mode, "mono") != 0 && strcmp(view, "none") == 0)
    return tx_bad_input("--stereo %s: needs --view png or --view window", stereo_mode);
  for (int i = 0; i < ndevices; i++)
    if ((strcmp(devices[i], "mouse") == 0 || strncmp(devices[i], "mouse:", 6) == 0) && strcmp(view, "window") != 0)
      return tx_bad_input("--device %s: the mouse drives the tool through a window: add --view window", devices[i]);

  // the processes of a session meet in real time: a virtual clock cannot be shared
  if (role && cfg.lockstep) return tx_bad_input("--role %s: a session runs in real time; leave out --lockstep", role);
  if (tx_out_check(cfg.out, force)) return TX_EXIT_BAD_INPUT;

  char path[PATH_MAX];
  if (tx_scenario_locate(cfg.scenario, path, sizeof path)) return tx_bad_input("%s", tx_error());
  tx_load_options o = {sets, nsets, true, devices, ndevices, view, stereo_mode, cfg.lockstep, role, probe};
  tx_scenario* sc = tx_scenario_load(path, &o);
  if (!sc) return tx_bad_input("%s", tx_error());
  tx_replay_warn(sc->system);
  int rc = tx_run_scenario(sc, &cfg, NULL);
  tx_scenario_free(sc);
  return rc;
}
