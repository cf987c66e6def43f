/* cmd_diff.c: `gonio diff A.exr B.exr`: RMSE, PSNR, MAE, relative bias and maximum error of A
 * against the reference B (formulas in image.h), with thresholds that set the exit status for
 * scripts: 0 within limits, 1 over a limit or a bad input, 2 bad usage. */
#include "cli.h"
#include "image.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char usage[] = "usage: gonio diff A.exr B.exr [--max-rmse X] [--max-rel-bias X] [--max-error X]\n"
                            "                  [--channels R,G,B] [--quiet]\n"
                            "  B is the reference; rel_bias = (mean A - mean B) / |mean B|\n";

/* Same form as cli_usage_error, plus the usage text; kept here so that cmd_diff links
 * without main.c (the unit tests call it in-process). */
static int bad_usage(const char *what, const char *arg)
{
    fprintf(stderr, "gonio diff: %s%s\n%s", what, arg, usage);
    return 2;
}

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

int cmd_diff(int argc, char **argv)
{
    static const char *const limit_flags[3] = {"--max-rmse", "--max-rel-bias", "--max-error"};
    double limits[3] = {-1, -1, -1}; /* negative: no limit */
    char names[IMAGE_MAX_CHANNELS][32];
    const char *files[2];
    image img[2] = {{0}, {0}};
    int num_files = 0, num_names = 0, status = 1;
    bool quiet = false;

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int k = 0;
        while (k < 3 && strcmp(a, limit_flags[k]) != 0)
            k++;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--quiet")) {
            quiet = true;
        } else if (k < 3 || !strcmp(a, "--channels")) {
            float v;
            if (i + 1 >= argc)
                return bad_usage("missing value after ", a);
            a = argv[++i];
            if (k == 3 && !parse_channels(a, names, &num_names))
                return bad_usage("bad channel list: ", a);
            if (k < 3 && (!util_parse_float(a, &v) || v < 0))
                return bad_usage("not a non-negative number: ", a);
            if (k < 3)
                limits[k] = v;
        } else if (a[0] == '-' && a[1]) {
            return bad_usage("unknown option ", a);
        } else if (num_files == 2) {
            return bad_usage("unexpected argument ", a);
        } else {
            files[num_files++] = a;
        }
    }
    if (num_files != 2)
        return bad_usage("expected two images", "");

    if (image_read_exr(&img[0], files[0]) && image_read_exr(&img[1], files[1]))
        status = diff_images(files, img, names, num_names, limits, quiet);
    image_destroy(&img[0]);
    image_destroy(&img[1]);
    return status;
}
