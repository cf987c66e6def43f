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

/* The inputs of a merge, as read (read_input). */
typedef struct merge_inputs {
    int n;
    char **path;    /* the command line's names */
    image *img;
    int64_t *spp;
    seed_list seeds;
    double seconds; /* their gonio:seconds, summed */
} merge_inputs;

/* Reads input i and checks it alone and against input 0: a gonio render's sample count, not
 * denoised, its data window inside its frame, finite pixels, input 0's frame and channels,
 * the same render (same_render); its seeds into in->seeds (complete false when it says none)
 * and its sample count into *total, which must fit the header's int. */
static bool read_input(merge_inputs *in, int i, int64_t *total)
{
    const char *path = in->path[i], *first = in->path[0];
    const image *img = &in->img[i], *img0 = &in->img[0];
    char dn[256];
    double s;
    if (!image_read_exr(&in->img[i], path) || !read_spp(path, &in->spp[i]))
        return false;
    /* A denoised file's R, G, B are no mean of samples (render --denoise, gonio denoise). */
    if (image_exr_attr_string(path, "gonio:denoiser", dn, sizeof dn)) {
        util_error("%s: is denoised (gonio:denoiser '%s'): its R, G, B are not a mean of samples; merge "
                   "renders made without --denoise, then denoise the merge (gonio denoise)", path, dn);
        return false;
    }
    if (!image_inside_frame(img)) {
        util_error("%s: its data window (%d,%d)+%dx%d lies outside its %dx%d display window: not a tile "
                   "of a render", path, img->x0, img->y0, img->width, img->height, img->full_width,
                   img->full_height);
        return false;
    }
    if (!finite_pixels(path, img))
        return false;
    if (frame_width(img) != frame_width(img0) || frame_height(img) != frame_height(img0) ||
        pixel_channels(img) != pixel_channels(img0)) {
        util_error("%s: a %dx%d frame with %d channels, but %s is %dx%d with %d", path, frame_width(img),
                   frame_height(img), pixel_channels(img), first, frame_width(img0), frame_height(img0),
                   pixel_channels(img0));
        return false;
    }
    for (int c = 0; c < img0->num_channels; c++)
        if (!is_sum(img0->names[c]) && image_channel(img, img0->names[c]) < 0) {
            util_error("%s: has no channel '%s' (which %s has)", path, img0->names[c], first);
            return false;
        }
    if (i > 0 && !same_render(first, path))
        return false;
    if (!read_seeds(path, i, &in->seeds))
        in->seeds.complete = false;
    if (image_exr_attr_double(path, "gonio:seconds", &s))
        in->seconds += s;
    *total += in->spp[i]; /* each <= INT32_MAX: int64 cannot overflow for any argc */
    if (*total > INT32_MAX) {
        util_error("%s: the total sample count reaches %lld, more than the header's int holds (%d)", path,
                   (long long)*total, INT32_MAX);
        return false;
    }
    return true;
}

/* A seed may repeat in tiles that do not overlap; in overlapping ones its samples repeat: an
 * error, or with force one warning for all the repeats, not one per pair. */
static bool check_seeds(const merge_inputs *in, bool force)
{
    const seed_list *l = &in->seeds;
    long repeats = 0;
    int fa = 0, fb = 0;
    uint32_t first_seed = 0;
    for (int a = 0; a < l->count; a++)
        for (int b = 0; b < a; b++)
            if (l->seed[a] == l->seed[b] && overlap(&in->img[l->file[a]], &in->img[l->file[b]]) && repeats++ == 0) {
                fa = l->file[b];
                fb = l->file[a];
                first_seed = l->seed[a];
            }
    if (repeats && !force) {
        util_error("%s and %s: both have seed %u: its samples repeat and add no information "
                   "(--force merges anyway)", in->path[fa], in->path[fb], first_seed);
        return false;
    }
    if (repeats)
        util_warn("%ld pair(s) of overlapping inputs share a seed, the first %s and %s (seed %u): merged "
                  "(--force)", repeats, in->path[fa], in->path[fb], first_seed);
    return true;
}

/* The merge's image: the union of the inputs' data windows (box: x0, y0, x1, y1 in the frame),
 * placed in their frame unless it is the whole frame, with their channels but the sums. */
static void create_output(image *out, int box[4], const merge_inputs *in)
{
    const image *img0 = &in->img[0];
    const char *names[IMAGE_MAX_CHANNELS];
    int nc = 0;
    box[0] = box[1] = INT32_MAX;
    box[2] = box[3] = 0;
    for (int c = 0; c < img0->num_channels; c++)
        if (!is_sum(img0->names[c]))
            names[nc++] = img0->names[c];
    for (int i = 0; i < in->n; i++) {
        const image *img = &in->img[i];
        box[0] = img->x0 < box[0] ? img->x0 : box[0];
        box[1] = img->y0 < box[1] ? img->y0 : box[1];
        box[2] = img->x0 + img->width > box[2] ? img->x0 + img->width : box[2];
        box[3] = img->y0 + img->height > box[3] ? img->y0 + img->height : box[3];
    }
    image_create(out, box[2] - box[0], box[3] - box[1], nc, names);
    if (out->width != frame_width(img0) || out->height != frame_height(img0)) {
        out->x0 = box[0];
        out->y0 = box[1];
        out->full_width = frame_width(img0);
        out->full_height = frame_height(img0);
    }
}

/* Every pixel of out must have the same sample count: each has all the tiles' samples or the
 * merge would be a patchwork of images of different noise (an error naming out_path
 * otherwise). *total: that count. The seeds: complete only when every pixel's inputs have
 * the same ones, then reduced to those of the inputs that cover a pixel. */
static bool check_coverage(merge_inputs *in, const image *out, const int box[4], const char *out_path,
                           int64_t *total)
{
    seed_list *l = &in->seeds;
    const int n = in->n;
    int64_t *covered = util_calloc((size_t)out->width * out->height, sizeof *covered);
    unsigned char *inside_now = util_calloc((size_t)n, 1), *first_in = util_calloc((size_t)n, 1);
    unsigned char *last_in = util_calloc((size_t)n, 1);
    uint32_t *first_seeds = util_calloc((size_t)l->count + 1, sizeof *first_seeds);
    uint32_t *pixel_seeds = util_calloc((size_t)l->count + 1, sizeof *pixel_seeds);
    int first_count = 0;
    bool even = true;
    for (int y = 0; y < out->height && even; y++)
        for (int x = 0; x < out->width && even; x++) {
            int64_t *cv = &covered[(size_t)y * out->width + x];
            for (int i = 0; i < n; i++) {
                inside_now[i] = inside(&in->img[i], box[0] + x, box[1] + y);
                *cv += inside_now[i] ? in->spp[i] : 0;
            }
            if (x == 0 && y == 0) {
                memcpy(first_in, inside_now, (size_t)n);
                first_count = covering_seeds(l, inside_now, first_seeds);
                memcpy(last_in, inside_now, (size_t)n);
            } else if (l->complete && memcmp(last_in, inside_now, (size_t)n)) {
                /* other inputs here (tiles): the same seeds, or no one list for the file */
                int k = covering_seeds(l, inside_now, pixel_seeds);
                if (k != first_count || memcmp(pixel_seeds, first_seeds, sizeof *pixel_seeds * (size_t)k))
                    l->complete = false;
                memcpy(last_in, inside_now, (size_t)n);
            }
            if (*cv != covered[0]) {
                util_error("%s: pixel (%d, %d) has %lld samples in the inputs, but pixel (%d, %d) %lld: "
                           "the tiles leave a hole or overlap unevenly", out_path, box[0] + x, box[1] + y,
                           (long long)*cv, box[0], box[1], (long long)covered[0]);
                even = false;
            }
        }
    *total = covered[0];
    for (int k = l->count - 1; even && l->complete && k >= 0; k--)
        if (!first_in[l->file[k]]) { /* only the seeds of the inputs that cover a pixel */
            memmove(&l->seed[k], &l->seed[k + 1], sizeof *l->seed * (size_t)(l->count - k - 1));
            memmove(&l->file[k], &l->file[k + 1], sizeof *l->file * (size_t)(l->count - k - 1));
            l->count--;
        }
    free(covered);
    free(inside_now);
    free(first_in);
    free(last_in);
    free(first_seeds);
    free(pixel_seeds);
    return even;
}

/* Each pixel of out the mean of the total samples of the inputs covering it; a variance
 * channel through the sums of x and x^2 its file's mean and variance imply. */
static void merge_pixels(image *out, const int box[4], const merge_inputs *in, int64_t total)
{
    for (int c = 0; c < out->num_channels; c++) {
        const char *name = out->names[c], *of = variance_of(name);
        bool var = of && image_channel(&in->img[0], of) >= 0;
        for (int y = 0; y < out->height; y++)
            for (int x = 0; x < out->width; x++) {
                double sum = 0, sq = 0;
                for (int i = 0; i < in->n; i++) {
                    const image *img = &in->img[i];
                    int fx = box[0] + x - img->x0, fy = box[1] + y - img->y0;
                    size_t p = (size_t)fy * img->width + fx;
                    double w = (double)in->spp[i], xv;
                    if (!inside(img, box[0] + x, box[1] + y))
                        continue;
                    xv = img->planes[image_channel(img, name)][p];
                    if (var) { /* back to the sums of x and x^2 of this file */
                        double m = img->planes[image_channel(img, of)][p];
                        sum += w * m;
                        sq += w * (xv * (w - 1) + m * m);
                    } else {
                        sum += w * xv;
                    }
                }
                float *o = &out->planes[c][(size_t)y * out->width + x];
                if (var) {
                    double N = (double)total, m = sum / N, v = total > 1 ? (sq / N - m * m) / (N - 1) : 0;
                    *o = v > 0 ? (float)v : 0;
                } else {
                    *o = (float)(sum / (double)total);
                }
            }
    }
}

/* Writes out with the identity of the first input (all are equal), then the merge's own:
 * gonio:spp total, every seed (when the inputs said them all), the sampler (when all said
 * the same one), the seconds summed. */
static bool write_merge(const image *out, const char *out_path, const merge_inputs *in, int64_t total,
                        const image_exr_options *exr)
{
    enum { MAX_ID = 16 };
    image_attr attrs[MAX_ID + 6];
    char values[MAX_ID][512], *seed_text = NULL, sampler[64] = "";
    int na = 0;
    for (int k = 0; render_identity_names[k] && k < MAX_ID; k++)
        if (image_exr_attr_string(in->path[0], render_identity_names[k], values[na], sizeof values[0])) {
            attrs[na] = (image_attr){render_identity_names[k], IMAGE_ATTR_STRING, values[na], 0, 0, NULL};
            na++;
        }
    attrs[na++] = (image_attr){"gonio:spp", IMAGE_ATTR_INT, NULL, (int)total, 0, NULL};
    if (in->seeds.complete) {
        size_t len = 0;
        seed_text = util_malloc(12 * (size_t)in->seeds.count + 1);
        seed_text[0] = 0;
        for (int k = 0; k < in->seeds.count; k++)
            len += (size_t)sprintf(seed_text + len, "%s%u", k ? "," : "", in->seeds.seed[k]);
        attrs[na++] = (image_attr){"gonio:seeds", IMAGE_ATTR_STRING, seed_text, 0, 0, NULL};
    }
    bool same_sampler = image_exr_attr_string(in->path[0], "gonio:sampler", sampler, sizeof sampler);
    for (int i = 1; i < in->n && same_sampler; i++) {
        char other[64];
        same_sampler = image_exr_attr_string(in->path[i], "gonio:sampler", other, sizeof other) && !strcmp(other, sampler);
    }
    if (same_sampler)
        attrs[na++] = (image_attr){"gonio:sampler", IMAGE_ATTR_STRING, sampler, 0, 0, NULL};
    attrs[na++] = (image_attr){"gonio:seconds", IMAGE_ATTR_DOUBLE, NULL, 0, in->seconds, NULL};
    attrs[na++] = (image_attr){"gonio:command", IMAGE_ATTR_STRING, cli_command_line(), 0, 0, NULL};
    attrs[na++] = (image_attr){"gonio:version", IMAGE_ATTR_STRING, GONIO_VERSION, 0, 0, NULL};
    bool ok = image_write_exr_with(out, out_path, attrs, na, exr);
    free(seed_text);
    return ok;
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
    const char *out_path = NULL;
    bool force = false;
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
    int rc = cli_parse(&cmd, argc, argv, &args);
    if (rc >= 0)
        return rc;
    if (!out_path || args.num_args < 1)
        return cli_usage_error("merge", out_path ? "no input files" : "no output given (-o OUT.exr)");
    if (image_format_of(out_path) != IMAGE_FORMAT_EXR)
        return cli_usage_error("merge", "-o '%s': merge writes OpenEXR: expected a .exr name", out_path);
    if (!util_check_output(out_path))
        return 1;

    merge_inputs in = {.n = args.num_args, .path = args.arg, .seeds = {.complete = true}};
    image out = {0};
    int box[4];
    int64_t total = 0;
    bool ok = true;
    in.img = util_calloc((size_t)in.n, sizeof *in.img);
    in.spp = util_calloc((size_t)in.n, sizeof *in.spp);
    for (int i = 0; i < in.n && ok; i++)
        ok = read_input(&in, i, &total);
    ok = ok && check_seeds(&in, force);
    if (ok) {
        create_output(&out, box, &in);
        ok = check_coverage(&in, &out, box, out_path, &total);
    }
    if (ok) {
        merge_pixels(&out, box, &in, total);
        ok = write_merge(&out, out_path, &in, total, &exr);
    }
    for (int i = 0; i < in.n; i++)
        image_destroy(&in.img[i]);
    image_destroy(&out);
    free(in.img);
    free(in.spp);
    free(in.seeds.seed);
    free(in.seeds.file);
    return ok ? 0 : 1;
}
