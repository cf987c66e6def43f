/* cmd_diff.c: `gonio diff A.exr B.exr`: RMSE, PSNR, MAE, relative bias and maximum error of A
 * against the reference B (formulas in image.h), with thresholds that set the exit status for
 * scripts: 0 within limits, 1 over a limit or a bad input, 2 bad usage. */
#include "cli.h"
#include "image.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* "R,G,B" -> names; false on an empty, too long or surplus name. */
static bool parse_channels(const char *list, char names[IMAGE_MAX_CHANNELS][32], int *n)
{
    *n = 0;
    for (const char *s = list;; s++) {
        size_t len = strcspn(s, ",");
        if (len == 0 || len >= 32 || *n == IMAGE_MAX_CHANNELS)
            return false;
        memcpy(names[*n], s, len);
        names[(*n)++][len] = 0;
        s += len;
        if (!*s)
            return true;
    }
}

static long count_nonfinite(const image *img)
{
    long n = 0;
    for (int c = 0; c < img->num_channels; c++)
        for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++)
            n += !isfinite(img->planes[c][i]);
    return n;
}

static bool has_channels(const image *img, const char *path, char names[][32], int n)
{
    for (int k = 0; k < n; k++) {
        if (image_channel(img, names[k]) < 0) {
            char list[IMAGE_MAX_CHANNELS * 33] = "";
            for (int c = 0; c < img->num_channels; c++)
                strcat(strcat(list, c ? "," : ""), img->names[c]);
            util_error("%s: no channel '%s' (it has %s)", path, names[k], list);
            return false;
        }
    }
    return true;
}

static int diff_images(const char *const files[2], const image img[2], char names[][32], int num_names,
                       double limits[3], bool quiet)
{
    static const char *const limit_names[3] = {"rmse", "rel_bias", "max_err"};
    const char *name_ptrs[IMAGE_MAX_CHANNELS];
    image_metrics m;
    double values[3];
    int status = 0;
    bool ok;

    if (img[0].width != img[1].width || img[0].height != img[1].height) {
        util_error("%s: size %dx%d differs from %s: %dx%d", files[0], img[0].width, img[0].height, files[1],
                   img[1].width, img[1].height);
        return 1;
    }
    for (int k = 0; k < num_names; k++)
        name_ptrs[k] = names[k];
    if (num_names)
        ok = has_channels(&img[0], files[0], names, num_names) && has_channels(&img[1], files[1], names, num_names) &&
             image_compare_channels(&img[0], &img[1], name_ptrs, num_names, &m);
    else
        ok = image_compare(&img[0], &img[1], &m);
    if (!ok)
        return 1;
    if (!quiet)
        printf("rmse %.6g\npsnr %.2f dB\nmae %.6g\nrel_bias %.6g\nmax_err %.6g\n", m.rmse, m.psnr, m.mae,
               m.rel_bias, m.max_err);
    for (int f = 0; f < 2; f++) {
        long bad = count_nonfinite(&img[f]);
        if (bad) {
            util_error("%s: %ld NaN/Inf values", files[f], bad);
            status = 1;
        }
    }
    values[0] = m.rmse;
    values[1] = fabs(m.rel_bias);
    values[2] = m.max_err;
    for (int k = 0; k < 3; k++) {
        if (limits[k] >= 0 && !(values[k] <= limits[k])) {
            fprintf(stderr, "gonio: diff: %s %.6g > %g\n", limit_names[k], values[k], limits[k]);
            status = 1;
        }
    }
    return status;
}

typedef struct channel_list {
    char names[IMAGE_MAX_CHANNELS][32];
    int n;
} channel_list;

static bool take_channels(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    channel_list *c = dest;
    return parse_channels(val, c->names, &c->n);
}

int cmd_diff(int argc, char **argv)
{
    float limits[3] = {-1, -1, -1}; /* negative: no limit */
    channel_list channels = {.n = 0};
    bool quiet = false;
    const cli_option options[] = {
        {"--max-rmse", "X", "exit 1 when the RMSE is above X", CLI_FLOAT, CLI_AS(float, &limits[0]), 0, 3e38,
         "a number >= 0", NULL, NULL},
        {"--max-rel-bias", "X", "exit 1 when |rel_bias| is above X", CLI_FLOAT, CLI_AS(float, &limits[1]), 0, 3e38,
         "a number >= 0", NULL, NULL},
        {"--max-error", "X", "exit 1 when the largest absolute difference is above X", CLI_FLOAT, CLI_AS(float, &limits[2]), 0, 3e38, "a number >= 0", NULL, NULL},
        {"--channels", "R,G,B", "compare these channels (default: R, G and B where both have\nthem, else the first channel of each)",
         CLI_CALL, &channels, 0, 0, "a comma-separated list of channel names", take_channels, NULL},
        CLI_OPT_QUIET(&quiet, "print no metrics (limits and errors still go to stderr)"),
    };
    const cli_command cmd = {
        .name = "diff", .synopsis = "A.exr B.exr [options]",
        .intro = "Compares two EXR images and prints rmse, psnr, mae, rel_bias and max_err. B is the\n"
                 "reference: rel_bias = (mean A - mean B) / |mean B|. Exit 1 above a limit or on\n"
                 "NaN/Inf values.\n",
        CLI_OPTIONS(options), .min_args = 2, .max_args = 2, .missing = "expected two images",
        .complete_args = "*.exr"};
    cli_args args;
    image img[2] = {{0}, {0}};
    int status = cli_parse(&cmd, argc, argv, &args);
    double limit[3] = {limits[0], limits[1], limits[2]};
    if (status >= 0)
        return status;
    status = 1;
    if (image_read_exr(&img[0], args.arg[0]) && image_read_exr(&img[1], args.arg[1]))
        status = diff_images((const char *const *)args.arg, img, channels.names, channels.n, limit, quiet);
    image_destroy(&img[0]);
    image_destroy(&img[1]);
    return status;
}
