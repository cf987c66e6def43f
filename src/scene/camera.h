/* camera.h: which camera a command renders from, one rule for render, preview, compare and
 * bench, and how an output records it.
 *
 * The default is the scene's own camera: the first met walking the default scene's nodes
 * depth-first (scene.cameras[0]); a scene without one is framed from a raised three-quarter
 * view (scene_default_camera). The command line can pick another of the file's cameras,
 * ask for the framing view, place a camera (pbrt's LookAt: eye, target, up) or take the view
 * recorded in an EXR that gonio wrote (render or preview), which reproduces it exactly. */
#ifndef GONIO_CAMERA_H
#define GONIO_CAMERA_H

#include <stdbool.h>
#include <stddef.h>

#include "scene.h"

typedef enum camera_kind {
    CAMERA_AUTO = 0, /* the scene's first camera, else CAMERA_FRAME (a zeroed option) */
    CAMERA_INDEX,    /* the scene's camera `index` */
    CAMERA_FRAME,    /* frame the bounds (scene_default_camera) */
    CAMERA_LOOK_AT,  /* eye, target, up */
} camera_kind;

typedef struct camera_option {
    camera_kind kind;
    int index;                       /* CAMERA_INDEX */
    float eye[3], target[3], up[3];  /* CAMERA_LOOK_AT */
    float ortho_half_height;         /* CAMERA_LOOK_AT: > 0 orthographic (from an EXR) */
    bool exact;                      /* CAMERA_LOOK_AT from an EXR: `frame` as recorded */
    float frame[15];                 /* position, right, up, forward, znear, zfar, yfov */
    int width, height;               /* from an EXR: its size (the default --size) */
    float fov;                       /* vertical, degrees; 0 = the camera's own (45 else) */
} camera_option;

/* The orthonormal frame (position, right, up, forward) of a camera at eye looking at
 * target; false when the view is degenerate (target at the eye, or up along the view). */
bool camera_look_at_frame(const float eye[3], const float target[3], const float up[3], scene_camera *out);

/* The camera c selects in sc for an image of the given aspect (width / height > 0). False,
 * with an error naming the scene, when c names a camera sc does not have. */
bool camera_resolve(const camera_option *c, const scene *sc, float aspect, scene_camera *out);

/* The image size a camera suggests when the user gives none: `longer` pixels on the longer
 * side at the camera's own aspect (square when it has none). */
void camera_default_size(const scene_camera *c, int longer, int *width, int *height);

/* One line naming the camera, for summary lines and headers: "camera 0 'Camera'",
 * "framing view", "--look-at ..." */
void camera_describe(const camera_option *c, const scene *sc, char *buf, size_t cap);

/* The world-to-camera matrix in OpenEXR's convention (the standard worldToCamera
 * attribute, as Nuke reads it): row vectors (p' = p M, translation in the last row), a
 * left-handed camera space with +X right, +Y up and +Z the viewing direction. */
void camera_world_to_camera(const scene_camera *c, float m[16]);

/* The view as the --look-at value that reproduces it ("EX,EY,EZ,TX,TY,TZ,UX,UY,UZ", the
 * target one unit ahead), printed exactly (float round trip). */
void camera_look_at_string(const scene_camera *c, char *buf, size_t cap);
/* The camera's frame exactly as --camera FILE.exr reads it back: position, right, up,
 * forward, znear, zfar and yfov (radians), 15 numbers (the gonio:view header attribute). */
void camera_frame_string(const scene_camera *c, char *buf, size_t cap);

#endif
