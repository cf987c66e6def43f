/* gltf_internal.h: what the files of the glTF loader share (C++, private to src/scene). The
 * loader is scene_load (scene_gltf.cpp), in cgltf's order: the container and the JSON document
 * checked (scene_gltf.cpp, gltf_json.cpp), tinygltf's parse with files read only through the
 * sandbox (gltf_files.cpp), the model it returns checked against the specification before
 * one byte is read (gltf_check.cpp), then read: animation (gltf_animation.cpp), geometry and
 * the node hierarchy (gltf_geometry.cpp), skins and morph targets (gltf_skin.cpp), images,
 * textures and materials (gltf_material.cpp).
 * No C++ exception escapes into C. */
#ifndef GONIO_GLTF_INTERNAL_H
#define GONIO_GLTF_INTERNAL_H

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdarg>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "image_decode.h"

extern "C" {
#include "scene.h"
#include "util.h"
}

namespace gltf {

/* Loader limits: keep a hostile file from asking for more memory than any real scene needs
 * (util_malloc would stop the program) and from recursing deeply inside tinygltf. */
const size_t MAX_ELEMENTS = size_t(1) << 28;      /* per accessor backed by a buffer view */
const size_t MAX_ZERO_ELEMENTS = size_t(1) << 22; /* per accessor without one (all zeros) */
/* The decoded scene (scene.h: SCENE_MAX_*), checked before anything is allocated: a few
 * hundred bytes of JSON that instance one large accessor many times asked for gigabytes. */
const size_t MAX_SCENE = SCENE_MAX_TRIANGLES;
const size_t MAX_PIXELS = size_t(1) << 28; /* per image */
const int MAX_JSON_DEPTH = 64;             /* tinygltf copies extras/extensions recursively */
/* Emission and light intensities above this are clamped: products with areas and squared
 * distances must stay finite in float (1e39 became inf and NaN pixels). */
const double MAX_RADIANCE = 1e9;

using Json = nlohmann::json;

typedef std::array<double, 16> Mat; /* column-major, as glTF stores matrices */

struct Prim {                  /* one triangle primitive of a glTF mesh, in the mesh's space */
    std::vector<float> pos;    /* 3 per vertex */
    std::vector<float> nrm;    /* 3 per vertex */
    std::vector<float> uv;     /* 2 per vertex, empty without TEXCOORD_0 */
    std::vector<float> uv1;    /* 2 per vertex, empty without TEXCOORD_1 */
    std::vector<float> tan;    /* 4 per vertex, empty without TANGENT */
    std::vector<float> col;    /* 4 per vertex (RGBA), empty without COLOR_0 */
    std::vector<uint32_t> idx; /* 3 per triangle */
    uint32_t material;         /* glTF material, or GN_INVALID for the default one */
    /* Skinning and morphing (gltf_skin.cpp), per vertex like the above: */
    size_t influences = 0;         /* joint-weight pairs per vertex, 4 per JOINTS_n/WEIGHTS_n set */
    std::vector<uint16_t> joints;  /* influences per vertex: indices into the node's skin's joints */
    std::vector<float> weights;    /* influences per vertex */
    struct Target {                /* a morph target: displacements, 3 per vertex, empty if absent */
        std::vector<float> pos, nrm, tan;
        std::vector<float> uv, uv1;    /* TEXCOORD_0, _1: 2 per vertex */
        std::vector<float> col;        /* COLOR_0: 4 per vertex (RGB for a VEC3 one, A 0) */
    };
    std::vector<Target> targets;
    int max_joint = -1;            /* the largest joint index with a weight > 0 ... */
    std::string max_joint_at;      /* ... and where: "meshes[0].primitives[1].attributes.JOINTS_0: vertex 5" */
    bool flat = false;             /* normals made flat (no NORMAL): recomputed once posed */
};

struct Instance {
    int node, mesh;
    Mat world;
    bool gpu = false;    /* one of EXT_mesh_gpu_instancing's instances */
    bool moving = false; /* an animation moves the node or one above it */
};

/* A node's animated properties at the animation time: which of T, R, S a channel set. */
struct Pose {
    bool has[3] = {false, false, false};
    double v[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1, 0}}; /* translation, rotation, scale */
};

/* A material's textureInfo, as the file has it (gltf_material.cpp: read_texture). */
struct TextureRef {
    int index = -1;    /* the glTF texture; -1: none */
    int tex_coord = 0; /* the set it reads: texCoord, or KHR_texture_transform's */
    float transform[6] = {1, 0, 0, 0, 1, 0}; /* KHR_texture_transform's T R S, as GnTexture's rows */
    bool transformed = false;                /* ... other than the identity */
};

/* A material as read from the document (gltf_material.cpp), before its textures are known. */
struct MaterialDraft {
    std::string name;                  /* "" when unnamed */
    std::string what;                  /* "material 3 'Body'": how messages name it */
    GnMaterial g;                      /* every factor, at glTF's defaults where absent */
    TextureRef tex[GN_MATERIAL_WORDS]; /* each texture slot, by its word in GnMaterial */
    nlohmann::json extras;             /* its extras (extras.gonio: read once its factors are) */
};

/* One load. */
/* An EXT_lights_image_based light as the JSON check read it (gltf_environment.cpp). */
struct Ibl {
    std::string name;
    float intensity = 1, rotation[4] = {0, 0, 0, 1};
    int size = 0, mips = 0;
    int faces[6] = {-1, -1, -1, -1, -1, -1}; /* the images of mip 0 */
};

struct Ctx {
    const char *path;
    tinygltf::Model m;
    bool failed = false;
    std::map<int, std::string> image_errors; /* decode failures reported by the image callback */
    std::vector<Mat> local;                  /* per node */
    std::vector<bool> animated;              /* per node: an animation sets its T, R or S */
    std::vector<bool> camera_ok, light_ok;   /* per glTF camera / light: values usable */
    std::vector<std::vector<Prim>> meshes;   /* per glTF mesh */
    std::vector<uint32_t> image_map, texture_map; /* glTF index -> scene index or GN_INVALID */
    std::map<int, std::string> texture_errors; /* texture -> its image that cannot be read, and why */
    std::set<int> texture_errors_said;       /* of those, the ones a material's error named */
    bool material_drawn = true;              /* load_materials: the scene draws the material read now */
    scene *textures_out = nullptr;           /* where texture_slot adds transformed textures */
    size_t textures_room = 0;                /* textures_out->textures' allocated entries */
    std::map<std::pair<uint32_t, size_t>, int> decoded; /* (crc32, size) of image bytes -> first image */
    std::map<int, int> image_alias;          /* image -> the earlier image with the same bytes */
    std::map<int, texture_format> image_formats; /* image -> the format of its bytes, once read */
    uint64_t texels = 0;                     /* of the images decoded so far */
    std::string limit_error;                 /* a SCENE_MAX_* limit exceeded while decoding */
    std::vector<std::vector<double>> anim_weights; /* per node: its animated morph weights, or empty */
    std::vector<Mat> world;                  /* per node, posed (gltf_skin.cpp: joint_matrices) */
    std::vector<std::vector<Mat>> joint_mats; /* per skin: each joint's world x inverse bind matrix */
    int scene_index = -1;                    /* the glTF scene to draw; -1: the default one */
    std::string folder;                      /* realpath of the scene's folder */
    std::string base_dir;                    /* the folder as tinygltf joins URIs to it */
    std::vector<std::string> access_errors;  /* files the confined loader refused */
    std::vector<MaterialDraft> materials;    /* per glTF material, read with the document */
    std::map<int, int> image_channels;       /* decoded image -> its channels in the file */
    std::vector<Ibl> ibls;                   /* EXT_lights_image_based lights, read with the document */
    size_t file_buffers = 0;                 /* the file's buffers; decompress puts what it decodes after them */
    std::vector<int> scene_ibl;              /* per glTF scene: the index of its light, or -1 */
};

/* ---- scene_gltf.cpp: the load, its settings and its messages ------------------------------- */
extern bool allow_outside_files; /* scene_allow_outside_files */
extern std::string variant;      /* scene_select_variant */
extern bool instance_animated;   /* scene_instance_animated */
extern double anim_time;         /* scene_animation_time; < 0: the nodes' own transforms */
/* Bad input: always returns false so checks read `if (bad) return fail(...)`. */
bool fail(Ctx &c, const char *fmt, ...) UTIL_PRINTF(2, 3);
void warn(Ctx &c, const char *fmt, ...) UTIL_PRINTF(2, 3);
/* "mesh 3 'Body'": how messages name a glTF object. */
std::string label(const char *kind, int i, const std::string &name);
inline bool in_range(int i, size_t n) { return i >= 0 && size_t(i) < n; }

/* ---- gltf_files.cpp: the file sandbox (tinygltf's file callbacks) -------------------------- */
bool fs_file_exists(const std::string &path, void *user);
std::string fs_expand(const std::string &path, void *);
bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *);
bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *);

/* ---- gltf_json.cpp: the JSON document, checked before tinygltf converts it ----------------- */
bool check_document(Ctx &c, const uint8_t *json, size_t n, bool glb);

/* ---- gltf_check.cpp: the model tinygltf returns, checked before it is read ----------------- */
/* Component formats of an attribute accessor, as bits. */
enum : unsigned { F_F = 1, F_I8 = 2, F_I8N = 4, F_U8 = 8, F_U8N = 16, F_I16 = 32, F_I16N = 64, F_U16 = 128, F_U16N = 256 };
const unsigned F_QUANT_ANY = F_F | F_I8 | F_I8N | F_U8 | F_U8N | F_I16 | F_I16N | F_U16 | F_U16N;
bool uses_extension(const tinygltf::Model &m, const char *name);
bool check_asset(Ctx &c);
bool check_buffers_and_views(Ctx &c);
bool check_accessor(Ctx &c, int i);
bool check_accessor_data(Ctx &c, int i); /* false: a decoded accessor out of its (stale) bounds */
bool check_primitive(Ctx &c, int mi, int pi);
bool check_number_array(Ctx &c, const std::vector<double> &v, size_t n, const std::string &what, const char *name);
bool check_nodes_and_scenes(Ctx &c);
void check_cameras(Ctx &c);
void check_lights(Ctx &c);

/* ---- gltf_animation.cpp: the channels sampled at one time ---------------------------------- */
bool check_animations(Ctx &c);
bool animate(Ctx &c, std::vector<Pose> &pose);

/* ---- gltf_geometry.cpp: accessors, nodes, primitives, meshes baked or kept with instances - */
size_t comp_size(int ct);
size_t num_comps(const tinygltf::Accessor &a);
const char *type_name(int type);
size_t elem_size(const tinygltf::Accessor &a);
bool fits(size_t off, size_t stride, size_t count, size_t size, size_t len);
unsigned format_bit(const tinygltf::Accessor &a);
const uint8_t *view_data(const Ctx &c, int view, size_t offset);
double read_comp(const uint8_t *p, int ct, bool norm);
std::vector<double> read_accessor(const Ctx &c, int i);
Mat mat_mul(const Mat &a, const Mat &b);
bool mat_finite(const Mat &m);
/* m's linear part (its upper 3x3, row-major) and its cofactor matrix: returns det. */
double mat_cofactors3(const Mat &m, double a[3][3], double cof[3][3]);
bool node_local(Ctx &c, int i, Mat &out, const Pose *pose = nullptr);
int node_light(const tinygltf::Node &n);
bool load_meshes(Ctx &c);
bool collect_instances(Ctx &c, std::vector<Instance> &inst, std::vector<Instance> &cams, std::vector<Instance> &lights);
bool bake_geometry(Ctx &c, const std::vector<Instance> &inst, scene *out);
void bake_cameras(Ctx &c, const std::vector<Instance> &cams, scene *out);
void bake_lights(Ctx &c, const std::vector<Instance> &lights, scene *out);

/* ---- gltf_skin.cpp: skins and morph targets ------------------------------------------------ */
/* Skins, morph targets, their weights and the nodes that use them as glTF 2.0 requires, with
 * the loader's limit on the data they add; errors name the JSON path. */
bool check_skins_and_targets(Ctx &c);
/* JOINTS_n/WEIGHTS_n and the morph targets of primitive pi of mesh mi into out, per vertex. */
bool read_skin_and_targets(Ctx &c, int mi, int pi, Prim &out);
/* Per-vertex skin and target data in a new vertex order: vertex v takes old vertex src[v]. */
void remap_skin_and_targets(Prim &p, const uint32_t *src, size_t n);
/* The morph weights node `node` draws its mesh with: animated, else the node's, else the mesh's. */
std::vector<double> morph_weights(const Ctx &c, int node);
/* Each skin's joint matrices at the pose of c.local (after the nodes' transforms are known). */
bool joint_matrices(Ctx &c);
/* Whether instance `in` is drawn skinned: its node's transform is then ignored (glTF 2.0,
 * "Skins"), the joints place the vertices in world space. */
bool instance_skinned(const Ctx &c, const Instance &in);
/* Primitive p as instance `in` draws it: the morph targets weighted, then the skin applied
 * (positions, normals, tangents; flat normals recomputed). False when nothing changes (p is
 * drawn as it is) or on an error (c.failed). */
bool pose_primitive(Ctx &c, const Instance &in, const Prim &p, Prim &out);

/* ---- gltf_material.cpp: the extensions, images, textures, materials ------------------------- */
/* The file's extensionsRequired and extensionsUsed against the table of extensions: an
 * unsupported required one is an error, an unsupported used one a warning (once each). */
bool check_extensions(Ctx &c);
/* The same list into out->extensions, with how gonio handles each. */
void list_extensions(Ctx &c, scene *out);
bool image_callback(tinygltf::Image *img, const int idx, std::string *, std::string *, int, int,
                    const unsigned char *bytes, int size, void *user);
bool check_textures(Ctx &c);
std::vector<std::string> variant_names(const tinygltf::Model &m);
bool select_variant(Ctx &c);
/* The texture coordinate set glTF material `material` wants tangents for: its normal map's,
 * else its clearcoat normal map's, else (anisotropy, whose direction is in the tangent frame)
 * its anisotropy texture's or 0; -1 when it needs none. */
int material_tangent_set(const Ctx &c, uint32_t material);
/* Decodes the images into out->images and the textures into out->textures. A texture whose
 * image cannot be read goes into c.texture_errors: texture_slot's error when a material uses
 * it (load_materials), else a warning; an unreadable image no texture uses is a warning. */
void load_images_and_textures(Ctx &c, scene *out);

/* ---- gltf_environment.cpp: the file's image-based light (EXT_lights_image_based) ---------- */
struct Doc;
/* Checks root extensions.EXT_lights_image_based and each scene's reference into c.ibls, c.scene_ibl. */
void check_ibl(Doc &d);
/* Bakes the drawn scene's image-based light into out->environment (after
 * load_images_and_textures: its faces are out->images); false on a bad face. */
bool bake_environment(Ctx &c, scene *out);
/* The scene's materials; false (with an error naming the material, the slot and the image)
 * when a material uses a texture whose image cannot be read. */
bool load_materials(Ctx &c, scene *out);

} // namespace gltf

#endif
