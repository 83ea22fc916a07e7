// OSMesa: a core-profile context drawing into a buffer we own.
#include "osmesa_target.h"

#include "../../model/error.h"

#include <GL/osmesa.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

struct tx_osmesa {
  OSMesaContext ctx;
  uint8_t* pixels; // (height x width x 4) RGBA, bottom row first
  int width, height;
};

int tx_osmesa_bound_threads(int wanted) {
  const char* set = getenv("LP_NUM_THREADS");
  if (set && *set) return atoi(set);
  if (wanted < 0) {
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    wanted = cpus > 2 ? (int)(cpus - 2) : 0; // 0: the rendering thread rasterises itself
    if (wanted > 8) wanted = 8;
  }
  char text[16];
  snprintf(text, sizeof text, "%d", wanted);
  setenv("LP_NUM_THREADS", text, 1);
  return wanted;
}

tx_osmesa* tx_osmesa_create(int width, int height) {
  tx_osmesa* o = calloc(1, sizeof *o);
  if (o) o->pixels = malloc((size_t)width * (size_t)height * 4);
  if (!o || !o->pixels) {
    if (o) free(o);
    return tx_set_error("out of memory for a %dx%d image", width, height), NULL;
  }
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                         OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  o->ctx = OSMesaCreateContextAttribs(attribs, NULL);
  if (!o->ctx) {
    free(o->pixels);
    free(o);
    return tx_set_error("OSMesa could not make a GL 3.3 core context"), NULL;
  }
  if (!OSMesaMakeCurrent(o->ctx, o->pixels, GL_UNSIGNED_BYTE, width, height)) {
    tx_osmesa_destroy(o);
    return tx_set_error("OSMesa could not make its context current"), NULL;
  }
  o->width = width;
  o->height = height;
  return o;
}

void tx_osmesa_destroy(tx_osmesa* o) {
  if (!o) return;
  if (o->ctx) OSMesaDestroyContext(o->ctx);
  free(o->pixels);
  free(o);
}

tx_gl_proc tx_osmesa_proc(const char* name) { return (tx_gl_proc)OSMesaGetProcAddress(name); }

const uint8_t* tx_osmesa_pixels(const tx_osmesa* o) { return o->pixels; }
