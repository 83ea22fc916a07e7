// udp_shim: the lossy relay of udp_shim.h as a program, for the command-line
// tests: `udp_shim SERVER_PORT [SEED]` relays 127.0.0.1:PORT (printed on the
// first line) to 127.0.0.1:SERVER_PORT until SIGINT or SIGTERM, then prints
// what it did to the traffic.
#include "udp_shim.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

static atomic_int stop;

static void on_stop(int sig) {
  (void)sig;
  atomic_store(&stop, 1);
}

int main(int argc, char** argv) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  if (argc < 2 || argc > 3) return fprintf(stderr, "usage: udp_shim SERVER_PORT [SEED]\n"), 2;
  long port = strtol(argv[1], NULL, 10);
  if (port < 1 || port > 65535) return fprintf(stderr, "udp_shim: bad port %s\n", argv[1]), 2;
  udp_shim s;
  if (shim_open(&s, (uint16_t)port, argc > 2 ? strtoull(argv[2], NULL, 10) : 1)) return perror("udp_shim"), 1;
  struct sigaction sa = {0};
  sa.sa_handler = on_stop;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  printf("udp_shim: listening on 127.0.0.1:%u\n", shim_port_of(s.a));
  shim_run(&s, &stop);
  shim_counts* c = &s.counts;
  printf("udp_shim: %llu in, %llu out, %llu dropped, %llu swapped, %llu duplicated, %llu garbage (%llu replays), "
         "%llu forged\n",
         (unsigned long long)c->in, (unsigned long long)c->out, (unsigned long long)c->dropped,
         (unsigned long long)c->swapped, (unsigned long long)c->duplicated, (unsigned long long)c->garbage,
         (unsigned long long)c->replayed, (unsigned long long)c->forged);
  shim_close(&s);
  return 0;
}
