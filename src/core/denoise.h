/* denoise.h: Intel Open Image Denoise (OIDN 2.x) on the CPU, loaded at run time.
 *
 * OIDN's RT filter is a convolutional network trained on path-traced images: given the
 * noisy HDR beauty and, as guides, the first hit's albedo and shading normal, it returns
 * an estimate of the converged image. Debian 12 packages no OIDN 2, so gonio does not link
 * it: `make denoiser` fetches its shared libraries (CPU device and TBB) into build/oidn/lib
 * and denoise_load finds them there with dlopen (docs/denoise.md). Without them gonio runs
 * as before and only denoising is refused, by an error that says how to get the library. */
#ifndef GONIO_DENOISE_H
#define GONIO_DENOISE_H

#include <stdbool.h>
#include <stddef.h>

/* The environment variable naming the library file to load (and only that one). */
#define DENOISE_LIB_ENV "GONIO_OIDN_LIB"

/* Where the library is looked for, in order: $GONIO_OIDN_LIB when set (nothing else then);
 * ../oidn/lib/libOpenImageDenoise.so.2 beside the running executable's folder (build/oidn/lib
 * for build/release/gonio); the system's search path. True once it is loaded (later calls
 * return at once); false with util_error saying what was tried, why each failed, and the
 * command that fetches the library. Thread-safe. */
bool denoise_load(void);

/* One image to denoise: planar float channels of width x height pixels, rows top to bottom.
 * color: the linear HDR beauty, values >= 0 (negative ones are taken as 0); albedo and
 * normal optional (NULL planes: not used). Albedo is clamped to [0, 1] and normals to
 * [-1, 1], the ranges OIDN's documentation requires. */
typedef struct denoise_input {
    int width, height;
    const float *color[3];
    const float *albedo[3];
    const float *normal[3];
    /* Prefilter the albedo and normal with the RT filter first and pass them as clean
     * (cleanAux), as OIDN recommends for final frames; false: noisy guides, a third of
     * the work (the preview's choice). */
    bool prefilter;
    /* OIDN's "balanced" quality instead of "high" (interactive use). */
    bool fast;
} denoise_input;

typedef struct denoise_info {
    double seconds;       /* this call: filter setup and execution */
    double setup_seconds; /* loading the library and creating the device, when this call did */
    int version;          /* OIDN's, e.g. 20501 */
    /* What was done, for headers and messages: "OpenImageDenoise 2.5.1 RT (hdr, albedo+normal
     * prefiltered, cleanAux, quality high)". */
    char description[160];
} denoise_info;

/* Denoises in->color into out[0..2] (planes of width x height the caller owns; they may be
 * the color planes themselves). Loads the library and creates the CPU device on first use.
 * Every input value must be finite: the caller checks (denoise_check_finite), since OIDN
 * spreads a NaN over its whole receptive field. False with util_error on failure (library
 * missing, OIDN's own error message). Thread-safe: calls are serialised. */
bool denoise_run(const denoise_input *in, float *const out[3], denoise_info *info);

/* The first non-finite value among n planes of `pixels` floats: true when all are finite;
 * otherwise false with *count the number of non-finite values and *first the index of the
 * first pixel that holds one. */
bool denoise_check_finite(const float *const *planes, int n, size_t pixels, size_t *count, size_t *first);

/* The layer a denoised image keeps its noisy beauty in: noisy.R, noisy.G, noisy.B. OpenEXR
 * viewers and libraries (OpenImageIO, tev, Blender) read "LAYER.CHANNEL" names as a layer
 * beside the unnamed default one, R, G, B. */
#define DENOISE_NOISY_LAYER "noisy"

/* Channels of an image by index: beauty[3] (required), albedo[3] and normal[3] (-1: none). */
typedef struct denoise_channels {
    int beauty[3], albedo[3], normal[3];
} denoise_channels;

/* Denoises img's beauty channels, guided by its albedo and normal channels when given: the
 * result becomes the channels R, G, B and the beauty moves to noisy.R/G/B; any earlier R, G,
 * B or noisy.* channels (other than the beauty's) are dropped, the others kept. `what` names
 * the image in errors (a path). False with an error naming it when a value of those channels
 * is NaN or infinite (how many, the first pixel), when the channels would exceed
 * IMAGE_MAX_CHANNELS, or when denoise_run fails; img is unchanged then. */
struct image;
bool denoise_image(struct image *img, const denoise_channels *ch, bool prefilter, denoise_info *info,
                   const char *what);

/* Releases the device and filters (the library stays loaded: TBB's threads outlive it). */
void denoise_shutdown(void);

#endif
