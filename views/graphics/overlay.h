// Internal: a small text overlay drawn over a frame (rates, force), with a
// built-in 5 x 7 pixel font of digits, capitals and a few signs. GL 3.3 core.
#ifndef TX_VIEWS_GRAPHICS_OVERLAY_H
#define TX_VIEWS_GRAPHICS_OVERLAY_H

#include "gl.h"

typedef struct tx_overlay tx_overlay;

tx_overlay* tx_overlay_create(const tx_gl* gl);
void tx_overlay_destroy(tx_overlay* o);
// queue text at (x, y) px from the top-left corner, `scale` px per font pixel; lower case prints as capitals
void tx_overlay_text(tx_overlay* o, int x, int y, int scale, const char* text, const float rgb[3]);
// queue a filled rectangle, px from the top-left
void tx_overlay_rect(tx_overlay* o, int x, int y, int w, int h, const float rgb[3]);
// draw what was queued over a viewport of width x height px and empty the queue
void tx_overlay_flush(tx_overlay* o, int width, int height);
// draw what was queued over the viewport at (x, y) (GL's lower-left origin) and
// keep it queued: each eye of a tiled stereo frame gets the same overlay
void tx_overlay_draw(tx_overlay* o, int x, int y, int width, int height);
// empty the queue
void tx_overlay_clear(tx_overlay* o);
// font pixels of a character: 7 rows of 5 bits (bit 4 is the left column); NULL when not in the font
const unsigned char* tx_overlay_glyph(char c);

#endif
