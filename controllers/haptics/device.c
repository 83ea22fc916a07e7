// Device specs to backends.
#include "device.h"

#include "../../model/error.h"

#include <tactus/config.h>

#include <stdio.h>
#include <string.h>

static const tx_device_backend* const backends[] = {&tx_device_scripted, &tx_device_replay, &tx_device_sim, &tx_device_udp, &tx_device_mouse,
#if TX_WITH_DDS
                                                    &tx_device_dds, // controllers/net/device_dds.c
#endif
};

int tx_device_open(const char* spec, double period_s, tx_device_handle* h) {
  *h = (tx_device_handle){0};
  const char* colon = strchr(spec, ':');
  size_t len = colon ? (size_t)(colon - spec) : strlen(spec);
  for (size_t i = 0; i < sizeof backends / sizeof backends[0]; i++) {
    if (strlen(backends[i]->scheme) != len || strncmp(spec, backends[i]->scheme, len) != 0) continue;
    h->backend = backends[i];
    h->device = backends[i]->open(colon ? colon + 1 : "", period_s);
    return h->device ? 0 : -1;
  }
  tx_set_error("device '%s': unknown kind (known: scripted:NAME, scripted:FILE.csv, replay:FILE, sim[:KEY=VALUE,...], udp:HOST:PORT, mouse%s)", spec,
               TX_WITH_DDS ? ", dds:DOMAIN[:NAME]" : "");
  return -1;
}

void tx_device_close(tx_device_handle* h) {
  if (h->backend && h->device) h->backend->close(h->device);
  *h = (tx_device_handle){0};
}
