// The stereo modes as viewports, colour masks and draw buffers.
#include "stereo_frame.h"

#include <string.h>

static const char* const names[] = {"mono", "sbs", "tb", "anaglyph", "lr", "quad"};

bool tx_stereo_mode_from_name(const char* name, tx_stereo_mode* out) {
  for (int i = 0; i < 5; i++) // quad is chosen by the window, never named
    if (strcmp(name, names[i]) == 0) return *out = (tx_stereo_mode)i, true;
  return false;
}

const char* tx_stereo_mode_name(tx_stereo_mode m) { return names[m]; }

void tx_stereo_image_size(tx_stereo_mode m, int eye_w, int eye_h, int* w, int* h) {
  *w = m == TX_STEREO_SBS ? 2 * eye_w : eye_w;
  *h = m == TX_STEREO_TB ? 2 * eye_h : eye_h;
}

int tx_stereo_passes(tx_stereo_mode m) { return m == TX_STEREO_LR ? 2 : 1; }

// the eyes of sbs and tb tile the image, so one clear of the whole image
// serves both: llvmpipe clears a whole image lazily, per tile, but a
// scissored clear is drawn as a quad over every pixel (5 ms a frame here)
#define ALL (GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT)

void tx_stereo_draw(tx_renderer* r, const tx_view_def* d, const tx_camera* c, tx_stereo_mode m, int pass, int w, int h) {
  const tx_gl* gl = tx_renderer_gl(r);
  switch (m) {
  case TX_STEREO_MONO: tx_renderer_draw(r, d, c, TX_EYE_MONO, 0, 0, w, h, ALL); break;
  case TX_STEREO_SBS:
    tx_renderer_draw(r, d, c, TX_EYE_LEFT, 0, 0, w, h, ALL);
    tx_renderer_draw(r, d, c, TX_EYE_RIGHT, w, 0, w, h, 0);
    break;
  case TX_STEREO_TB: // GL's rows run bottom-up: the left eye takes the upper half
    tx_renderer_draw(r, d, c, TX_EYE_LEFT, 0, h, w, h, ALL);
    tx_renderer_draw(r, d, c, TX_EYE_RIGHT, 0, 0, w, h, 0);
    break;
  case TX_STEREO_ANAGLYPH:
    gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl->ClearColor(0, 0, 0, 1);
    gl->Clear(GL_COLOR_BUFFER_BIT);
    gl->ColorMask(GL_TRUE, GL_FALSE, GL_FALSE, GL_TRUE);
    tx_renderer_draw(r, d, c, TX_EYE_LEFT, 0, 0, w, h, ALL);
    gl->ColorMask(GL_FALSE, GL_TRUE, GL_TRUE, GL_TRUE);
    tx_renderer_draw(r, d, c, TX_EYE_RIGHT, 0, 0, w, h, ALL);
    gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    break;
  case TX_STEREO_LR: tx_renderer_draw(r, d, c, pass == 0 ? TX_EYE_LEFT : TX_EYE_RIGHT, 0, 0, w, h, ALL); break;
  case TX_STEREO_QUAD:
    gl->DrawBuffer(GL_BACK_LEFT);
    tx_renderer_draw(r, d, c, TX_EYE_LEFT, 0, 0, w, h, ALL);
    gl->DrawBuffer(GL_BACK_RIGHT);
    tx_renderer_draw(r, d, c, TX_EYE_RIGHT, 0, 0, w, h, ALL);
    gl->DrawBuffer(GL_BACK);
    break;
  }
}
