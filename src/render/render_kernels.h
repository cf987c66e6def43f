/* render_kernels.h: the render modes' kernels as pipelines: each made on first use for its
 * specialisation, kept while that stays the same, and pointed at the renderer's current
 * buffers when some were made anew (a larger image, more lights, another map), which costs a
 * descriptor update, not a compile. */
#ifndef GONIO_RENDER_KERNELS_H
#define GONIO_RENDER_KERNELS_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu.h"
#include "render_modes.h"
#include "shared.h"

/* The specialisation constants of the render kernels (constant ids: glsl/lib/shared.h):
 * 0 the mode (or a kernel's own variant), GN_SPEC_FEATURES and GN_SPEC_FEATURES_HI the two
 * words of the GN_FEAT_* set it is built for, GN_SPEC_WALK_REGS, GN_SPEC_LOOP_CAP (the path
 * kernel's; 0 for the others), GN_SPEC_INSTANCES and GN_SPEC_SAMPLER (the path kernel's; 0
 * for the others). */
#define RENDER_SPEC_COUNT 7
typedef struct render_spec {
    uint32_t values[RENDER_SPEC_COUNT];
    VkSpecializationMapEntry entries[RENDER_SPEC_COUNT];
    VkSpecializationInfo info;
} render_spec;

/* What a kernel is specialised on: scene_features the GN_FEAT_* the scene and the render
 * need (the mode's kernel is built for those of them it specialises, every other one
 * compiled in). */
typedef struct render_kernel_key {
    uint32_t mode;
    GnFeatures scene_features;
    uint32_t walk_regs, loop_cap;
    bool instances;
    uint32_t sampler; /* GN_SAMPLER_* (the path kernel's) */
} render_kernel_key;

/* Fills spec for key and returns its VkSpecializationInfo (pointing into spec). */
const VkSpecializationInfo *render_kernel_specialize(const render_kernel_key *key, render_spec *spec);

typedef struct render_kernels {
    gpu_pipeline pipelines[GN_MODE_COUNT];
    uint32_t spec[GN_MODE_COUNT][RENDER_SPEC_COUNT]; /* what each kernel was built for */
    uint32_t bound[GN_MODE_COUNT];                   /* the buffers' generation its descriptor set names */
} render_kernels;

/* The kernel of key->mode for key, bound to the buffers b of `generation` (a count the
 * caller raises whenever it makes a buffer anew): made when there is none or it was built
 * for another specialisation, rebound when the generation changed. */
gpu_pipeline *render_kernels_get(render_kernels *k, gpu *g, const render_kernel_key *key, const gpu_binding *b,
                                 uint32_t num_bindings, uint32_t generation);
void render_kernels_destroy(render_kernels *k, gpu *g); /* accepts a zeroed struct */

#endif
