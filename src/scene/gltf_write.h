/* gltf_write.h: writes a glTF 2.0 scene as one self-contained file: a .gltf is JSON with its
 * one buffer embedded as a base64 data URI (glTF 2.0 specification, sections 3.6-3.7 and 5),
 * a .glb the same document as binary glTF (section 4.4) with the buffer in its BIN chunk.
 *
 * The caller describes the scene with plain arrays (meshes, materials, nodes, cameras,
 * lights); every node is a root of the one scene. Each mesh is one indexed triangle
 * primitive. A zero field means the default documented beside it; extensionsUsed lists
 * exactly the extensions the file uses. Floats are printed with %.9g, so they read back
 * bit for bit. */
#ifndef GONIO_GLTF_WRITE_H
#define GONIO_GLTF_WRITE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct gltf_write_mesh {
    const char *name;          /* NULL: unnamed (likewise for every name below) */
    uint32_t num_vertices;
    const float *positions;    /* 3 per vertex, finite */
    const float *normals;      /* 3 per vertex, unit length; NULL: none */
    const float *uvs;          /* 2 per vertex; NULL: none */
    uint32_t num_indices;      /* a multiple of 3 */
    const uint32_t *indices;   /* each < num_vertices */
    uint32_t material;         /* index into materials; ignored when there are none */
} gltf_write_mesh;

typedef struct gltf_write_material {
    const char *name;
    float base_color[4];       /* linear RGBA, written as given (set alpha!) */
    float metallic, roughness; /* written as given */
    float emissive[3];         /* each in [0, 1]; scale with emissive_strength */
    float emissive_strength;   /* KHR_materials_emissive_strength; 0: not written */
    bool has_specular;         /* write KHR_materials_specular with the next two */
    float specular, specular_color[3];
    float ior;                 /* KHR_materials_ior; 0: not written */
    float transmission;        /* KHR_materials_transmission; 0: not written */
    bool unlit;                /* KHR_materials_unlit */
    bool double_sided;
    const char *alpha_mode;    /* "MASK" or "BLEND"; NULL: OPAQUE (not written) */
    float alpha_cutoff;        /* MASK only; 0: not written (glTF's 0.5) */
    const char *extras;        /* raw JSON object text, e.g. {"gonio":{...}}; NULL: none */
} gltf_write_material;

typedef struct gltf_write_camera { /* perspective */
    const char *name;
    float yfov;                /* radians, > 0 */
    float aspect;              /* width / height; 0: not written */
    float znear;               /* 0: 0.01 */
    float zfar;                /* 0: infinite (not written) */
} gltf_write_camera;

typedef enum gltf_write_light_type {
    GLTF_WRITE_POINT,
    GLTF_WRITE_SPOT,
    GLTF_WRITE_DIRECTIONAL
} gltf_write_light_type;

typedef struct gltf_write_light { /* KHR_lights_punctual; shines along its node's -Z */
    const char *name;
    gltf_write_light_type type;
    float color[3];            /* linear RGB; all 0: white */
    float intensity;           /* 0: 1 */
    float range;               /* 0: infinite (not written) */
    float inner_cone, outer_cone; /* spot only, radians; outer 0: pi/4 */
} gltf_write_light;

typedef enum gltf_write_node_kind {
    GLTF_WRITE_NODE_MESH,
    GLTF_WRITE_NODE_CAMERA,
    GLTF_WRITE_NODE_LIGHT
} gltf_write_node_kind;

typedef struct gltf_write_node {
    const char *name;
    gltf_write_node_kind kind;
    uint32_t index;            /* into meshes, cameras or lights, by kind */
    float translation[3];
    float rotation[4];         /* unit quaternion x, y, z, w; all 0: identity */
    float scale[3];            /* all 0: 1 */
    const float *matrix;       /* 16 floats, column-major; non-NULL: written instead of TRS */
    /* A mesh node's EXT_mesh_gpu_instancing: num_instances > 0 places its mesh once per
     * instance (after the node's transform) with these translations (3 floats each), unit
     * quaternions (4) and scales (3); each NULL: that attribute not written. */
    uint32_t num_instances;
    const float *instance_translation, *instance_rotation, *instance_scale;
} gltf_write_node;

typedef struct gltf_write_desc {
    const gltf_write_mesh *meshes;
    uint32_t num_meshes;
    const gltf_write_material *materials;
    uint32_t num_materials;
    const gltf_write_camera *cameras;
    uint32_t num_cameras;
    const gltf_write_light *lights;
    uint32_t num_lights;
    const gltf_write_node *nodes;
    uint32_t num_nodes;
} gltf_write_desc;

/* Writes desc to path, as GLB when its name ends in .glb (any case), else as .gltf JSON
 * (through a temporary file renamed into place). Preconditions
 * (asserted): indices and node references in range, finite positions. On an I/O failure
 * prints an error naming the file and returns false; no partial file is left behind. */
bool gltf_write_file(const char *path, const gltf_write_desc *desc);

/* gltf_write_file's GLB step (gltf_glb.cpp): the JSON document of len bytes, buffers as data
 * URIs, written to path as GLB by tinygltf. False with an error naming path on failure. */
bool gltf_write_glb_from_json(const char *path, const char *json, size_t len);

#endif
