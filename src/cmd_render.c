/* cmd_render.c: `gonio render`, `gonio info` and `gonio devices`. */
#include <errno.h>
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
#include "environment.h"
#include "image.h"
#include "render.h"
#include "render_output.h"
#include "scene.h"
#include "util.h"

static const char render_usage[] =
    "usage: gonio render SCENE.gltf|.glb -o OUT.exr|OUT.png [options]\n"
    "\n"
    "  -o, --output FILE   the image, in the format its name says: .exr linear float RGBA\n"
    "                      OpenEXR with the gonio:* header; .png the PNG --png writes\n"
    "                      (any other name is a usage error); written atomically\n"
    "  --png FILE          also write a PNG: tonemapped sRGB; in modes depth, normal and\n"
    "                      cost a picture of the data: depth grey from white (nearest) to 20%\n"
    "                      grey (farthest visible), normals 0.5 n + 0.5, cost a viridis heat\n"
    "                      map up to the image's maximum (misses too: they walk the tree);\n"
    "                      the background of depth and normals black\n"
    "  --mode M            path (default: Monte Carlo path tracing), phong, gouraud, flat,\n"
    "                      normal, albedo, depth, cost (depth: along the camera axis, 0 where\n"
    "                      nothing is hit, in the EXR as in the depth AOV)\n"
    "  --spp N             samples per pixel (default 16)\n"
    "  --time SECONDS      render for this long instead of --spp\n"
    "  --size WxH          image size (default 512 on the longer side, the camera's aspect)\n"
    CAMERA_OPTIONS_HELP
    "  --scene N           render the file's glTF scene N (default: its default scene)\n"
    "  --variant NAME      the materials of the file's KHR_materials_variants variant NAME\n"
    "                      (gonio info lists them; default: the file's own materials)\n"
    "  --allow-outside-files  let the scene read files outside its folder (default: only\n"
    "                      regular files under it)\n"
    "  --seed S            random seed (default 0); renders with different seeds merge\n"
    "  --frame N           the scene's glTF animations at frame N / --fps (all play at once:\n"
    "                      node translation, rotation, scale; meshes, cameras, lights)\n"
    "  --fps F             frames per second for --frame and --frames (default 24)\n"
    "  --at SECONDS        the animations at this time\n"
    "  --frames A-B        render frames A to B, one file each: -o and --png are patterns\n"
    "                      with one %d (e.g. out/frame_%04d.exr); stops at the first failure\n"
    "  --crop X0,Y0,X1,Y1  render only pixels [X0, X1) x [Y0, Y1) of the image, each as the\n"
    "                      whole render has it, bit for bit: an EXR whose data window is the\n"
    "                      region of the full display window (gonio merge assembles tiles);\n"
    "                      values with a '.' are fractions of the size (0,0,0.5,0.5: the\n"
    "                      top-left quarter; pixel = ceil(fraction x size), as pbrt's)\n"
    "  --resumable         EXR: also write the exact sums (sum.* channels, 32-bit float)\n"
    "                      that --resume goes on from; SIGTERM always writes them\n"
    "  --resume FILE.exr   go on from a --resumable render of the same scene, camera, crop,\n"
    "                      seed and options (checked): --spp is the total; the result is the\n"
    "                      render of --spp in one run, bit for bit\n"
    "  --aov LIST          extra EXR channels, exactly those listed: any of normal (normal.XYZ),\n"
    "                      albedo (albedo.RGB), depth (depth.Z, 0 on a miss), variance\n"
    "                      (variance.RGB: of each pixel's mean), comma-separated\n"
    "  --half              EXR: 16-bit half channels (default 32-bit float)\n"
    "  --compression C     EXR: none, rle, zips, zip (default), piz, pxr24, b44, b44a\n"
    ENV_OPTIONS_HELP
    "  --max-depth N       path: at most N bounces (default 0: unbounded, roulette ends paths)\n"
    "  --brdf MODEL[:P=V]  path: render every material with a BRDF model (see gonio brdf\n"
    "                      --list), e.g. --brdf torrance-sparrow:exponent=128:specular=0.5\n"
    "  --estimator E       path: mis (default), light or bsdf: one strategy only (tests)\n"
    "  --no-shadows        local modes: no shadow rays\n"
    "  --ambient R,G,B | V local modes: the Phong model's global ambient light (default 0)\n"
    "  --exposure E        PNG only: scale by 2^E before tonemapping (default 0)\n"
    "  --tonemap T         PNG only: clamp (default), reinhard, aces\n"
    "  --device N          Vulkan device index (see gonio devices)\n"
    "  --validate          enable the Vulkan validation layer; any message fails the render\n"
    "  --quiet             no progress and no summary line\n"
    "\n"
    "An option the mode or outputs do not use (--max-depth with phong, --ambient with path,\n"
    "--exposure without --png) is a warning. Progress goes to stderr: a bar on a terminal;\n"
    "in a log, a line at each tenth once a second has passed (by time with --time).\n"
    "Exit status: 0 ok, 1 bad input or failed render, 2 bad usage; 128 + N after signal N\n"
    "(130: Ctrl-C, 143: SIGTERM): the render stopped after its pass and wrote what it had.\n"
    "A second signal quits at once and leaves no output.\n";

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

/* A file-name pattern with exactly one %d, %Nd or %0Nd and no other '%'. */
static bool frame_pattern(const char *p)
{
    const char *c = strchr(p, '%');
    if (!c)
        return false;
    c++;
    while (*c >= '0' && *c <= '9')
        c++;
    return *c == 'd' && !strchr(c, '%');
}

/* --frames A-B: cmd_render once per frame, --frame N in place of --frames and the output
 * patterns filled in. */
static int render_frames(int argc, char **argv, int at)
{
    long a, b;
    char *dash, range[64], **args = util_calloc((size_t)argc + 1, sizeof *args);
    char frame[16], names[2][4096];
    int rc = 0;
    snprintf(range, sizeof range, "%s", argv[at + 1]);
    dash = strchr(range + 1, '-');
    if (dash)
        *dash = 0;
    if (!dash || !util_parse_int(range, 0, 1 << 24, &a) || !util_parse_int(dash + 1, 0, 1 << 24, &b) || b < a) {
        free(args);
        return cli_usage_error("render", "--frames '%s': expected A-B, frames 0 <= A <= B", argv[at + 1]);
    }
    for (int i = 1; i < argc; i++)
        if ((!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output") || !strcmp(argv[i], "--png")) && i + 1 < argc &&
            !frame_pattern(argv[i + 1])) {
            free(args);
            return cli_usage_error("render", "%s '%s': with --frames, a pattern with one %%d (e.g. frame_%%04d.exr)",
                                   argv[i], argv[i + 1]);
        } else if (!strcmp(argv[i], "--frame") || !strcmp(argv[i], "--at")) {
            free(args);
            return cli_usage_error("render", "--frames and %s exclude each other", argv[i]);
        }
    for (long f = a; f <= b && rc == 0 && !stop_requested; f++) {
        int nout = 0;
        snprintf(frame, sizeof frame, "%ld", f);
        for (int i = 0; i < argc; i++) {
            args[i] = argv[i];
            if (i == at)
                args[i] = "--frame";
            else if (i == at + 1)
                args[i] = frame;
            else if (i > 0 && (!strcmp(argv[i - 1], "-o") || !strcmp(argv[i - 1], "--output") ||
                               !strcmp(argv[i - 1], "--png")) && nout < 2) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
                snprintf(names[nout], sizeof names[0], argv[i], (int)f); /* checked: frame_pattern */
#pragma GCC diagnostic pop
                args[i] = names[nout++];
            }
        }
        rc = cmd_render(argc, args);
    }
    free(args);
    return rc;
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

/* --resume FILE: the file must be an earlier render of exactly this one (identity, seed,
 * region) with fewer samples and the sums; loads it into *prev and sets s->resume. */
static bool check_resume(const char *path, const renderer *r, render_settings *s, const char *brdf, image *prev)
{
    render_header h;
    render_stats st = {0};
    int region[4];
    double spp;
    uint32_t seed;
    render_header_build(&h, r, s, &st, brdf);
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

/* Options that the chosen mode or outputs do not use: a warning each, never silence. Reads
 * argv again (values skipped) rather than flags set by the parser, so it sees what was
 * typed, defaults included. */
static void warn_inapplicable(int argc, char **argv, const render_settings *s, const char *png_path,
                              const char *out_path)
{
    static const struct {
        const char *opt;
        int when; /* 0: path mode only; 1: local modes only; 2: with a PNG only; 3: not with
                   * --time; 4: path and albedo (the model's colour) only; 5: with an EXR only */
    } rules[] = {{"--max-depth", 0}, {"--brdf", 4}, {"--estimator", 0}, {"--ambient", 1},
                 {"--no-shadows", 1}, {"--exposure", 2}, {"--tonemap", 2}, {"--spp", 3},
                 {"--aov", 5}};
    const bool path = s->mode == GN_MODE_PATH;
    const bool png = png_path || (out_path && util_has_suffix(out_path, ".png"));
    const bool exr = out_path && util_has_suffix(out_path, ".exr");
    for (int i = 1; i < argc; i++) {
        for (size_t k = 0; k < sizeof rules / sizeof *rules; k++) {
            if (strcmp(argv[i], rules[k].opt))
                continue;
            if (rules[k].when == 0 && !path)
                util_warn("%s applies to --mode path only; ignored with --mode %s", rules[k].opt,
                          render_mode_name(s->mode));
            else if (rules[k].when == 1 && path)
                util_warn("%s applies to the local modes only; ignored with --mode path", rules[k].opt);
            else if (rules[k].when == 2 && !png)
                util_warn("%s applies to the PNG only; ignored without a PNG output", rules[k].opt);
            else if (rules[k].when == 5 && !exr)
                util_warn("%s applies to the EXR only; ignored without an EXR output", rules[k].opt);
            else if (rules[k].when == 4 && !path && s->mode != GN_MODE_ALBEDO)
                util_warn("%s applies to --mode path (and albedo, its colour) only; ignored with "
                          "--mode %s", rules[k].opt, render_mode_name(s->mode));
            else if (rules[k].when == 3 && s->time_limit > 0)
                util_warn("%s is ignored with --time: the render takes as many samples as fit",
                          rules[k].opt);
        }
        if (cli_usage_lists_value(render_usage, argv[i]))
            i++;
    }
}

int cmd_render(int argc, char **argv)
{
    const char *scene_path = NULL, *out_path = NULL, *png_path = NULL;
    const char *brdf = NULL;
    image env_map = {0};
    render_settings s = {.mode = GN_MODE_PATH, .spp = 16, .camera = -1, .shadows = true,
                         .progress = true, .stop = &stop_requested};
    camera_option cam = {0};
    env_option env = {0};
    scene_camera view;
    char camera_text[160];
    bool size_given = false, quiet = false, validate = false, studio = false, resumable = false;
    crop_option crop = {0};
    int frame = -1;      /* --frame */
    float fps = 24;
    double at = -1;      /* --at, or the frame's time */
    const char *crop_text = NULL, *resume_path = NULL;
    image prev = {0};
    int device = -1, scene_index = -1, taken;
    float exposure = 0;
    image_tonemap tm = IMAGE_TONEMAP_CLAMP;
    image_exr_options exr = IMAGE_EXR_DEFAULTS;
    const char *exr_option = NULL, *exr_path = NULL, *png_o = NULL; /* -o as EXR or as PNG */
    long v;
    scene sc = {0};
    gpu g = {0};
    renderer r = {0};
    image img = {0};
    render_stats st;
    int rc = 1;

    for (int i = 1; i + 1 < argc; i++)
        if (!strcmp(argv[i], "--frames"))
            return render_frames(argc, argv, i);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(render_usage, stdout);
            return 0;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            quiet = true;
        } else if (!strcmp(a, "--validate")) {
            validate = true;
        } else if (!strcmp(a, "--no-shadows")) {
            s.shadows = false;
        } else if (!strcmp(a, "--allow-outside-files")) {
            scene_allow_outside_files(true);
        } else if (!strcmp(a, "--resumable")) {
            resumable = true;
        } else if (!strcmp(a, "--half")) {
            exr.half = true;
            exr_option = "--half";
        } else if (a[0] == '-' && a[1]) {
            if (!(val = cli_option_value(argc, argv, &i, render_usage)))
                return 2;
            if ((taken = camera_parse_option(&cam, "render", a, val)) ||
                (taken = env_parse_option(&env, "render", a, val))) {
                if (taken == 2)
                    return 2;
            } else if (!strcmp(a, "--scene")) {
                if (!util_parse_int(val, 0, 1 << 20, &v))
                    return cli_usage_error("render", "--scene '%s': expected an index >= 0", val);
                scene_index = (int)v;
            } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
                out_path = val;
            } else if (!strcmp(a, "--png")) {
                png_path = val;
            } else if (!strcmp(a, "--mode")) {
                int m = render_mode_from_name(val);
                if (m < 0)
                    return cli_usage_error("render", "--mode '%s': expected one of %s", val,
                                           render_mode_list());
                s.mode = (uint32_t)m;
            } else if (!strcmp(a, "--spp")) {
                if (!util_parse_int(val, 1, 1 << 24, &v))
                    return cli_usage_error("render", "--spp '%s': expected an integer 1..16777216", val);
                s.spp = (int)v;
            } else if (!strcmp(a, "--time")) {
                float t;
                if (!util_parse_float(val, &t) || t <= 0)
                    return cli_usage_error("render", "--time '%s': expected seconds > 0", val);
                s.time_limit = t;
            } else if (!strcmp(a, "--size")) {
                if (!util_parse_size(val, &s.width, &s.height))
                    return cli_usage_error("render", "--size '%s': expected WxH, e.g. 640x480 (1..16384)", val);
                size_given = true;
            } else if (!strcmp(a, "--seed")) {
                if (!util_parse_int(val, 0, 0xffffffffL, &v))
                    return cli_usage_error("render", "--seed '%s': expected an integer 0..4294967295", val);
                s.seed = (uint32_t)v;
            } else if (!strcmp(a, "--frame")) {
                if (!util_parse_int(val, 0, 1 << 24, &v))
                    return cli_usage_error("render", "--frame '%s': expected a frame number >= 0", val);
                frame = (int)v;
            } else if (!strcmp(a, "--variant")) {
                scene_select_variant(val);
            } else if (!strcmp(a, "--fps")) {
                if (!util_parse_float(val, &fps) || !(fps > 0 && fps <= 1e6f))
                    return cli_usage_error("render", "--fps '%s': expected frames per second > 0", val);
            } else if (!strcmp(a, "--at")) {
                float t;
                if (!util_parse_float(val, &t) || !(t >= 0 && t <= 1e9f))
                    return cli_usage_error("render", "--at '%s': expected seconds >= 0", val);
                at = t;
            } else if (!strcmp(a, "--crop")) {
                if (!parse_crop(val, &crop))
                    return cli_usage_error("render", "--crop '%s': expected X0,Y0,X1,Y1 in pixels (integers) "
                                           "or fractions 0..1", val);
                crop_text = val;
            } else if (!strcmp(a, "--resume")) {
                resume_path = val;
            } else if (!strcmp(a, "--aov")) {
                char buf[256], *tok, *save;
                snprintf(buf, sizeof buf, "%s", val);
                s.aov = 0;
                for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
                    uint32_t bit = render_aov_from_name(tok);
                    if (!bit)
                        return cli_usage_error("render", "--aov '%s': expected a list of normal, albedo, depth, variance", tok);
                    s.aov |= bit;
                }
                if (!s.aov)
                    return cli_usage_error("render", "--aov '%s': expected a list of normal, albedo, depth, variance", val);
            } else if (!strcmp(a, "--compression")) {
                if (!image_exr_compression_from_name(val, &exr.compression))
                    return cli_usage_error("render", "--compression '%s': expected none, rle, zips, zip, piz, "
                                           "pxr24, b44 or b44a", val);
                exr_option = "--compression";
            } else if (!strcmp(a, "--ambient")) {
                if (!util_parse_rgb(val, s.ambient))
                    return cli_usage_error("render", "--ambient '%s': expected R,G,B or one value >= 0", val);
                s.ambient_set = true;
            } else if (!strcmp(a, "--max-depth")) {
                if (!util_parse_int(val, 0, 1 << 20, &v))
                    return cli_usage_error("render", "--max-depth '%s': expected an integer >= 0", val);
                s.max_depth = (int)v;
            } else if (!strcmp(a, "--brdf")) {
                if (!brdf_spec_check(val))
                    return cli_usage_error("render", "--brdf '%s': see gonio brdf --list", val);
                brdf = val;
            } else if (!strcmp(a, "--estimator")) {
                if (!strcmp(val, "mis")) s.strategy = 0;
                else if (!strcmp(val, "light")) s.strategy = GN_FRAME_LIGHT_ONLY;
                else if (!strcmp(val, "bsdf")) s.strategy = GN_FRAME_BSDF_ONLY;
                else return cli_usage_error("render", "--estimator '%s': expected mis, light or bsdf", val);
            } else if (!strcmp(a, "--exposure")) {
                if (!util_parse_float(val, &exposure))
                    return cli_usage_error("render", "--exposure '%s': expected a number", val);
            } else if (!strcmp(a, "--tonemap")) {
                if (!image_tonemap_from_name(val, &tm))
                    return cli_usage_error("render", "--tonemap '%s': expected clamp, reinhard or aces", val);
            } else if (!strcmp(a, "--device")) {
                if (!util_parse_int(val, 0, 64, &v))
                    return cli_usage_error("render", "--device '%s': expected an index (see gonio devices)", val);
                device = (int)v;
            } else {
                return cli_usage_error("render", "unknown option '%s'", a);
            }
        } else if (!scene_path) {
            scene_path = a;
        } else {
            return cli_usage_error("render", "unexpected argument '%s'", a);
        }
    }
    warn_inapplicable(argc, argv, &s, png_path, out_path);
    if (!scene_path)
        return cli_usage_error("render", "no scene given");
    if (!out_path && !png_path)
        return cli_usage_error("render", "no output given (-o OUT.exr and/or --png OUT.png)");
    /* The name says the format: -o OUT.png is the tonemapped PNG, as --png is. */
    if (out_path && image_format_of(out_path) == IMAGE_FORMAT_UNKNOWN)
        return cli_usage_error("render", "-o '%s': expected a .exr (OpenEXR) or .png name", out_path);
    if (png_path && image_format_of(png_path) != IMAGE_FORMAT_PNG)
        return cli_usage_error("render", "--png '%s': expected a .png name", png_path);
    if (out_path && image_format_of(out_path) == IMAGE_FORMAT_EXR)
        exr_path = out_path;
    else
        png_o = out_path;
    if (exr_option && !exr_path)
        return cli_usage_error("render", "%s is for an EXR output (-o OUT.exr)", exr_option);
    if (resumable && !exr_path)
        return cli_usage_error("render", "--resumable is for an EXR output (-o OUT.exr)");
    if (resume_path && image_format_of(resume_path) != IMAGE_FORMAT_EXR)
        return cli_usage_error("render", "--resume '%s': expected a .exr render", resume_path);
    exr.exact_prefix = "sum"; /* sum.* and sum2.*: the state --resume needs exactly */
    util_set_quiet(quiet);
    s.progress = !quiet;
    if ((out_path && !util_check_output(out_path)) || (png_path && !util_check_output(png_path)))
        return 1;

    if (frame >= 0 && at >= 0)
        return cli_usage_error("render", "--frame and --at exclude each other");
    if (frame >= 0)
        at = frame / (double)fps;
    scene_animation_time(at);
    if (!scene_load_scene(&sc, scene_path, scene_index))
        return 1;
    if (!render_material_overrides(&sc, brdf) || !env_setup(&env, &sc, quiet, &env_map, &s, &studio) ||
        !camera_resolve(&cam, &sc, size_given ? (float)s.width / (float)s.height : 1.0f, &view)) {
        scene_destroy(&sc);
        image_destroy(&env_map);
        return 1;
    }
    if (!size_given) {
        if (cam.width > 0) { /* --camera FILE.exr: that render's size, as its view had it */
            s.width = cam.width;
            s.height = cam.height;
        } else {
            camera_default_size(&view, 512, &s.width, &s.height);
        }
        camera_resolve(&cam, &sc, (float)s.width / (float)s.height, &view); /* framing: the real aspect */
    }
    if (crop.given && !apply_crop(&crop, &s, crop_text)) {
        scene_destroy(&sc);
        image_destroy(&env_map);
        return 2;
    }
    s.view = &view;
    camera_describe(&cam, &sc, camera_text, sizeof camera_text);
    s.camera_label = camera_text;
    s.env_label = studio ? "studio" : env.path ? env.path : env.given ? "constant" : "none";
    if (!cli_gpu_create(&g, device, validate)) {
        scene_destroy(&sc);
        image_destroy(&env_map);
        return 1;
    }
    catch_signals(quiet);
    renderer_create(&r, &g, &sc);
    if ((!resume_path || check_resume(resume_path, &r, &s, brdf, &prev)) && renderer_render(&r, &s, &img, &st)) {
        char seconds[32];
        render_header h;
        bool ok = true;
        int region[4];
        render_header_build(&h, &r, &s, &st, brdf);
        if (at >= 0 && h.count + 2 <= RENDER_HEADER_MAX) { /* the animation's time, and frame */
            h.attrs[h.count++] = (image_attr){"gonio:time", IMAGE_ATTR_DOUBLE, NULL, 0, at, NULL};
            if (frame >= 0)
                h.attrs[h.count++] = (image_attr){"gonio:frame", IMAGE_ATTR_INT, NULL, frame, 0, NULL};
        }
        if (stop_requested && !quiet)
            util_warn("interrupted: writing the %d spp rendered so far%s", st.spp,
                      stop_requested == SIGTERM && exr_path ? " (resumable: --resume)" : "");
        if (resumable || stop_requested == SIGTERM)
            renderer_sums(&r, s.aov, &img);
        render_region(&s, region);
        if (s.crop_x1 > 0) { /* the region in the whole frame: OpenEXR's data window */
            img.x0 = region[0];
            img.y0 = region[1];
            img.full_width = s.width;
            img.full_height = s.height;
        }
        if (exr_path)
            ok = image_write_exr_with(&img, exr_path, h.attrs, h.count, &exr);
        if (ok && png_o)
            ok = render_write_png(&img, s.mode, png_o, exposure, tm);
        if (ok && png_path)
            ok = render_write_png(&img, s.mode, png_path, exposure, tm);
        snprintf(seconds, sizeof seconds, "%.2f", st.seconds);
        if (ok && !quiet)
            /* One camera ray per pixel and sample: a whole path in path mode. */
            fprintf(stderr, "gonio: %s %dx%d, %s, %s, %d spp in %s s (%.2f %s), setup %.2f s\n",
                    out_path ? out_path : png_path, s.width, s.height, camera_text, render_mode_name(s.mode),
                    st.spp, seconds, st.seconds > 0 ? (double)st.rays / st.seconds * 1e-6 : 0.0,
                    s.mode == GN_MODE_PATH ? "M paths/s" : "Mrays/s primary", st.setup_seconds);
        rc = !ok ? 1 : stop_requested ? 128 + stop_requested : 0;
    }
    image_destroy(&img);
    image_destroy(&prev);
    image_destroy(&env_map);
    renderer_destroy(&r);
    if (!cli_gpu_finish(&g))
        rc = 1;
    scene_destroy(&sc);
    return rc;
}

static const char info_usage[] =
    "usage: gonio info SCENE.gltf|.glb [--allow-outside-files]\n\n"
    "Prints the scene's contents and its BVH statistics: the emissive triangles (the path\n"
    "tracer's area lights) and the materials that emit, and one line per camera (index, name,\n"
    "position, forward direction, vertical field of view or orthographic width x height;\n"
    "the first is the one gonio render uses by default), the KHR_materials_variants\n"
    "variants by index and name (for --variant), and one line per material that bounds a\n"
    "medium (KHR_materials_volume) or disperses (KHR_materials_dispersion): attenuation\n"
    "colour and distance, the absorption coefficient they give, thickness (unused by the\n"
    "path tracer), IOR and dispersion.\n";

/* The area lights as the path tracer sees them (render.c: build_emitters): triangles of
 * non-zero area whose material emits and is not unlit; prints the materials by name. */
static void print_emitters(const scene *sc)
{
    uint32_t tris = 0, mats = 0;
    uint32_t *count = util_calloc(sc->num_materials, sizeof *count);
    for (uint32_t t = 0; t < sc->num_triangles; t++) {
        const GnMaterial *m = &sc->materials[sc->tri_material[t]];
        double c[3];
        if (!(m->emissive.x > 0 || m->emissive.y > 0 || m->emissive.z > 0) || (m->flags & GN_MAT_UNLIT))
            continue;
        scene_triangle_cross(sc, t, c);
        if (!(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 0))
            continue;
        tris++;
        mats += count[sc->tri_material[t]]++ == 0;
    }
    printf("emissive       %u triangles in %u material(s)", tris, mats);
    for (uint32_t m = 0, n = 0; m < sc->num_materials; m++)
        if (count[m])
            printf("%s%s (%u)", n++ ? ", " : ": ", sc->material_names[m][0] ? sc->material_names[m] : "(unnamed)",
                   count[m]);
    printf("\n");
    free(count);
}

/* The materials with a medium or dispersion, as the path tracer reads them (glsl/path.comp:
 * sigma_a = -ln(attenuation colour) / attenuation distance). */
static void print_media(const scene *sc)
{
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        const GnMaterial *m = &sc->materials[i];
        const float *c = &m->attenuation_color.x;
        double sigma[3];
        if (!m->volume && !(m->dispersion > 0))
            continue;
        for (int k = 0; k < 3; k++)
            sigma[k] = c[k] >= 1 ? 0 : -log(c[k] > 1e-30f ? c[k] : 1e-30f) / m->attenuation_distance;
        printf("medium %-7u \"%s\" %s attenuation (%g, %g, %g) distance %g (sigma_a %g, %g, %g), "
               "thickness %g, ior %g, dispersion %g\n", i, sc->material_names[i][0] ? sc->material_names[i] : "(unnamed)",
               m->volume ? "volume" : "thin-walled", c[0], c[1], c[2], m->attenuation_distance, sigma[0], sigma[1],
               sigma[2], m->thickness, m->ior, m->dispersion);
    }
}

int cmd_info(int argc, char **argv)
{
    const char *path = NULL;
    scene sc = {0};
    bvh b = {0};
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(info_usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "--allow-outside-files")) {
            scene_allow_outside_files(true);
            continue;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("info", "unknown option '%s'", argv[i]);
        } else if (path) {
            return cli_usage_error("info", "unexpected argument '%s'", argv[i]);
        }
        path = argv[i];
    }
    if (!path)
        return cli_usage_error("info", "no scene given");
    if (!scene_load(&sc, path))
        return 1;
    bvh_build(&b, &sc.vertices[0].position.x, sizeof(GnVertex) / sizeof(float), sc.indices,
              sc.num_triangles);
    printf("scene          %s\n", path);
    printf("triangles      %u\n", sc.num_triangles);
    printf("vertices       %u\n", sc.num_vertices);
    printf("meshes         %u (primitive instances; %u glTF meshes, %u nodes)\n", sc.num_meshes,
           sc.num_gltf_meshes, sc.num_nodes);
    printf("materials      %u\n", sc.num_materials);
    printf("variants       %u\n", sc.num_variants);
    for (uint32_t i = 0; i < sc.num_variants; i++)
        printf("variant %-6u \"%s\"\n", i, sc.variant_names[i]);
    printf("textures       %u (%u images)\n", sc.num_textures, sc.num_images);
    printf("lights         %u\n", sc.num_lights);
    print_emitters(&sc);
    print_media(&sc);
    printf("cameras        %u\n", sc.num_cameras);
    for (uint32_t i = 0; i < sc.num_cameras; i++) {
        const scene_camera *c = &sc.cameras[i];
        printf("camera %-7u \"%s\" position (%g, %g, %g) forward (%g, %g, %g) ", i, c->name, c->position[0],
               c->position[1], c->position[2], c->forward[0], c->forward[1], c->forward[2]);
        if (c->ortho_half_height > 0)
            printf("orthographic %g x %g\n", 2 * c->ortho_half_height * c->aspect, 2 * c->ortho_half_height);
        else
            printf("yfov %.4g deg\n", c->yfov * 180 / M_PI);
    }
    printf("bounds         (%g, %g, %g) - (%g, %g, %g)\n", sc.bounds_min[0], sc.bounds_min[1],
           sc.bounds_min[2], sc.bounds_max[0], sc.bounds_max[1], sc.bounds_max[2]);
    printf("bvh nodes      %u (%zu bytes each)\n", b.num_nodes, sizeof(GnBvhNode));
    printf("bvh leaf prims %u (%u triangle pairs sharing an edge, %u single triangles)\n",
           b.num_pairs, b.num_tris - b.num_pairs, 2 * b.num_pairs - b.num_tris);
    printf("bvh depth      %u\n", b.depth);
    printf("bvh max leaf   %u triangle pairs\n", b.max_leaf_size);
    printf("bvh sah cost   %.2f\n", b.sah_cost);
    printf("bvh build      %.2f ms (%.2f M triangles/s)\n", b.build_seconds * 1e3,
           b.build_seconds > 0 ? sc.num_triangles / b.build_seconds * 1e-6 : 0.0);
    bvh_destroy(&b);
    scene_destroy(&sc);
    return 0;
}

int cmd_devices(int argc, char **argv)
{
    if (argc > 1 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
        puts("usage: gonio devices\n\nLists the Vulkan devices: index (for --device), name, "
             "type, driver, API version.\nWithout --device, gonio picks a discrete GPU, then "
             "an integrated one, then the CPU (lavapipe).");
        return 0;
    }
    if (argc > 1)
        return cli_usage_error("devices", argv[1][0] == '-' ? "unknown option '%s'" : "unexpected argument '%s'",
                               argv[1]);
    return gpu_print_devices() ? 0 : 1;
}
