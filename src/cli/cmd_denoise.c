/* cmd_denoise.c: `gonio denoise IN.exr -o OUT.exr`: OIDN's RT filter (src/core/denoise.h)
 * on an EXR's beauty, guided by its albedo and normal layers when it has them: gonio's own
 * renders (render --aov albedo,normal), or another renderer's under the usual layer names.
 * The output is laid out as `render --denoise` writes it: R, G, B denoised, noisy.R/G/B the
 * input's beauty, every other channel and header attribute of the input kept. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "cli.h"
#include "denoise.h"
#include "image.h"
#include "util.h"

/* The layer names each role goes by (compared without case with the last part of a layer's
 * name, so that Blender's "ViewLayer.Denoising Albedo" matches "denoising albedo"), and the
 * channel suffixes it may use. The beauty is first the unnamed layer's R, G, B. */
static const char *const beauty_names[] = {"combined", "beauty", "rgba", "rgb", "color", "colour", "noisy image", NULL};
static const char *const albedo_names[] = {"albedo", "denoising albedo", "diffuse_albedo", NULL};
static const char *const normal_names[] = {"normal", "normals", "n", "ns", "nn", "sh_normal", "denoising normal", NULL};
static const char *const rgb[] = {"R", "G", "B"}, *const xyz[] = {"X", "Y", "Z"};

/* The channels of layer `layer` ("" the unnamed one) with suffixes s[0..2] (either case);
 * false when one is missing. */
static bool layer_channels(const image *img, const char *layer, const char *const s[3], int ch[3])
{
    for (int k = 0; k < 3; k++) {
        ch[k] = -1;
        for (int c = 0; c < img->num_channels && ch[k] < 0; c++) {
            const char *dot = strrchr(img->names[c], '.'), *suffix = dot ? dot + 1 : img->names[c];
            size_t len = dot ? (size_t)(dot - img->names[c]) : 0;
            if (len == strlen(layer) && !strncmp(img->names[c], layer, len) && !strcasecmp(suffix, s[k]))
                ch[k] = c;
        }
        if (ch[k] < 0)
            return false;
    }
    return true;
}

/* Whether a layer's last name part is one of names. */
static bool layer_is(const char *layer, const char *const *names)
{
    const char *dot = strrchr(layer, '.'), *last = dot ? dot + 1 : layer;
    for (int k = 0; names[k]; k++)
        if (!strcasecmp(last, names[k]))
            return true;
    return false;
}

/* The first layer of img whose name is one of names and that has the channels of s1 (or
 * s2); the layers of the beauty's own prefix first (Blender's "ViewLayer."). */
static bool find_role(const image *img, const char *const *names, const char *const *s1, const char *const *s2,
                      const char *prefix, int ch[3], char *layer, size_t cap)
{
    for (int pass = 0; pass < 2; pass++)
        for (int c = 0; c < img->num_channels; c++) {
            const char *dot = strrchr(img->names[c], '.');
            char name[32];
            if (!dot)
                continue;
            snprintf(name, sizeof name, "%.*s", (int)(dot - img->names[c]), img->names[c]);
            if ((pass == 0) != (strncmp(name, prefix, strlen(prefix)) == 0) || !layer_is(name, names))
                continue;
            if (layer_channels(img, name, s1, ch) || (s2 && layer_channels(img, name, s2, ch))) {
                snprintf(layer, cap, "%s", name);
                return true;
            }
        }
    return false;
}

/* A guide given as another file: its layer of the role (or its unnamed R,G,B / X,Y,Z),
 * appended to img as LAYER.R/G/B or .X/Y/Z. */
static bool guide_from_file(image *img, const char *in_path, const char *path, const char *role,
                            const char *const *names, const char *const *s, int ch[3])
{
    image g = {0};
    char layer[32] = "";
    int gc[3];
    bool ok = false;
    if (!image_read_exr(&g, path))
        return false;
    if (g.width != img->width || g.height != img->height || g.x0 != img->x0 || g.y0 != img->y0) {
        util_error("%s: its %dx%d pixels at (%d, %d) are not those of %s, %dx%d at (%d, %d): the %s must be "
                   "the same image's", path, g.width, g.height, g.x0, g.y0, in_path, img->width, img->height,
                   img->x0, img->y0, role);
    } else if (!find_role(&g, names, s, s == rgb ? xyz : rgb, "", gc, layer, sizeof layer) &&
               !layer_channels(&g, "", s, gc) && !layer_channels(&g, "", s == rgb ? xyz : rgb, gc)) {
        util_error("%s: no %s layer (%s.%s/%s/%s) and no %s, %s, %s channels", path, role, role, s[0], s[1], s[2],
                   s[0], s[1], s[2]);
    } else if (img->num_channels + 3 > IMAGE_MAX_CHANNELS) {
        util_error("%s: too many channels to add the %s of %s", in_path, role, path);
    } else {
        /* As ROLE.R/G/B (or .X/Y/Z); the file's guide replaces the input's own of that name. */
        ok = true;
        for (int k = 0; k < 3; k++) {
            char name[32];
            int c;
            snprintf(name, sizeof name, "%s.%s", role, s[k]);
            if ((c = image_channel(img, name)) >= 0) {
                free(img->planes[c]);
            } else {
                c = img->num_channels++;
                snprintf(img->names[c], sizeof img->names[0], "%s", name);
            }
            img->planes[c] = g.planes[gc[k]];
            g.planes[gc[k]] = NULL;
            ch[k] = c;
        }
    }
    image_destroy(&g);
    return ok;
}

/* A guide option's value: "none", a layer of IN.exr, or another EXR file. */
static bool guide(image *img, const char *in_path, const char *opt, const char *value, const char *role,
                  const char *const *names, const char *const *s, const char *prefix, int ch[3], char *desc,
                  size_t cap)
{
    struct stat sb;
    const char *const *s2 = s == rgb ? xyz : rgb;
    ch[0] = ch[1] = ch[2] = -1;
    if (value && !strcmp(value, "none")) {
        snprintf(desc, cap, "none");
        return true;
    }
    if (value && (image_format_of(value) == IMAGE_FORMAT_EXR || stat(value, &sb) == 0) &&
        !layer_channels(img, value, s, ch) && !layer_channels(img, value, s2, ch)) {
        snprintf(desc, cap, "%s of %s", role, value);
        return guide_from_file(img, in_path, value, role, names, s, ch);
    }
    if (value) {
        if (layer_channels(img, value, s, ch) || layer_channels(img, value, s2, ch)) {
            snprintf(desc, cap, "layer '%s'", value);
            return true;
        }
        util_error("%s: %s '%s': no layer %s with channels %s.%s/%s/%s (nor an EXR file of that name)", in_path, opt,
                   value, value, value, s[0], s[1], s[2]);
        return false;
    }
    if (find_role(img, names, s, s2, prefix, ch, desc + 7, cap - 7)) {
        memcpy(desc, "layer '", 7);
        snprintf(desc + strlen(desc), cap - strlen(desc), "'");
        return true;
    }
    ch[0] = ch[1] = ch[2] = -1;
    snprintf(desc, cap, "none found");
    return true;
}

static bool regular_input(const char *path)
{
    struct stat sb;
    if (stat(path, &sb) != 0) {
        util_error("%s: cannot read: no such file", path);
        return false;
    }
    if (!S_ISREG(sb.st_mode)) {
        util_error("%s: is not a regular file (a directory, FIFO or device); gonio denoise reads EXR files", path);
        return false;
    }
    return true;
}

#define DENOISE_INTRO                                                                            \
    "Denoises an OpenEXR render with Intel Open Image Denoise's RT filter, as render --denoise\n" \
    "does: the beauty (linear HDR) guided by the albedo and normal when the file has them;\n"   \
    "the guides are prefiltered and then passed as clean (OIDN's advice for final frames).\n"   \
    "\n"                                                                                          \
    "The beauty is the unnamed layer's R, G, B, or a layer called Combined, beauty, RGBA,\n"    \
    "RGB or color (Blender's ViewLayer.Combined); in a file render --denoise wrote, its\n"      \
    "noisy layer. The albedo is a layer called albedo or Denoising Albedo (R, G, B), the\n"     \
    "normal one called normal, N, Ns, nn, sh_normal or Denoising Normal (X, Y, Z or R, G, B),\n" \
    "in either case; --albedo and --normal name another layer, another EXR of the same size,\n"   \
    "or none.\n"                                                                                 \
    "\n"                                                                                          \
    "The output: R, G, B denoised; noisy.R/G/B the input's beauty; every other channel and\n"    \
    "the input's header attributes kept, with gonio:denoiser (the library, its version and\n"    \
    "what it did) and gonio:denoise-seconds added. gonio merge refuses denoised files.\n"

#define DENOISE_EPILOG                                                                          \
    "A NaN or infinite value in the beauty or a guide, a missing beauty, a guide of another\n" \
    "size, or a file that is not a readable EXR is an error naming the file (exit 1, no\n"     \
    "output); so is a missing library, with the command that fetches it (make denoiser).\n"

int cmd_denoise(int argc, char **argv)
{
    const char *out_path = NULL, *png_path = NULL, *beauty_opt = NULL, *albedo_opt = NULL, *normal_opt = NULL;
    bool quiet = false, no_prefilter = false;
    float exposure = 0;
    image_tonemap tm = IMAGE_TONEMAP_CLAMP;
    image_exr_options exr = IMAGE_EXR_DEFAULTS;
    const cli_option options[] = {
        {"-o, --output", "FILE", "the denoised image: .exr (layers as above) or .png (tonemapped\n"
                                 "sRGB); written atomically",
         CLI_STRING, CLI_AS(const char *, &out_path), 0, 0, NULL, NULL, "*.exr *.png"},
        CLI_OPT_PNG(&png_path, "also write the denoised image as PNG"),
        {"--beauty", "LAYER", "the layer to denoise (default: found as above)", CLI_STRING,
         CLI_AS(const char *, &beauty_opt), 0, 0, NULL, NULL, NULL},
        {"--albedo", "LAYER|FILE|none", "the albedo guide (default: found as above)", CLI_STRING,
         CLI_AS(const char *, &albedo_opt), 0, 0, NULL, NULL, "none *.exr"},
        {"--normal", "LAYER|FILE|none", "the normal guide (default: found as above)", CLI_STRING,
         CLI_AS(const char *, &normal_opt), 0, 0, NULL, NULL, "none *.exr"},
        {"--no-prefilter", NULL, "pass the guides as they are (noisy guides: OIDN's cleanAux off)",
         CLI_FLAG, CLI_AS(bool, &no_prefilter), 0, 0, NULL, NULL, NULL},
        CLI_OPT_EXR_HALF(&exr.half),
        CLI_OPT_EXR_COMPRESSION(&exr.compression),
        CLI_OPT_EXPOSURE(&exposure, "PNG only: scale by 2^E before tonemapping (default 0)"),
        CLI_OPT_TONEMAP(&tm, "PNG only: clamp (default), reinhard, aces"),
        CLI_OPT_QUIET(&quiet, "no summary line"),
    };
    const cli_command cmd = {.name = "denoise", .synopsis = "IN.exr -o OUT.exr|OUT.png [options]",
                             .intro = DENOISE_INTRO, CLI_OPTIONS(options), .epilog = DENOISE_EPILOG,
                             .min_args = 1, .max_args = 1, .missing = "no input EXR given",
                             .complete_args = "*.exr"};
    cli_args args;
    int rc = cli_parse(&cmd, argc, argv, &args);
    const char *in_path, *exr_path = NULL, *png_o = NULL;
    image img = {0};
    image_attr_list in_attrs = {0};
    image_attr *attrs = NULL;
    denoise_channels ch;
    denoise_info info;
    char beauty_desc[64] = "", albedo_desc[300] = "", normal_desc[300] = "", prefix[32] = "", already[256];
    int na = 0;
    bool ok;

    if (rc >= 0)
        return rc;
    in_path = args.arg[0];
    if ((rc = cli_image_outputs("denoise", out_path, png_path, &exr_path)) >= 0)
        return rc;
    if (!exr_path)
        png_o = out_path;
    if ((cli_given(&cmd, &args, "--half") || cli_given(&cmd, &args, "--compression")) && !exr_path)
        return cli_usage_error("denoise", "--half and --compression are for an EXR output (-o OUT.exr)");
    util_set_quiet(quiet);
    if (!regular_input(in_path) || (out_path && !util_check_output(out_path)) ||
        (png_path && !util_check_output(png_path)) || !denoise_load() || !image_read_exr(&img, in_path))
        return 1;
    rc = 1;

    /* The beauty: --beauty, the noisy layer of a denoised file, R/G/B, or a named layer. */
    if (beauty_opt) {
        if (!layer_channels(&img, beauty_opt, rgb, ch.beauty)) {
            util_error("%s: --beauty '%s': no channels %s.R, %s.G, %s.B", in_path, beauty_opt, beauty_opt, beauty_opt,
                       beauty_opt);
            goto done;
        }
        snprintf(beauty_desc, sizeof beauty_desc, "layer '%s'", beauty_opt);
        snprintf(prefix, sizeof prefix, "%s", beauty_opt);
    } else if (image_exr_attr_string(in_path, "gonio:denoiser", already, sizeof already) &&
               layer_channels(&img, DENOISE_NOISY_LAYER, rgb, ch.beauty)) {
        util_info("%s: denoised already (%s): denoising its %s layer again", in_path, already, DENOISE_NOISY_LAYER);
        snprintf(beauty_desc, sizeof beauty_desc, "layer '%s'", DENOISE_NOISY_LAYER);
    } else if (layer_channels(&img, "", rgb, ch.beauty)) {
        snprintf(beauty_desc, sizeof beauty_desc, "R, G, B");
    } else if (find_role(&img, beauty_names, rgb, NULL, "", ch.beauty, prefix, sizeof prefix)) {
        snprintf(beauty_desc, sizeof beauty_desc, "layer '%s'", prefix);
    } else {
        char list[IMAGE_MAX_CHANNELS * 33] = "";
        for (int c = 0; c < img.num_channels; c++)
            strcat(strcat(list, c ? ", " : ""), img.names[c]);
        util_error("%s: no beauty to denoise: no R, G, B channels and no Combined, beauty, RGBA or color layer "
                   "(it has %s); --beauty names one", in_path, list);
        goto done;
    }
    /* Guides of the beauty's view layer first: "ViewLayer." of "ViewLayer.Combined". */
    {
        char *dot = strrchr(prefix, '.');
        if (dot)
            dot[1] = 0;
        else
            prefix[0] = 0;
    }
    if (!guide(&img, in_path, "--albedo", albedo_opt, "albedo", albedo_names, rgb, prefix, ch.albedo, albedo_desc,
               sizeof albedo_desc) ||
        !guide(&img, in_path, "--normal", normal_opt, "normal", normal_names, xyz, prefix, ch.normal, normal_desc,
               sizeof normal_desc))
        goto done;
    if (ch.albedo[0] < 0 && !albedo_opt)
        util_warn("%s: no albedo layer: denoising the beauty alone keeps less detail (gonio render --aov "
                  "albedo,normal writes the guides)", in_path);
    if (ch.albedo[0] < 0 && ch.normal[0] >= 0) {
        util_warn("%s: a normal guide without an albedo one is not used (OIDN takes the normal only with an albedo)",
                  in_path);
        ch.normal[0] = ch.normal[1] = ch.normal[2] = -1;
        snprintf(normal_desc, sizeof normal_desc, "not used");
    }
    if (!denoise_image(&img, &ch, !no_prefilter, &info, in_path))
        goto done;

    /* The input's header, less what this run says anew. */
    if (exr_path && !image_exr_attrs(in_path, &in_attrs))
        goto done;
    attrs = util_calloc((size_t)in_attrs.count + 3, sizeof *attrs);
    for (int k = 0; k < in_attrs.count; k++)
        if (strcmp(in_attrs.attrs[k].name, "gonio:denoiser") && strcmp(in_attrs.attrs[k].name, "gonio:denoise-seconds") &&
            strcmp(in_attrs.attrs[k].name, "gonio:denoise-command"))
            attrs[na++] = in_attrs.attrs[k];
    attrs[na++] = (image_attr){"gonio:denoiser", IMAGE_ATTR_STRING, info.description, 0, 0, NULL};
    attrs[na++] = (image_attr){"gonio:denoise-seconds", IMAGE_ATTR_DOUBLE, NULL, 0, info.seconds, NULL};
    attrs[na++] = (image_attr){"gonio:denoise-command", IMAGE_ATTR_STRING, cli_command_line(), 0, 0, NULL};
    ok = (!exr_path || image_write_exr_with(&img, exr_path, attrs, na, &exr)) &&
         (!png_o || image_write_png_from(&img, png_o, exposure, tm)) &&
         (!png_path || image_write_png_from(&img, png_path, exposure, tm));
    if (ok) {
        rc = 0;
        if (!quiet)
            fprintf(stderr, "gonio: %s %dx%d denoised in %.2f s (%s); beauty %s, albedo %s, normal %s\n",
                    out_path ? out_path : png_path, img.width, img.height, info.seconds, info.description,
                    beauty_desc, albedo_desc, normal_desc);
    }
done:
    free(attrs);
    image_attr_list_destroy(&in_attrs);
    image_destroy(&img);
    denoise_shutdown();
    return rc;
}
