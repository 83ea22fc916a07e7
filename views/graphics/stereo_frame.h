// Internal: how one frame of a view is laid out for each stereo mode.
//
//   mono      one eye, width x height
//   sbs       left | right, 2 width x height
//   tb        left over right, width x 2 height
//   anaglyph  both eyes in one width x height image: left in red, right in green and blue
//   lr        two width x height images, one per eye (two passes)
//   quad      quad-buffered stereo: each eye into its own back buffer (windows only)
#ifndef TX_VIEWS_GRAPHICS_STEREO_FRAME_H
#define TX_VIEWS_GRAPHICS_STEREO_FRAME_H

#include "renderer.h"

typedef enum tx_stereo_mode {
  TX_STEREO_MONO,
  TX_STEREO_SBS,
  TX_STEREO_TB,
  TX_STEREO_ANAGLYPH,
  TX_STEREO_LR,
  TX_STEREO_QUAD
} tx_stereo_mode;

// "mono", "sbs", "tb", "anaglyph", "lr"; false for anything else
bool tx_stereo_mode_from_name(const char* name, tx_stereo_mode* out);
const char* tx_stereo_mode_name(tx_stereo_mode m);
// size of one image of the frame, px
void tx_stereo_image_size(tx_stereo_mode m, int eye_w, int eye_h, int* w, int* h);
// images per frame: 2 for lr, else 1
int tx_stereo_passes(tx_stereo_mode m);
// draw image `pass` of a frame into the bound framebuffer (quad: sets the draw buffers itself)
void tx_stereo_draw(tx_renderer* r, const tx_view_def* d, const tx_camera* c, tx_stereo_mode m, int pass, int eye_w,
                    int eye_h);

#endif
