/* options.c: the options several commands take (cli.h): the parsers of the shared values
 * (size, mode, tonemap, variant, EXR compression) and of the view (the camera: --camera,
 * --look-at, --fov; the environment: --env, --env-rotate, --env-intensity, whose rule is
 * src/render/render_default_light.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "brdf.h"
#include "camera.h"
#include "cli.h"
#include "environment.h"
#include "image.h"
#include "render.h"
#include "util.h"
#include "vec.h"

/* ---- shared values ---------------------------------------------------------------------- */

bool cli_take_size(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    int *wh = dest;
    return util_parse_size(value, &wh[0], &wh[1]);
}

/* (a name not in the list: cli_parse says "expected one of" the option's completion list) */
bool cli_take_mode(const char *cmd, const char *opt, const char *value, void *dest)
{
    int m = render_mode_from_name(value);
    (void)cmd, (void)opt;
    if (m >= 0)
        *(uint32_t *)dest = (uint32_t)m;
    return m >= 0;
}

bool cli_take_sampler(const char *cmd, const char *opt, const char *value, void *dest)
{
    int k = render_sampler_from_name(value);
    (void)cmd, (void)opt;
    if (k >= 0)
        *(uint32_t *)dest = (uint32_t)k;
    return k >= 0;
}

bool cli_take_tonemap(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    return image_tonemap_from_name(value, dest);
}

bool cli_take_variant(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)dest;
    if (!*value) {
        cli_usage_error(cmd, "%s '': a variant's name (gonio info lists them)", opt);
        return false;
    }
    scene_select_variant(value);
    return true;
}

bool cli_take_exr_compression(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    return image_exr_compression_from_name(value, dest);
}

const char *cli_brdf_models(void)
{
    static char list[512];
    const char *names[64];
    int n = 0;
    for (int i = 0; i < brdf_num_models && n < 64; i++)
        names[n++] = brdf_models[i].name;
    return list[0] ? list : util_join(list, sizeof list, names, n);
}

/* ---- the camera ------------------------------------------------------------------------- */

/* Parses n comma-separated finite floats (n in [min_n, max_n]); returns how many, 0 on error. */
static int parse_floats(const char *s, float *out, int min_n, int max_n)
{
    int n = 0;
    const char *p = s;
    char *end = NULL;
    while (n < max_n) {
        float v = strtof(p, &end);
        if (end == p || !isfinite(v))
            return 0;
        out[n++] = v;
        if (*end == 0)
            break;
        if (*end != ',')
            return 0;
        p = end + 1;
    }
    return n >= min_n && *end == 0 ? n : 0;
}

/* --camera FILE.exr: the view gonio recorded in the file's header (camera_record_attrs). */
static int camera_from_exr(camera_option *c, const char *cmd, const char *path)
{
    char view[256];
    double fov = 0, ortho = 0;
    int fd = util_open_read(path); /* a missing file, a FIFO: its own message, nothing more */
    if (fd < 0)
        return 2;
    close(fd);
    if (!image_exr_attr_string(path, "gonio:look-at", view, sizeof view))
        return cli_usage_error(cmd, "--camera '%s': not an EXR with a gonio:look-at header (written by "
                                    "gonio render or preview)", path);
    float v[9];
    if (parse_floats(view, v, 9, 9) != 9)
        return cli_usage_error(cmd, "--camera '%s': gonio:look-at '%s' is not 9 numbers", path, view);
    image_exr_attr_double(path, "gonio:fov", &fov);
    image_exr_attr_double(path, "gonio:ortho-half-height", &ortho);
    if (!(fov > 0 && fov < 180) && !(ortho > 0 && isfinite(ortho)))
        return cli_usage_error(cmd, "--camera '%s': no valid gonio:fov or gonio:ortho-half-height", path);
    c->kind = CAMERA_LOOK_AT;
    memcpy(c->eye, v, sizeof c->eye);
    memcpy(c->target, v + 3, sizeof c->target);
    memcpy(c->up, v + 6, sizeof c->up);
    c->ortho_half_height = ortho > 0 ? (float)ortho : 0;
    /* The exact frame, when recorded: the look-at form loses the last bits of the view
     * direction (target - eye), which moves some silhouette pixels. */
    if (image_exr_attr_string(path, "gonio:view", view, sizeof view) && parse_floats(view, c->frame, 15, 15) == 15)
        c->exact = true;
    if (!image_exr_size(path, &c->width, &c->height))
        c->width = c->height = 0;
    if (c->fov == 0 && fov > 0 && !c->exact) /* gonio:view has the exact yfov */
        c->fov = (float)fov;
    return 1;
}

static int camera_parse_option(camera_option *c, const char *cmd, const char *opt, const char *val)
{
    long v;
    if (!strcmp(opt, "--camera")) {
        if (!strcmp(val, "frame")) {
            c->kind = CAMERA_FRAME;
        } else if (util_has_suffix(val, ".exr")) {
            return camera_from_exr(c, cmd, val);
        } else if (util_parse_int(val, 0, 1 << 20, &v)) {
            c->kind = CAMERA_INDEX;
            c->index = (int)v;
        } else {
            return cli_usage_error(cmd, "--camera '%s': expected an index in [0, %d], 'frame' or FILE.exr", val,
                                   1 << 20);
        }
        return 1;
    }
    if (!strcmp(opt, "--look-at")) {
        float f[9] = {0, 0, 0, 0, 0, 0, 0, 1, 0};
        int n = parse_floats(val, f, 6, 9);
        if (n != 6 && n != 9)
            return cli_usage_error(cmd, "--look-at '%s': expected EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ]", val);
        scene_camera probe;
        if (!camera_look_at_frame(f, f + 3, f + 6, &probe))
            return cli_usage_error(cmd, "--look-at '%s': the target must differ from the eye and the "
                                        "up vector must not point along the view", val);
        c->kind = CAMERA_LOOK_AT;
        c->exact = false;
        memcpy(c->eye, f, sizeof c->eye);
        memcpy(c->target, f + 3, sizeof c->target);
        memcpy(c->up, f + 6, sizeof c->up);
        c->ortho_half_height = 0;
        return 1;
    }
    if (!strcmp(opt, "--fov")) {
        float f;
        if (!util_parse_float(val, &f) || !(f > 0 && f < 180))
            return cli_usage_error(cmd, "--fov '%s': expected degrees in (0, 180)", val);
        c->fov = f;
        return 1;
    }
    return 0;
}

bool cli_take_camera(const char *cmd, const char *opt, const char *val, void *dest)
{
    return camera_parse_option((camera_option *)dest, cmd, opt, val) == 1;
}

/* ---- the environment -------------------------------------------------------------------- */

/* Radiance beyond this overflows the flux products in float (--env 1e38 wrote NaN pixels). */
#define ENV_MAX 1e9f

static int env_parse_option(env_option *e, const char *cmd, const char *opt, const char *val)
{
    if (!strcmp(opt, "--env")) {
        e->given = true;
        e->path = NULL;
        e->studio = !strcmp(val, "studio");
        if (e->studio)
            return 1;
        if (util_has_suffix(val, ".exr") || util_has_suffix(val, ".hdr"))
            e->path = val;
        else if (!util_parse_rgb(val, e->color) || e->color[0] > ENV_MAX || e->color[1] > ENV_MAX || e->color[2] > ENV_MAX)
            return cli_usage_error(cmd, "--env '%s': expected R,G,B or one value in [0, %g], FILE.exr, FILE.hdr or studio",
                                   val, ENV_MAX);
        return 1;
    }
    if (!strcmp(opt, "--env-rotate")) {
        if (!util_parse_float(val, &e->rotation) || !isfinite(e->rotation))
            return cli_usage_error(cmd, "--env-rotate '%s': expected degrees", val);
        return 1;
    }
    if (!strcmp(opt, "--env-intensity")) {
        if (!util_parse_float(val, &e->intensity) || !(e->intensity > 0) || !(e->intensity <= ENV_MAX))
            return cli_usage_error(cmd, "--env-intensity '%s': expected a number in (0, %g]", val, ENV_MAX);
        return 1;
    }
    return 0;
}

bool cli_take_env(const char *cmd, const char *opt, const char *val, void *dest)
{
    return env_parse_option((env_option *)dest, cmd, opt, val) == 1;
}
