// Internal: RGBA images to PNG files with libpng, whole or absent (written
// aside and renamed).
#ifndef TX_VIEWS_GRAPHICS_PNG_WRITER_H
#define TX_VIEWS_GRAPHICS_PNG_WRITER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

// write width x height RGBA (bottom row first when bottom_up) as an RGB PNG; 0 or -1 with the message in tx_error()
int tx_png_write(const char* path, const uint8_t* rgba, int width, int height, bool bottom_up);
// read a PNG as RGBA, top row first (caller frees *rgba); 0 or -1 with the message in tx_error()
int tx_png_read(const char* path, uint8_t** rgba, int* width, int* height);

#endif
