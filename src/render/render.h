/* render.h: a scene on the GPU and the progressive sample passes that render it.
 *
 * Work is submitted as short dispatches of a few samples per pixel each (keeps a window
 * responsive, GPU watchdogs quiet, and lets an interrupted render write what it has; the
 * path kernel finishes in a later dispatch what llvmpipe's loop cap interrupts:
 * docs/architecture.md). Samples depend only on (pixel, sample, dimension, seed). */
#ifndef GONIO_RENDER_H
#define GONIO_RENDER_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "bvh.h"
#include "gpu.h"
#include "image.h"
#include "render_accum.h"
#include "render_geometry.h"
#include "render_gouraud.h"
#include "render_kernels.h"
#include "render_lights.h"
#include "render_modes.h"
#include "scene.h"

/* Progress reports of renderer_render, for a display (the command line's: src/cli/progress.c):
 * RENDER_PROGRESS_START before the first pass, RENDER_PROGRESS_BATCH after each batch of
 * passes, RENDER_PROGRESS_END once after the last (s->stop tells whether a stop ended it).
 * done: the samples per pixel taken so far; elapsed: seconds since the passes began (with a
 * time limit, the work done is the time, not the spp). */
typedef enum render_progress_event {
    RENDER_PROGRESS_START,
    RENDER_PROGRESS_BATCH,
    RENDER_PROGRESS_END,
} render_progress_event;
struct render_settings;
typedef void render_progress_fn(void *user, const struct render_settings *s,
                                render_progress_event event, int done, double elapsed);

/* What to render. A zero field is the default where one exists (mode path, seed 0, no AOVs,
 * shadows on, unbounded depth, a black environment, MIS, the whole image, no resume, no
 * progress); width, height and spp must be given, and camera (-1: frame the scene). */
typedef struct render_settings {
    uint32_t mode;          /* GN_MODE_* */
    int width, height;
    int spp;                /* samples per pixel */
    double time_limit;      /* > 0: stop after this many seconds (at least one pass) */
    uint32_t seed;
    uint32_t sampler;       /* path: GN_SAMPLER_* (0: Sobol) */
    int camera;             /* glTF camera index, -1 = frame the scene */
    uint32_t aov;           /* RENDER_AOV_* set: the extra channels to add */
    bool no_shadows;        /* local modes: no ray-traced shadows (false, the default: shadows) */
    int max_depth;          /* path tracer: 0 = unbounded (roulette only) */
    float env[3];           /* constant environment radiance */
    bool ambient_set;       /* local modes: ambient replaces the scene's global ambient light */
    float ambient[3];
    render_progress_fn *progress; /* NULL: no progress reports */
    void *progress_user;          /* progress's first argument */
    volatile sig_atomic_t *stop; /* set asynchronously to end after the current pass */
    const GnCamera *camera_override; /* non-NULL: this camera (aspect from the image), not `camera` */
    const scene_camera *view; /* non-NULL: this camera (aspect from the image), not `camera`
                               * (camera_resolve, src/scene/camera.h, makes it) */
    const char *camera_label; /* for headers: which camera, e.g. "camera 0 'Camera'" */
    const char *env_label;    /* for headers: "studio", a map's path, "constant" */
    const image *env_map;   /* path: lat-long radiance map (R, G, B or Y), replaces env */
    float env_rotation;     /* path: the map turned about +Y, degrees (right-handed) */
    uint32_t strategy;      /* path: 0 = MIS, GN_FRAME_LIGHT_ONLY or GN_FRAME_BSDF_ONLY */
    /* The region rendered: pixels [crop_x0, crop_x1) x [crop_y0, crop_y1) of the
     * width x height image, each exactly as the whole render has it; crop_x1 = 0: all. */
    int crop_x0, crop_y0, crop_x1, crop_y1;
    /* Non-NULL: go on from an earlier render of these settings: its sums (channels
     * RENDER_SUM_*, as renderer_sums writes them) of resume_spp samples are loaded and the
     * render takes samples resume_spp to spp - 1, so the result is that of one render of spp. */
    const image *resume;
    int resume_spp;
} render_settings;

/* The region s renders, {x0, y0, x1, y1}. */
void render_region(const render_settings *s, int region[4]);

typedef struct render_stats {
    int spp;                /* samples per pixel actually taken */
    double seconds;         /* rendering time (passes only) */
    double first_pass_seconds;
    double setup_seconds;   /* BVH build and upload */
    uint64_t rays;          /* camera rays traced (pixels * spp) */
    uint32_t truncated;     /* rays cut short by the traversal budget (path: 0, or a bug) */
    uint32_t resumes;       /* path: dispatches that only finished paths the loop cap interrupted */
    int bands;              /* horizontal bands the region was rendered in (1: one piece) */
} render_stats;

/* The renderer: a scene on the GPU and what renders it, as parts that own their state
 * (docs/architecture.md, src/render): the trees (render_geometry.h), the lights
 * (render_lights.h), the accumulation (render_accum.h), the kernels (render_kernels.h) and
 * Gouraud's vertex pass (render_gouraud.h); the renderer composes them, and the parts never
 * call it. Read its fields, write none. */
typedef struct renderer {
    gpu *g;
    const scene *sc;
    render_geometry geo;    /* the trees and the arrays the walk reads */
    render_lights lights;
    render_accum accum;     /* sized for the current image: accum.width x accum.height */
    render_kernels kernels;
    render_gouraud gouraud;
    /* the renderer's own buffers: the frame constants, the kernels' counters (status[0]:
     * truncated walks, status[1]: pixels pending past the loop cap), and the scene's arrays
     * as the kernels read them */
    gpu_buffer frame, status, nodes, tris, prims, vertices, materials, texels, textures, instances;
    GnFeatures material_features; /* GN_FEAT_* the materials need (renderer_create) */
    GnFeatures path_features;     /* ... and the current path render (renderer_begin) */
    uint32_t path_samples;  /* samples per path dispatch (1..GN_PATH_SAMPLES) */
    uint32_t sampler;       /* path: the current render's GN_SAMPLER_* */
    uint32_t loop_cap;      /* path: the kernel's LOOP_CAP (glsl/lib/bvh.glsl), 0 without a cap */
    uint32_t state_stride;  /* path: words a pixel of saved state (render_limits.h), 0 without a cap */
    double setup_seconds;
    bool failed;            /* renderer_create refused the scene: nothing renders */
} renderer;

/* Builds the BVH and uploads the scene. False (with an error naming the scene, the limit
 * and the numbers) when the scene's buffers exceed the device's limits; the renderer is then
 * marked failed, so that renderer_begin and renderer_render return false too. */
bool renderer_create(renderer *r, gpu *g, const scene *sc);
void renderer_destroy(renderer *r); /* accepts a zeroed struct */
/* sc is r's scene at another time of its animation: the same geometry and materials
 * (scene_same_geometry), other instance transforms, lights and cameras; r renders sc from
 * now on. Only the top tree over the instances is rebuilt (render_geometry_update), and the
 * lights and the light table are made again; the kernels stay. setup_seconds becomes the
 * time this took. False (the renderer then failed) when the tree cannot be built. */
bool renderer_update(renderer *r, const scene *sc);

/* The camera for settings->camera (or the framing one) as the GPU wants it. Returns false
 * (with an error) if the index is out of range. */
bool renderer_camera(const renderer *r, const render_settings *s, GnCamera *out);

/* Fills and uploads the frame constants for s; (re)allocates and clears the accumulation,
 * AOV and status buffers for s's region (the AOV and squares buffers only when s->aov asks
 * for them; 16-byte dummies otherwise). False (with an error) when the region needs more
 * than one buffer may hold: only renderer_render renders such a region, in bands. */
bool renderer_begin(renderer *r, const render_settings *s, GnFrame *frame);
/* The descriptor bindings of every render kernel (up to GN_BIND_COUNT entries), for a
 * command's own kernel over the renderer's buffers (gonio bench's). */
uint32_t renderer_bindings(const renderer *r, gpu_binding *out);
/* The specialisation of mode's kernel for r's scene and current render (no loop cap), for
 * such a kernel: render_kernels.h. */
const VkSpecializationInfo *renderer_specialize(const renderer *r, uint32_t mode, render_spec *spec);

/* The kernel of a mode (created on first use, kept until renderer_destroy or until its
 * specialisation changes), its descriptor set naming the renderer's current buffers. */
gpu_pipeline *renderer_pipeline(renderer *r, uint32_t mode);
/* Records one sample pass (sample `sample_index` in every pixel) and a barrier. Call
 * renderer_begin first. */
void renderer_record_samples(renderer *r, VkCommandBuffer cmd, uint32_t mode, uint32_t first,
                             uint32_t count);
/* After the submission of renderer_record_samples(..., first, count) has completed: the path
 * kernel's pixels left pending by llvmpipe's loop cap (glsl/kernels/path.comp) finished, by further
 * dispatches that take no new samples, so every pixel has all first + count samples. */
uint32_t renderer_finish(renderer *r, uint32_t mode, uint32_t next); /* returns the dispatches */
/* The accumulated image divided by spp: R, G, B, A and the AOV channels of the set aov
 * (RENDER_AOV_*; the GPU ones need a render with them, variance any). */
void renderer_resolve(renderer *r, int spp, uint32_t aov, image *out);
/* Appends the exact accumulation sums to out, the state --resume goes on from: sum.R/G/B/A
 * always, sum.normal.X/Y/Z, sum.albedo.R/G/B, sum.depth.Z with the GPU AOVs of aov, and
 * sum2.R/G/B (the squares) with variance; and sum.N, each pixel's sample count (spp), which
 * --resume checks against the header. The EXR keeps them as 32-bit floats. */
void renderer_sums(const renderer *r, int spp, uint32_t aov, image *out);

/* Renders and fills `out` with R, G, B, A (A = coverage) and the channels of the AOVs in
 * s->aov, in the order normal.X/Y/Z, albedo.R/G/B, depth.Z, variance.R/G/B. Each is the
 * mean over the pixel's samples, a miss counting 0 (so depth is 0 where nothing is hit).
 * A region whose accumulation buffers exceed the device's limits (gpu_storage_limit, half
 * the host heap, maxComputeWorkGroupCount[1]) is rendered in horizontal bands, each a crop
 * with the same bits: every batch of samples goes through all bands in turn (their sums
 * kept on the host), so --time, a stop and the progress act on whole rounds of bands. */
bool renderer_render(renderer *r, const render_settings *s, image *out, render_stats *stats);

#endif
