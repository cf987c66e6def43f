/* cmd_render.c: `gonio render`. */
#include <assert.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "brdf.h"
#include "camera.h"
#include "cli.h"
#include "denoise.h"
#include "environment.h"
#include "image.h"
#include "progress.h"
#include "render.h"
#include "render_material.h"
#include "render_output.h"
#include "scene.h"
#include "util.h"

static volatile sig_atomic_t stop_requested; /* the signal that asked, 0 = none */
static bool signal_quiet;

/* The first SIGINT or SIGTERM ends the render after the current pass (what it has is
 * written, and the exit status is 128 + the signal); a second one ends the program at once,
 * removing the temporary file of a write under way. Only async-signal-safe calls here. */
static void on_signal(int sig)
{
    static const char msg[] = "\ngonio: stopping after this pass (interrupt again to quit now)\n";
    if (stop_requested) {
        util_remove_pending_tmp();
        _exit(128 + sig);
    }
    stop_requested = sig;
    if (!signal_quiet && write(2, msg, sizeof msg - 1) < 0)
        return;
}

/* --frames' file-name patterns: exactly one %d, %Nd or %0Nd, N at most FRAME_WIDTH_MAX, and
 * no other '%'. */
#define FRAME_WIDTH_MAX 16

static bool frame_pattern(const char *p, const char *opt)
{
    const char *c = strchr(p, '%'), *digits;
    if (!c)
        return cli_usage_error("render", "%s '%s': with --frames, a pattern with one %%d (e.g. frame_%%04d.exr)",
                               opt, p), false;
    digits = ++c;
    if (*c == '0')
        c++;
    while (*c >= '0' && *c <= '9' && c - digits <= 3)
        c++;
    if (*c >= '0' && *c <= '9')
        return cli_usage_error("render", "%s '%s': the width of the frame number is too large (at most %d)", opt,
                               p, FRAME_WIDTH_MAX), false;
    if (*c != 'd' || strchr(c, '%'))
        return cli_usage_error("render", "%s '%s': with --frames, a pattern with one %%d, %%Nd or %%0Nd and no "
                               "other %% (e.g. frame_%%04d.exr)", opt, p), false;
    if (c > digits && atoi(digits) > FRAME_WIDTH_MAX)
        return cli_usage_error("render", "%s '%s': the width of the frame number is too large (at most %d)", opt,
                               p, FRAME_WIDTH_MAX), false;
    return true;
}

/* The name of frame f of a checked pattern, into out (PATH_MAX bytes); false when it does
 * not fit or no longer names the pattern's format. */
static bool frame_name(const char *pattern, long f, const char *opt, char *out, size_t cap)
{
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
    int n = snprintf(out, cap, pattern, (int)f); /* checked: frame_pattern */
#pragma GCC diagnostic pop
    if (n < 0 || (size_t)n >= cap)
        return cli_usage_error("render", "%s '%s': frame %ld's name is too long", opt, pattern, f), false;
    if (image_format_of(out) != image_format_of(pattern))
        return cli_usage_error("render", "%s '%s': frame %ld's name '%s' does not end in the pattern's extension",
                               opt, pattern, f, out), false;
    return true;
}

/* --crop X0,Y0,X1,Y1: pixels, or fractions when any value has a '.'. */
typedef struct crop_option {
    bool given, fractions;
    double v[4];
} crop_option;

static bool parse_crop(const char *val, crop_option *c)
{
    char buf[128], *tok, *save, *end;
    int n = 0;
    snprintf(buf, sizeof buf, "%s", val);
    c->fractions = strchr(val, '.') != NULL;
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (n == 4)
            return false;
        c->v[n] = strtod(tok, &end);
        if (end == tok || *end || !isfinite(c->v[n]) || c->v[n] < 0 ||
            (!c->fractions && c->v[n] != floor(c->v[n])) || (c->fractions && c->v[n] > 1))
            return false;
        n++;
    }
    c->given = true;
    return n == 4;
}

/* The crop in pixels for the image size; false (usage error) when it is empty or outside. */
static bool apply_crop(const crop_option *c, render_settings *s, const char *val)
{
    int p[4];
    for (int k = 0; k < 4; k++) {
        double size = k % 2 ? s->height : s->width;
        double x = c->fractions ? ceil(c->v[k] * size) : c->v[k];
        p[k] = x > size ? -1 : (int)x;
        if (p[k] < 0) {
            cli_usage_error("render", "--crop '%s': outside the %dx%d image", val, s->width, s->height);
            return false;
        }
    }
    if (p[0] >= p[2] || p[1] >= p[3]) {
        cli_usage_error("render", "--crop '%s': an empty region (%d,%d to %d,%d: X0 < X1 and Y0 < Y1 "
                        "needed)", val, p[0], p[1], p[2], p[3]);
        return false;
    }
    s->crop_x0 = p[0];
    s->crop_y0 = p[1];
    s->crop_x1 = p[2];
    s->crop_y1 = p[3];
    return true;
}

/* The sums of a --resumable file are trusted only as far as they are what a render writes:
 * each sum.* and sum2.* channel stored as 32-bit float, every value finite, sum.N (each
 * pixel's sample count) the header's spp everywhere, each pixel's coverage sum.A a whole
 * number from 0 to spp, the sums of depth, albedo and squares (and of radiance, in path
 * mode) not negative, of normals within +-spp. False with an error naming the first
 * problem: the channel, the pixel and the value. */
static bool check_sums(const char *path, const image *prev, int spp, uint32_t mode)
{
    const size_t n = (size_t)prev->width * (size_t)prev->height;
    const int cn = image_channel(prev, "sum.N");
    if (image_channel(prev, "sum.R") < 0)
        return true; /* not a --resumable file: the render names the first channel it lacks */
    if (cn < 0) {
        util_error("%s: cannot resume: no sum.N channel (each pixel's sample count; written by "
                   "--resumable since this version: render it again)", path);
        return false;
    }
    for (int c = 0; c < prev->num_channels; c++) {
        const char *name = prev->names[c];
        const float *v = prev->planes[c];
        const bool nonneg = !strcmp(name, "sum.A") || !strcmp(name, "sum.depth.Z") ||
                            !strncmp(name, "sum.albedo.", 11) || !strncmp(name, "sum2.", 5) ||
                            (mode == GN_MODE_PATH && (!strcmp(name, "sum.R") || !strcmp(name, "sum.G") ||
                                                      !strcmp(name, "sum.B")));
        const bool unit = !strncmp(name, "sum.normal.", 11), coverage = !strcmp(name, "sum.A");
        if (strncmp(name, "sum.", 4) && strncmp(name, "sum2.", 5))
            continue;
        if (prev->stored[c] != IMAGE_STORED_FLOAT) {
            util_error("%s: cannot resume: channel '%s' is stored as %s; the sums are 32-bit float", path, name,
                       prev->stored[c] == IMAGE_STORED_HALF ? "16-bit half" : "unsigned int");
            return false;
        }
        for (size_t p = 0; p < n; p++) {
            const char *why = !isfinite(v[p])                ? "not finite"
                              : c == cn && v[p] != (float)spp ? "the header's gonio:spp is %d"
                              : nonneg && v[p] < 0            ? "negative"
                              : coverage && (v[p] > spp || v[p] != floorf(v[p]))
                                  ? "not a whole number of samples from 0 to gonio:spp (%d)"
                              : unit && fabsf(v[p]) > spp ? "beyond gonio:spp (%d) samples of a unit vector"
                                                          : NULL;
            if (why) {
                char text[128];
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
                snprintf(text, sizeof text, why, spp); /* one of the literals above */
#pragma GCC diagnostic pop
                util_error("%s: cannot resume: channel '%s' at pixel (%d, %d) is %g: %s", path, name,
                           prev->x0 + (int)(p % (size_t)prev->width), prev->y0 + (int)(p / (size_t)prev->width),
                           (double)v[p], text);
                return false;
            }
        }
    }
    return true;
}

/* --resume FILE: the file must be an earlier render of exactly this one (identity, seed,
 * region) with fewer samples and the sums; loads it into *prev and sets s->resume. */
static bool check_resume(const char *path, const renderer *r, render_settings *s, const char *brdf, image *prev)
{
    render_header h;
    render_stats st = {0};
    int region[4];
    double spp;
    uint32_t seed;
    render_header_build(&h, r, s, &st, brdf, cli_command_line());
    if (!image_read_exr(prev, path))
        return false;
    if (!image_exr_attr_double(path, "gonio:spp", &spp) || !(spp >= 1 && spp <= INT32_MAX && spp == floor(spp))) {
        util_error("%s: no gonio:spp sample count in the header (not a gonio render?)", path);
        return false;
    }
    for (int k = 0; render_identity_names[k]; k++) {
        char file[512] = "", now[512] = "";
        bool in_file = image_exr_attr_string(path, render_identity_names[k], file, sizeof file), in_now = false;
        for (int a = 0; a < h.count; a++)
            if (!strcmp(h.attrs[a].name, render_identity_names[k])) {
                snprintf(now, sizeof now, "%s", h.attrs[a].s);
                in_now = true;
            }
        if (in_file != in_now || strcmp(file, now)) {
            util_error("%s: cannot resume: %s differs (the file's %s%s%s, this render's %s%s%s)", path,
                       render_identity_names[k], in_file ? "'" : "", in_file ? file : "absent",
                       in_file ? "'" : "", in_now ? "'" : "", in_now ? now : "absent", in_now ? "'" : "");
            return false;
        }
    }
    if (!render_header_seed(path, &seed) || seed != s->seed) {
        util_error("%s: cannot resume: its seed is not this render's %u (--seed)", path, s->seed);
        return false;
    }
    if (s->mode == GN_MODE_PATH) {
        char file[64];
        if (!image_exr_attr_string(path, "gonio:sampler", file, sizeof file)) {
            /* (a render from before the samplers: its numbers are none of today's) */
            util_error("%s: cannot resume: no gonio:sampler in the header (a render older than the samplers: "
                       "render it again)", path);
            return false;
        }
        if (strcmp(file, render_sampler_name(s->sampler))) {
            util_error("%s: cannot resume: its samples are the %s sampler's, this render's the %s one's (--sampler)",
                       path, file, render_sampler_name(s->sampler));
            return false;
        }
    }
    render_region(s, region);
    {
        bool whole = region[0] == 0 && region[1] == 0 && region[2] == s->width && region[3] == s->height;
        int fx0 = prev->full_width ? prev->x0 : 0, fy0 = prev->full_width ? prev->y0 : 0;
        if (fx0 != region[0] || fy0 != region[1] || prev->width != region[2] - region[0] ||
            prev->height != region[3] - region[1] || (!whole && !prev->full_width)) {
            util_error("%s: cannot resume: its pixels (%d,%d)+%dx%d are not this render's region "
                       "(%d,%d)+%dx%d (--crop)", path, fx0, fy0, prev->width, prev->height, region[0],
                       region[1], region[2] - region[0], region[3] - region[1]);
            return false;
        }
    }
    if (!image_inside_frame(prev)) {
        util_error("%s: cannot resume: its data window lies outside its display window", path);
        return false;
    }
    if (!check_sums(path, prev, (int)spp, s->mode))
        return false;
    if (s->time_limit <= 0 && spp >= s->spp) {
        util_error("%s: cannot resume: it has %d spp already, and --spp %d is the total wanted", path,
                   (int)spp, s->spp);
        return false;
    }
    s->resume = prev;
    s->resume_spp = (int)spp;
    return true;
}

static void catch_signals(bool quiet)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    signal_quiet = quiet;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

/* Where an option of render applies (warn_inapplicable). */
typedef enum render_applies {
    APPLIES_PATH,        /* --mode path only */
    APPLIES_LOCAL,       /* the local modes only */
    APPLIES_PNG,         /* with a PNG output only */
    APPLIES_NO_TIME,     /* not with --time */
    APPLIES_PATH_ALBEDO, /* --mode path and albedo (the model's colour) only */
    APPLIES_EXR,         /* with an EXR output only */
} render_applies;

/* Options that the chosen mode or outputs do not use: a warning each, never silence. */
static void warn_inapplicable(const cli_command *c, const cli_args *args, const render_settings *s,
                              const char *png_path, const char *out_path)
{
    static const struct {
        const char *opt;
        render_applies when;
    } rules[] = {{"--max-depth", APPLIES_PATH},   {"--brdf", APPLIES_PATH_ALBEDO}, {"--estimator", APPLIES_PATH},
                 {"--ambient", APPLIES_LOCAL},    {"--no-shadows", APPLIES_LOCAL}, {"--exposure", APPLIES_PNG},
                 {"--tonemap", APPLIES_PNG},      {"--spp", APPLIES_NO_TIME},      {"--aov", APPLIES_EXR}};
    const bool path = s->mode == GN_MODE_PATH;
    const bool png = png_path || (out_path && util_has_suffix(out_path, ".png"));
    const bool exr = out_path && util_has_suffix(out_path, ".exr");
    for (size_t k = 0; k < sizeof rules / sizeof *rules; k++) {
        const char *opt = rules[k].opt;
        if (!cli_given(c, args, opt))
            continue;
        switch (rules[k].when) {
        case APPLIES_PATH:
            if (!path)
                util_warn("%s applies to --mode path only; ignored with --mode %s", opt, render_mode_name(s->mode));
            break;
        case APPLIES_LOCAL:
            if (path)
                util_warn("%s applies to the local modes only; ignored with --mode path", opt);
            break;
        case APPLIES_PNG:
            if (!png)
                util_warn("%s applies to the PNG only; ignored without a PNG output", opt);
            break;
        case APPLIES_EXR:
            if (!exr)
                util_warn("%s applies to the EXR only; ignored without an EXR output", opt);
            break;
        case APPLIES_PATH_ALBEDO:
            if (!path && s->mode != GN_MODE_ALBEDO)
                util_warn("%s applies to --mode path (and albedo, its colour) only; ignored with --mode %s", opt,
                          render_mode_name(s->mode));
            break;
        case APPLIES_NO_TIME:
            if (s->time_limit > 0)
                util_warn("%s is ignored with --time: the render takes as many samples as fit", opt);
            break;
        }
    }
}

/* --frames: what a frame leaves to the next. The device, and the renderer with its scene while
 * the frames differ only in the instances' transforms (scene_same_geometry: the loader keeps
 * the meshes an animation moves as instances, scene_instance_animated), so that a frame
 * rebuilds only the top tree (renderer_update) and compiles no kernel. */
typedef struct frame_cache {
    bool gpu_live, renderer_live;
    gpu g;
    renderer r;
    scene sc;
} frame_cache;

/* Everything the command line says about one render (--frames: one per frame). */
typedef struct render_job {
    const char *scene_path, *out_path, *png_path, *brdf, *crop_text, *resume_path, *frames;
    render_settings s;
    camera_option cam;
    env_option env;
    crop_option crop;
    int size[2];  /* --size */
    bool size_given, quiet, validate, resumable, outside, denoise, strict;
    int strict_since; /* the warnings before the command's own (cli_strict_begin) */
    int frame;   /* --frame, -1 none */
    float fps;
    float at;    /* --at, -1 none */
    int device, scene_index;
    float exposure;
    image_tonemap tm;
    image_exr_options exr;
    frame_cache *cache; /* --frames: kept from frame to frame; NULL: one render */
} render_job;

/* CLI_CALL parsers of render's own values. */
static bool take_crop(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    render_job *j = dest;
    j->crop_text = val;
    return parse_crop(val, &j->crop);
}

static bool take_aov(const char *cmd, const char *opt, const char *val, void *dest)
{
    char buf[256], *tok, *save;
    uint32_t *aov = dest;
    snprintf(buf, sizeof buf, "%s", val);
    *aov = 0;
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        uint32_t bit = render_aov_from_name(tok);
        if (!bit) {
            cli_usage_error(cmd, "%s '%s': expected a list of normal, albedo, depth, variance", opt, tok);
            return false;
        }
        *aov |= bit;
    }
    return *aov != 0 || (cli_usage_error(cmd, "%s '%s': expected a list of normal, albedo, depth, variance",
                                         opt, val), false);
}

static bool take_ambient(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    render_settings *s = dest;
    s->ambient_set = true;
    return util_parse_rgb(val, s->ambient);
}

static bool take_brdf(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    *(const char **)dest = val;
    return brdf_spec_check(val);
}

/* --estimator: the names and their GnFrame strategy flags. */
static const char *const estimator_names[] = {"mis", "light", "bsdf"};
static const uint32_t estimator_flags[] = {0, GN_FRAME_LIGHT_ONLY, GN_FRAME_BSDF_ONLY};

static bool take_estimator(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    for (int i = 0; i < 3; i++)
        if (!strcmp(val, estimator_names[i])) {
            *(uint32_t *)dest = estimator_flags[i];
            return true;
        }
    return false;
}

static const char *estimator_list(void)
{
    static char list[32];
    return list[0] ? list : util_join(list, sizeof list, estimator_names, 3);
}

static int render_run(const render_job *job);

/* --frames A-B: render_run once per frame, -o and --png filled in with the frame number. */
static int render_frames(const render_job *job)
{
    long a, b;
    char range[64] = "", *dash, names[2][4096];
    int rc = 0;
    snprintf(range, sizeof range, "%s", job->frames);
    dash = range[0] ? strchr(range + 1, '-') : NULL;
    if (dash)
        *dash = 0;
    if (!dash || !util_parse_int(range, 0, 1 << 24, &a) || !util_parse_int(dash + 1, 0, 1 << 24, &b) || b < a)
        return cli_usage_error("render", "--frames '%s': expected A-B, frames 0 <= A <= B", job->frames);
    const char *outs[2] = {job->out_path, job->png_path}, *opts[2] = {"-o", "--png"};
    /* Every name is checked before any work: the pattern's form, and the first and last
     * frames' names (the longest is the last's). */
    for (int k = 0; k < 2; k++) {
        if (!outs[k])
            continue;
        if (!frame_pattern(outs[k], opts[k]) || !frame_name(outs[k], a, opts[k], names[k], sizeof names[k]) ||
            !frame_name(outs[k], b, opts[k], names[1 - k], sizeof names[k]))
            return 2;
        if (!util_check_output(names[k]) || !util_check_output(names[1 - k]))
            return 1;
    }
    if (job->frame >= 0 || job->at >= 0)
        return cli_usage_error("render", "--frames and %s exclude each other", job->frame >= 0 ? "--frame" : "--at");
    frame_cache cache = {0};
    scene_instance_animated(true);
    for (long f = a; f <= b && rc == 0 && !stop_requested; f++) {
        render_job one = *job;
        one.frames = NULL;
        one.frame = (int)f;
        one.cache = &cache;
        for (int k = 0; k < 2; k++)
            if (outs[k] && !frame_name(outs[k], f, opts[k], names[k], sizeof names[k]))
                return 2;
        one.out_path = outs[0] ? names[0] : NULL;
        one.png_path = outs[1] ? names[1] : NULL;
        rc = render_run(&one);
    }
    scene_instance_animated(false);
    if (cache.renderer_live) {
        renderer_destroy(&cache.r);
        scene_destroy(&cache.sc);
    }
    if (cache.gpu_live && !cli_gpu_finish(&cache.g))
        rc = rc ? rc : 1;
    return rc;
}

#define RENDER_EPILOG                                                                          \
    "An option the mode or outputs do not use (--max-depth with phong, --ambient with path,\n"  \
    "--exposure without --png) is a warning. Progress goes to stderr: a bar on a terminal;\n"  \
    "in a log, a line at each tenth once a second has passed (by time with --time).\n"         \
    "Exit status: 0 ok, 1 bad input or failed render, 2 bad usage; 128 + N after signal N\n"  \
    "(130: Ctrl-C, 143: SIGTERM): the render stopped after its pass and wrote what it had.\n"  \
    "A second signal quits at once and leaves no output.\n"

int cmd_render(int argc, char **argv)
{
    render_job j = {.s = {.mode = GN_MODE_PATH, .spp = 16, .camera = -1, .stop = &stop_requested},
                    .frame = -1, .fps = 24, .at = -1, .device = -1, .scene_index = -1,
                    .tm = IMAGE_TONEMAP_CLAMP, .exr = IMAGE_EXR_DEFAULTS};
    bool no_shadows = false;
    const cli_option options[] = {
        {"-o, --output", "FILE", "the image, in the format its name says: .exr linear float RGBA\n"
                                 "OpenEXR with the gonio:* header; .png the PNG --png writes\n"
                                 "(any other name is a usage error); written atomically",
         CLI_STRING, CLI_AS(const char *, &j.out_path), 0, 0, NULL, NULL, "*.exr *.png"},
        CLI_OPT_PNG(&j.png_path, "also write a PNG: tonemapped sRGB; in modes depth, normal and\n"
                                 "cost a picture of the data: depth grey from white (nearest) to 20%\n"
                                 "grey (farthest visible), normals 0.5 n + 0.5, cost a viridis heat\n"
                                 "map up to the image's maximum (misses too: they walk the tree);\n"
                                 "the background of depth and normals black"),
        CLI_OPT_MODE(&j.s.mode),
        CLI_OPT_SPP(&j.s.spp, "samples per pixel (default 16)"),
        {"--time", "SECONDS", "render for this long instead of --spp", CLI_DOUBLE, CLI_AS(double, &j.s.time_limit), FLT_MIN,
         3e38, "seconds > 0", NULL, NULL},
        CLI_OPT_SIZE(j.size, "image size (default 512 on the longer side, the camera's aspect)"),
        CAMERA_OPTIONS(&j.cam),
        CLI_OPT_SCENE(&j.scene_index, "render the file's glTF scene N (default: its default scene)"),
        CLI_OPT_VARIANT("the materials of the file's KHR_materials_variants variant NAME\n"
                        "(gonio info lists them; default: the file's own materials)"),
        CLI_OPT_ALLOW_OUTSIDE_FILES(&j.outside),
        CLI_OPT_SEED(&j.s.seed, "random seed (default 0); renders with different seeds merge"),
        CLI_OPT_SAMPLER(&j.s.sampler),
        {"--frame", "N", "the scene's glTF animations at frame N / --fps (all play at once:\n"
                         "node translation, rotation, scale; meshes, cameras, lights)",
         CLI_INT, CLI_AS(int, &j.frame), 0, 1 << 24, "a frame number >= 0", NULL, NULL},
        {"--fps", "F", "frames per second for --frame and --frames (default 24)", CLI_FLOAT, CLI_AS(float, &j.fps), FLT_MIN,
         1e6, "frames per second > 0", NULL, NULL},
        {"--at", "SECONDS", "the animations at this time", CLI_FLOAT, CLI_AS(float, &j.at), 0, 1e9, "seconds >= 0", NULL, NULL},
        {"--frames", "A-B", "render frames A to B, one file each: -o and --png are patterns\n"
                            "with one %d (e.g. out/frame_%04d.exr); stops at the first failure",
         CLI_STRING, CLI_AS(const char *, &j.frames), 0, 0, NULL, NULL, NULL},
        {"--crop", "X0,Y0,X1,Y1", "render only pixels [X0, X1) x [Y0, Y1) of the image, each as the\n"
                                  "whole render has it, bit for bit: an EXR whose data window is the\n"
                                  "region of the full display window (gonio merge assembles tiles);\n"
                                  "values with a '.' are fractions of the size (0,0,0.5,0.5: the\n"
                                  "top-left quarter; pixel = ceil(fraction x size), as pbrt's)",
         CLI_CALL, &j, 0, 0, "X0,Y0,X1,Y1 in pixels (integers) or fractions 0..1", take_crop, NULL},
        {"--resumable", NULL, "EXR: also write the exact sums (sum.* channels, 32-bit float)\n"
                              "that --resume goes on from; SIGTERM always writes them",
         CLI_FLAG, CLI_AS(bool, &j.resumable), 0, 0, NULL, NULL, NULL},
        {"--resume", "FILE.exr", "go on from a --resumable render of the same scene, camera, crop,\n"
                                 "seed and options (checked): --spp is the total; the result is the\n"
                                 "render of --spp in one run, bit for bit",
         CLI_STRING, CLI_AS(const char *, &j.resume_path), 0, 0, NULL, NULL, "*.exr"},
        CLI_OPT_DENOISE(&j.denoise, "path: denoise with Intel Open Image Denoise (RT filter), guided by\n"
                                    "the albedo and normal (rendered for it, written only as --aov\n"
                                    "says): the PNG and the EXR's R,G,B denoised, its noisy.R/G/B the\n"
                                    "render itself (make denoiser fetches the library; docs/denoise.md)"),
        {"--aov", "LIST", "extra EXR channels, exactly those listed: any of normal (normal.XYZ),\n"
                          "albedo (albedo.RGB), depth (depth.Z, 0 on a miss), variance\n"
                          "(variance.RGB: of each pixel's mean), comma-separated",
         CLI_CALL, &j.s.aov, 0, 0, NULL, take_aov, render_aov_list()},
        CLI_OPT_EXR_HALF(&j.exr.half),
        CLI_OPT_EXR_COMPRESSION(&j.exr.compression),
        ENV_OPTIONS(&j.env),
        CLI_OPT_MAX_DEPTH(&j.s.max_depth, "path: at most N bounces (default 0: unbounded, roulette ends paths)"),
        {"--brdf", "MODEL[:P=V]", "path: render every material with a BRDF model (see gonio brdf\n"
                                  "--list), e.g. --brdf torrance-sparrow:exponent=128:specular=0.5",
         CLI_CALL, &j.brdf, 0, 0, "a model of gonio brdf --list", take_brdf, cli_brdf_models()},
        {"--estimator", "E", "path: mis (default), light or bsdf: one strategy only (tests)", CLI_CALL,
         &j.s.strategy, 0, 0, NULL, take_estimator, estimator_list()},
        CLI_OPT_NO_SHADOWS(&no_shadows),
        {"--ambient", "R,G,B | V", "local modes: the Phong model's global ambient light (default 0)", CLI_CALL,
         &j.s, 0, 0, "R,G,B or one value >= 0", take_ambient, NULL},
        CLI_OPT_EXPOSURE(&j.exposure, "PNG only: scale by 2^E before tonemapping (default 0)"),
        CLI_OPT_TONEMAP(&j.tm, "PNG only: clamp (default), reinhard, aces"),
        CLI_OPT_DEVICE(&j.device),
        CLI_OPT_VALIDATE(&j.validate),
        CLI_OPT_QUIET(&j.quiet, "no progress and no summary line"),
        CLI_OPT_STRICT(&j.strict),
    };
    const cli_command command = {.name = "render", .synopsis = "SCENE.gltf|.glb -o OUT.exr|OUT.png [options]",
                                 CLI_OPTIONS(options), .epilog = RENDER_EPILOG, .min_args = 1, .max_args = 1,
                                 .missing = "no scene given", .complete_args = "*.gltf *.glb"};
    cli_args args;
    int rc = cli_parse(&command, argc, argv, &args);
    if (rc >= 0)
        return rc;
    j.scene_path = args.arg[0];
    if ((j.size_given = cli_given(&command, &args, "--size"))) {
        j.s.width = j.size[0];
        j.s.height = j.size[1];
    }
    j.s.no_shadows = no_shadows;
    const char *out_path = j.out_path, *png_path = j.png_path, *exr_path = NULL;
    j.strict_since = cli_strict_begin(j.strict);
    warn_inapplicable(&command, &args, &j.s, png_path, out_path);
    /* The name says the format: -o OUT.png is the tonemapped PNG, as --png is. */
    if ((rc = cli_image_outputs("render", out_path, png_path, &exr_path)) >= 0)
        return rc;
    const char *exr_option = cli_given(&command, &args, "--compression") ? "--compression"
                             : cli_given(&command, &args, "--half")      ? "--half"
                                                                         : NULL;
    if (exr_option && !exr_path)
        return cli_usage_error("render", "%s is for an EXR output (-o OUT.exr)", exr_option);
    if (j.resumable && !exr_path)
        return cli_usage_error("render", "--resumable is for an EXR output (-o OUT.exr)");
    if (j.resume_path && image_format_of(j.resume_path) != IMAGE_FORMAT_EXR)
        return cli_usage_error("render", "--resume '%s': expected a .exr render", j.resume_path);
    if (j.frame >= 0 && j.at >= 0 && !j.frames)
        return cli_usage_error("render", "--frame and --at exclude each other");
    if (j.denoise && j.s.mode != GN_MODE_PATH)
        return cli_usage_error("render", "--denoise is for --mode path (the other modes have no noise to remove)");
    return j.frames ? render_frames(&j) : render_run(&j);
}

/* ---- --denoise ---------------------------------------------------------------------------
 * The render's albedo and normal guide OIDN (src/core/denoise.h); they stay in the EXR only
 * when --aov asked for them. The header says what the denoiser did and how long it took. */
static bool denoise_render(image *img, uint32_t user_aov, const char *name, denoise_info *info)
{
    denoise_channels ch;
    static const char *const names[9] = {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B",
                                         "normal.X", "normal.Y", "normal.Z"};
    for (int k = 0; k < 3; k++) {
        ch.beauty[k] = image_channel(img, names[k]);
        ch.albedo[k] = image_channel(img, names[3 + k]);
        ch.normal[k] = image_channel(img, names[6 + k]);
    }
    if (!denoise_image(img, &ch, true, info, name))
        return false;
    for (int k = 0; k < 6; k++) {
        int c = image_channel(img, names[3 + k]);
        if (!(user_aov & (k < 3 ? RENDER_AOV_ALBEDO : RENDER_AOV_NORMAL)) && c >= 0)
            image_remove_channel(img, c);
    }
    return true;
}

/* One render of the job as it goes through render_run's steps. */
typedef struct render_state {
    const render_job *job;
    render_settings s;
    camera_option cam;
    scene_camera view;
    char camera_text[160];
    render_lighting light;
    scene own_sc, *sc;   /* the scene: its own, or (--frames) the cache's */
    gpu own_g, *g;
    renderer own_r, *r;
    const char *exr_path, *png_o; /* -o as EXR or as PNG */
    image img, prev;     /* the render; the --resume file */
    render_stats st;
} render_state;

/* The scene loaded with its --brdf, light and camera, the image's size and region: 0, or
 * the exit status of the error it reported. */
static int load_view(render_state *rs)
{
    const render_job *job = rs->job;
    render_settings *s = &rs->s;
    scene_animation_time(job->frame >= 0 ? job->frame / (double)job->fps : job->at);
    if (!scene_load_scene(&rs->own_sc, job->scene_path, job->scene_index))
        return 1;
    if (!render_material_overrides(&rs->own_sc, job->brdf) ||
        !render_light_begin(&job->env, &rs->own_sc, job->quiet, s, &rs->light) ||
        !camera_resolve(&rs->cam, &rs->own_sc, job->size_given ? (float)s->width / (float)s->height : 1.0f, &rs->view))
        return 1;
    if (!job->size_given) {
        if (rs->cam.width > 0) { /* --camera FILE.exr: that render's size, as its view had it */
            s->width = rs->cam.width;
            s->height = rs->cam.height;
        } else {
            camera_default_size(&rs->view, 512, &s->width, &s->height);
        }
        camera_resolve(&rs->cam, &rs->own_sc, (float)s->width / (float)s->height, &rs->view); /* framing: the real aspect */
    }
    if (job->crop.given && !apply_crop(&job->crop, s, job->crop_text))
        return 2;
    s->view = &rs->view;
    camera_describe(&rs->cam, &rs->own_sc, rs->camera_text, sizeof rs->camera_text);
    s->camera_label = rs->camera_text;
    return 0;
}

/* The device and the renderer of the scene (--frames: the cache's, the renderer only updated
 * while the geometry stays the same), and the light rule's second step. */
static bool start_renderer(render_state *rs)
{
    frame_cache *cache = rs->job->cache;
    if (cache && cache->gpu_live) {
        rs->g = &cache->g;
    } else if (!cli_gpu_create(&rs->own_g, rs->job->device, rs->job->validate)) {
        return false;
    } else if (cache) { /* the first frame's device serves them all */
        cache->g = rs->own_g;
        cache->gpu_live = true;
        rs->g = &cache->g;
    } else {
        rs->g = &rs->own_g;
    }
    catch_signals(rs->job->quiet);
    rs->sc = &rs->own_sc;
    rs->r = &rs->own_r;
    if (cache) { /* (a frame's scene moves into the cache) */
        bool same = cache->renderer_live && scene_same_geometry(&cache->sc, &rs->own_sc);
        if (cache->renderer_live && !same)
            renderer_destroy(&cache->r);
        if (cache->renderer_live)
            scene_destroy(&cache->sc);
        cache->sc = rs->own_sc;
        memset(&rs->own_sc, 0, sizeof rs->own_sc);
        rs->sc = &cache->sc;
        rs->r = &cache->r;
        if (same) {
            /* the frame before's trees and kernels: only the instances moved */
            renderer_update(rs->r, rs->sc);
            if (!rs->job->quiet)
                fprintf(stderr, "gonio: frame %d: the same geometry, moved: the top tree over %u instances rebuilt "
                                "and the lights updated in %.2f ms\n", rs->job->frame, rs->r->geo.top.num_instances,
                        rs->r->setup_seconds * 1e3);
        } else {
            renderer_create(rs->r, rs->g, rs->sc);
        }
        cache->renderer_live = true;
    } else {
        renderer_create(rs->r, rs->g, rs->sc);
    }
    if (!render_light_finish(&rs->job->env, rs->sc, rs->r, &rs->s, rs->job->quiet, &rs->light))
        return false;
    rs->s.env_label = rs->light.label;
    return true;
}

/* The header of the finished render: the renderer's, the animation's time and frame. */
static void build_header(const render_state *rs, render_header *h)
{
    const render_job *job = rs->job;
    render_header_build(h, rs->r, &rs->s, &rs->st, job->brdf, cli_command_line());
    double at = job->frame >= 0 ? job->frame / (double)job->fps : job->at;
    if (at >= 0 && h->count + 2 <= RENDER_HEADER_MAX) {
        h->attrs[h->count++] = (image_attr){"gonio:time", IMAGE_ATTR_DOUBLE, NULL, 0, at, NULL};
        if (job->frame >= 0)
            h->attrs[h->count++] = (image_attr){"gonio:frame", IMAGE_ATTR_INT, NULL, job->frame, 0, NULL};
    }
}

/* The rendered image denoised (--denoise), with the resumable sums, written to the EXR and
 * PNGs asked for, and the summary said: the exit status. */
static int write_outputs(render_state *rs)
{
    const render_job *job = rs->job;
    const render_settings *s = &rs->s;
    const char *out_path = job->out_path ? job->out_path : job->png_path;
    render_header h;
    denoise_info dn = {0};
    int region[4];
    bool ok = true;
    build_header(rs, &h);
    if (stop_requested && !job->quiet) /* (said, not a warning about the file: --strict writes it too) */
        (util_strict() ? util_info : util_warn)("interrupted: writing the %d spp rendered so far%s", rs->st.spp,
                                                stop_requested == SIGTERM && rs->exr_path ? " (resumable: --resume)" : "");
    if (job->denoise) {
        ok = denoise_render(&rs->img, job->s.aov, out_path, &dn);
        if (ok) {
            assert(h.count + 2 <= RENDER_HEADER_MAX); /* a path render's header has 25 at most */
            h.attrs[h.count++] = (image_attr){"gonio:denoiser", IMAGE_ATTR_STRING, dn.description, 0, 0, NULL};
            h.attrs[h.count++] = (image_attr){"gonio:denoise-seconds", IMAGE_ATTR_DOUBLE, NULL, 0, dn.seconds, NULL};
        }
    }
    /* With --denoise the sums include the guides', so that --resume --denoise goes on. */
    if (ok && (job->resumable || stop_requested == SIGTERM))
        renderer_sums(rs->r, rs->st.spp, s->aov, &rs->img);
    render_region(s, region);
    if (s->crop_x1 > 0) { /* the region in the whole frame: OpenEXR's data window */
        rs->img.x0 = region[0];
        rs->img.y0 = region[1];
        rs->img.full_width = s->width;
        rs->img.full_height = s->height;
    }
    image_exr_options exr = job->exr;
    exr.exact_prefix = "sum"; /* sum.* and sum2.*: the state --resume needs exactly */
    if (ok && rs->exr_path)
        ok = image_write_exr_with(&rs->img, rs->exr_path, h.attrs, h.count, &exr);
    if (ok && rs->png_o)
        ok = render_write_png(&rs->img, s->mode, rs->png_o, job->exposure, job->tm);
    if (ok && job->png_path)
        ok = render_write_png(&rs->img, s->mode, job->png_path, job->exposure, job->tm);
    if (ok && !job->quiet)
        /* One camera ray per pixel and sample: a whole path in path mode. */
        fprintf(stderr, "gonio: %s %dx%d, %s, %s, %d spp in %.2f s (%.2f %s), setup %.2f s\n", out_path, s->width,
                s->height, rs->camera_text, render_mode_name(s->mode), rs->st.spp, rs->st.seconds,
                rs->st.seconds > 0 ? (double)rs->st.rays / rs->st.seconds * 1e-6 : 0.0,
                s->mode == GN_MODE_PATH ? "M paths/s" : "Mrays/s primary", rs->st.setup_seconds);
    if (ok && !job->quiet && job->denoise)
        fprintf(stderr, "gonio: denoised in %.2f s (%s; library and device setup %.2f s)\n", dn.seconds,
                dn.description, dn.setup_seconds);
    return !ok ? 1 : stop_requested ? 128 + stop_requested : 0;
}

/* One render of the job: load, render, write. */
static int render_run(const render_job *job)
{
    render_state rs = {.job = job, .s = job->s, .cam = job->cam};
    cli_progress progress;
    int rc = 1;
    if (job->out_path && image_format_of(job->out_path) == IMAGE_FORMAT_EXR)
        rs.exr_path = job->out_path;
    else
        rs.png_o = job->out_path;
    util_set_quiet(job->quiet);
    rs.s.progress = job->quiet ? NULL : cli_progress_report;
    rs.s.progress_user = &progress;
    scene_allow_outside_files(job->outside);
    if ((job->out_path && !util_check_output(job->out_path)) || (job->png_path && !util_check_output(job->png_path)))
        return 1;
    if (job->denoise) { /* the library is there, before any work; the guides are rendered */
        if (!denoise_load())
            return 1;
        rs.s.aov |= RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL;
    }
    if ((rc = load_view(&rs)) == 0) {
        rc = 1;
        /* --strict: what loading said stops it before the device is made, what the light
         * rule said before the render, what the render said before its outputs */
        if (cli_strict_ok(job->strict_since, job->scene_path) && start_renderer(&rs) && (!job->resume_path || check_resume(job->resume_path, rs.r, &rs.s, job->brdf, &rs.prev)) &&
            cli_strict_ok(job->strict_since, job->scene_path) && renderer_render(rs.r, &rs.s, &rs.img, &rs.st) &&
            cli_strict_ok(job->strict_since, job->scene_path))
            rc = write_outputs(&rs);
    }
    image_destroy(&rs.img);
    image_destroy(&rs.prev);
    rs.s.env_map = NULL;
    render_lighting_destroy(&rs.light);
    if (job->denoise)
        denoise_shutdown();
    if (!job->cache && rs.g) {
        renderer_destroy(rs.r);
        if (!cli_gpu_finish(rs.g))
            rc = 1;
    }
    scene_destroy(&rs.own_sc);
    return rc;
}
