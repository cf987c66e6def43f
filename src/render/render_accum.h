/* render_accum.h: where a render's samples accumulate. The buffers of a region (sized within
 * the device's limits; a region beyond them is rendered in bands, the whole region's sums
 * kept on the host between bands), the resolve into an image with its AOVs, and the exact
 * sums that --resumable writes and --resume loads. The kernels add each sample to the sums
 * in sample order (glsl/kernels/path.comp), so the bits do not depend on how passes, bands
 * or runs split the samples. */
#ifndef GONIO_RENDER_ACCUM_H
#define GONIO_RENDER_ACCUM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gpu.h"
#include "image.h"
#include "shared.h"

/* The AOVs (extra EXR channels) a render can add. Normal, albedo and depth come from one
 * GPU pass (GN_FRAME_AOV) whichever of them is asked for; none asked costs nothing. */
#define RENDER_AOV_NORMAL 1u   /* normal.X/Y/Z: world-space shading normal */
#define RENDER_AOV_ALBEDO 2u   /* albedo.R/G/B: base colour */
#define RENDER_AOV_DEPTH 4u    /* depth.Z: distance along the camera axis, 0 on a miss */
#define RENDER_AOV_VARIANCE 8u /* variance.R/G/B: the estimated variance of each pixel's mean */
#define RENDER_AOV_GPU (RENDER_AOV_NORMAL | RENDER_AOV_ALBEDO | RENDER_AOV_DEPTH)
/* "normal", "albedo", "depth", "variance" -> RENDER_AOV_*; 0 when unknown. */
uint32_t render_aov_from_name(const char *name);
/* Every AOV's name, ", "-separated. */
const char *render_aov_list(void);

typedef struct render_accum {
    /* GN_BIND_ACCUM (16 bytes a pixel), GN_BIND_AOV (48, with the GPU AOVs), GN_BIND_SQUARES
     * (16, with variance) and, for the path kernel under a loop cap, GN_BIND_PSTATE (the
     * paths left pending: 4 x state_stride bytes a pixel); 16-byte dummies where unused */
    gpu_buffer accum, aov, squares, pstate;
    int width, height;      /* the pixels a dispatch covers: the region's, or a band's */
    /* A render in bands: the whole region's sums on the host, which resolve and sums read
     * instead of the buffers; NULL otherwise. */
    float *band_accum, *band_aov, *band_squares;
    int region_width, region_height;
    uint32_t replaced;      /* buffers made anew so far: kernels bound to the old ones rebind */
} render_accum;

/* How many rows of a w x h region one set of buffers holds within the device's limits
 * (the saved paths of state_stride words a pixel included); 0 with an error naming
 * scene_path, the limit and the numbers when not even one row fits. *why (may be NULL)
 * names what bounds it when rows < h. */
int render_accum_rows(const gpu *g, const char *scene_path, int w, int h, uint32_t aov, uint32_t state_stride,
                      char *why, size_t why_size);
/* (Re)allocates the buffers for w x h pixels (kept while they hold them and are at most
 * twice the size needed, so the bands of a render share one set) and clears them. */
void render_accum_begin(render_accum *a, gpu *g, int w, int h, uint32_t aov, uint32_t state_stride);
/* A render in bands of `rows` rows over a rw x rh region: the buffers for one band (cleared)
 * and the whole region's sums on the host, zeroed. */
void render_accum_begin_bands(render_accum *a, gpu *g, int rw, int rh, int rows, uint32_t aov, uint32_t state_stride);
/* The host sums of the bh rows from y0 copied into the buffers (load), or the buffers' sums
 * copied back to the host (!load). */
void render_accum_band_swap(render_accum *a, int y0, int bh, bool load);
void render_accum_destroy(render_accum *a, gpu *g); /* accepts a zeroed struct */

/* The accumulated image divided by spp: R, G, B, A and the AOV channels of the set aov
 * (the GPU ones need a render with them, variance any). */
void render_accum_resolve(const render_accum *a, int spp, uint32_t aov, image *out);
/* Appends the exact sums to out: sum.N (each pixel's sample count, spp), sum.R/G/B/A, the
 * GPU AOVs' sum.normal.X/Y/Z, sum.albedo.R/G/B, sum.depth.Z and variance's sum2.R/G/B as aov
 * asks. */
void render_accum_sums(const render_accum *a, int spp, uint32_t aov, image *out);
/* Loads the sums of `from` (render_accum_sums' channels of aov) into the freshly cleared
 * sums; false (with an error) when a channel is missing or the size differs. */
bool render_accum_load(render_accum *a, const image *from, uint32_t aov);

#endif
