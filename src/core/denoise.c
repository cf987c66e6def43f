/* denoise.c: OIDN's RT filter through dlopen (denoise.h says why at run time).
 *
 * The filter follows OIDN's documentation for final frames: the auxiliary images (albedo,
 * normal) are first denoised by the RT filter themselves (prefiltering), then passed as
 * clean (cleanAux) beside the HDR beauty. */
#include "denoise.h"

#include <dlfcn.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image.h"
#include "util.h"

/* ---- the OIDN 2.x C API, as much as gonio calls ------------------------------------------
 * Declared here in the form of OIDN 2.x's include/OpenImageDenoise/oidn.h (Apache-2.0),
 * because no Debian 12 package ships that header and the library is loaded at run time:
 * the handle types, the three enums' values gonio uses, and the signatures of the
 * functions looked up below. */
typedef struct OIDNDeviceImpl *OIDNDevice;
typedef struct OIDNFilterImpl *OIDNFilter;
typedef enum { OIDN_DEVICE_TYPE_CPU = 1 } OIDNDeviceType;
typedef enum { OIDN_ERROR_NONE = 0 } OIDNError;
typedef enum { OIDN_FORMAT_FLOAT3 = 3 } OIDNFormat;
enum { OIDN_QUALITY_BALANCED = 5, OIDN_QUALITY_HIGH = 6 }; /* OIDNQuality */

typedef struct oidn_api {
    OIDNDevice (*NewDevice)(OIDNDeviceType type);
    void (*CommitDevice)(OIDNDevice device);
    void (*ReleaseDevice)(OIDNDevice device);
    int (*GetDeviceInt)(OIDNDevice device, const char *name);
    OIDNError (*GetDeviceError)(OIDNDevice device, const char **outMessage);
    OIDNFilter (*NewFilter)(OIDNDevice device, const char *type);
    void (*ReleaseFilter)(OIDNFilter filter);
    void (*SetSharedFilterImage)(OIDNFilter filter, const char *name, void *devPtr, OIDNFormat format,
                                 size_t width, size_t height, size_t byteOffset, size_t pixelByteStride,
                                 size_t rowByteStride);
    void (*SetFilterBool)(OIDNFilter filter, const char *name, bool value);
    void (*SetFilterInt)(OIDNFilter filter, const char *name, int value);
    void (*CommitFilter)(OIDNFilter filter);
    void (*ExecuteFilter)(OIDNFilter filter);
} oidn_api;

#define DENOISE_LIB_NAME "libOpenImageDenoise.so.2"

static const struct {
    const char *name;
    size_t offset;
} oidn_symbols[] = {
#define SYM(f) {"oidn" #f, offsetof(oidn_api, f)}
    SYM(NewDevice),     SYM(CommitDevice),  SYM(ReleaseDevice),        SYM(GetDeviceInt),
    SYM(GetDeviceError), SYM(NewFilter),    SYM(ReleaseFilter),        SYM(SetSharedFilterImage),
    SYM(SetFilterBool), SYM(SetFilterInt),  SYM(CommitFilter),         SYM(ExecuteFilter),
#undef SYM
};

/* Everything below is guarded by `lock`: OIDN serialises calls on a device anyway, and the
 * buffers and filters are reused from one call to the next. */
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static struct {
    void *lib;
    char lib_path[PATH_MAX];
    char lib_env[PATH_MAX]; /* DENOISE_LIB_ENV when it was loaded ("": unset) */
    oidn_api api;
    OIDNDevice device;
    int version;
    /* The filters of the last configuration, and the interleaved RGB buffers they read and
     * write (OIDN takes interleaved pixels; gonio's images are planar). */
    OIDNFilter beauty, albedo_filter, normal_filter;
    int width, height;
    bool has_albedo, has_normal, prefilter, fast;
    float *color, *albedo, *normal, *output;
} st;

/* Tries one file; on failure appends "PATH: why" to `tried` ("; " between them: a message
 * is one line, util_error escapes a newline). */
static bool try_open(const char *path, char *tried, size_t cap)
{
    size_t len = strlen(tried);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        const char *why = dlerror();
        snprintf(tried + len, cap - len, "%s%s: %s", len ? "; " : "", path, why ? why : "cannot be loaded");
        return false;
    }
    for (size_t k = 0; k < sizeof oidn_symbols / sizeof *oidn_symbols; k++) {
        void *f = dlsym(lib, oidn_symbols[k].name);
        if (!f) {
            snprintf(tried + len, cap - len, "%s%s: has no %s (not OpenImageDenoise 2.x)", len ? "; " : "", path,
                     oidn_symbols[k].name);
            dlclose(lib);
            return false;
        }
        memcpy((char *)&st.api + oidn_symbols[k].offset, &f, sizeof f);
    }
    st.lib = lib;
    snprintf(st.lib_path, sizeof st.lib_path, "%s", path);
    return true;
}

/* Is the library that DENOISE_LIB_ENV (env, or NULL) asks for the one loaded? The same
 * setting, or a path to the same file. */
static bool same_library(const char *env)
{
    char a[PATH_MAX], b[PATH_MAX];
    if (!strcmp(env ? env : "", st.lib_env))
        return true;
    return env && *env && realpath(env, a) && realpath(st.lib_path, b) && !strcmp(a, b);
}

static bool load_locked(void)
{
    char tried[4 * PATH_MAX + 512] = "", exe[PATH_MAX], path[PATH_MAX + 64];
    const char *env = getenv(DENOISE_LIB_ENV);
    ssize_t n;
    /* The library stays loaded for the process (unloading OIDN under its thread pool is not
     * safe): a later command (a batch line) that names another one is refused, not served
     * by the first. */
    if (st.lib && !same_library(env)) {
        util_error("the denoiser: %s=%s, but this process has Open Image Denoise loaded from %s already (a "
                   "batch loads one library for all its lines): run this command in a process of its own",
                   DENOISE_LIB_ENV, env ? env : "(unset)", st.lib_path);
        return false;
    }
    if (st.lib)
        return true;
    snprintf(st.lib_env, sizeof st.lib_env, "%s", env ? env : "");
    if (env && *env) {
        if (try_open(env, tried, sizeof tried))
            return true;
        util_error("the denoiser cannot load Intel Open Image Denoise from %s=%s (%s); unset it to use the "
                   "library `make denoiser` fetches into build/oidn/lib",
                   DENOISE_LIB_ENV, env, tried);
        return false;
    }
    /* build/release/gonio -> build/oidn/lib: the folder above the executable's. */
    n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = 0;
        snprintf(path, sizeof path, "%s/../oidn/lib/" DENOISE_LIB_NAME, dirname(exe));
        if (access(path, F_OK) == 0) {
            if (try_open(path, tried, sizeof tried))
                return true;
        } else {
            size_t len = strlen(tried);
            snprintf(tried + len, sizeof tried - len, "%s%s: absent", len ? "; " : "", path);
        }
    }
    if (try_open(DENOISE_LIB_NAME, tried, sizeof tried))
        return true;
    util_error("the denoiser needs Intel Open Image Denoise 2 (%s), which is not installed (tried %s). "
               "Run `make denoiser` in gonio's source tree (it fetches the pyoidn wheel's libraries "
               "into build/oidn/lib), or set %s to the path of a %s.",
               DENOISE_LIB_NAME, tried, DENOISE_LIB_ENV, DENOISE_LIB_NAME);
    return false;
}

bool denoise_load(void)
{
    pthread_mutex_lock(&lock);
    bool ok = load_locked();
    pthread_mutex_unlock(&lock);
    return ok;
}

/* OIDN's pending error on the device (or, with device NULL, of its creation). */
static bool oidn_ok(OIDNDevice device, const char *what)
{
    const char *msg = NULL;
    OIDNError e = st.api.GetDeviceError(device, &msg);
    if (e == OIDN_ERROR_NONE)
        return true;
    util_error("Open Image Denoise (%s): %s: %s (error %d)", st.lib_path, what, msg && *msg ? msg : "failed", (int)e);
    return false;
}

static void release_filters(void)
{
    OIDNFilter *f[3] = {&st.beauty, &st.albedo_filter, &st.normal_filter};
    for (int k = 0; k < 3; k++)
        if (*f[k]) {
            st.api.ReleaseFilter(*f[k]);
            *f[k] = NULL;
        }
    free(st.color);
    free(st.albedo);
    free(st.normal);
    free(st.output);
    st.color = st.albedo = st.normal = st.output = NULL;
    st.width = st.height = 0;
}

static void set_image(OIDNFilter f, const char *name, float *data)
{
    st.api.SetSharedFilterImage(f, name, data, OIDN_FORMAT_FLOAT3, (size_t)st.width, (size_t)st.height, 0, 0, 0);
}

/* An RT filter that denoises one auxiliary image in place (the prefilter). */
static OIDNFilter aux_filter(const char *name, float *data)
{
    OIDNFilter f = st.api.NewFilter(st.device, "RT");
    if (!f)
        return NULL;
    set_image(f, name, data);
    set_image(f, "output", data);
    st.api.SetFilterInt(f, "quality", st.fast ? OIDN_QUALITY_BALANCED : OIDN_QUALITY_HIGH);
    st.api.CommitFilter(f);
    return f;
}

/* The filters for this size and set of inputs, made anew only when those change (making and
 * committing a filter is the costly part of a small image). */
static bool configure(const denoise_input *in, bool has_albedo, bool has_normal)
{
    const size_t n = 3 * (size_t)in->width * (size_t)in->height;
    if (st.beauty && st.width == in->width && st.height == in->height && st.has_albedo == has_albedo &&
        st.has_normal == has_normal && st.prefilter == in->prefilter && st.fast == in->fast)
        return true;
    release_filters();
    st.width = in->width;
    st.height = in->height;
    st.has_albedo = has_albedo;
    st.has_normal = has_normal;
    st.prefilter = in->prefilter;
    st.fast = in->fast;
    st.color = util_malloc(n * sizeof(float));
    st.output = util_malloc(n * sizeof(float));
    st.albedo = has_albedo ? util_malloc(n * sizeof(float)) : NULL;
    st.normal = has_normal ? util_malloc(n * sizeof(float)) : NULL;
    st.beauty = st.api.NewFilter(st.device, "RT");
    if (!st.beauty || !oidn_ok(st.device, "creating the RT filter")) {
        release_filters();
        return false;
    }
    set_image(st.beauty, "color", st.color);
    set_image(st.beauty, "output", st.output);
    if (has_albedo)
        set_image(st.beauty, "albedo", st.albedo);
    if (has_normal)
        set_image(st.beauty, "normal", st.normal);
    st.api.SetFilterBool(st.beauty, "hdr", true);
    st.api.SetFilterBool(st.beauty, "cleanAux", has_albedo && in->prefilter);
    st.api.SetFilterInt(st.beauty, "quality", in->fast ? OIDN_QUALITY_BALANCED : OIDN_QUALITY_HIGH);
    st.api.CommitFilter(st.beauty);
    if (has_albedo && in->prefilter) {
        st.albedo_filter = aux_filter("albedo", st.albedo);
        if (has_normal)
            st.normal_filter = aux_filter("normal", st.normal);
    }
    if (!oidn_ok(st.device, "setting up the RT filter") || (has_albedo && in->prefilter && !st.albedo_filter) ||
        (has_normal && in->prefilter && !st.normal_filter)) {
        release_filters();
        return false;
    }
    return true;
}

/* planes -> interleaved RGB, each value clamped to [lo, hi]. */
static void interleave(float *dst, const float *const src[3], size_t pixels, float lo, float hi)
{
    for (size_t p = 0; p < pixels; p++)
        for (int c = 0; c < 3; c++)
            dst[3 * p + (size_t)c] = fminf(fmaxf(src[c][p], lo), hi);
}

bool denoise_run(const denoise_input *in, float *const out[3], denoise_info *info)
{
    const size_t pixels = (size_t)in->width * (size_t)in->height;
    const bool has_albedo = in->albedo[0] != NULL;
    /* OIDN's RT filter takes a normal only together with an albedo. */
    const bool has_normal = has_albedo && in->normal[0] != NULL;
    double t0 = util_now(), t1;
    bool ok = false;
    memset(info, 0, sizeof *info);
    pthread_mutex_lock(&lock);
    if (!load_locked())
        goto done;
    if (!st.device) {
        st.device = st.api.NewDevice(OIDN_DEVICE_TYPE_CPU);
        if (!st.device) {
            oidn_ok(NULL, "creating the CPU device");
            goto done;
        }
        st.api.CommitDevice(st.device);
        if (!oidn_ok(st.device, "creating the CPU device")) {
            st.api.ReleaseDevice(st.device);
            st.device = NULL;
            goto done;
        }
        st.version = st.api.GetDeviceInt(st.device, "version");
        info->setup_seconds = util_now() - t0;
    }
    t1 = util_now();
    if (!configure(in, has_albedo, has_normal))
        goto done;
    interleave(st.color, in->color, pixels, 0.0f, INFINITY);
    if (has_albedo) {
        interleave(st.albedo, in->albedo, pixels, 0.0f, 1.0f);
        if (st.albedo_filter)
            st.api.ExecuteFilter(st.albedo_filter);
    }
    if (has_normal) {
        interleave(st.normal, in->normal, pixels, -1.0f, 1.0f);
        if (st.normal_filter)
            st.api.ExecuteFilter(st.normal_filter);
    }
    st.api.ExecuteFilter(st.beauty);
    if (!oidn_ok(st.device, "denoising")) {
        release_filters();
        goto done;
    }
    for (size_t p = 0; p < pixels; p++)
        for (int c = 0; c < 3; c++)
            out[c][p] = st.output[3 * p + (size_t)c];
    info->seconds = util_now() - t1;
    info->version = st.version;
    snprintf(info->description, sizeof info->description, "OpenImageDenoise %d.%d.%d RT (hdr, %s%s, quality %s)",
             st.version / 10000, st.version / 100 % 100, st.version % 100,
             has_normal ? "albedo+normal" : has_albedo ? "albedo" : "no guides",
             has_albedo ? (in->prefilter ? " prefiltered, cleanAux" : " as they are") : "",
             in->fast ? "balanced" : "high");
    ok = true;
done:
    pthread_mutex_unlock(&lock);
    return ok;
}

bool denoise_check_finite(const float *const *planes, int n, size_t pixels, size_t *count, size_t *first)
{
    *count = 0;
    *first = 0;
    for (size_t p = 0; p < pixels; p++)
        for (int c = 0; c < n; c++)
            if (!isfinite(planes[c][p])) {
                if (!*count)
                    *first = p;
                ++*count;
            }
    return *count == 0;
}

/* Any non-finite value among the n channels idx[0..n) (skipping -1): an error naming them. */
static bool finite_or_error(const image *img, const int *idx, const char *role, const char *what)
{
    const float *planes[3];
    char names[3 * 34] = "";
    int n = 0;
    size_t count, first;
    for (int k = 0; k < 3; k++)
        if (idx[k] >= 0) {
            planes[n++] = img->planes[idx[k]];
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? ", " : "", img->names[idx[k]]);
        }
    if (n == 0 || denoise_check_finite(planes, n, (size_t)img->width * (size_t)img->height, &count, &first))
        return true;
    util_error("%s: %zu value(s) of the %s (%s) are NaN or infinite, the first at pixel (%zu, %zu); "
               "the denoiser would spread them over their neighbourhood, so it refuses the image",
               what, count, role, names, first % (size_t)img->width, first / (size_t)img->width);
    return false;
}

static bool is_output_name(const char *name)
{
    return !strcmp(name, "R") || !strcmp(name, "G") || !strcmp(name, "B") ||
           !strncmp(name, DENOISE_NOISY_LAYER ".", strlen(DENOISE_NOISY_LAYER) + 1);
}

bool denoise_image(image *img, const denoise_channels *ch, bool prefilter, denoise_info *info, const char *what)
{
    static const char *const rgb[3] = {"R", "G", "B"};
    const size_t pixels = (size_t)img->width * (size_t)img->height;
    denoise_input in = {.width = img->width, .height = img->height, .prefilter = prefilter};
    image out = {.width = img->width, .height = img->height, .x0 = img->x0, .y0 = img->y0,
                 .full_width = img->full_width, .full_height = img->full_height};
    float *result[3];
    bool keep[IMAGE_MAX_CHANNELS];
    int kept = 0;
    if (!finite_or_error(img, ch->beauty, "beauty", what) || !finite_or_error(img, ch->albedo, "albedo", what) ||
        !finite_or_error(img, ch->normal, "normal", what))
        return false;
    for (int c = 0; c < img->num_channels; c++) {
        bool beauty = c == ch->beauty[0] || c == ch->beauty[1] || c == ch->beauty[2];
        keep[c] = !beauty && !is_output_name(img->names[c]);
        kept += keep[c];
    }
    if (kept + 6 > IMAGE_MAX_CHANNELS) {
        util_error("%s: %d channels besides the beauty: with R, G, B and %s.R/G/B that is more than "
                   "the %d an image may have here", what, kept, DENOISE_NOISY_LAYER, IMAGE_MAX_CHANNELS);
        return false;
    }
    for (int k = 0; k < 3; k++) {
        in.color[k] = img->planes[ch->beauty[k]];
        in.albedo[k] = ch->albedo[0] >= 0 ? img->planes[ch->albedo[k]] : NULL;
        in.normal[k] = ch->normal[0] >= 0 ? img->planes[ch->normal[k]] : NULL;
        result[k] = util_malloc(pixels * sizeof(float));
    }
    if (!denoise_run(&in, result, info)) {
        for (int k = 0; k < 3; k++)
            free(result[k]);
        return false;
    }
    /* R, G, B (denoised), then the channels kept, then noisy.R/G/B (the beauty's planes). */
    for (int k = 0; k < 3; k++) {
        snprintf(out.names[out.num_channels], sizeof out.names[0], "%s", rgb[k]);
        out.planes[out.num_channels++] = result[k];
    }
    for (int c = 0; c < img->num_channels; c++)
        if (keep[c]) {
            memcpy(out.names[out.num_channels], img->names[c], sizeof out.names[0]);
            out.planes[out.num_channels++] = img->planes[c];
            img->planes[c] = NULL;
        }
    for (int k = 0; k < 3; k++) {
        snprintf(out.names[out.num_channels], sizeof out.names[0], "%s.%s", DENOISE_NOISY_LAYER, rgb[k]);
        out.planes[out.num_channels++] = img->planes[ch->beauty[k]];
        img->planes[ch->beauty[k]] = NULL;
    }
    image_destroy(img); /* the channels dropped */
    *img = out;
    return true;
}

void denoise_shutdown(void)
{
    pthread_mutex_lock(&lock);
    if (st.lib) {
        release_filters();
        if (st.device)
            st.api.ReleaseDevice(st.device);
        st.device = NULL;
    }
    pthread_mutex_unlock(&lock);
}
