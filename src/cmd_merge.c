/* cmd_merge.c: `gonio merge`: renders of one scene with different seeds -> one image, each
 * pixel the mean of all N = sum n_i samples (sum n_i x_i / N), so the result is the render
 * of N spp. Variance channels combine through the sums of squares they imply:
 * sum x^2 = n (v (n - 1) + m^2) for a file's mean m and variance of the mean v. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "image.h"
#include "util.h"

static const char merge_usage[] =
    "usage: gonio merge A.exr B.exr ... -o OUT.exr\n"
    "\n"
    "Combines renders of the same scene and settings made with different --seed values\n"
    "into one, weighted by each file's sample count (its gonio:spp header): the result is\n"
    "exactly the mean of all the samples, with gonio:spp their total. Every input needs the\n"
    "same size and channels. variance.R/G/B channels are merged exactly too.\n"
    "\n"
    "  -o, --output FILE   the merged EXR (written atomically)\n";

/* The channel whose mean a variance channel describes ("variance.R" -> "R"), or NULL. */
static const char *variance_of(const char *name)
{
    return strncmp(name, "variance.", 9) == 0 ? name + 9 : NULL;
}

int cmd_merge(int argc, char **argv)
{
    const char *out_path = NULL, **inputs = util_calloc((size_t)argc, sizeof *inputs);
    int n = 0, rc = 1;
    image *imgs = NULL, out = {0};
    double *spp = NULL, total = 0, seconds = 0, seed0 = 0;
    char mode[64] = "";

    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(merge_usage, stdout);
            free(inputs);
            return 0;
        } else if (!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) {
            if (!(out_path = cli_value(argc, argv, &i))) {
                free(inputs);
                return 2;
            }
        } else if (argv[i][0] == '-' && argv[i][1]) {
            free(inputs);
            return cli_usage_error("merge", "unknown option '%s'", argv[i]);
        } else {
            inputs[n++] = argv[i];
        }
    }
    if (!out_path || n < 1) {
        free(inputs);
        return cli_usage_error("merge", out_path ? "no input files" : "no output given (-o OUT.exr)");
    }

    imgs = util_calloc((size_t)n, sizeof *imgs);
    spp = util_calloc((size_t)n, sizeof *spp);
    for (int i = 0; i < n; i++) {
        double s, seed;
        if (!image_read_exr(&imgs[i], inputs[i]))
            goto done;
        if (!image_exr_attr_double(inputs[i], "gonio:spp", &spp[i]) || !(spp[i] >= 1)) {
            util_error("%s: no gonio:spp sample count in the header (not a gonio render?)", inputs[i]);
            goto done;
        }
        if (imgs[i].width != imgs[0].width || imgs[i].height != imgs[0].height ||
            imgs[i].num_channels != imgs[0].num_channels) {
            util_error("%s: %dx%d with %d channels, but %s is %dx%d with %d", inputs[i],
                       imgs[i].width, imgs[i].height, imgs[i].num_channels, inputs[0],
                       imgs[0].width, imgs[0].height, imgs[0].num_channels);
            goto done;
        }
        for (int c = 0; c < imgs[0].num_channels; c++)
            if (image_channel(&imgs[i], imgs[0].names[c]) < 0) {
                util_error("%s: has no channel '%s' (which %s has)", inputs[i], imgs[0].names[c], inputs[0]);
                goto done;
            }
        if (image_exr_attr_double(inputs[i], "gonio:seed", &seed)) {
            if (i == 0)
                seed0 = seed;
            else if (seed == seed0)
                util_warn("%s: same seed (%.0f) as %s: its samples repeat, they add no information",
                          inputs[i], seed, inputs[0]);
        }
        if (image_exr_attr_double(inputs[i], "gonio:seconds", &s))
            seconds += s;
        total += spp[i];
    }
    if (!image_exr_attr_string(inputs[0], "gonio:mode", mode, sizeof mode))
        strcpy(mode, "?");

    {
        const char *names[IMAGE_MAX_CHANNELS];
        const size_t pixels = (size_t)imgs[0].width * imgs[0].height;
        for (int c = 0; c < imgs[0].num_channels; c++)
            names[c] = imgs[0].names[c];
        image_create(&out, imgs[0].width, imgs[0].height, imgs[0].num_channels, names);
        for (int c = 0; c < out.num_channels; c++) {
            const char *of = variance_of(names[c]);
            int mc = of ? image_channel(&imgs[0], of) : -1;
            for (size_t p = 0; p < pixels; p++) {
                double sum = 0, sq = 0;
                for (int i = 0; i < n; i++) {
                    double x = imgs[i].planes[image_channel(&imgs[i], names[c])][p];
                    if (mc >= 0) { /* back to the sums of x and x^2 of this file */
                        double m = imgs[i].planes[image_channel(&imgs[i], of)][p];
                        sum += spp[i] * m;
                        sq += spp[i] * (x * (spp[i] - 1) + m * m);
                    } else {
                        sum += spp[i] * x;
                    }
                }
                if (mc >= 0) {
                    double m = sum / total, v = total > 1 ? (sq / total - m * m) / (total - 1) : 0;
                    out.planes[c][p] = v > 0 ? (float)v : 0;
                } else {
                    out.planes[c][p] = (float)(sum / total);
                }
            }
        }
    }
    {
        image_attr attrs[] = {
            {"gonio:spp", IMAGE_ATTR_INT, NULL, (int)total, 0, NULL},
            {"gonio:mode", IMAGE_ATTR_STRING, mode, 0, 0, NULL},
            {"gonio:seconds", IMAGE_ATTR_DOUBLE, NULL, 0, seconds, NULL},
            {"gonio:command", IMAGE_ATTR_STRING, cli_command_line(), 0, 0, NULL},
            {"gonio:version", IMAGE_ATTR_STRING, GONIO_VERSION, 0, 0, NULL},
        };
        if (image_write_exr(&out, out_path, attrs, sizeof attrs / sizeof *attrs))
            rc = 0;
    }
done:
    for (int i = 0; i < n && imgs; i++)
        image_destroy(&imgs[i]);
    image_destroy(&out);
    free(imgs);
    free(spp);
    free(inputs);
    return rc;
}
