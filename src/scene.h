/* scene.h: a renderable scene in world space, loaded from glTF 2.0 (.gltf or .glb).
 *
 * The loader (scene_gltf.cpp) hides tinygltf behind scene_load. It walks the node
 * hierarchy (matrix and TRS), bakes every mesh primitive instance into world space and
 * merges them into one triangle list; per-vertex data stays indexed. Materials and lights
 * are stored directly in their GPU form (glsl/shared.h). */
#ifndef GONIO_SCENE_H
#define GONIO_SCENE_H

#include <stdbool.h>
#include <stdint.h>

#include "../glsl/shared.h"

typedef struct scene_camera {
    char name[64];
    float position[3];
    float right[3], up[3], forward[3]; /* orthonormal, world space (forward = node -Z) */
    float yfov;                        /* radians */
    float aspect;                      /* 0 when the glTF camera gives none */
    float znear, zfar;                 /* zfar 0 = infinite */
} scene_camera;

typedef struct scene_image {
    uint32_t width, height;
    uint8_t *rgba8; /* width * height * 4 bytes, rows top to bottom, as stored in the file */
} scene_image;

typedef struct scene_texture {
    uint32_t image; /* index into images */
    uint32_t flags; /* GnTexture flags: wrap S/T and GN_TEX_NEAREST */
} scene_texture;

/* Raw `extras: {"gonio": {...}}` of a material, kept for the integrators that read them. */
typedef struct scene_material_extras {
    char brdf[32];              /* "" when absent */
    int num_params;
    char param_names[8][24];
    float param_values[8];
    bool has_phong;             /* "phong": {...} was present; fields already in GnMaterial */
} scene_material_extras;

typedef struct scene {
    char path[1024];

    uint32_t num_vertices;
    GnVertex *vertices;         /* world space; normals normalised; tangents zero if absent */

    uint32_t num_triangles;
    uint32_t *indices;          /* 3 per triangle, into vertices */
    uint32_t *tri_material;     /* per triangle, into materials */

    uint32_t num_meshes;        /* glTF mesh primitives drawn (after instancing by nodes) */
    uint32_t num_gltf_meshes;   /* glTF meshes in the file */
    uint32_t num_nodes;         /* glTF nodes in the file */

    uint32_t num_materials;     /* >= 1: a default material is appended when needed */
    GnMaterial *materials;
    scene_material_extras *material_extras;
    char (*material_names)[64];

    uint32_t num_lights;
    GnLight *lights;

    uint32_t num_images;
    scene_image *images;
    uint32_t num_textures;
    scene_texture *textures;

    uint32_t num_cameras;       /* perspective cameras only, in node-traversal order */
    scene_camera *cameras;

    float bounds_min[3], bounds_max[3]; /* of all triangles; min > max when empty */
    float ambient[3];           /* global ambient light of the Phong model (default 0) */
} scene;

/* Loads a .gltf or .glb file. On failure prints an error naming the file and the problem
 * and returns false with *out zeroed. Unsupported features that can be skipped safely
 * (non-triangle primitives, orthographic cameras, unknown optional extensions, alpha modes)
 * print a warning naming the file and the feature. Triangles with non-finite or absurdly
 * large (|x| > 1e15) vertices are dropped with a warning. A scene without any triangle is
 * an error. */
bool scene_load(scene *out, const char *path);

/* Frees everything; accepts a zeroed struct. */
void scene_destroy(scene *s);

/* A camera that frames the whole scene: looking down -Z at the centre of the bounds from
 * a distance at which the bounding sphere fits in the vertical and horizontal field of
 * view (yfov 45 degrees) for the given image aspect (width / height). */
void scene_default_camera(const scene *s, float aspect, scene_camera *out);

/* Recomputes bounds_min/bounds_max from the triangles. */
void scene_compute_bounds(scene *s);

/* Default material, as glTF 2.0 specifies for primitives without one (white, metallic 1,
 * roughness 1), with the Phong parameters derived as scene_phong_from_pbr does. */
void scene_material_default(GnMaterial *m);

/* Classic Phong parameters from the metallic-roughness ones (documented in docs/shading.md):
 * diffuse = base * (1 - metallic); specular = specular_color * specular * mix(0.04, base,
 * metallic) normalised so a white dielectric gives 0.04 ... see scene.c for the rule. */
void scene_phong_from_pbr(GnMaterial *m);

#endif
