// tactus-device: serve a haptic device over UDP (docs/device-protocol.md),
// so that a simulation on this or another machine can use it with
// `tactus run ... --device udp:HOST:PORT`.
#include "../controllers/haptics/device_protocol.h"
#include "../controllers/haptics/device_server.h"
#include "../controllers/haptics/recorder.h"
#include "../scenarios/command.h"

#include <tactus/config.h>
#if TX_WITH_DDS
#include "../controllers/net/device_dds.h"
#endif

#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


static const char usage[] =
    "usage: tactus-device SPEC [OPTIONS]\n"
    "\n"
    "Serves a haptic device over UDP: sends its state at --rate, applies the forces that come back.\n"
    "\n"
    "  SPEC                the device: scripted:NAME, scripted:FILE.csv, replay:FILE.bin, sim[:KEY=VALUE,...]\n"
    "                      (not mouse, which needs the window of tactus run --view window)\n"
    "  --listen ADDR:PORT  where to listen (default 127.0.0.1:47100; port 0 takes a free one)\n"
    "  --peer ADDR:PORT    the only simulator answered (default: the first that says hello)\n"
    "  --rate HZ           state packets per second, up to 100000 (default 1000; a replay's recorded rate)\n"
    "  --duration S        stop S seconds after the first hello (default: until Ctrl-C)\n"
    "  --quiet             no summary at the end\n"
    "  --dds DOMAIN[:NAME][,peer=HOST]...\n"
    "                      serve over Cyclone DDS instead (DDS builds): domain in [0, 232], the device's name\n"
    "                      (default device0); loopback only unless peers are named (or CYCLONEDDS_URI); for\n"
    "                      `tactus run --device dds:DOMAIN[:NAME]`. No force for 3 ms ramps it to zero over 5 ms\n"
    "\n"
    "ADDR is an IPv4 address or localhost. It listens on loopback unless --listen says otherwise,\n"
    "and takes packets only from its peer. The first line on stdout names the address it serves on.\n"
    "At the end it prints the packets counted and the round trip (state out, force back) p50/p99.\n"
    "A client not heard from for 1 s is let go, and the next to say hello is served; each client's\n"
    "forces ramp from zero over 5 ms. Ctrl-C stops it; the device is left with zero force.\n"
    "Bad input exits with status 2.\n"
    "\n"
    "  tactus-device scripted:pierce-down --listen 127.0.0.1:47100 &\n"
    "  tactus run haptics-wall --device udp:127.0.0.1:47100\n";

static atomic_int stop_requested;

static void on_stop(int sig) {
  (void)sig;
  atomic_store(&stop_requested, 1);
}

static void print_stats(const tx_device_server_stats* s) {
  printf("packets: %llu hellos, %llu states sent, %llu forces applied; dropped: %llu stale, %llu malformed, "
         "%llu foreign, %llu of no session, %llu unexpected; %llu send errors, %llu force timeouts, %llu late ticks\n",
         (unsigned long long)s->hellos, (unsigned long long)s->states, (unsigned long long)s->forces,
         (unsigned long long)s->stale, (unsigned long long)s->malformed, (unsigned long long)s->foreign,
         (unsigned long long)s->other_session, (unsigned long long)s->unexpected, (unsigned long long)s->send_errors,
         (unsigned long long)s->force_timeouts, (unsigned long long)s->late_ticks);
  printf("clients: %llu served, %llu let go after falling silent; %llu forces ramped from zero after a hello\n",
         (unsigned long long)s->clients, (unsigned long long)s->clients_gone, (unsigned long long)s->ramped);
  if (s->round_trips)
    printf("round trip (%llu): link p50 %.1f us p99 %.1f us max %.1f us; with the simulator's tick wait p50 %.1f us "
           "p99 %.1f us\n",
           (unsigned long long)s->round_trips, s->link.p50 * 1e-3, s->link.p99 * 1e-3, s->link.max * 1e-3,
           s->loop.p50 * 1e-3, s->loop.p99 * 1e-3);
  else
    printf("round trip: no forces came back\n");
}

// --dds: the same device, over Cyclone DDS (controllers/net/device_dds.h)
static int serve_dds(const char* arg, const tx_device_server_def* udp, bool quiet) {
#if TX_WITH_DDS
  tx_device_dds_server_def def = tx_device_dds_server_def_default();
  static tx_device_dds_spec spec; // 8 kB of peer names: not on the stack
  if (!tx_device_dds_parse(arg, &spec)) return tx_bad_input("--dds %s: %s", arg, tx_error());
  def.dds = arg;
  def.spec = udp->spec;
  def.rate_hz = udp->rate_hz;
  def.duration_s = udp->duration_s;
  tx_device_dds_server* s = tx_device_dds_server_open(&def);
  if (!s) return tx_bad_input("%s", tx_error());
  struct sigaction sa = {0};
  sa.sa_handler = on_stop;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  printf("tactus-device: serving %s on DDS domain %d as %s at %g Hz, %s\n", def.spec, spec.domain, spec.name, def.rate_hz,
         spec.npeers ? "discovering only its peers" : "on loopback only");
  int rc = tx_device_dds_server_run(s, &stop_requested);
  tx_device_dds_server_stats st;
  tx_device_dds_server_get_stats(s, &st);
  tx_device_dds_server_close(s);
  if (!quiet) {
    printf("samples: %llu states sent, %llu forces applied; dropped: %llu foreign, %llu malformed\n",
           (unsigned long long)st.states, (unsigned long long)st.forces, (unsigned long long)st.foreign,
           (unsigned long long)st.malformed);
    printf("simulations: %llu lost (force ramped to zero), %llu taken up again; force zero %.1f ms after the last "
           "force at most; %llu late ticks, %s\n",
           (unsigned long long)st.timeouts, (unsigned long long)st.resumes, st.zero_after_s * 1e3,
           (unsigned long long)st.late_ticks, st.fifo ? "SCHED_FIFO" : "SCHED_OTHER (SCHED_FIFO refused)");
    if (st.forces) printf("round trip (state out, force back): p50 %.1f us p99 %.1f us max %.1f us\n", st.loop.p50 * 1e-3,
                          st.loop.p99 * 1e-3, st.loop.max * 1e-3);
  }
  return rc ? 1 : 0;
#else
  (void)udp, (void)quiet;
  return tx_bad_input("--dds %s: this build has no DDS (configure with -DTX_WITH_DDS=ON)", arg);
#endif
}

int main(int argc, char** argv) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  tx_program = "tactus-device";
  static const struct option longs[] = {{"listen", required_argument, 0, 'l'}, {"peer", required_argument, 0, 'p'},
                                        {"rate", required_argument, 0, 'r'},   {"duration", required_argument, 0, 'd'},
                                        {"quiet", no_argument, 0, 'q'},        {"help", no_argument, 0, 'h'},
                                        {"dds", required_argument, 0, 'D'},
                                        {0, 0, 0, 0}};
  tx_device_server_def def = tx_device_server_def_default();
  bool quiet = false, rate_given = false;
  const char* dds = NULL;
  const char* why = NULL;
  opterr = 0;
  // GNU getopt moves operands behind the options, so SPEC may stand anywhere
  for (int c; (c = getopt_long(argc, argv, "h", longs, NULL)) != -1;) {
    switch (c) {
    case 'l':
      if (!tx_dp_parse_addr(optarg, true, &def.listen, &why)) return tx_bad_input("--listen %s: %s", optarg, why);
      break;
    case 'p':
      if (!tx_dp_parse_addr(optarg, false, &def.peer, &why)) return tx_bad_input("--peer %s: %s", optarg, why);
      break;
    case 'r':
      if (!tx_parse_num(optarg, 1, TX_DP_MAX_RATE_HZ, &def.rate_hz))
        return tx_bad_input("--rate %s: expected a rate in [1, 100000] Hz", optarg);
      rate_given = true;
      break;
    case 'd':
      if (!tx_parse_num(optarg, 1e-3, 1e6, &def.duration_s))
        return tx_bad_input("--duration %s: expected seconds in [0.001, 1000000]", optarg);
      break;
    case 'q': quiet = true; break;
    case 'D': dds = optarg; break;
    case 'h': return fputs(usage, stdout), 0;
    default:
      if (optopt && strncmp(argv[optind - 1], "--", 2) != 0)
        return tx_bad_input("unknown option '-%c' (tactus-device --help)", optopt);
      return tx_bad_input("unknown or incomplete option '%s' (tactus-device --help)", argv[optind - 1]);
    }
  }
  if (optind >= argc) return tx_bad_input("expected a device SPEC such as scripted:pierce-down (tactus-device --help)");
  def.spec = argv[optind++];
  if (optind < argc) return tx_bad_input("unexpected argument '%s'", argv[optind]);
  bool listen_loopback = (ntohl(def.listen.sin_addr.s_addr) >> 24) == 127;
  if (def.peer.sin_port && listen_loopback && (ntohl(def.peer.sin_addr.s_addr) >> 24) != 127)
    return tx_bad_input("--peer: a peer on another machine needs --listen on an address it can reach");
  if (strncmp(def.spec, "udp:", 4) == 0) return tx_bad_input("%s: a udp device cannot be served again over UDP", def.spec);
  if (strcmp(def.spec, "mouse") == 0 || strncmp(def.spec, "mouse:", 6) == 0)
    return tx_bad_input("%s: the mouse device needs a window (tactus run --view window --device mouse); "
                        "tactus-device serves scripted:, replay: and sim devices", def.spec);
  // a replay plays one record per tick, so it is served at its recorded rate:
  // that rate unless --rate says otherwise, and a --rate that differs names the fix
  char cut_short[sizeof ((tx_record_file*)0)->cut_short] = "";
  if (strncmp(def.spec, "replay:", 7) == 0) {
    tx_record_file rf;
    // a file that does not load is reported by the server's open below, once
    if (tx_record_load(def.spec + 7, &rf) == 0) {
      free(rf.records);
      snprintf(cut_short, sizeof cut_short, "%s", rf.cut_short);
      double recorded = rf.header.rate_hz;
      if (rate_given && fabs(recorded - def.rate_hz) > 1e-9 * recorded)
        return tx_bad_input("--rate %g: %s was recorded at %g Hz; serve it with --rate %g (or leave --rate out)",
                            def.rate_hz, def.spec + 7, recorded, recorded);
      if (recorded >= 1 && recorded <= TX_DP_MAX_RATE_HZ) def.rate_hz = recorded;
    }
  }

  if (dds) return serve_dds(dds, &def, quiet);
  tx_device_server* s = tx_device_server_open(&def);
  if (!s) return tx_bad_input("%s", tx_error());
  if (*cut_short) fprintf(stderr, "tactus-device: warning: %s\n", cut_short); // once the server has taken it

  struct sigaction sa = {0};
  sa.sa_handler = on_stop; // no SA_RESTART: a signal wakes the wait at once
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  struct sockaddr_in bound = def.listen;
  bound.sin_port = htons(tx_device_server_port(s));
  char where[64];
  printf("tactus-device: serving %s on %s at %g Hz\n", def.spec, tx_dp_addr_text(&bound, where, sizeof where),
         def.rate_hz);

  int rc = tx_device_server_run(s, &stop_requested);
  if (rc) fprintf(stderr, "tactus-device: %s\n", tx_error());
  tx_device_server_stats stats;
  tx_device_server_get_stats(s, &stats);
  tx_device_server_close(s);
  if (!quiet) print_stats(&stats);
  return rc ? 1 : 0;
}
