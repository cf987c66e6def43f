/* render_gouraud.h: Gouraud's vertex pass (glsl/kernels/vertex.comp): a colour per vertex and
 * side (GN_BIND_VCOLOR), lit once per frame, which --mode gouraud's pixels interpolate. */
#ifndef GONIO_RENDER_GOURAUD_H
#define GONIO_RENDER_GOURAUD_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu.h"
#include "render_geometry.h"
#include "scene.h"

typedef struct render_gouraud {
    gpu_buffer vcolor;      /* two vec4 a vertex; the first one's w holds its material */
    uint32_t count;         /* the vertices: the scene's, or every instance's copies */
    VkDeviceSize bytes;     /* their colours: more than a storage buffer holds when vcolor is a
                             * 16-byte dummy (then --mode gouraud is refused) */
    gpu_pipeline pass;      /* made on the first vertex pass */
    uint32_t bound;         /* the buffers' generation its descriptor set names */
} render_gouraud;

/* The buffer of Gouraud's colours for sc's vertices (with instances, every instance's copy). */
void render_gouraud_create(render_gouraud *v, gpu *g, const scene *sc, const render_geometry *geo);
void render_gouraud_destroy(render_gouraud *v, gpu *g); /* accepts a zeroed struct */
/* Lights every vertex for the frame just uploaded, the kernel bound to the renderer's
 * buffers b (of `generation`: rebound when it changes). False (with an error naming
 * scene_path) when the device cannot hold or dispatch the vertices. */
bool render_gouraud_light(render_gouraud *v, gpu *g, const char *scene_path, bool instances, const gpu_binding *b,
                          uint32_t num_bindings, uint32_t generation);

#endif
