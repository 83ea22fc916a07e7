// tactus run: one scenario, real time or lockstep, ending in a report.
#include "command.h"
#include "run.h"

#include "../../views/report.h"
#include "../../views/trace_plot.h"

#include <tactus/config.h>

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char run_usage[] =
    "usage: tactus run SCENARIO [OPTIONS]\n"
    "\n"
    "  --duration S        run length in seconds (default: the scenario's duration_s)\n"
    "  --lockstep          one thread on a virtual clock: deterministic, writes OUT/trace.csv\n"
    "  --set KEY=VALUE     override CONTROLLER.PARAM, CONTROLLER.rate_hz or duration_s (repeatable)\n"
    "  --device SPEC       a haptic device per hand: scripted:NAME|FILE.csv, replay:FILE, sim, udp:HOST:PORT, mouse\n"
    "  --view SPEC         none|png|window (default none): png writes OUT/frames/ (OSMesa), window needs DISPLAY\n"
    "  --stereo MODE       mono|sbs|tb|anaglyph|lr (default mono): side by side, top-bottom, red-cyan, or left and right files\n"
    "  --out DIR           output folder (default out/SCENARIO-TIMESTAMP)\n"
    "  --no-record         no device recordings (OUT/deviceN.bin and .csv are written by default)\n"
    "  --quiet             no summary table\n"
    "\n"
    "Writes OUT/report.json: per controller achieved rate, missed deadlines, period jitter and step time,\n"
    "and OUT/device0.png (force and position traces) when a haptics device was recorded.\n"
    "Ctrl-C stops the run early and still writes the report.\n";

static bool one_of(const char* s, const char* const* options) {
  for (; *options; options++)
    if (strcmp(s, *options) == 0) return true;
  return false;
}

int tx_run_scenario(tx_scenario* sc, const tx_run_config* cfg, json_t** report_out) {
  char dir[4096], err[1024];
  if (tx_out_dir(cfg->out, sc->name, dir, sizeof dir, err, sizeof err)) return tx_bad_input("%s", err);
  double duration = cfg->duration_s > 0 ? cfg->duration_s : sc->duration_s;
  FILE* trace = NULL;
  char trace_path[4200], trace_tmp[4300];
  if (cfg->lockstep) { // written aside and renamed once the run is whole
    snprintf(trace_path, sizeof trace_path, "%s/trace.csv", dir);
    snprintf(trace_tmp, sizeof trace_tmp, "%s.tmp", trace_path);
    trace = fopen(trace_tmp, "w");
    if (!trace) return tx_bad_input("--out %s: cannot write trace.csv", dir);
    fprintf(trace, "sim_ns,controller,component,seq,rows,hash\n");
  }
  tx_catch_stop_signals();
  tx_run_options o = {.duration_s = duration, .lockstep = cfg->lockstep, .trace = trace, .realtime_priority = true,
                      .pin_threads = true, .keep_cpus_awake = true, .record_dir = cfg->no_record ? NULL : dir, .out_dir = dir,
                      .progress = tx_progress, .progress_user = &duration};
  tx_run_result r;
  int rc = tx_system_run(sc->system, &o, &r, err, sizeof err);
  if (trace && (fclose(trace) != 0 || rc != 0 || rename(trace_tmp, trace_path) != 0)) {
    remove(trace_tmp);
    if (rc == 0) rc = -1, snprintf(err, sizeof err, "trace.csv in %.900s could not be written", dir);
  }
  if (isatty(2)) fprintf(stderr, "\r%40s\r", "");
  if (rc) {
    fprintf(stderr, "tactus: run %s: %s\n", sc->name, err);
    return 1;
  }
  json_t* report = tx_report_json(&(tx_report){sc->name, cfg->lockstep, &r, sc->system});
  if (!report || tx_report_save(report, dir, "report.json", err, sizeof err)) {
    json_decref(report);
    fprintf(stderr, "tactus: %s\n", report ? err : "out of memory for the report");
    return 1;
  }
  // force and position traces of every device recorded in this run
  for (int hand = 0; hand < 2 && !cfg->no_record; hand++) {
    char csv[4200], png[4200], perr[1024];
    snprintf(csv, sizeof csv, "%s/device%d.csv", dir, hand);
    snprintf(png, sizeof png, "%s/device%d.png", dir, hand);
    if (access(csv, R_OK) == 0 && tx_trace_plot_png(csv, png, perr, sizeof perr) != 0 && TX_WITH_PLPLOT)
      fprintf(stderr, "tactus: %s\n", perr);
  }
  if (!cfg->quiet) {
    tx_report_print(stdout, report);
    printf("report: %s/report.json%s\n", dir, cfg->lockstep ? " (and trace.csv)" : "");
  }
  if (report_out) *report_out = report;
  else json_decref(report);
  if (r.halted) return fprintf(stderr, "tactus: run %s stopped at t = %.3f s: %s\n", sc->name, r.halt_t_s, r.halt_reason), 1;
  return 0;
}

int tx_cmd_run(int argc, char** argv) {
  static const struct option longs[] = {
      {"duration", required_argument, 0, 'd'}, {"lockstep", no_argument, 0, 'l'}, {"set", required_argument, 0, 's'},
      {"device", required_argument, 0, 'D'},   {"view", required_argument, 0, 'v'}, {"stereo", required_argument, 0, 'S'},
      {"out", required_argument, 0, 'o'},      {"quiet", no_argument, 0, 'q'},   {"help", no_argument, 0, 'h'},
      {"no-record", no_argument, 0, 'R'},
      {0, 0, 0, 0}};
  static const char* const views[] = {"none", "png", "window", NULL};
  static const char* const stereo[] = {"mono", "sbs", "tb", "anaglyph", "lr", NULL};
  tx_run_config cfg = {0};
  const char* sets[64];
  const char* devices[2];
  int nsets = 0, ndevices = 0;
  const char* view = "none";
  const char* stereo_mode = "mono";
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

  tx_scenario* sc = tx_load_for_command_view(cfg.scenario, sets, nsets, devices, ndevices, view, stereo_mode, cfg.lockstep);
  if (!sc) return TX_EXIT_BAD_INPUT;
  int rc = tx_run_scenario(sc, &cfg, NULL);
  tx_scenario_free(sc);
  return rc;
}
