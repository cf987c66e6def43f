/* camera.c: the camera rule shared by the commands (camera.h). */
#include "camera.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "image.h"
#include "util.h"
#include "vec.h"

/* The orthonormal frame of eye, target and up; false when the view is degenerate (target
 * at the eye, or up along the view). */
bool camera_look_at_frame(const float eye[3], const float target[3], const float up[3], scene_camera *out)
{
    float f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]}, r[3], u[3];
    if (!vec_normalize(f))
        return false;
    vec_cross(f, up, r);
    if (!vec_normalize(r) || fabsf(vec_dot(f, up)) > 0.9999f * sqrtf(vec_dot(up, up)))
        return false;
    vec_cross(r, f, u);
    memcpy(out->position, eye, sizeof out->position);
    memcpy(out->forward, f, sizeof out->forward);
    memcpy(out->right, r, sizeof out->right);
    memcpy(out->up, u, sizeof out->up);
    return true;
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
        } else if (!camera_look_at_frame(c->eye, c->target, c->up, out)) {
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
        m[12 + j] = -vec_dot(c->position, axes[j]);
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
