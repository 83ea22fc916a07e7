// Internal: a headless GL 3.3 core context on OSMesa (Mesa's llvmpipe), drawing
// into memory. llvmpipe starts its rasteriser threads when the first context
// is made, reading LP_NUM_THREADS then: tx_osmesa_bound_threads sets it
// before that, so rendering never takes every core from the haptic thread.
#ifndef TX_VIEWS_GRAPHICS_OSMESA_TARGET_H
#define TX_VIEWS_GRAPHICS_OSMESA_TARGET_H

#include "gl.h"

#include <stddef.h>
#include <stdint.h>

typedef struct tx_osmesa tx_osmesa;

// the rasteriser threads llvmpipe will use: `wanted` (< 0: CPUs - 2, at most 8),
// unless LP_NUM_THREADS is already set, which wins; call before any thread starts
int tx_osmesa_bound_threads(int wanted);
// a current context with a width x height RGBA buffer; NULL with the message in tx_error() on failure
tx_osmesa* tx_osmesa_create(int width, int height);
void tx_osmesa_destroy(tx_osmesa* o);
// the proc-address function for tx_gl_load
tx_gl_proc tx_osmesa_proc(const char* name);
// the finished image: width x height RGBA, bottom row first (call after glFinish)
const uint8_t* tx_osmesa_pixels(const tx_osmesa* o);

#endif
