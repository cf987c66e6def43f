/* scene.h: a renderable scene in world space, loaded from glTF 2.0 (.gltf or .glb).
 *
 * The loader (scene_gltf.cpp and the gltf_*.cpp files: gltf_internal.h names them) hides
 * tinygltf behind scene_load. It walks the node hierarchy (matrix and TRS, animated at the
 * time scene_animation_time gives), poses skinned and morphed meshes at that time, bakes every
 * mesh primitive instance into world space and
 * merges them into one triangle list; per-vertex data stays indexed. Materials and lights
 * are stored directly in their GPU form (glsl/lib/shared.h; a material's fields and where
 * the file sets them: glsl/lib/material.h). */
#ifndef GONIO_SCENE_H
#define GONIO_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image.h"
#include "shared.h"

typedef struct scene_camera {
    char name[64];
    float position[3];
    float right[3], up[3], forward[3]; /* orthonormal, world space (forward = node -Z) */
    float yfov;                        /* radians (perspective) */
    float ortho_half_height;           /* > 0: orthographic, half the view's height (ymag) */
    float aspect;                      /* 0 when the glTF camera gives none (ortho: xmag / ymag) */
    float znear, zfar;                 /* zfar 0 = infinite */
} scene_camera;

typedef struct scene_image {
    uint32_t width, height;
    uint8_t *rgba8; /* width * height * 4 bytes, rows top to bottom, as stored in the file */
    uint32_t format; /* the file's encoding: texture_format (image_decode.h) */
} scene_image;

/* A material's use of an image (GnTexture): one per glTF texture, plus one per texture
 * reference with its own texCoord or KHR_texture_transform. */
typedef struct scene_texture {
    uint32_t image; /* index into images */
    uint32_t flags; /* GnTexture flags: wrap S/T, GN_TEX_NEAREST, GN_TEX_UV1 */
    float transform[6]; /* the rows of KHR_texture_transform's matrix (GnTexture.row0, row1) */
} scene_texture;

/* A mesh drawn by instances (scene_instance): one the scene places several times (several
 * nodes use it, or EXT_mesh_gpu_instancing), kept once in its own object space instead of
 * once per placement in world space; the renderer builds its BVH once (src/render/
 * render_geometry.c). Its vertices are as the loader makes a baked mesh's before the
 * transform (normals normalised, tangents generated where a material needs them). */
typedef struct scene_instanced_mesh {
    uint32_t num_vertices;
    GnVertex *vertices;         /* object space */
    uint32_t num_triangles;
    uint32_t *indices;          /* 3 per triangle, into vertices */
    uint32_t *tri_material;     /* per triangle, into materials */
    uint32_t gltf_mesh;         /* the glTF mesh */
    float bounds_min[3], bounds_max[3]; /* of its triangles, object space */
} scene_instanced_mesh;

/* One placement of an instanced mesh: its object-to-world transform, 3x4 row-major (as
 * GnInstance.to_world), invertible (the loader bakes a mesh a singular transform flattens). */
typedef struct scene_instance {
    float to_world[12];
    uint32_t mesh;              /* into instanced_meshes */
    uint32_t node;              /* the glTF node that places it */
} scene_instance;

/* Raw `extras: {"gonio": {...}}` of a material, kept for the integrators that read them. */
typedef struct scene_material_extras {
    char brdf[32];              /* "" when absent */
    int num_params;
    char param_names[8][24];
    float param_values[8];
    bool has_phong;             /* "phong": {...} was present; fields already in GnMaterial */
} scene_material_extras;

/* How gonio handles a glTF extension (the loader's table of extensions, gltf_material.cpp). */
typedef enum scene_support {
    SCENE_UNSUPPORTED, /* not read (how: why, and what the file gets instead) */
    SCENE_PARTLY,      /* read, with something left out (how: what) */
    SCENE_SUPPORTED,   /* read as its specification says (how: by what) */
} scene_support;

/* An extension a file lists (extensionsUsed, extensionsRequired). */
typedef struct scene_extension {
    char name[64];         /* as the file spells it, cut to 63 bytes */
    bool required;         /* in extensionsRequired (the file is refused if unsupported) */
    scene_support support;
    const char *how;       /* a static sentence: what gonio does with it */
} scene_extension;

typedef struct scene {
    char path[1024];

    uint32_t num_vertices;
    GnVertex *vertices;         /* world space; normals normalised; tangents zero if absent
                                   and not generated (src/scene/tangent.c: for normal maps) */

    uint32_t num_triangles;
    uint32_t *indices;          /* 3 per triangle, into vertices */
    uint32_t *tri_material;     /* per triangle, into materials */

    /* Meshes placed by instances, besides the triangles above (which are the meshes used
     * once, baked into world space); none in most scenes. */
    uint32_t num_instanced_meshes;
    scene_instanced_mesh *instanced_meshes;
    uint32_t num_instances;
    scene_instance *instances;

    uint32_t num_meshes;        /* glTF mesh primitives drawn (after instancing by nodes) */
    uint32_t num_gltf_meshes;   /* glTF meshes in the file */
    uint32_t num_nodes;         /* glTF nodes in the file */
    uint32_t num_skins;         /* glTF skins in the file ... */
    uint32_t num_joints;        /* ... and their joints, all together */
    uint32_t num_morph_targets; /* morph targets of the file's meshes, all together ... */
    uint32_t num_morphed_meshes; /* ... and the meshes that have them */
    double pose_seconds;        /* the time posing skinned and morphed meshes took */

    uint32_t num_materials;     /* >= 1: a default material is appended when needed */
    GnMaterial *materials;
    scene_material_extras *material_extras;
    char (*material_names)[64];
    uint32_t num_variants;      /* KHR_materials_variants of the file (any one selected or not) */
    char (*variant_names)[64];

    uint32_t num_extensions;    /* the extensions the file lists, once each, in its order */
    scene_extension *extensions;

    uint32_t num_lights;
    GnLight *lights;

    uint32_t num_images;
    scene_image *images;
    uint32_t num_textures;
    scene_texture *textures;

    uint32_t num_cameras;       /* in node-traversal order (depth-first, children in order) */
    scene_camera *cameras;

    float bounds_min[3], bounds_max[3]; /* of all triangles; min > max when empty */
    float ambient[3];           /* global ambient light of the Phong model (default 0) */
    image environment;          /* the file's image-based light (EXT_lights_image_based) as a
                                   lat-long map; num_channels 0 without one */
    char environment_what[96];  /* how it was made, for messages ("light 0 'Studio', 6 faces of 256x256") */
    bool vertex_colors;         /* some mesh has COLOR_0 (GnVertex.color; 1 elsewhere) */
} scene;

/* Loads a .gltf or .glb file (GLB chosen by its magic, or by the extension); false with
 * *out zeroed on an error, which names the file and the problem.
 * Errors: the GLB container; JSON the glTF schema does not allow in what gonio reads (a wrong
 * type, an index that is no integer or names nothing, a size or offset out of range, an
 * unknown enum: the message names the JSON path, materials[2].extensions.KHR_materials_sheen.
 * sheenRoughnessFactor, and is the same for every extension); anything that could make a read
 * go out of bounds (buffers, views, accessors and their sparse parts, attribute formats,
 * indices), node loops, non-finite transforms, bad animation samplers, skins and morph targets
 * glTF does not allow (a joint index beyond the skin's joints, a target whose count is not the
 * primitive's, weights that do not match the targets, a skin on a mesh without JOINTS_0, ...:
 * the message names the JSON path), compressed data its
 * decoder rejects; an extension in extensionsRequired that gonio does not support
 * (scene_extension_support); files outside the scene's folder (scene_allow_outside_files);
 * a scene too large (SCENE_MAX_*) or without any triangle ("no triangles").
 * Warnings, naming the file and the feature, for what is skipped or repaired: a material
 * factor out of its range (clamped, or the default kept: its row of glsl/lib/material.h
 * says which), unsupported extensions in extensionsUsed (ignored, one warning each),
 * points/lines primitives (strips and fans become triangles), invalid cameras and lights,
 * texCoord > 1 and missing or undecodable images (PNG, JPEG, and WebP and KTX2 through
 * EXT_texture_webp and KHR_texture_basisu, whose core source is the fallback: the slot is
 * GN_INVALID), non-unit normals (renormalised), joint weights that do not sum to one
 * (renormalised), morph target attributes other than POSITION, NORMAL, TANGENT, bad COLOR_0,
 * triangles with non-finite or absurdly large (|x| > 1e15) vertices (dropped, one warning).
 * Primitives without NORMAL get flat normals (de-indexed); normal maps, clearcoat normal maps
 * and anisotropy get MikkTSpace tangents where a mesh has no TANGENT. out->extensions lists
 * the extensions the file uses and how gonio handles each. */
bool scene_load(scene *out, const char *path);

/* How gonio handles the glTF extension `name`: its support and a static sentence saying how
 * (also for a name it does not know: SCENE_UNSUPPORTED, "unknown to gonio"; for
 * KHR_texture_basisu in a build without Basis Universal: SCENE_UNSUPPORTED, and why). */
scene_support scene_extension_support(const char *name, const char **how);

/* What gonio info says of a material for an extension of the loader's table (gltf_material.cpp),
 * one line a material that uses it: "LABEL INDEX "NAME" TEXT". */
typedef struct scene_material_line {
    const char *label; /* the line's first words: "anisotropy" */
    const char *help;  /* what the line says, for gonio info --help (lines of at most 68
                        * characters, '\n' between them) */
    /* The line's TEXT for material m into out, or false when m does not use the extension. */
    bool (*text)(const GnMaterial *m, char *out, size_t size);
} scene_material_line;
/* The table's lines on materials, k = 0, 1, ... in its order; NULL after the last. */
const scene_material_line *scene_material_line_at(size_t k);

/* Limits of a decoded scene, checked before anything is allocated, with the numbers in the
 * error: triangles and vertices stored (the meshes used once after baking them into world
 * space, and each instanced mesh once; about 300 bytes each through loading and the BVH
 * build: 5 GB at the limit), and texels of all images together (RGBA8; images with
 * the same bytes are decoded once and count once). */
#define SCENE_MAX_TRIANGLES (1u << 24)
#define SCENE_MAX_TEXELS (1ull << 28)
/* Instances (each about 300 bytes through loading and the top tree's build: 300 MB at the
 * limit). The triangles they place do not count against SCENE_MAX_TRIANGLES: a mesh placed
 * by instances is kept once. */
#define SCENE_MAX_INSTANCES (1u << 20)
/* The same for the glTF scene of index scene_index (-1: the file's default scene, else its
 * first, else every node without a parent); an index the file lacks is an error. */
bool scene_load_scene(scene *out, const char *path, int scene_index);
/* By default a scene reads only regular files under its own folder (URIs resolved, `..`,
 * percent-escapes and symlinks included; never the working directory): anything else is an
 * error naming the URI. True lets a scene read any file (--allow-outside-files). */
void scene_allow_outside_files(bool allow);
/* Loads that follow apply the KHR_materials_variants variant of this name: each primitive's
 * mapping that lists it replaces the primitive's material (primitives without one keep
 * theirs); a file without a variant of that name is an error listing the variants it has.
 * NULL or "" (the default): the files' own materials. */
void scene_select_variant(const char *name);
/* Loads that follow see the file's animations at this time in seconds: every animation's
 * translation, rotation and scale channels (STEP, LINEAR with slerp for rotations,
 * CUBICSPLINE as glTF 2.0 defines them) replace the nodes' own, so meshes, cameras and
 * lights move, skinned meshes follow their joints, and `weights` channels set the nodes' morph
 * target weights. Negative (the default): the nodes' own transforms and weights. Skins and
 * morph targets are posed either way (gltf_skin.cpp). */
void scene_animation_time(double seconds);

/* Loads that follow keep a mesh that an animation moves (its node's or a parent's
 * translation, rotation or scale) in its own space, placed by an instance, as they keep
 * shared meshes: the frames of an animation then differ only in their instances'
 * transforms (scene_same_geometry), and a renderer moves them by rebuilding only the top
 * tree (renderer_update). False (the default): such a mesh is baked like any other. */
void scene_instance_animated(bool on);

/* Frees everything; accepts a zeroed struct. */
void scene_destroy(scene *s);

/* A camera that frames the whole scene: a raised three-quarter view of the centre of the
 * bounds (from the +Z side, turned SCENE_FRAME_AZIMUTH degrees toward +X and raised
 * SCENE_FRAME_ELEVATION degrees, level horizon) from the nearest distance at which every corner
 * of the bounding box projects inside the vertical and horizontal field of view (yfov 45
 * degrees) for the given image aspect (width / height, > 0), less a margin of
 * SCENE_FRAME_MARGIN of the half-width, moved across (its direction kept) so that the box's
 * picture is centred: the model fills the frame, whatever its size. znear
 * and zfar enclose the box with a factor of 2 to spare. Empty or single-point bounds still
 * give a valid camera (a tiny box around the point, or the unit box at the origin). */
#define SCENE_FRAME_AZIMUTH 35.0
#define SCENE_FRAME_ELEVATION 25.0
#define SCENE_FRAME_MARGIN 0.05f
void scene_default_camera(const scene *s, float aspect, scene_camera *out);
/* The same with another vertical field of view (radians, in (0, pi)). */
void scene_frame_camera(const scene *s, float aspect, float yfov, scene_camera *out);

/* Triangle t's edge cross product (p1 - p0) x (p2 - p0), in double: twice its area along
 * its normal. */
void scene_triangle_cross(const scene *s, uint32_t t, double out[3]);

/* Recomputes bounds_min/bounds_max from the triangles, and from the instances: the box of
 * each one's mesh bounds transformed (so a turned instance may widen them a little). Also
 * each instanced mesh's own bounds. */
void scene_compute_bounds(scene *s);

/* The triangles the scene places: the world's and, for each instance, its mesh's. */
uint64_t scene_placed_triangles(const scene *s);
/* Instance i's world box (its mesh's bounds transformed, as scene_compute_bounds takes them). */
void scene_instance_box(const scene *s, uint32_t i, float lo[3], float hi[3]);
/* Triangle t of instanced mesh m, transformed by instance i's transform: its corners' cross
 * product, in double (twice its world area along its normal; for a mirroring instance the
 * direction is that of the corners as stored, see GN_INSTANCE_MIRROR). */
void scene_instance_triangle_cross(const scene *s, uint32_t i, uint32_t t, double out[3]);
/* Are a and b the same geometry and materials, up to the instances' transforms (the same
 * triangles, vertices, materials, instanced meshes and instances of the same meshes and
 * nodes)? Then one's BVHs serve the other with only the top tree rebuilt (an animated frame;
 * lights and cameras may differ). */
bool scene_same_geometry(const scene *a, const scene *b);

/* Removes every triangle with a corner whose position is not finite or has a coordinate
 * beyond 1e15 in magnitude (such values overflow ray-box tests in float), compacting indices
 * and tri_material, and zeroes those vertices (no triangle refers to them any more); the same
 * in the instanced meshes, and removes instances whose world box goes beyond 1e15 and the
 * meshes left without triangles or instances. Returns the number of triangles removed (an
 * instance's, once); prints nothing (the caller warns once). */
uint32_t scene_drop_invalid_triangles(scene *s);
/* The same on one set of arrays. */
uint32_t scene_drop_invalid_triangles_of(GnVertex *vertices, uint32_t num_vertices, uint32_t *indices,
                                         uint32_t *tri_material, uint32_t *num_triangles);
/* (src/scene/scene_instances.c: the instanced meshes' and instances' parts of
 * scene_drop_invalid_triangles, scene_compute_bounds and scene_destroy) */
uint32_t scene_drop_invalid_instanced(scene *s);
void scene_bound_instances(scene *s);
void scene_free_instances(scene *s);

/* Default material, as glTF 2.0 specifies for primitives without one (white, metallic 1,
 * roughness 1), with the Phong parameters derived as scene_phong_from_pbr does. */
void scene_material_default(GnMaterial *m);

/* Classic (OpenGL 1.x) Phong parameters from the metallic-roughness ones:
 *   diffuse   = base_color.rgb * (1 - metallic) * (1 - transmission)
 *               (and * (1 - max(specular_color)) for GN_MAT_SPEC_GLOSS, specular-glossiness)
 *   specular  = mix(min(F0 * specular_color, 1) * specular, base_color.rgb, metallic)
 *               (the dielectric F0 = ((ior - 1) / (ior + 1))^2, 0.04 at glTF's 1.5, tinted by
 *               KHR_materials_specular; metals reflect their base colour)
 *   shininess = clamp(2 / alpha^2 - 2, 1, 10000), alpha = roughness^2 (the Blinn-Phong
 *               exponent matching a Beckmann lobe of roughness alpha, Walter et al. 2007)
 *   ambient   = diffuse (OpenGL's convention that ambient tracks the diffuse colour; the
 *               scene's ambient light is 0 by default, so it only shows under one)
 *   emission  = emissive */
void scene_phong_from_pbr(GnMaterial *m);

#endif
