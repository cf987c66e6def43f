/* render_accum.c: where samples accumulate (render_accum.h). */
#include "render_accum.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"


/* Bytes per pixel of the accumulation buffers a render with the AOVs `aov` writes: accum
 * always, the GPU AOVs' buffer and the squares only when asked for. */
static VkDeviceSize aov_pixel_bytes(uint32_t aov) { return aov & RENDER_AOV_GPU ? 48 : 0; }
static VkDeviceSize squares_pixel_bytes(uint32_t aov) { return aov & RENDER_AOV_VARIANCE ? 16 : 0; }

/* Each buffer within gpu_storage_limit, all of them within half the host heap (the rest for
 * the scene and the image), at most 8 maxComputeWorkGroupCount[1] rows and each row within
 * maxComputeWorkGroupCount[0] work groups; the saved paths within the device's own storage
 * buffer range. */
int render_accum_rows(const gpu *g, const char *scene_path, int w, int h, uint32_t aov, uint32_t state_stride,
                      char *why, size_t why_size)
{
    const char *limit_name;
    const VkDeviceSize limit = gpu_storage_limit(g, &limit_name), heap = gpu_host_heap(g) / 2;
    const VkDeviceSize largest = aov_pixel_bytes(aov) > 16 ? aov_pixel_bytes(aov) : 16;
    const VkDeviceSize all = 16 + aov_pixel_bytes(aov) + squares_pixel_bytes(aov);
    const uint32_t groups_x = (uint32_t)(w + GN_TILE_X - 1) / GN_TILE_X;
    VkDeviceSize rows = limit / (largest * (VkDeviceSize)w);
    const VkDeviceSize heap_rows = heap / (all * (VkDeviceSize)w);
    const VkDeviceSize group_rows = (VkDeviceSize)gpu_max_groups(g, 1) * GN_TILE_Y;
    if (why)
        why[0] = 0;
    if (groups_x > gpu_max_groups(g, 0)) {
        util_error("%s: a row of %d pixels needs %u work groups, more than the %u this device "
                   "dispatches (maxComputeWorkGroupCount[0])", scene_path, w, groups_x,
                   gpu_max_groups(g, 0));
        return 0;
    }
    if (rows < (VkDeviceSize)h && why)
        snprintf(why, why_size, "its %llu-byte %s buffer exceeds the device's %s (%llu bytes)",
                 (unsigned long long)(largest * (VkDeviceSize)w * (VkDeviceSize)h),
                 largest > 16 ? "AOV" : "accumulation", limit_name, (unsigned long long)limit);
    if (heap_rows < rows) {
        rows = heap_rows;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %llu bytes of accumulation buffers exceed half the "
                     "device's memory heap (%llu bytes)",
                     (unsigned long long)(all * (VkDeviceSize)w * (VkDeviceSize)h),
                     (unsigned long long)heap);
    }
    if (group_rows < rows) {
        rows = group_rows;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %d rows need more work groups than the device's "
                     "maxComputeWorkGroupCount[1] (%u)", h, gpu_max_groups(g, 1));
    }
    /* The path kernel's saved paths (state_stride) are one more storage buffer, within the
     * device's own limit (GONIO_MAX_BUFFER_BYTES is for the accumulation buffers' bands). */
    const VkDeviceSize state = 4 * (VkDeviceSize)state_stride * (VkDeviceSize)w;
    VkDeviceSize state_limit = g->props.limits.maxStorageBufferRange;
    if (g->max_allocation && g->max_allocation < state_limit)
        state_limit = g->max_allocation;
    if (state && state_limit / state < rows) {
        rows = state_limit / state;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %llu-byte buffer of paths left for the next pass exceeds "
                     "the device's storage buffer range (%llu bytes)",
                     (unsigned long long)(state * (VkDeviceSize)h), (unsigned long long)state_limit);
    }
    if (rows == 0) {
        util_error("%s: a row of %d pixels needs %llu bytes of accumulation buffers, more than this "
                   "device allows (%s: %llu bytes; half the memory heap: %llu bytes)", scene_path, w,
                   (unsigned long long)(largest * (VkDeviceSize)w), limit_name,
                   (unsigned long long)limit, (unsigned long long)heap);
        return 0;
    }
    return rows < (VkDeviceSize)h ? (int)rows : h;
}


/* (Re)allocates the buffers for w x h pixels: accum always, the AOV and squares buffers only
 * when the render writes them, pstate with a saved state (16-byte dummies otherwise: every
 * descriptor must name a buffer). A buffer is kept while it holds the pixels and is at most
 * twice the size needed, so the bands of a tiled render share one set. */
static void size_buffers(render_accum *a, gpu *g, int w, int h, uint32_t aov, uint32_t state_stride)
{
    const VkDeviceSize pixels = (VkDeviceSize)w * h;
    gpu_buffer *bufs[4] = {&a->accum, &a->aov, &a->squares, &a->pstate};
    const VkDeviceSize need[4] = {16 * pixels, aov_pixel_bytes(aov) ? aov_pixel_bytes(aov) * pixels : 16,
                                  squares_pixel_bytes(aov) ? squares_pixel_bytes(aov) * pixels : 16,
                                  state_stride ? 4 * (VkDeviceSize)state_stride * pixels : 16};
    bool changed = false;
    for (int i = 0; i < 4; i++) {
        if (bufs[i]->buffer && bufs[i]->size >= need[i] && bufs[i]->size / 2 <= need[i])
            continue;
        gpu_buffer_destroy(g, bufs[i]);
        gpu_buffer_create(g, bufs[i], need[i], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        assert(bufs[i]->mapped); /* resolve, resume and bands read and write them directly */
        changed = true;
    }
    if (changed && getenv("GONIO_DEBUG_BUFFERS")) /* tests/regress/limits.sh */
        fprintf(stderr, "gonio: debug: buffers for %dx%d: accum %llu, aov %llu, squares %llu bytes\n",
                w, h, (unsigned long long)a->accum.size, (unsigned long long)a->aov.size,
                (unsigned long long)a->squares.size);
    a->width = w;
    a->height = h;
    if (changed) /* the cached kernels' descriptor sets name the old buffers */
        a->replaced++;
}

/* The host copies of a render in bands. */
static void free_bands(render_accum *a)
{
    free(a->band_accum);
    free(a->band_aov);
    free(a->band_squares);
    a->band_accum = a->band_aov = a->band_squares = NULL;
}

void render_accum_begin(render_accum *a, gpu *g, int w, int h, uint32_t aov, uint32_t state_stride)
{
    free_bands(a);
    size_buffers(a, g, w, h, aov, state_stride);
    gpu_buffer_fill_zero(g, &a->accum);
    gpu_buffer_fill_zero(g, &a->aov);
    gpu_buffer_fill_zero(g, &a->squares);
    gpu_buffer_fill_zero(g, &a->pstate);
}

void render_accum_destroy(render_accum *a, gpu *g)
{
    if (g) {
        gpu_buffer_destroy(g, &a->accum);
        gpu_buffer_destroy(g, &a->aov);
        gpu_buffer_destroy(g, &a->squares);
        gpu_buffer_destroy(g, &a->pstate);
    }
    free_bands(a);
    memset(a, 0, sizeof *a);
}

/* The AOVs' names, in the order of their RENDER_AOV_* bits. */
static const char *const aov_names[] = {"normal", "albedo", "depth", "variance"};

uint32_t render_aov_from_name(const char *name)
{
    for (uint32_t i = 0; i < 4; i++)
        if (!strcmp(name, aov_names[i]))
            return 1u << i;
    return 0;
}

const char *render_aov_list(void)
{
    static char list[64];
    return list[0] ? list : util_join(list, sizeof list, aov_names, 4);
}

/* Appends one zeroed channel and returns its plane. */
static float *add_channel(image *out, const char *name)
{
    const size_t pixels = (size_t)out->width * (size_t)out->height;
    assert(out->num_channels < IMAGE_MAX_CHANNELS);
    snprintf(out->names[out->num_channels], sizeof out->names[0], "%s", name);
    return out->planes[out->num_channels++] = util_calloc(pixels, sizeof(float));
}

/* Where a render's sums are: its buffers, or the host copies of a render in bands. */
typedef struct sums_at {
    float *accum, *aov, *squares;
    int width, height;
} sums_at;

static sums_at sums_of(const render_accum *a)
{
    if (a->band_accum)
        return (sums_at){a->band_accum, a->band_aov, a->band_squares, a->region_width, a->region_height};
    return (sums_at){a->accum.mapped, a->aov.mapped, a->squares.mapped, a->width, a->height};
}

/* aov_offset: where the AOV is in each pixel's 12 floats of the aov buffer (GN_BIND_AOV). */
static void add_gpu_aov(const render_accum *a, int spp, const char *const *names, int n, int aov_offset, image *out)
{
    const sums_at at = sums_of(a);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *aovs = at.aov;
    float inv = 1.0f / (float)spp;
    for (int c = 0; c < n; c++) {
        float *plane = add_channel(out, names[c]);
        for (VkDeviceSize p = 0; p < pixels; p++)
            plane[p] = aovs[12 * p + (VkDeviceSize)(aov_offset + c)] * inv;
    }
}

/* Appends variance.R/G/B: the unbiased variance estimate of each pixel's mean,
 * (sum x^2 / n - mean^2) / (n - 1) (0 for n = 1), from the sums of squares. */
static void add_variance(const render_accum *a, int spp, image *out)
{
    static const char *const names[] = {"variance.R", "variance.G", "variance.B"};
    const sums_at at = sums_of(a);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *acc = at.accum, *sq = at.squares;
    for (int c = 0; c < 3; c++) {
        float *plane = add_channel(out, names[c]);
        for (VkDeviceSize p = 0; spp > 1 && p < pixels; p++) {
            double m = (double)acc[4 * p + c] / spp, v = ((double)sq[4 * p + c] / spp - m * m) / (spp - 1);
            plane[p] = v > 0 ? (float)v : 0;
        }
    }
}

void render_accum_resolve(const render_accum *a, int spp, uint32_t aov, image *out)
{
    static const char *const names[] = {"R", "G", "B", "A"};
    static const char *const normal[] = {"normal.X", "normal.Y", "normal.Z"};
    static const char *const albedo[] = {"albedo.R", "albedo.G", "albedo.B"};
    static const char *const depth[] = {"depth.Z"};
    const sums_at at = sums_of(a);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *acc = at.accum;
    float inv = 1.0f / (float)spp;
    image_create(out, at.width, at.height, 4, names);
    for (VkDeviceSize p = 0; p < pixels; p++)
        for (int c = 0; c < 4; c++)
            out->planes[c][p] = acc[4 * p + c] * inv;
    if (aov & RENDER_AOV_NORMAL)
        add_gpu_aov(a, spp, normal, 3, 0, out);
    if (aov & RENDER_AOV_ALBEDO)
        add_gpu_aov(a, spp, albedo, 3, 4, out);
    if (aov & RENDER_AOV_DEPTH)
        add_gpu_aov(a, spp, depth, 1, 8, out);
    if (aov & RENDER_AOV_VARIANCE)
        add_variance(a, spp, out);
}

/* The channels of render_accum_sums: name, buffer (0 accum, 1 aov, 2 squares), float offset
 * in a pixel's entry of that buffer, and the AOV bit that needs it (0: always). */
static const struct sum_channel {
    const char *name;
    int buffer, offset;
    uint32_t aov;
} sum_channels[] = {
    {"sum.R", 0, 0, 0}, {"sum.G", 0, 1, 0}, {"sum.B", 0, 2, 0}, {"sum.A", 0, 3, 0},
    {"sum.normal.X", 1, 0, RENDER_AOV_NORMAL}, {"sum.normal.Y", 1, 1, RENDER_AOV_NORMAL},
    {"sum.normal.Z", 1, 2, RENDER_AOV_NORMAL}, {"sum.albedo.R", 1, 4, RENDER_AOV_ALBEDO},
    {"sum.albedo.G", 1, 5, RENDER_AOV_ALBEDO}, {"sum.albedo.B", 1, 6, RENDER_AOV_ALBEDO},
    {"sum.depth.Z", 1, 8, RENDER_AOV_DEPTH}, {"sum2.R", 2, 0, RENDER_AOV_VARIANCE},
    {"sum2.G", 2, 1, RENDER_AOV_VARIANCE}, {"sum2.B", 2, 2, RENDER_AOV_VARIANCE},
};

static float *sum_buffer(const render_accum *a, int buffer, int *stride)
{
    const sums_at at = sums_of(a);
    *stride = buffer == 1 ? 12 : 4;
    return buffer == 0 ? at.accum : buffer == 1 ? at.aov : at.squares;
}

void render_accum_sums(const render_accum *a, int spp, uint32_t aov, image *out)
{
    const sums_at at = sums_of(a);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    float *n = add_channel(out, "sum.N");
    for (VkDeviceSize p = 0; p < pixels; p++)
        n[p] = (float)spp; /* exact: spp <= 2^24 */
    for (size_t k = 0; k < sizeof sum_channels / sizeof *sum_channels; k++) {
        const struct sum_channel *c = &sum_channels[k];
        int stride;
        const float *buf = sum_buffer(a, c->buffer, &stride);
        float *plane;
        if (c->aov && !(aov & c->aov))
            continue;
        plane = add_channel(out, c->name);
        for (VkDeviceSize p = 0; p < pixels; p++)
            plane[p] = buf[(VkDeviceSize)stride * p + (VkDeviceSize)c->offset];
    }
}

bool render_accum_load(render_accum *a, const image *from, uint32_t aov)
{
    const sums_at at = sums_of(a);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    if (from->width != at.width || from->height != at.height) {
        util_error("--resume: the file's %dx%d pixels are not the %dx%d region rendered",
                   from->width, from->height, at.width, at.height);
        return false;
    }
    for (size_t k = 0; k < sizeof sum_channels / sizeof *sum_channels; k++) {
        const struct sum_channel *c = &sum_channels[k];
        int stride, ch;
        float *buf = sum_buffer(a, c->buffer, &stride);
        if (c->aov && !(aov & c->aov))
            continue;
        if ((ch = image_channel(from, c->name)) < 0) {
            util_error("--resume: the file has no channel '%s' (not written with --resumable, or "
                       "with other --aov)", c->name);
            return false;
        }
        for (VkDeviceSize p = 0; p < pixels; p++)
            buf[(VkDeviceSize)stride * p + (VkDeviceSize)c->offset] = from->planes[ch][p];
    }
    return true;
}

void render_accum_begin_bands(render_accum *a, gpu *g, int rw, int rh, int rows, uint32_t aov, uint32_t state_stride)
{
    const size_t pixels = (size_t)rw * (size_t)rh;
    free_bands(a);
    size_buffers(a, g, rw, rows, aov, state_stride);
    gpu_buffer_fill_zero(g, &a->pstate);
    a->band_accum = util_calloc(4 * pixels, sizeof(float));
    if (aov & RENDER_AOV_GPU)
        a->band_aov = util_calloc(12 * pixels, sizeof(float));
    if (aov & RENDER_AOV_VARIANCE)
        a->band_squares = util_calloc(4 * pixels, sizeof(float));
    a->region_width = rw;
    a->region_height = rh;
}

void render_accum_band_swap(render_accum *a, int y0, int bh, bool load)
{
    const size_t first = (size_t)a->region_width * (size_t)y0, n = (size_t)a->region_width * (size_t)bh;
    struct { float *host; gpu_buffer *buf; size_t floats; } parts[3] = {
        {a->band_accum, &a->accum, 4}, {a->band_aov, &a->aov, 12}, {a->band_squares, &a->squares, 4}};
    if (load)
        a->height = bh; /* the dispatch's rows; the buffers hold the band's */
    for (int i = 0; i < 3; i++) {
        float *host = parts[i].host ? parts[i].host + parts[i].floats * first : NULL;
        if (host && load)
            memcpy(parts[i].buf->mapped, host, parts[i].floats * sizeof(float) * n);
        else if (host)
            memcpy(host, parts[i].buf->mapped, parts[i].floats * sizeof(float) * n);
    }
}
