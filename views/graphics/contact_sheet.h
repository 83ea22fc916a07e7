// Internal: a contact sheet, one PNG of small copies of the frames a run
// wrote, so a whole run can be seen at a glance. It keeps at most `cap`
// thumbnails: when full it drops every other one and takes every second
// frame from then on, so the kept ones stay evenly spread over the run.
#ifndef TX_VIEWS_GRAPHICS_CONTACT_SHEET_H
#define TX_VIEWS_GRAPHICS_CONTACT_SHEET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct tx_contact_sheet {
  int thumb_w, thumb_h; // px, one thumbnail
  int cap;              // thumbnails kept at most (even)
  int count;            // thumbnails kept now
  int stride;           // offered frames per kept thumbnail
  int offered;          // frames offered so far
  uint8_t* pixels;      // (cap x thumb_h x thumb_w x 4) RGBA, top row first
} tx_contact_sheet;

// thumbnails about thumb_width px wide with the frames' aspect; false when out of memory
bool tx_contact_sheet_init(tx_contact_sheet* s, int frame_w, int frame_h, int thumb_width, int cap);
void tx_contact_sheet_free(tx_contact_sheet* s);
// offer a frame (RGBA, bottom row first); `last` always keeps it, replacing the newest if full
void tx_contact_sheet_add(tx_contact_sheet* s, const uint8_t* rgba, int w, int h, bool last);
// write the kept thumbnails in rows of `columns`; 0 or -1 with the message in tx_error()
int tx_contact_sheet_write(const tx_contact_sheet* s, const char* path, int columns);

#endif
