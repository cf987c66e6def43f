/* render_limits.h: what the device allows and how a render keeps within it: the scene's
 * buffers against the texel buffer limit, and llvmpipe's loop cap (the samples a path
 * dispatch takes, the walk budget of a ray, the path kernel's loop cap and saved state)
 * with the walk's stack. Functions of the device and the scene's trees only. The
 * accumulation buffers' limits are render_accum.h's (render_accum_rows). */
#ifndef GONIO_RENDER_LIMITS_H
#define GONIO_RENDER_LIMITS_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu.h"
#include "render_geometry.h"
#include "scene.h"

/* llvmpipe (lavapipe) ends an invocation's loops silently after 65,535 iterations; real
 * GPUs have no such cap. */
bool render_loop_capped(const gpu *g);

/* How many samples one invocation of the path kernel takes per dispatch, 1 to GN_PATH_SAMPLES. */
uint32_t render_path_samples(const gpu *g, const render_geometry *geo);

/* The per-ray walk budget of the local modes' kernels (unbounded without a loop cap). */
uint32_t render_traversal_budget(const gpu *g, uint32_t rays_per_invocation);

/* The walk's stack in registers: the tree's depth for trees of at most GN_WALK_REGS_MAX
 * levels, else 0 (in memory; GONIO_WALK_ARRAY=1 forces it). The GN_SPEC_WALK_REGS constant. */
uint32_t render_walk_regs(const render_geometry *geo);

/* Words a pixel of the path kernel's saved state takes under a loop cap, 0 without one. */
uint32_t render_state_stride(const gpu *g, const render_geometry *geo);

/* The path kernel's loop cap (GN_SPEC_LOOP_CAP) for a saved state of state_stride words (0:
 * no cap), the same for every render of the process; sets frame->loop_overhead (from its
 * light table and environment map) and frame->state_stride. */
uint32_t render_loop_setup(uint32_t state_stride, GnFrame *frame);

/* The scene's buffers against the device's texel buffer limit, before any is made:
 * sheen_texels ahead of the texture images in the texel buffer, light_room the light
 * table's triangle entries at most (render_lights_room). False with an error naming the
 * scene, the buffer and the numbers. */
bool render_scene_fits(const gpu *g, const scene *sc, const render_geometry *geo, uint32_t sheen_texels,
                       uint64_t light_room);

#endif
