/* image.h: float images (planar channels), OpenEXR read/write through OpenEXR's C API
 * (openexr.h), sRGB PNG output, tonemapping, and the image metrics behind `gonio diff`. */
#ifndef GONIO_IMAGE_H
#define GONIO_IMAGE_H

#include <stdbool.h>
#include <stdint.h>

#define IMAGE_MAX_CHANNELS 32

typedef struct image {
    int width, height;
    /* Where the pixels are in a larger picture, OpenEXR's data window inside its display
     * window: the top-left pixel (x0, y0) of a full_width x full_height frame; full_width 0
     * means the image is the whole frame. */
    int x0, y0, full_width, full_height;
    int num_channels;
    char names[IMAGE_MAX_CHANNELS][32]; /* EXR channel names, e.g. "R", "G", "B", "A", "normal.X" */
    float *planes[IMAGE_MAX_CHANNELS];  /* width * height floats each, rows top to bottom */
    /* How image_read_exr found each channel stored (IMAGE_STORED_NONE for an image made in
     * memory): data that must be exact (a --resume file's sums) must have been float. */
    unsigned char stored[IMAGE_MAX_CHANNELS];
} image;
enum { IMAGE_STORED_NONE, IMAGE_STORED_UINT, IMAGE_STORED_HALF, IMAGE_STORED_FLOAT };
/* The data window lies inside the display window (always, for an image that is the whole
 * frame). */
bool image_inside_frame(const image *img);

typedef enum image_attr_type { IMAGE_ATTR_STRING, IMAGE_ATTR_INT, IMAGE_ATTR_DOUBLE, IMAGE_ATTR_M44F } image_attr_type;

typedef struct image_attr {
    const char *name;   /* e.g. "gonio:spp" */
    image_attr_type type;
    const char *s;
    int i;
    double d;
    const float *m;     /* IMAGE_ATTR_M44F: 16 floats, row by row (OpenEXR's M44f) */
} image_attr;

/* Allocates zeroed planes for the named channels. */
void image_create(image *img, int width, int height, int num_channels, const char *const *names);
void image_destroy(image *img); /* accepts a zeroed struct */
/* Index of a channel by name, or -1. */
int image_channel(const image *img, const char *name);
/* Removes channel c (its plane freed); the later channels move up one. */
void image_remove_channel(image *img, int c);

/* The file formats an output name can ask for, by its extension (case-insensitive). */
typedef enum image_format { IMAGE_FORMAT_UNKNOWN, IMAGE_FORMAT_EXR, IMAGE_FORMAT_PNG } image_format;
/* ".exr" -> EXR, ".png" -> PNG, anything else (or no extension) -> UNKNOWN. */
image_format image_format_of(const char *path);

typedef struct image_exr_options {
    bool half;       /* 16-bit half channels instead of 32-bit float */
    int compression; /* an exr_compression_t (openexr.h) */
    const char *exact_prefix; /* channels whose names start with it stay float under half */
} image_exr_options;
#define IMAGE_EXR_DEFAULTS ((image_exr_options){false, 3 /* EXR_COMPRESSION_ZIP */, NULL})

/* The compressions OpenEXR's C API can write: none, rle, zips, zip, piz, pxr24, b44, b44a
 * (pxr24 is lossy for float channels, b44/b44a for half ones and keep float ones whole).
 * False for any other name. */
bool image_exr_compression_from_name(const char *name, int *out);
/* The names image_exr_compression_from_name takes, ", "-separated. */
const char *image_exr_compression_list(void);
/* Writes every channel as 32-bit float (or half, opt->half) with opt->compression (NULL:
 * IMAGE_EXR_DEFAULTS) and the given header attributes; the data window is the image, at
 * (x0, y0) of a full_width x full_height display window when full_width > 0. Written to a temporary file beside
 * path and renamed, so failure leaves no partial file. False (and an error naming the
 * file) on failure. */
bool image_write_exr_with(const image *img, const char *path, const image_attr *attrs, int num_attrs,
                          const image_exr_options *opt);
/* The same with IMAGE_EXR_DEFAULTS: float channels, ZIP. */
bool image_write_exr(const image *img, const char *path, const image_attr *attrs, int num_attrs);

/* Reads a scanline or tiled EXR (half, float or uint channels) into float planes: the data
 * window's pixels, with x0, y0, full_width, full_height saying where they are in the
 * display window (full_width 0 when the two are the same). False
 * with an error naming the file on any problem (missing, not EXR, truncated). Attributes
 * of type string/int/float/double can be fetched with image_exr_attr_double/string. */
bool image_read_exr(image *img, const char *path);
/* Reads one attribute from an EXR header as a double (int, float or double attributes) or
 * string; false if absent. */
bool image_exr_attr_double(const char *path, const char *name, double *out);
bool image_exr_attr_string(const char *path, const char *name, char *out, int cap);
/* The size of an EXR's data window; false if path is not a readable EXR. */
bool image_exr_size(const char *path, int *width, int *height);
/* The header attributes of an EXR that image_write_exr_with can write again: string, int,
 * double, m44f, and float (as double); OpenEXR's required attributes (channels, windows,
 * compression...) and other types left out. False (with an error) if path is not a readable
 * EXR. The list owns its names and values: image_attr_list_destroy frees them. */
typedef struct image_attr_list {
    int count;
    image_attr *attrs;
} image_attr_list;
bool image_exr_attrs(const char *path, image_attr_list *out);
void image_attr_list_destroy(image_attr_list *l); /* accepts a zeroed struct */

typedef enum image_tonemap { IMAGE_TONEMAP_CLAMP, IMAGE_TONEMAP_ACES, IMAGE_TONEMAP_REINHARD } image_tonemap;

/* "clamp", "aces", "reinhard" <-> image_tonemap; false for an unknown name. */
bool image_tonemap_from_name(const char *name, image_tonemap *out);
const char *image_tonemap_name(image_tonemap tm);
/* Every tonemap's name, ", "-separated. */
const char *image_tonemap_list(void);

/* Linear RGB planes -> 8-bit sRGB RGBA (alpha 255): scale by 2^exposure, tonemap, sRGB
 * transfer function, round. NaN maps to 0. */
void image_to_srgb8(const float *r, const float *g, const float *b, int width, int height,
                    float exposure, image_tonemap tm, uint8_t *rgba8);

/* Writes 8-bit RGBA pixels as PNG (libpng), through a temporary file. */
bool image_write_png(const char *path, const uint8_t *rgba8, int width, int height);
/* Convenience: the R, G, B channels of img (or the first channel as grey) -> PNG. */
bool image_write_png_from(const image *img, const char *path, float exposure, image_tonemap tm);
/* Reads a PNG into 8-bit RGBA (tests and comparisons). */
bool image_read_png(const char *path, uint8_t **rgba8, int *width, int *height);

typedef struct image_metrics {
    double rmse;        /* sqrt(mean((a-b)^2)) over the compared channels and pixels */
    double psnr;        /* 20 log10(peak / rmse), peak = max(|b|) (1 when b is all zero) */
    double mae;         /* mean |a-b| */
    double rel_bias;    /* (mean(a) - mean(b)) / |mean(b)|; 0 when both means are 0 */
    double max_err;     /* max |a-b| */
    long nonfinite;     /* NaN/Inf values found in a or b */
} image_metrics;

/* Compares the channels present in both images among R, G, B (or the first channel of
 * each when neither has RGB). False with an error when sizes differ or nothing matches.
 * NaN/Inf values are counted in nonfinite and their pixel pairs left out of the other metrics. */
bool image_compare(const image *a, const image *b, image_metrics *m);
/* The same over the n named channels, each of which must exist in both images. */
bool image_compare_channels(const image *a, const image *b, const char *const *names, int n, image_metrics *m);

#endif
