/* render_output.c: a render's EXR header attributes and the PNGs of its data modes. The
 * scene hash is zlib's CRC-32: it tells renders of different scenes apart, it is not a
 * defence against a crafted collision. */
#include "render_output.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "camera.h"
#include "draw.h"
#include "util.h"

const char *const render_identity_names[] = {
    "gonio:scene", "gonio:size",    "gonio:mode",    "gonio:camera", "gonio:max-depth",
    "gonio:estimator", "gonio:env", "gonio:shadows", "gonio:ambient", NULL};

static uLong crc(uLong c, const void *data, size_t bytes)
{
    return data && bytes ? crc32_z(c, data, bytes) : c;
}

/* Everything of the scene that reaches a pixel; cameras are in gonio:camera. */
static uint32_t scene_crc(const scene *sc)
{
    uLong c = crc32_z(0, NULL, 0);
    c = crc(c, sc->vertices, sizeof *sc->vertices * sc->num_vertices);
    c = crc(c, sc->indices, sizeof *sc->indices * 3 * (size_t)sc->num_triangles);
    c = crc(c, sc->tri_material, sizeof *sc->tri_material * sc->num_triangles);
    c = crc(c, sc->materials, sizeof *sc->materials * sc->num_materials);
    c = crc(c, sc->lights, sizeof *sc->lights * sc->num_lights);
    c = crc(c, sc->textures, sizeof *sc->textures * sc->num_textures);
    for (uint32_t i = 0; i < sc->num_images; i++)
        c = crc(c, sc->images[i].rgba8, (size_t)sc->images[i].width * sc->images[i].height * 4);
    c = crc(c, sc->ambient, sizeof sc->ambient);
    c = crc(c, &sc->vertex_colors, sizeof sc->vertex_colors);
    for (uint32_t m = 0; m < sc->num_instanced_meshes; m++) { /* (none: the crc scenes had before) */
        const scene_instanced_mesh *im = &sc->instanced_meshes[m];
        c = crc(c, im->vertices, sizeof *im->vertices * im->num_vertices);
        c = crc(c, im->indices, sizeof *im->indices * 3 * (size_t)im->num_triangles);
        c = crc(c, im->tri_material, sizeof *im->tri_material * im->num_triangles);
    }
    c = crc(c, sc->instances, sizeof *sc->instances * sc->num_instances);
    return (uint32_t)c;
}

static uint32_t image_crc(const image *img)
{
    uLong c = crc32_z(0, NULL, 0);
    for (int k = 0; k < img->num_channels; k++) {
        c = crc(c, img->names[k], strlen(img->names[k]));
        c = crc(c, img->planes[k], sizeof(float) * (size_t)img->width * (size_t)img->height);
    }
    return (uint32_t)c;
}

static void add_string(render_header *h, const char *name, const char *fmt, ...)
{
    va_list ap;
    assert(h->count < RENDER_HEADER_MAX);
    va_start(ap, fmt);
    vsnprintf(h->text[h->count], sizeof h->text[0], fmt, ap);
    va_end(ap);
    h->attrs[h->count] = (image_attr){name, IMAGE_ATTR_STRING, h->text[h->count], 0, 0, NULL};
    h->count++;
}

static void add_attr(render_header *h, image_attr a)
{
    assert(h->count < RENDER_HEADER_MAX);
    h->attrs[h->count++] = a;
}

void render_header_build(render_header *h, const renderer *r, const render_settings *s,
                         const render_stats *st, const char *brdf, const char *command)
{
    const bool lit = render_modes[s->mode].flags & GN_MODEF_LIT;
    GnCamera cam;
    memset(h, 0, sizeof *h);
    if (!renderer_camera(r, s, &cam)) /* cannot fail: the render just used it */
        memset(&cam, 0, sizeof cam);
    add_string(h, "gonio:scene", "crc32:%08x", scene_crc(r->sc));
    add_string(h, "gonio:size", "%dx%d", s->width, s->height);
    add_string(h, "gonio:mode", "%s", render_mode_name(s->mode));
    add_string(h, "gonio:camera", "position %.9g,%.9g,%.9g forward %.9g,%.9g,%.9g up %.9g,%.9g,%.9g "
               "tan-half-fovy %.9g ortho-half-height %.9g near %.9g far %.9g", cam.position.x, cam.position.y,
               cam.position.z, cam.forward.x, cam.forward.y, cam.forward.z, cam.up.x, cam.up.y, cam.up.z,
               cam.tan_half_fovy, cam.ortho_half_height, cam.znear, cam.zfar);
    if (s->mode == GN_MODE_PATH) {
        add_string(h, "gonio:max-depth", "%d", s->max_depth);
        add_string(h, "gonio:estimator", "%s", s->strategy == GN_FRAME_LIGHT_ONLY ? "light"
                                               : s->strategy == GN_FRAME_BSDF_ONLY ? "bsdf" : "mis");
    }
    if (s->mode == GN_MODE_PATH && s->env_map)
        add_string(h, "gonio:env", "map %dx%d crc32:%08x rotate %.9g", s->env_map->width, s->env_map->height,
                   image_crc(s->env_map), s->env_rotation);
    else if (s->mode == GN_MODE_PATH || lit)
        add_string(h, "gonio:env", "%.9g,%.9g,%.9g", s->env[0], s->env[1], s->env[2]);
    if (lit) {
        const float *a = s->ambient_set ? s->ambient : r->sc->ambient;
        add_string(h, "gonio:shadows", "%s", s->no_shadows ? "off" : "on");
        add_string(h, "gonio:ambient", "%.9g,%.9g,%.9g", a[0], a[1], a[2]);
    }
    add_attr(h, (image_attr){"gonio:spp", IMAGE_ATTR_INT, NULL, st->spp, 0, NULL});
    add_attr(h, (image_attr){"gonio:seed", IMAGE_ATTR_INT, NULL, (int)s->seed, 0, NULL});
    if (s->mode == GN_MODE_PATH)
        add_string(h, "gonio:sampler", "%s", render_sampler_name(s->sampler));
    add_string(h, "gonio:scene-path", "%s", r->sc->path);
    /* The view for people and for --camera FILE.exr (src/scene/camera.h), and OpenEXR's own. */
    {
        scene_camera v = {.position = {cam.position.x, cam.position.y, cam.position.z},
                          .right = {cam.right.x, cam.right.y, cam.right.z},
                          .up = {cam.up.x, cam.up.y, cam.up.z},
                          .forward = {cam.forward.x, cam.forward.y, cam.forward.z},
                          .yfov = 2 * atanf(cam.tan_half_fovy), .ortho_half_height = cam.ortho_half_height,
                          .znear = cam.znear, .zfar = cam.zfar};
        if (s->view && !s->camera_override) /* the camera itself: its yfov exactly */
            v = *s->view;
        if (s->camera_label)
            add_string(h, "gonio:camera-name", "%s", s->camera_label);
        camera_look_at_string(&v, h->text[h->count], sizeof h->text[0]);
        add_attr(h, (image_attr){"gonio:look-at", IMAGE_ATTR_STRING, h->text[h->count], 0, 0, NULL});
        camera_frame_string(&v, h->text[h->count], sizeof h->text[0]);
        add_attr(h, (image_attr){"gonio:view", IMAGE_ATTR_STRING, h->text[h->count], 0, 0, NULL});
        if (cam.ortho_half_height > 0)
            add_attr(h, (image_attr){"gonio:ortho-half-height", IMAGE_ATTR_DOUBLE, NULL, 0, cam.ortho_half_height, NULL});
        else
            add_attr(h, (image_attr){"gonio:fov", IMAGE_ATTR_DOUBLE, NULL, 0, 2 * atan(cam.tan_half_fovy) * 180 / M_PI, NULL});
        camera_world_to_camera(&v, h->world_to_camera);
        add_attr(h, (image_attr){"worldToCamera", IMAGE_ATTR_M44F, NULL, 0, 0, h->world_to_camera});
        if (s->env_label)
            add_string(h, "gonio:environment", "%s", s->env_label);
    }
    if (brdf)
        add_string(h, "gonio:brdf", "%s", brdf);
    add_attr(h, (image_attr){"gonio:seconds", IMAGE_ATTR_DOUBLE, NULL, 0, st->seconds, NULL});
    add_attr(h, (image_attr){"gonio:command", IMAGE_ATTR_STRING, command, 0, 0, NULL});
    add_attr(h, (image_attr){"gonio:version", IMAGE_ATTR_STRING, GONIO_VERSION, 0, 0, NULL});
}

bool render_header_seed(const char *path, uint32_t *seed)
{
    double v;
    if (!image_exr_attr_double(path, "gonio:seed", &v) || v != floor(v) || v < INT32_MIN || v > UINT32_MAX)
        return false;
    *seed = v < 0 ? (uint32_t)(int32_t)v : (uint32_t)v;
    return true;
}

/* ---- PNGs of the data modes --------------------------------------------------------- */

static uint8_t unorm8(double v)
{
    return v > 0 ? (uint8_t)(fmin(v, 1) * 255 + 0.5) : 0; /* NaN -> 0 */
}

bool render_write_png(const image *img, uint32_t mode, const char *path, float exposure, image_tonemap tm)
{
    const size_t pixels = (size_t)img->width * (size_t)img->height;
    const float *r = img->planes[0], *g = img->planes[1], *b = img->planes[2], *a = img->planes[3];
    uint8_t *rgba8;
    bool ok;
    if (mode != GN_MODE_DEPTH && mode != GN_MODE_NORMAL && mode != GN_MODE_COST)
        return image_write_png_from(img, path, exposure, tm);
    assert(img->num_channels >= 4 && !strcmp(img->names[3], "A"));
    rgba8 = util_malloc(pixels * 4);
    if (mode == GN_MODE_DEPTH) {
        /* A pixel's value is the mean over its samples with misses 0: coverage times the
         * depth of what it hit. */
        double zmin = INFINITY, zmax = -INFINITY;
        for (size_t p = 0; p < pixels; p++)
            if (a[p] > 0) {
                zmin = fmin(zmin, r[p] / a[p]);
                zmax = fmax(zmax, r[p] / a[p]);
            }
        for (size_t p = 0; p < pixels; p++) {
            double t = a[p] > 0 && zmax > zmin ? (r[p] / a[p] - zmin) / (zmax - zmin) : 0;
            rgba8[4 * p] = rgba8[4 * p + 1] = rgba8[4 * p + 2] = unorm8(a[p] * (1 - 0.8 * t));
        }
    } else if (mode == GN_MODE_NORMAL) {
        for (size_t p = 0; p < pixels; p++) {
            rgba8[4 * p] = unorm8(0.5 * r[p] + 0.5 * a[p]);
            rgba8[4 * p + 1] = unorm8(0.5 * g[p] + 0.5 * a[p]);
            rgba8[4 * p + 2] = unorm8(0.5 * b[p] + 0.5 * a[p]);
        }
    } else {
        double cmax = 0;
        for (size_t p = 0; p < pixels; p++)
            cmax = fmax(cmax, r[p]);
        for (size_t p = 0; p < pixels; p++) {
            uint32_t c = draw_colormap(cmax > 0 ? (float)(r[p] / cmax) : 0);
            rgba8[4 * p] = (uint8_t)(c >> 24);
            rgba8[4 * p + 1] = (uint8_t)(c >> 16);
            rgba8[4 * p + 2] = (uint8_t)(c >> 8);
        }
    }
    for (size_t p = 0; p < pixels; p++)
        rgba8[4 * p + 3] = 255;
    ok = image_write_png(path, rgba8, img->width, img->height);
    free(rgba8);
    return ok;
}
