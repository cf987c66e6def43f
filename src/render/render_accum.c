/* render_accum.c: where samples accumulate: the buffers of a region (sized within the
 * device's limits, or a render in bands with the sums kept on the host), the resolve into an
 * image with its AOVs, and the exact sums --resumable writes and --resume loads. */
#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"
#include "util.h"


/* Bytes per pixel of the accumulation buffers a render with the AOVs `aov` writes: accum
 * always, the GPU AOVs' buffer and the squares only when asked for. */
static VkDeviceSize aov_pixel_bytes(uint32_t aov) { return aov & RENDER_AOV_GPU ? 48 : 0; }
static VkDeviceSize squares_pixel_bytes(uint32_t aov) { return aov & RENDER_AOV_VARIANCE ? 16 : 0; }

/* How many rows of a w x h region one set of accumulation buffers holds within the device's
 * limits: each buffer within gpu_storage_limit, all of them within half the host heap (the
 * rest for the scene and the image), at most 8 maxComputeWorkGroupCount[1] rows and each row
 * within maxComputeWorkGroupCount[0] work groups. 0 (with an error naming the limit and the
 * numbers) when not even one row fits; *why (may be NULL) names what bounds it, else NULL. */
int band_rows(const renderer *r, int w, int h, uint32_t aov, uint32_t mode, char *why,
                     size_t why_size)
{
    const char *limit_name;
    const VkDeviceSize limit = gpu_storage_limit(r->g, &limit_name), heap = gpu_host_heap(r->g) / 2;
    const VkDeviceSize largest = aov_pixel_bytes(aov) > 16 ? aov_pixel_bytes(aov) : 16;
    const VkDeviceSize all = 16 + aov_pixel_bytes(aov) + squares_pixel_bytes(aov);
    const uint32_t groups_x = (uint32_t)(w + GN_TILE_X - 1) / GN_TILE_X;
    VkDeviceSize rows = limit / (largest * (VkDeviceSize)w);
    const VkDeviceSize heap_rows = heap / (all * (VkDeviceSize)w);
    const VkDeviceSize group_rows = (VkDeviceSize)gpu_max_groups(r->g, 1) * GN_TILE_Y;
    if (why)
        why[0] = 0;
    if (groups_x > gpu_max_groups(r->g, 0)) {
        util_error("%s: a row of %d pixels needs %u work groups, more than the %u this device "
                   "dispatches (maxComputeWorkGroupCount[0])", r->sc->path, w, groups_x,
                   gpu_max_groups(r->g, 0));
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
                     "maxComputeWorkGroupCount[1] (%u)", h, gpu_max_groups(r->g, 1));
    }
    /* The path kernel's saved paths (state_stride) are one more storage buffer, within the
     * device's own limit (GONIO_MAX_BUFFER_BYTES is for the accumulation buffers' bands). */
    const VkDeviceSize state = 4 * (VkDeviceSize)state_stride(r, mode) * (VkDeviceSize)w;
    VkDeviceSize state_limit = r->g->props.limits.maxStorageBufferRange;
    if (r->g->max_allocation && r->g->max_allocation < state_limit)
        state_limit = r->g->max_allocation;
    if (state && state_limit / state < rows) {
        rows = state_limit / state;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %llu-byte buffer of paths left for the next pass exceeds "
                     "the device's storage buffer range (%llu bytes)",
                     (unsigned long long)(state * (VkDeviceSize)h), (unsigned long long)state_limit);
    }
    if (rows == 0) {
        util_error("%s: a row of %d pixels needs %llu bytes of accumulation buffers, more than this "
                   "device allows (%s: %llu bytes; half the memory heap: %llu bytes)", r->sc->path, w,
                   (unsigned long long)(largest * (VkDeviceSize)w), limit_name,
                   (unsigned long long)limit, (unsigned long long)heap);
        return 0;
    }
    return rows < (VkDeviceSize)h ? (int)rows : h;
}


/* (Re)allocates the accumulation buffers for w x h pixels: accum always, the AOV and squares
 * buffers only when the render writes them (16-byte dummies otherwise: every descriptor
 * must name a buffer). A buffer is kept while it holds the pixels and is at most twice the
 * size needed, so the bands of a tiled render share one set. */
void size_buffers(renderer *r, int w, int h, uint32_t aov)
{
    const VkDeviceSize pixels = (VkDeviceSize)w * h;
    gpu_buffer *bufs[4] = {&r->accum, &r->aov, &r->squares, &r->pstate};
    const VkDeviceSize need[4] = {16 * pixels, aov_pixel_bytes(aov) ? aov_pixel_bytes(aov) * pixels : 16,
                                  squares_pixel_bytes(aov) ? squares_pixel_bytes(aov) * pixels : 16,
                                  r->state_stride ? 4 * (VkDeviceSize)r->state_stride * pixels : 16};
    bool changed = false;
    for (int i = 0; i < 4; i++) {
        if (bufs[i]->buffer && bufs[i]->size >= need[i] && bufs[i]->size / 2 <= need[i])
            continue;
        gpu_buffer_destroy(r->g, bufs[i]);
        gpu_buffer_create(r->g, bufs[i], need[i], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        assert(bufs[i]->mapped); /* resolve, resume and bands read and write them directly */
        changed = true;
    }
    if (changed && getenv("GONIO_DEBUG_BUFFERS")) /* tests/regress/limits.sh */
        fprintf(stderr, "gonio: debug: buffers for %dx%d: accum %llu, aov %llu, squares %llu bytes\n",
                w, h, (unsigned long long)r->accum.size, (unsigned long long)r->aov.size,
                (unsigned long long)r->squares.size);
    r->width = w;
    r->height = h;
    if (changed) /* the cached kernels' descriptor sets name the old buffers */
        renderer_buffers_replaced(r);
}


/* The host copies of a render in bands (renderer_render). */
void free_bands(renderer *r)
{
    free(r->band_accum);
    free(r->band_aov);
    free(r->band_squares);
    r->band_accum = r->band_aov = r->band_squares = NULL;
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

static sums_at sums_of(const renderer *r)
{
    if (r->band_accum)
        return (sums_at){r->band_accum, r->band_aov, r->band_squares, r->region_width, r->region_height};
    return (sums_at){r->accum.mapped, r->aov.mapped, r->squares.mapped, r->width, r->height};
}

/* aov_offset: where the AOV is in each pixel's 12 floats of the aov buffer (GN_BIND_AOV). */
static void add_gpu_aov(const renderer *r, int spp, const char *const *names, int n, int aov_offset, image *out)
{
    const sums_at at = sums_of(r);
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
static void add_variance(const renderer *r, int spp, image *out)
{
    static const char *const names[] = {"variance.R", "variance.G", "variance.B"};
    const sums_at at = sums_of(r);
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

void renderer_resolve(renderer *r, int spp, uint32_t aov, image *out)
{
    static const char *const names[] = {"R", "G", "B", "A"};
    static const char *const normal[] = {"normal.X", "normal.Y", "normal.Z"};
    static const char *const albedo[] = {"albedo.R", "albedo.G", "albedo.B"};
    static const char *const depth[] = {"depth.Z"};
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *acc = at.accum;
    float inv = 1.0f / (float)spp;
    image_create(out, at.width, at.height, 4, names);
    for (VkDeviceSize p = 0; p < pixels; p++)
        for (int c = 0; c < 4; c++)
            out->planes[c][p] = acc[4 * p + c] * inv;
    if (aov & RENDER_AOV_NORMAL)
        add_gpu_aov(r, spp, normal, 3, 0, out);
    if (aov & RENDER_AOV_ALBEDO)
        add_gpu_aov(r, spp, albedo, 3, 4, out);
    if (aov & RENDER_AOV_DEPTH)
        add_gpu_aov(r, spp, depth, 1, 8, out);
    if (aov & RENDER_AOV_VARIANCE)
        add_variance(r, spp, out);
}

/* The channels of renderer_sums: name, buffer (0 accum, 1 aov, 2 squares), float offset
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

static float *sum_buffer(const renderer *r, int buffer, int *stride)
{
    const sums_at at = sums_of(r);
    *stride = buffer == 1 ? 12 : 4;
    return buffer == 0 ? at.accum : buffer == 1 ? at.aov : at.squares;
}

void renderer_sums(const renderer *r, int spp, uint32_t aov, image *out)
{
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    float *n = add_channel(out, "sum.N");
    for (VkDeviceSize p = 0; p < pixels; p++)
        n[p] = (float)spp; /* exact: spp <= 2^24 */
    for (size_t k = 0; k < sizeof sum_channels / sizeof *sum_channels; k++) {
        const struct sum_channel *c = &sum_channels[k];
        int stride;
        const float *buf = sum_buffer(r, c->buffer, &stride);
        float *plane;
        if (c->aov && !(aov & c->aov))
            continue;
        plane = add_channel(out, c->name);
        for (VkDeviceSize p = 0; p < pixels; p++)
            plane[p] = buf[(VkDeviceSize)stride * p + (VkDeviceSize)c->offset];
    }
}

/* Loads the sums of s->resume into the freshly cleared buffers; false (with an error) when
 * a channel the render needs is missing or the size differs. */
bool load_sums(renderer *r, const render_settings *s)
{
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    if (s->resume->width != at.width || s->resume->height != at.height) {
        util_error("--resume: the file's %dx%d pixels are not the %dx%d region rendered",
                   s->resume->width, s->resume->height, at.width, at.height);
        return false;
    }
    for (size_t k = 0; k < sizeof sum_channels / sizeof *sum_channels; k++) {
        const struct sum_channel *c = &sum_channels[k];
        int stride, ch;
        float *buf = sum_buffer(r, c->buffer, &stride);
        if (c->aov && !(s->aov & c->aov))
            continue;
        if ((ch = image_channel(s->resume, c->name)) < 0) {
            util_error("--resume: the file has no channel '%s' (not written with --resumable, or "
                       "with other --aov)", c->name);
            return false;
        }
        for (VkDeviceSize p = 0; p < pixels; p++)
            buf[(VkDeviceSize)stride * p + (VkDeviceSize)c->offset] = s->resume->planes[ch][p];
    }
    return true;
}

/* A render in bands of `rows` rows: the frame and buffers for the first band (the others
 * share them), and the whole region's sums on the host, zeroed. */
bool begin_bands(renderer *r, const render_settings *s, const int region[4], int rows,
                        GnFrame *frame)
{
    const int rw = region[2] - region[0], rh = region[3] - region[1];
    const size_t pixels = (size_t)rw * (size_t)rh;
    free_bands(r);
    if (!frame_setup(r, s, region, frame))
        return false;
    size_buffers(r, rw, rows, s->aov);
    gpu_buffer_fill_zero(r->g, &r->pstate);
    gpu_buffer_fill_zero(r->g, &r->status);
    r->band_accum = util_calloc(4 * pixels, sizeof(float));
    if (s->aov & RENDER_AOV_GPU)
        r->band_aov = util_calloc(12 * pixels, sizeof(float));
    if (s->aov & RENDER_AOV_VARIANCE)
        r->band_squares = util_calloc(4 * pixels, sizeof(float));
    r->region_width = rw;
    r->region_height = rh;
    return !(render_modes[s->mode].flags & GN_MODEF_VERTEX_LIGHT) || light_vertices(r);
}

/* Band b's frame uploaded and its sums (host) copied into the buffers (load), or the
 * buffers' sums copied back to the host (!load). */
void band_swap(renderer *r, GnFrame *frame, const int region[4], int rows, int b, bool load)
{
    const int y0 = b * rows, rh = region[3] - region[1], bh = rh - y0 < rows ? rh - y0 : rows;
    const size_t first = (size_t)r->region_width * (size_t)y0, n = (size_t)r->region_width * (size_t)bh;
    struct { float *host; gpu_buffer *buf; size_t floats; } parts[3] = {
        {r->band_accum, &r->accum, 4}, {r->band_aov, &r->aov, 12}, {r->band_squares, &r->squares, 4}};
    if (load) {
        frame->crop_y = (uint32_t)(region[1] + y0);
        frame->crop_height = (uint32_t)bh;
        gpu_buffer_upload(r->g, &r->frame, frame, sizeof *frame, 0);
        r->height = bh; /* the dispatch's rows; the buffers hold `rows` */
    }
    for (int i = 0; i < 3; i++) {
        float *host = parts[i].host ? parts[i].host + parts[i].floats * first : NULL;
        if (host && load)
            memcpy(parts[i].buf->mapped, host, parts[i].floats * sizeof(float) * n);
        else if (host)
            memcpy(host, parts[i].buf->mapped, parts[i].floats * sizeof(float) * n);
    }
}
