// Internal: draws a view's items with GL 3.3 core (on OSMesa or in a GLFW
// window): triangle meshes with a procedural skin texture, ray-cast sphere
// impostors (exact silhouette, depth and normal per pixel), instanced
// cylinders, tools, planes; per-pixel Blinn-Phong lighting from one
// directional light, two-sided. Needs a current context; one renderer per context.
//
//     tx_renderer* r = tx_renderer_create(loader);
//     tx_renderer_upload(r, &def, &scene);                  // once per frame
//     tx_renderer_draw(r, &def, &def.camera, TX_EYE_LEFT, 0, 0, w, h, GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
//     tx_renderer_draw(r, &def, &def.camera, TX_EYE_RIGHT, w, 0, w, h, 0);  // the eyes tile the image
#ifndef TX_VIEWS_GRAPHICS_RENDERER_H
#define TX_VIEWS_GRAPHICS_RENDERER_H

#include "gl.h"
#include "view_def.h"

#include <tactus/components.h>

#include <stdint.h>

// the lighting model, shared with the tests that check a lit pixel:
// colour = base * (AMBIENT + DIFFUSE * max(n.l, 0)) + SPECULAR * max(n.h, 0)^32 (where n.l > 0),
// l towards the light, h the half vector of l and the direction to the viewer (at infinity)
#define TX_LIGHT_AMBIENT 0.25f
#define TX_LIGHT_DIFFUSE 0.65f
#define TX_LIGHT_SPECULAR 0.2f
#define TX_LIGHT_SHININESS 32.0f // five squarings in the shader

typedef struct tx_scene_item {
  const tx_draw_item* item;
  const void* data[3]; // the item's components, in tx_draw_item_components order
  uint32_t rows[3];    // rows in use of each
} tx_scene_item;

typedef struct tx_scene {
  tx_scene_item items[TX_DRAW_MAX];
  int count;
  const tx_marker_list* markers[TX_DRAW_MAX]; // markers items: their live grasps and knots; NULL for none
} tx_scene;

typedef struct tx_renderer tx_renderer;

// Instruments drawn from their URDF visual meshes (instrument_mesh.c): the
// instruments of one hand ("needle_holder metzenbaum_scissors", names in
// assets/instruments or .urdf paths); NULL with tx_error() set for one that
// cannot be read (or a build without urdfdom and assimp). Place: the one
// at index `held` at the link frames `links` (a pose per URDF link, root
// first): its vertices (m, world) and triangles, valid until the next call;
// false for an index out of the list, too few or non-finite links.
typedef struct tx_instrument_mesh tx_instrument_mesh;
tx_instrument_mesh* tx_instrument_mesh_load(const char* list);
void tx_instrument_mesh_free(tx_instrument_mesh* m);
bool tx_instrument_mesh_place(tx_instrument_mesh* m, double held, const tx_pose* links, uint32_t nlinks,
                              const float** x, uint32_t* nv, const int32_t** tri, uint32_t* nt);

tx_renderer* tx_renderer_create(tx_gl_loader load);
void tx_renderer_destroy(tx_renderer* r);
const tx_gl* tx_renderer_gl(const tx_renderer* r);
// take one frame's geometry (shared by both eyes); rows that are not finite or
// index past the vertices are skipped and counted
void tx_renderer_upload(tx_renderer* r, const tx_scene* s);
// the box around what the last upload holds, m; false when it holds nothing
bool tx_renderer_bounds(const tx_renderer* r, double lo[3], double hi[3]);
// clear the whole image first (clear: GL_COLOR_BUFFER_BIT and/or
// GL_DEPTH_BUFFER_BIT, or 0), then draw one eye into the viewport
void tx_renderer_draw(tx_renderer* r, const tx_view_def* d, const tx_camera* c, tx_eye eye, int x, int y, int w, int h,
                      unsigned clear);
// rows skipped so far as not finite or out of range
uint64_t tx_renderer_skipped(const tx_renderer* r);
// where a tool's force rod starts, so that the tool never hides it: on the HIP
// sphere (centre p, radius) along the force f, or, for a force within reach of
// the shaft (p to p + shaft, 0.35 radius thick), past the shaft's end along f;
// p itself for no force
void tx_force_arrow_start(const float p[3], const float shaft[3], float radius, const double f[3], float out[3]);
// scalar to colour along the map (blue, cyan, green, yellow, red) for t in [0, 1]
void tx_colour_map(float t, float rgb[3]);
// the procedural skin texture, size x size RGB (for tests and the renderer)
void tx_skin_texture(uint8_t* rgb, int size);

#endif
