/* cmd_merge.c: `gonio merge`: renders of one scene with different seeds, or tiles of it
 * (--crop: placed by their EXR data windows) -> one image, each
 * pixel the mean of all N = sum n_i samples (sum n_i x_i / N), so the result is the render
 * of N spp. Variance channels combine through the sums of squares they imply:
 * sum x^2 = n (v (n - 1) + m^2) for a file's mean m and variance of the mean v.
 *
 * Only samples of one image can be averaged: the inputs' identity attributes
 * (render_identity_names, written by render) must be equal, their seeds all different and
 * their sample counts positive integers whose sum fits the header's int. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "image.h"
#include "render_output.h"
#include "util.h"

/* The channel whose mean a variance channel describes ("variance.R" -> "R"), or NULL. */
static const char *variance_of(const char *name)
{
    return strncmp(name, "variance.", 9) == 0 ? name + 9 : NULL;
}

/* The whole frame a file's pixels are part of (its display window). */
static int frame_width(const image *img) { return img->full_width ? img->full_width : img->width; }
static int frame_height(const image *img) { return img->full_width ? img->full_height : img->height; }

/* sum.* and sum2.*: a --resumable render's exact sums, state for --resume, not merged. */
static bool is_sum(const char *name) { return !strncmp(name, "sum.", 4) || !strncmp(name, "sum2.", 5); }

static int pixel_channels(const image *img)
{
    int n = 0;
    for (int c = 0; c < img->num_channels; c++)
        n += !is_sum(img->names[c]);
    return n;
}

/* Frame pixel (x, y) is in img's data window. */
static bool inside(const image *img, int x, int y)
{
    return x >= img->x0 && y >= img->y0 && x < img->x0 + img->width && y < img->y0 + img->height;
}

static bool overlap(const image *a, const image *b)
{
    return a->x0 < b->x0 + b->width && b->x0 < a->x0 + a->width && a->y0 < b->y0 + b->height &&
           b->y0 < a->y0 + a->height;
}

/* Every value of the channels that are merged is finite: a NaN or Inf would spread into the
 * result unseen. False, with an error naming the file, channel, pixel and count, if not. */
static bool finite_pixels(const char *path, const image *img)
{
    for (int c = 0; c < img->num_channels; c++) {
        const size_t n = (size_t)img->width * (size_t)img->height;
        size_t bad = 0, first = 0;
        if (is_sum(img->names[c]))
            continue;
        for (size_t p = 0; p < n; p++)
            if (!isfinite(img->planes[c][p]) && bad++ == 0)
                first = p;
        if (bad) {
            util_error("%s: channel '%s' has %zu NaN or infinite value(s), the first at pixel (%d, %d); "
                       "a render writes none", path, img->names[c], bad, img->x0 + (int)(first % (size_t)img->width),
                       img->y0 + (int)(first / (size_t)img->width));
            return false;
        }
    }
    return true;
}

/* The file's sample count: a finite positive integer no larger than INT32_MAX. */
static bool read_spp(const char *path, int64_t *out)
{
    double v;
    if (!image_exr_attr_double(path, "gonio:spp", &v)) {
        util_error("%s: no gonio:spp sample count in the header (not a gonio render?)", path);
        return false;
    }
    if (!(v >= 1 && v <= INT32_MAX && v == floor(v))) {
        util_error("%s: gonio:spp %g is not a sample count (a positive integer up to %d)", path, v, INT32_MAX);
        return false;
    }
    *out = (int64_t)v;
    return true;
}

typedef struct seed_list {
    uint32_t *seed;
    int *file;      /* the input each seed came from */
    int count, cap;
    bool complete;  /* every input said its seeds */
} seed_list;

static void add_seed(seed_list *l, uint32_t seed, int file)
{
    if (l->count == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 16;
        l->seed = util_realloc(l->seed, sizeof *l->seed * (size_t)l->cap);
        l->file = util_realloc(l->file, sizeof *l->file * (size_t)l->cap);
    }
    l->seed[l->count] = seed;
    l->file[l->count++] = file;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The sorted seeds of the inputs marked in `in`, into out; their count. */
static int covering_seeds(const seed_list *l, const unsigned char *in, uint32_t *out)
{
    int k = 0;
    for (int i = 0; i < l->count; i++)
        if (in[l->file[i]])
            out[k++] = l->seed[i];
    qsort(out, (size_t)k, sizeof *out, cmp_u32);
    return k;
}

/* A file's seeds: gonio:seeds (a merge's list) or gonio:seed (a render's); false when the
 * header has neither or a malformed one. */
static bool read_seeds(const char *path, int file, seed_list *l)
{
    char text[4096], *end;
    uint32_t seed;
    if (image_exr_attr_string(path, "gonio:seeds", text, sizeof text)) {
        for (const char *p = text; *p; p = *end ? end + 1 : end) {
            unsigned long long x = strtoull(p, &end, 10);
            if (end == p || (*end && *end != ',') || x > UINT32_MAX)
                return false;
            add_seed(l, (uint32_t)x, file);
        }
        return true;
    }
    if (render_header_seed(path, &seed)) {
        add_seed(l, seed, file);
        return true;
    }
    return false;
}

/* The identity attributes of a and b agree (absent in both counts as equal). */
static bool same_render(const char *a, const char *b)
{
    for (int k = 0; render_identity_names[k]; k++) {
        char va[512] = "", vb[512] = "";
        bool ha = image_exr_attr_string(a, render_identity_names[k], va, sizeof va);
        bool hb = image_exr_attr_string(b, render_identity_names[k], vb, sizeof vb);
        if (ha != hb || strcmp(va, vb)) {
            util_error("%s and %s are not one render: %s differs (%s%s%s vs %s%s%s)", a, b,
                       render_identity_names[k], ha ? "'" : "", ha ? va : "absent", ha ? "'" : "",
                       hb ? "'" : "", hb ? vb : "absent", hb ? "'" : "");
            return false;
        }
    }
    return true;
}

#define MERGE_INTRO \
    "Combines renders of the same scene and settings made with different --seed values\n" \
    "into one, weighted by each file's sample count (its gonio:spp header): the result is\n" \
    "exactly the mean of all the samples, with gonio:spp their total. variance.R/G/B\n" \
    "channels are merged exactly too.\n" \
    "\n" \
    "Inputs rendered with --crop are placed by their EXR data windows: tiles assemble into\n" \
    "the frame (or the region they cover), and at every pixel the inputs covering it are\n" \
    "combined; every pixel must get the same number of samples (no holes, no uneven\n" \
    "overlaps). The sum.* channels of --resumable renders are left out. Denoised renders\n" \
    "(render --denoise, gonio denoise) are refused: their pixels are no mean of samples.\n" \
    "\n" \
    "The inputs must be one render: the same frame size and channels, and the same gonio:scene\n" \
    "(a hash of the scene's content), gonio:size, gonio:mode, gonio:camera and options of the\n" \
    "mode (gonio:max-depth, gonio:estimator, gonio:env, gonio:shadows, gonio:ambient); each\n" \
    "gonio:spp a positive integer, their total at most 2147483647. Anything else is an error\n" \
    "naming both files and the field (exit 1, no output). A seed used twice in inputs that\n" \
    "overlap is an error too (its samples repeat and add nothing) unless --force. The output\n" \
    "records every seed in gonio:seeds, so merged files merge again.\n"

int cmd_merge(int argc, char **argv)
{
    const char *out_path = NULL, **inputs;
    int n, rc = 1;
    bool force = false;
    image *imgs = NULL, out = {0};
    image_exr_options exr = IMAGE_EXR_DEFAULTS;
    const cli_option options[] = {
        {"-o, --output", "FILE", "the merged OpenEXR (a .exr name; written atomically)", CLI_STRING, CLI_AS(const char *, &out_path),
         0, 0, NULL, NULL, "*.exr"},
        {"--force", NULL, "merge inputs that share a seed", CLI_FLAG, CLI_AS(bool, &force), 0, 0, NULL, NULL, NULL},
        CLI_OPT_EXR_HALF(&exr.half),
        CLI_OPT_EXR_COMPRESSION(&exr.compression),
    };
    const cli_command cmd = {
        .name = "merge", .synopsis = "A.exr B.exr ... -o OUT.exr [--force] [--half] [--compression C]",
        .intro = MERGE_INTRO, CLI_OPTIONS(options), .max_args = -1, .complete_args = "*.exr"};
    cli_args args;
    if ((rc = cli_parse(&cmd, argc, argv, &args)) >= 0)
        return rc;
    rc = 1;
    n = args.num_args;
    inputs = util_calloc((size_t)n + 1, sizeof *inputs);
    int64_t *spp = NULL, total = 0;
    double seconds = 0;
    seed_list seeds = {.complete = true};
    char *seed_text = NULL;

    for (int i = 0; i < n; i++)
        inputs[i] = args.arg[i];
    if (!out_path || n < 1) {
        free(inputs);
        return cli_usage_error("merge", out_path ? "no input files" : "no output given (-o OUT.exr)");
    }
    if (image_format_of(out_path) != IMAGE_FORMAT_EXR) {
        free(inputs);
        return cli_usage_error("merge", "-o '%s': merge writes OpenEXR: expected a .exr name", out_path);
    }
    if (!util_check_output(out_path)) {
        free(inputs);
        return 1;
    }

    imgs = util_calloc((size_t)n, sizeof *imgs);
    spp = util_calloc((size_t)n, sizeof *spp);
    for (int i = 0; i < n; i++) {
        double s;
        if (!image_read_exr(&imgs[i], inputs[i]) || !read_spp(inputs[i], &spp[i]))
            goto done;
        {
            /* A denoised file's R, G, B are no mean of samples (render --denoise, gonio denoise). */
            char dn[256];
            if (image_exr_attr_string(inputs[i], "gonio:denoiser", dn, sizeof dn)) {
                util_error("%s: is denoised (gonio:denoiser '%s'): its R, G, B are not a mean of samples; merge "
                           "renders made without --denoise, then denoise the merge (gonio denoise)", inputs[i], dn);
                goto done;
            }
        }
        if (!image_inside_frame(&imgs[i])) {
            util_error("%s: its data window (%d,%d)+%dx%d lies outside its %dx%d display window: not a tile "
                       "of a render", inputs[i], imgs[i].x0, imgs[i].y0, imgs[i].width, imgs[i].height,
                       imgs[i].full_width, imgs[i].full_height);
            goto done;
        }
        if (!finite_pixels(inputs[i], &imgs[i]))
            goto done;
        if (frame_width(&imgs[i]) != frame_width(&imgs[0]) || frame_height(&imgs[i]) != frame_height(&imgs[0]) ||
            pixel_channels(&imgs[i]) != pixel_channels(&imgs[0])) {
            util_error("%s: a %dx%d frame with %d channels, but %s is %dx%d with %d", inputs[i],
                       frame_width(&imgs[i]), frame_height(&imgs[i]), pixel_channels(&imgs[i]), inputs[0],
                       frame_width(&imgs[0]), frame_height(&imgs[0]), pixel_channels(&imgs[0]));
            goto done;
        }
        for (int c = 0; c < imgs[0].num_channels; c++)
            if (!is_sum(imgs[0].names[c]) && image_channel(&imgs[i], imgs[0].names[c]) < 0) {
                util_error("%s: has no channel '%s' (which %s has)", inputs[i], imgs[0].names[c], inputs[0]);
                goto done;
            }
        if (i > 0 && !same_render(inputs[0], inputs[i]))
            goto done;
        if (!read_seeds(inputs[i], i, &seeds))
            seeds.complete = false;
        if (image_exr_attr_double(inputs[i], "gonio:seconds", &s))
            seconds += s;
        total += spp[i]; /* each <= INT32_MAX: int64 cannot overflow for any argc */
        if (total > INT32_MAX) {
            util_error("%s: the total sample count reaches %lld, more than the header's int holds (%d)",
                       inputs[i], (long long)total, INT32_MAX);
            goto done;
        }
    }
    /* A seed may repeat in tiles that do not overlap; in overlapping ones its samples repeat.
     * With --force, one warning for all the repeats, not one per pair. */
    {
        long repeats = 0;
        int fa = 0, fb = 0;
        uint32_t first_seed = 0;
        for (int a = 0; a < seeds.count; a++)
            for (int b = 0; b < a; b++)
                if (seeds.seed[a] == seeds.seed[b] && overlap(&imgs[seeds.file[a]], &imgs[seeds.file[b]]) &&
                    repeats++ == 0) {
                    fa = seeds.file[b];
                    fb = seeds.file[a];
                    first_seed = seeds.seed[a];
                }
        if (repeats && !force) {
            util_error("%s and %s: both have seed %u: its samples repeat and add no information "
                       "(--force merges anyway)", inputs[fa], inputs[fb], first_seed);
            goto done;
        }
        if (repeats)
            util_warn("%ld pair(s) of overlapping inputs share a seed, the first %s and %s (seed %u): merged "
                      "(--force)", repeats, inputs[fa], inputs[fb], first_seed);
    }

    {
        const char *names[IMAGE_MAX_CHANNELS];
        int nc = 0, box[4] = {INT32_MAX, INT32_MAX, 0, 0}; /* the union of the data windows */
        int64_t *covered;
        unsigned char *in = util_calloc((size_t)n, 1), *first_in = util_calloc((size_t)n, 1);
        unsigned char *last_in = util_calloc((size_t)n, 1);
        uint32_t *first_seeds = util_calloc((size_t)seeds.count + 1, sizeof *first_seeds);
        uint32_t *pixel_seeds = util_calloc((size_t)seeds.count + 1, sizeof *pixel_seeds);
        int first_count = 0;
        bool hole = false; /* the tiles leave a hole: refused after the scratch arrays are freed */
        for (int c = 0; c < imgs[0].num_channels; c++)
            if (!is_sum(imgs[0].names[c]))
                names[nc++] = imgs[0].names[c];
        for (int i = 0; i < n; i++) {
            box[0] = imgs[i].x0 < box[0] ? imgs[i].x0 : box[0];
            box[1] = imgs[i].y0 < box[1] ? imgs[i].y0 : box[1];
            box[2] = imgs[i].x0 + imgs[i].width > box[2] ? imgs[i].x0 + imgs[i].width : box[2];
            box[3] = imgs[i].y0 + imgs[i].height > box[3] ? imgs[i].y0 + imgs[i].height : box[3];
        }
        image_create(&out, box[2] - box[0], box[3] - box[1], nc, names);
        if (out.width != frame_width(&imgs[0]) || out.height != frame_height(&imgs[0])) {
            out.x0 = box[0];
            out.y0 = box[1];
            out.full_width = frame_width(&imgs[0]);
            out.full_height = frame_height(&imgs[0]);
        }
        /* Every pixel must have the same sample count, gonio:spp: each has all the tiles'
         * samples or the merge would be a patchwork of images of different noise. */
        covered = util_calloc((size_t)out.width * out.height, sizeof *covered);
        for (int y = 0; y < out.height; y++)
            for (int x = 0; x < out.width; x++) {
                int64_t *cv = &covered[(size_t)y * out.width + x];
                for (int i = 0; i < n; i++) {
                    in[i] = inside(&imgs[i], box[0] + x, box[1] + y);
                    *cv += in[i] ? spp[i] : 0;
                }
                if (x == 0 && y == 0) {
                    memcpy(first_in, in, (size_t)n);
                    first_count = covering_seeds(&seeds, in, first_seeds);
                    memcpy(last_in, in, (size_t)n);
                } else if (seeds.complete && memcmp(last_in, in, (size_t)n)) {
                    /* other inputs here (tiles): the same seeds, or no one list for the file */
                    int k = covering_seeds(&seeds, in, pixel_seeds);
                    if (k != first_count || memcmp(pixel_seeds, first_seeds, sizeof *pixel_seeds * (size_t)k))
                        seeds.complete = false;
                    memcpy(last_in, in, (size_t)n);
                }
                if (*cv != covered[0]) {
                    util_error("%s: pixel (%d, %d) has %lld samples in the inputs, but pixel (%d, %d) %lld: "
                               "the tiles leave a hole or overlap unevenly", out_path, box[0] + x, box[1] + y,
                               (long long)*cv, box[0], box[1], (long long)covered[0]);
                    hole = true;
                    goto scratch;
                }
            }
        total = covered[0];
        for (int k = seeds.count - 1; seeds.complete && k >= 0; k--)
            if (!first_in[seeds.file[k]]) { /* only the seeds of the inputs that cover a pixel */
                memmove(&seeds.seed[k], &seeds.seed[k + 1], sizeof *seeds.seed * (size_t)(seeds.count - k - 1));
                memmove(&seeds.file[k], &seeds.file[k + 1], sizeof *seeds.file * (size_t)(seeds.count - k - 1));
                seeds.count--;
            }
    scratch:
        free(covered);
        free(in);
        free(first_in);
        free(last_in);
        free(first_seeds);
        free(pixel_seeds);
        if (hole)
            goto done;
        for (int c = 0; c < out.num_channels; c++) {
            const char *of = variance_of(names[c]);
            bool var = of && image_channel(&imgs[0], of) >= 0;
            for (int y = 0; y < out.height; y++)
                for (int x = 0; x < out.width; x++) {
                    double sum = 0, sq = 0;
                    for (int i = 0; i < n; i++) {
                        int fx = box[0] + x - imgs[i].x0, fy = box[1] + y - imgs[i].y0;
                        size_t p = (size_t)fy * imgs[i].width + fx;
                        double w = (double)spp[i], xv;
                        if (!inside(&imgs[i], box[0] + x, box[1] + y))
                            continue;
                        xv = imgs[i].planes[image_channel(&imgs[i], names[c])][p];
                        if (var) { /* back to the sums of x and x^2 of this file */
                            double m = imgs[i].planes[image_channel(&imgs[i], of)][p];
                            sum += w * m;
                            sq += w * (xv * (w - 1) + m * m);
                        } else {
                            sum += w * xv;
                        }
                    }
                    float *o = &out.planes[c][(size_t)y * out.width + x];
                    if (var) {
                        double N = (double)total, m = sum / N, v = total > 1 ? (sq / N - m * m) / (N - 1) : 0;
                        *o = v > 0 ? (float)v : 0;
                    } else {
                        *o = (float)(sum / (double)total);
                    }
                }
        }
    }
    {
        /* The identity of the first input (all are equal), then the merge's own. */
        enum { MAX_ID = 16 };
        image_attr attrs[MAX_ID + 5];
        char values[MAX_ID][512];
        int na = 0;
        for (int k = 0; render_identity_names[k] && k < MAX_ID; k++)
            if (image_exr_attr_string(inputs[0], render_identity_names[k], values[na], sizeof values[0])) {
                attrs[na] = (image_attr){render_identity_names[k], IMAGE_ATTR_STRING, values[na], 0, 0, NULL};
                na++;
            }
        attrs[na++] = (image_attr){"gonio:spp", IMAGE_ATTR_INT, NULL, (int)total, 0, NULL};
        if (seeds.complete) {
            size_t len = 0;
            seed_text = util_malloc(12 * (size_t)seeds.count + 1);
            seed_text[0] = 0;
            for (int k = 0; k < seeds.count; k++)
                len += (size_t)sprintf(seed_text + len, "%s%u", k ? "," : "", seeds.seed[k]);
            attrs[na++] = (image_attr){"gonio:seeds", IMAGE_ATTR_STRING, seed_text, 0, 0, NULL};
        }
        attrs[na++] = (image_attr){"gonio:seconds", IMAGE_ATTR_DOUBLE, NULL, 0, seconds, NULL};
        attrs[na++] = (image_attr){"gonio:command", IMAGE_ATTR_STRING, cli_command_line(), 0, 0, NULL};
        attrs[na++] = (image_attr){"gonio:version", IMAGE_ATTR_STRING, GONIO_VERSION, 0, 0, NULL};
        if (image_write_exr_with(&out, out_path, attrs, na, &exr))
            rc = 0;
    }
done:
    for (int i = 0; i < n && imgs; i++)
        image_destroy(&imgs[i]);
    image_destroy(&out);
    free(imgs);
    free(spp);
    free(inputs);
    free(seeds.seed);
    free(seeds.file);
    free(seed_text);
    return rc;
}
