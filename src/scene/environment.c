/* environment.c: --env, the studio environment and Radiance .hdr maps (environment.h). */
#include "environment.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <stb_image.h>

#include "util.h"
#include "vec.h"


bool env_scene_has_light(const scene *sc)
{
    if (sc->num_lights > 0)
        return true;
    /* Core glTF's emissive factor stops at 1: emission within that range is a glow texture
     * (DamagedHelmet's displays, a lit window) on an object that still needs light; a light
     * source is brighter than that (KHR_materials_emissive_strength, the Cornell box's 17). */
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        const vec3 e = sc->materials[i].emissive;
        if (e.x > 1 || e.y > 1 || e.z > 1)
            return true;
    }
    return false;
}

/* ---- the studio ------------------------------------------------------------------------
 * Why this light: a model viewer's job is to show shape and material, so the light is soft
 * and neutral (no tint that would shift base colours), brighter above than below (as a room
 * or an overcast sky, which reads as "up"), with one large key light high at the front left
 * and a weaker fill at the right that model the shape (a constant environment shows no shape
 * on a diffuse object), and a dim floor instead of black so that undersides and glass are
 * not lost. It is a map, so the path tracer importance samples it like any other. A white
 * Lambertian surface facing up reflects about 0.8 under it. */
#define STUDIO_WIDTH 512
#define STUDIO_HEIGHT 256
static const float studio_key_dir[3] = {-0.45f, 0.75f, 0.50f};  /* toward the key (unnormalised) */
static const float studio_fill_dir[3] = {0.80f, 0.25f, 0.45f};
#define STUDIO_KEY_RADIANCE 4.0f
#define STUDIO_KEY_RADIUS 22.0f /* degrees: the edge of the soft box */
#define STUDIO_FILL_RADIANCE 0.8f
#define STUDIO_FILL_RADIUS 30.0f

static float smoothstepf(float a, float b, float x)
{
    float t = fminf(fmaxf((x - a) / (b - a), 0), 1);
    return t * t * (3 - 2 * t);
}

/* The unit vector along v (the studio's directions). */
static void unit(const float v[3], float out[3])
{
    memcpy(out, v, 3 * sizeof *out);
    vec_normalize(out);
}

/* A soft disc of angular radius r degrees about unit direction c: 1 inside 70 % of r, 0 outside. */
static float soft_disc(const float d[3], const float c[3], float r)
{
    float cosa = d[0] * c[0] + d[1] * c[1] + d[2] * c[2];
    float a = acosf(fminf(fmaxf(cosa, -1), 1)) * (float)(180 / M_PI);
    return 1 - smoothstepf(0.7f * r, r, a);
}

void environment_studio(image *out, bool with_key)
{
    static const char *const names[3] = {"R", "G", "B"};
    float key[3], fill[3];
    unit(studio_key_dir, key);
    unit(studio_fill_dir, fill);
    image_create(out, STUDIO_WIDTH, STUDIO_HEIGHT, 3, names);
    for (int y = 0; y < STUDIO_HEIGHT; y++)
        for (int x = 0; x < STUDIO_WIDTH; x++) {
            /* The texel centre's direction, in path.comp's lat-long mapping. */
            float theta = (float)M_PI * (y + 0.5f) / STUDIO_HEIGHT;
            float phi = ((x + 0.5f) / STUDIO_WIDTH - 0.5f) * 2 * (float)M_PI;
            float d[3] = {sinf(theta) * cosf(phi), cosf(theta), sinf(theta) * sinf(phi)};
            float sky = 0.30f + 0.30f * fmaxf(d[1], 0), floor = 0.10f;
            float L = floor + (sky - floor) * smoothstepf(-0.1f, 0.1f, d[1]);
            L += STUDIO_FILL_RADIANCE * soft_disc(d, fill, STUDIO_FILL_RADIUS);
            if (with_key)
                L += STUDIO_KEY_RADIANCE * soft_disc(d, key, STUDIO_KEY_RADIUS);
            for (int k = 0; k < 3; k++)
                out->planes[k][(size_t)y * STUDIO_WIDTH + x] = L;
        }
}

void environment_studio_key(GnLight *out)
{
    float key[3];
    unit(studio_key_dir, key);
    /* The soft box's irradiance at normal incidence (its radiance over its solid angle, taken
     * as a disc of the mean of its inner and outer radius) over pi: the classic Phong model's
     * diffuse term kd E (n.l) has no 1 / pi, so this gives a white surface what the path
     * tracer gives it. */
    double r = 0.85 * STUDIO_KEY_RADIUS * M_PI / 180, e = STUDIO_KEY_RADIANCE * 2 * (1 - cos(r));
    memset(out, 0, sizeof *out);
    out->type = GN_LIGHT_DIRECTIONAL;
    out->direction = (vec3){-key[0], -key[1], -key[2]};
    out->color = (vec3){(float)e, (float)e, (float)e};
}

void environment_mean(const image *map, float out[3])
{
    int ch[3] = {image_channel(map, "R"), image_channel(map, "G"), image_channel(map, "B")};
    if (ch[0] < 0 || ch[1] < 0 || ch[2] < 0)
        ch[0] = ch[1] = ch[2] = image_channel(map, "Y");
    double sum[3] = {0, 0, 0}, wsum = 0;
    for (int y = 0; y < map->height && ch[0] >= 0; y++) {
        double w = sin(M_PI * (y + 0.5) / map->height);
        for (int x = 0; x < map->width; x++)
            for (int k = 0; k < 3; k++) {
                float v = map->planes[ch[k]][(size_t)y * map->width + x];
                sum[k] += w * (v > 0 && isfinite(v) ? v : 0);
            }
        wsum += w * map->width;
    }
    for (int k = 0; k < 3; k++)
        out[k] = wsum > 0 ? (float)(sum[k] / wsum) : 0;
}

/* ---- Radiance .hdr ---------------------------------------------------------------------- */

/* The size line of a Radiance header (after the header's empty line): "-Y H +X W", the
 * orientation stb_image reads. False when it is not there: stb_image names the problem. */
static bool hdr_size(FILE *f, long *w, long *h)
{
    char line[256];
    bool blank = false;
    for (int n = 0; n < 4096 && fgets(line, sizeof line, f); n++) {
        if (blank) {
            char sy, sx;
            return sscanf(line, "%cY %ld %cX %ld", &sy, h, &sx, w) == 4;
        }
        blank = line[0] == '\n';
    }
    return false;
}

bool environment_read_hdr(image *out, const char *path)
{
    static const char *const names[3] = {"R", "G", "B"};
    const long max_pixels = 1L << 28;
    int w, h, comp;
    long fw, fh;
    memset(out, 0, sizeof *out);
    FILE *f = util_fopen_read(path);
    if (!f)
        return false;
    /* stb_image would convert an 8-bit image to "HDR" through a guessed gamma: refuse it. */
    if (!stbi_is_hdr_from_file(f)) {
        fclose(f);
        util_error("%s: not a Radiance HDR (RGBE) file", path);
        return false;
    }
    /* stb_image refuses a huge image as one of no format it knows ("not BMP"): say why. */
    if (hdr_size(f, &fw, &fh) && (fw < 1 || fh < 1 || fw > max_pixels / (fh > 0 ? fh : 1))) {
        fclose(f);
        util_error("%s: a Radiance HDR of %ldx%ld pixels: %s", path, fw, fh,
                   fw < 1 || fh < 1 ? "an empty image" : "too large (at most 2^28 pixels)");
        return false;
    }
    rewind(f);
    if (!stbi_info_from_file(f, &w, &h, &comp) || (double)w * h > (double)max_pixels) {
        fclose(f);
        util_error("%s: %s", path, stbi_failure_reason() ? stbi_failure_reason() : "image too large");
        return false;
    }
    float *rgb = stbi_loadf_from_file(f, &w, &h, &comp, 3);
    fclose(f);
    if (!rgb) {
        util_error("%s: cannot decode: %s", path, stbi_failure_reason());
        return false;
    }
    image_create(out, w, h, 3, names);
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (int k = 0; k < 3; k++)
            out->planes[k][i] = rgb[3 * i + k];
    stbi_image_free(rgb);
    return true;
}

