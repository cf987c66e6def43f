/* camera.c: the camera rule shared by the commands (camera.h). */
#include "camera.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cli.h"
#include "image.h"
#include "util.h"

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

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static bool normalize3(float v[3])
{
    float l = sqrtf(dot3(v, v));
    if (!(l > 0) || !isfinite(l))
        return false;
    for (int k = 0; k < 3; k++)
        v[k] /= l;
    return true;
}

/* The orthonormal frame of eye, target and up; false when the view is degenerate (target
 * at the eye, or up along the view). */
static bool look_at_frame(const float eye[3], const float target[3], const float up[3], scene_camera *out)
{
    float f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]}, r[3], u[3];
    if (!normalize3(f))
        return false;
    cross3(f, up, r);
    if (!normalize3(r) || fabsf(dot3(f, up)) > 0.9999f * sqrtf(dot3(up, up)))
        return false;
    cross3(r, f, u);
    memcpy(out->position, eye, sizeof out->position);
    memcpy(out->forward, f, sizeof out->forward);
    memcpy(out->right, r, sizeof out->right);
    memcpy(out->up, u, sizeof out->up);
    return true;
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

int camera_parse_option(camera_option *c, const char *cmd, const char *opt, const char *val)
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
            return cli_usage_error(cmd, "--camera '%s': expected an index >= 0, 'frame' or FILE.exr", val);
        }
        return 1;
    }
    if (!strcmp(opt, "--look-at")) {
        float f[9] = {0, 0, 0, 0, 0, 0, 0, 1, 0};
        int n = parse_floats(val, f, 6, 9);
        if (n != 6 && n != 9)
            return cli_usage_error(cmd, "--look-at '%s': expected EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ]", val);
        scene_camera probe;
        if (!look_at_frame(f, f + 3, f + 6, &probe))
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

bool camera_resolve(const camera_option *c, const scene *sc, float aspect, scene_camera *out)
{
    camera_kind kind = c->kind;
    if (kind == CAMERA_AUTO)
        kind = sc->num_cameras > 0 ? CAMERA_INDEX : CAMERA_FRAME;
    switch (kind) {
    case CAMERA_INDEX: {
        int i = c->kind == CAMERA_AUTO ? 0 : c->index;
        if (i < 0 || (uint32_t)i >= sc->num_cameras) {
            util_error("%s: --camera %d: the scene has %u camera(s)", sc->path, i, sc->num_cameras);
            return false;
        }
        *out = sc->cameras[i];
        break;
    }
    case CAMERA_FRAME:
        scene_frame_camera(sc, aspect, c->fov > 0 ? c->fov * (float)(M_PI / 180) : (float)(M_PI / 4), out);
        break;
    case CAMERA_LOOK_AT: {
        memset(out, 0, sizeof *out);
        strcpy(out->name, "look-at");
        if (c->exact) {
            memcpy(out->position, c->frame, sizeof out->position);
            memcpy(out->right, c->frame + 3, sizeof out->right);
            memcpy(out->up, c->frame + 6, sizeof out->up);
            memcpy(out->forward, c->frame + 9, sizeof out->forward);
        } else if (!look_at_frame(c->eye, c->target, c->up, out)) {
            util_error("--look-at: degenerate view");
            return false;
        }
        out->yfov = (float)(M_PI / 4);
        out->ortho_half_height = c->ortho_half_height;
        /* Near and far planes from the scene's bounding sphere, as for the framing view. */
        float r2 = 0, d2 = 0;
        for (int k = 0; k < 3; k++) {
            float e = sc->bounds_max[k] - sc->bounds_min[k], m = 0.5f * (sc->bounds_max[k] + sc->bounds_min[k]);
            r2 += e > 0 ? 0.25f * e * e : 0;
            d2 += (m - c->eye[k]) * (m - c->eye[k]);
        }
        float r = sqrtf(r2), d = sqrtf(d2);
        out->znear = c->ortho_half_height > 0 ? 0 : fmaxf(1e-4f * fmaxf(r, d), d - r > 0 ? 0.5f * (d - r) : 1e-3f * r);
        out->zfar = 0;
        if (c->exact) { /* the recorded planes and field of view */
            out->znear = c->frame[12];
            out->zfar = c->frame[13];
            out->yfov = c->frame[14];
        }
        if (c->width > 0 && c->height > 0)
            out->aspect = (float)c->width / (float)c->height;
        break;
    }
    default:
        return false;
    }
    if (c->fov > 0 && kind != CAMERA_FRAME)
        out->yfov = c->fov * (float)(M_PI / 180);
    return true;
}

void camera_default_size(const scene_camera *c, int longer, int *width, int *height)
{
    float aspect = c->aspect > 0 && isfinite(c->aspect) ? c->aspect : 1.0f;
    if (aspect >= 1) {
        *width = longer;
        *height = (int)fmaxf(1.0f, (float)longer / aspect + 0.5f);
    } else {
        *height = longer;
        *width = (int)fmaxf(1.0f, (float)longer * aspect + 0.5f);
    }
}

void camera_describe(const camera_option *c, const scene *sc, char *buf, size_t cap)
{
    camera_kind kind = c->kind;
    int i = c->kind == CAMERA_AUTO ? 0 : c->index;
    if (kind == CAMERA_AUTO)
        kind = sc->num_cameras > 0 ? CAMERA_INDEX : CAMERA_FRAME;
    if (kind == CAMERA_INDEX && i >= 0 && (uint32_t)i < sc->num_cameras)
        snprintf(buf, cap, "camera %d '%s'%s", i, sc->cameras[i].name,
                 sc->cameras[i].ortho_half_height > 0 ? " (orthographic)" : "");
    else if (kind == CAMERA_FRAME)
        snprintf(buf, cap, "framing view%s", sc->num_cameras ? "" : " (the scene has no camera)");
    else
        snprintf(buf, cap, "look-at %g,%g,%g -> %g,%g,%g", c->eye[0], c->eye[1], c->eye[2], c->target[0],
                 c->target[1], c->target[2]);
}

void camera_world_to_camera(const scene_camera *c, float m[16])
{
    const float *axes[3] = {c->right, c->up, c->forward};
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++)
            m[4 * i + j] = axes[j][i];
        m[12 + j] = -dot3(c->position, axes[j]);
        m[4 * j + 3] = 0;
    }
    m[15] = 1;
}

void camera_look_at_string(const scene_camera *c, char *buf, size_t cap)
{
    snprintf(buf, cap, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", c->position[0], c->position[1],
             c->position[2], c->position[0] + c->forward[0], c->position[1] + c->forward[1],
             c->position[2] + c->forward[2], c->up[0], c->up[1], c->up[2]);
}

void camera_frame_string(const scene_camera *c, char *buf, size_t cap)
{
    const float *v[4] = {c->position, c->right, c->up, c->forward};
    size_t n = 0;
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, "%s%.9g", n ? "," : "", v[i][k]);
    snprintf(buf + n, n < cap ? cap - n : 0, ",%.9g,%.9g,%.9g", c->znear, c->zfar, c->yfov);
}

bool camera_take_option(const char *cmd, const char *opt, const char *val, void *dest)
{
    return camera_parse_option((camera_option *)dest, cmd, opt, val) == 1;
}
