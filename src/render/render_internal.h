/* render_internal.h: how the renderer's files share its work (only src/render includes it;
 * the interface is render.h). A file per concern:
 *   render.c          the renderer: scene upload, frame constants, kernels and their
 *                     specialisation, the pass loop (renderer_render)
 *   render_modes.c    the registry of modes and the kernels they run
 *   render_lights.c   lights: the local modes' emissive lights, the path tracer's light
 *                     table and environment map sampling
 *   render_accum.c    accumulation: buffers and bands, resolve, sums and --resume
 *   render_limits.c   device limits and llvmpipe's loop cap
 *   render_gouraud.c  Gouraud's vertex pass
 *   render_material.c what the renderer derives from materials (features, --brdf overrides) */
#ifndef GONIO_RENDER_INTERNAL_H
#define GONIO_RENDER_INTERNAL_H

#include "render.h"

/* ---- render_modes.c ---------------------------------------------------------------------- */

/* The kernels the modes name. specialised: the GN_FEAT_* the kernel is built for as the
 * scene needs them (the others compiled in); the path kernel is specialised on all, the
 * local one only on what its lookups test per pixel (surfaces cut away: glsl/lib/bvh.glsl;
 * texture transforms and TEXCOORD_1: glsl/lib/scene.glsl). batched: it takes up to
 * renderer.path_samples samples a dispatch and is resumed past llvmpipe's loop cap (the
 * GN_SPEC_LOOP_CAP constant, renderer_finish); otherwise one sample a dispatch. */
typedef struct render_kernel {
    const char *name;
    const uint32_t *code;
    size_t code_size;
    GnFeatures specialised;
    bool batched;
} render_kernel;
const render_kernel *mode_kernel(uint32_t mode);

/* ---- render.c ---------------------------------------------------------------------------- */

/* The frame constants of s for the pixels `region` (no upload); false when the camera is bad. */
bool frame_setup(renderer *r, const render_settings *s, const int region[4], GnFrame *frame);

/* ---- render_lights.c --------------------------------------------------------------------- */

/* The local modes' lights of a scene without punctual lights: one per emissive material
 * (at most cap); returns how many. */
uint32_t emissive_lights(const scene *sc, GnLight *out, uint32_t cap);
/* The path tracer's light table without the environment (renderer_create). */
void build_emitters(renderer *r, const GnPrim *prims);
/* The path tracer's lights for s: the environment (a map uploaded when it is new) added to
 * the table, which is normalised and uploaded; frame's emitter and environment fields set,
 * *env the environment's selection weight (0: none). False (with an error) on a bad map. */
bool path_lights(renderer *r, const render_settings *s, GnFrame *frame, double *env);

/* ---- render_accum.c ---------------------------------------------------------------------- */

/* How many rows of a w x h region one set of accumulation buffers holds (0 with an error). */
int band_rows(const renderer *r, int w, int h, uint32_t aov, uint32_t mode, char *why, size_t why_size);
void size_buffers(renderer *r, int w, int h, uint32_t aov);
void free_bands(renderer *r);
bool begin_bands(renderer *r, const render_settings *s, const int region[4], int rows, GnFrame *frame);
void band_swap(renderer *r, GnFrame *frame, const int region[4], int rows, int b, bool load);
bool load_sums(renderer *r, const render_settings *s);

/* ---- render_limits.c --------------------------------------------------------------------- */

uint32_t path_samples(const renderer *r);
uint32_t traversal_budget(const gpu *g, uint32_t rays_per_invocation);
/* Texels of the sheen's albedo table at the head of the texel buffer (0 without layers). */
uint32_t sheen_prefix(const renderer *r);
bool scene_fits(renderer *r);
uint32_t walk_regs(const renderer *r);
uint32_t state_stride(const renderer *r, uint32_t mode);
void loop_setup(renderer *r, GnFrame *frame);

/* ---- render_gouraud.c -------------------------------------------------------------------- */

/* The buffer of Gouraud's colours (renderer_create). */
void vertex_colors_create(renderer *r);
bool light_vertices(renderer *r);

#endif
