/* render_output.h: what a render writes besides its pixels: the gonio:* EXR header
 * attributes, and the PNGs of the modes that are not colours.
 *
 * The header's identity attributes say which image a render estimates: the scene's
 * content, the size, the mode, the camera and the options that change the image in that
 * mode. Two renders with equal identities and different seeds are samples of one image,
 * and `gonio merge` compares exactly the attributes listed in render_identity_names. */
#ifndef GONIO_RENDER_OUTPUT_H
#define GONIO_RENDER_OUTPUT_H

#include <stdbool.h>

#include "image.h"
#include "render.h"

#define RENDER_HEADER_MAX 28

typedef struct render_header {
    int count;
    image_attr attrs[RENDER_HEADER_MAX];
    char text[RENDER_HEADER_MAX][256]; /* storage for the string values */
    float world_to_camera[16];
} render_header;

/* The identity attributes (all strings), NULL-terminated:
 *   gonio:scene      "crc32:XXXXXXXX" of the loaded scene (geometry, materials after --brdf
 *                    and extras, lights, textures, ambient light), so a moved or re-saved
 *                    file (.gltf or .glb) is the same scene and an edited one is not
 *   gonio:size       "WxH"
 *   gonio:mode       the mode's name
 *   gonio:camera     the camera actually used: position, forward, up, tan(yfov / 2),
 *                    znear, zfar (%.9g each)
 *   gonio:max-depth, gonio:estimator                       path only
 *   gonio:env        path: "R,G,B" or "map WxH crc32:XXXXXXXX"; lit local modes: "R,G,B"
 *   gonio:shadows, gonio:ambient                           phong, gouraud, flat only
 * An attribute a mode does not use is not written, so it cannot keep renders apart. */
extern const char *const render_identity_names[];

/* Every header attribute of a finished render: the identity, then gonio:spp (int),
 * gonio:seed (int), gonio:sampler (path: its name), gonio:scene-path; the view:
 * gonio:camera-name (s->camera_label), gonio:look-at, gonio:view (src/scene/camera.h),
 * gonio:fov or gonio:ortho-half-height (double),
 * worldToCamera (m44f, OpenEXR's), gonio:environment (s->env_label); then gonio:brdf (when
 * brdf is not NULL), gonio:seconds, gonio:command (`command`, the command line),
 * gonio:version. */
void render_header_build(render_header *h, const renderer *r, const render_settings *s,
                         const render_stats *st, const char *brdf, const char *command);

/* The gonio:seed of an EXR header: an OpenEXR int is signed, so seeds of 2^31 and above are
 * stored as their two's complement and read back here. False when absent or not an int. */
bool render_header_seed(const char *path, uint32_t *seed);

/* Writes the PNG of a render of `mode`: the colour modes tonemapped (exposure, tm, sRGB);
 * depth, normal and cost as pictures of the data, written as 8-bit values without a
 * transfer curve:
 *   depth   grey: the nearest visible point white, the farthest 20% grey (linear in
 *           between over the image's visible range), background black
 *   normal  0.5 n + 0.5 per channel (X red, Y green, Z blue), background black
 *   cost    viridis heat map of the BVH steps, 0 to the image's maximum, every pixel (a ray
 *           that misses still walks the tree)
 * In depth and normal, an edge pixel blends with the background by its coverage (A). */
bool render_write_png(const image *img, uint32_t mode, const char *path, float exposure, image_tonemap tm);

#endif
