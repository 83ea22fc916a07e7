// Internal: the procedural tissue texture of the organs (the LAGB scene's
// liver, stomach and spleen), made at load: a grey detail map that the
// renderer multiplies with a mesh's colour (a mesh's "texture": "tissue"),
// so one texture serves every organ in its own colour. It holds what a
// laparoscope shows on a serosa: a mottled tone (four octaves of value
// noise), a network of fine vessels (the zero lines of two noise fields, darker),
// and a faint speckle. Tileable: it repeats every `size` texels.
#ifndef TX_VIEWS_GRAPHICS_ORGAN_TEXTURE_H
#define TX_VIEWS_GRAPHICS_ORGAN_TEXTURE_H

#include <stdint.h>

// the shader's factor is TX_TISSUE_LO + TX_TISSUE_SPAN * texel / 255 (about 1 on average)
#define TX_TISSUE_LO 0.55f
#define TX_TISSUE_SPAN 0.9f

// size x size RGB (grey: the three channels equal, vessels a little redder)
void tx_tissue_texture(uint8_t* rgb, int size);

#endif
