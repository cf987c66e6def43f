/* render_modes.h: the render modes (glsl/lib/shared.h: GN_MODES) as the host reads them, and
 * the kernels they run. Adding a mode: docs/architecture.md. */
#ifndef GONIO_RENDER_MODES_H
#define GONIO_RENDER_MODES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared.h"

/* A mode, indexed by GN_MODE_*. */
typedef struct render_mode_info {
    const char *name; /* --mode's */
    const char *help; /* a line */
    uint32_t kernel;  /* GN_KERNEL_* */
    uint32_t flags;   /* GN_MODEF_* */
} render_mode_info;
extern const render_mode_info render_modes[GN_MODE_COUNT];

/* Name <-> GN_MODE_* ("path", "phong", ...); -1 when unknown. */
int render_mode_from_name(const char *name);
const char *render_mode_name(uint32_t mode);
/* Comma-separated list of every mode name, for messages. */
const char *render_mode_list(void);
/* A line per mode, "name  help", for --mode's help. */
const char *render_mode_help(void);

/* The samplers (glsl/lib/shared.h: GN_SAMPLERS), as the modes: an index or -1, a name
 * ("?" out of range), "a, b" and the help lines. */
int render_sampler_from_name(const char *name);
const char *render_sampler_name(uint32_t sampler);
const char *render_sampler_list(void);
const char *render_sampler_help(void);

/* The kernels the modes name. specialised: the GN_FEAT_* the kernel is built for as the
 * scene needs them (the others compiled in); the path kernel is specialised on all, the
 * local one only on what its lookups test per pixel (surfaces cut away: glsl/lib/bvh.glsl;
 * texture transforms and TEXCOORD_1: glsl/lib/scene.glsl). batched: it takes several
 * samples a dispatch (renderer.path_samples) and is resumed past llvmpipe's loop cap (the
 * GN_SPEC_LOOP_CAP constant, renderer_finish); otherwise one sample a dispatch. */
typedef struct render_kernel {
    const char *name;
    const uint32_t *code;
    size_t code_size;
    GnFeatures specialised;
    bool batched;
} render_kernel;
const render_kernel *render_mode_kernel(uint32_t mode);

#endif
