/* bvh.h: bounding volume hierarchy over triangles: binned SAH build (Wald 2007, "On fast
 * construction of SAH-based bounding volume hierarchies"), flattened to the GPU node layout
 * of glsl/lib/shared.h (GnBvhNode: both children's boxes in one node), and a C traversal of
 * that same layout with the watertight ray-triangle test (Woop, Benthin & Wald 2013), which
 * is the reference the GLSL traversal is tested against. */
#ifndef GONIO_BVH_H
#define GONIO_BVH_H

#include <stdbool.h>
#include <stdint.h>

#include "shared.h"

typedef struct bvh {
    GnBvhNode *nodes;
    uint32_t num_nodes;
    GnTriPair *pairs;       /* the leaves' primitives in leaf order: a triangle or two */
    uint32_t num_pairs;
    uint32_t num_slots;     /* BVH-order triangles: 2 per pair (A = 2i, B = 2i + 1) */
    uint32_t *tri_index;    /* BVH-order triangle -> original index; GN_INVALID: no B */
    uint8_t *tri_rotation;  /* BVH-order triangle -> r: its corner k in the test's order (and
                               in bvh_hit's barycentrics) is its own corner (r + k) mod 3 */
    uint32_t num_tris;      /* triangles */
    uint32_t depth;         /* longest root-to-leaf path, in GnBvhNode levels */
    uint32_t max_leaf_size; /* in GnTriPairs */
    float sah_cost;         /* SAH cost with C_trav = 1, C_isect = 1 per GnTriPair, relative
                               to the root's area */
    double build_seconds;
} bvh;

typedef struct bvh_hit {
    float t, u, v;          /* p = (1-u-v) c0 + u c1 + v c2, c_k: the triangle's own corner
                               (tri_rotation[tri] + k) mod 3 */
    uint32_t tri;           /* BVH-order triangle (GnPrim order, tri_index), GN_INVALID: miss;
                               two levels: in the GPU arrays (bvh_top: 2 pair_base[mesh] + the
                               mesh tree's own) */
    uint32_t inst;          /* two levels: the instance hit (GN_INVALID: none, or one level) */
} bvh_hit;

/* Builds over num_triangles triangles given by positions (xyz floats) and indices (3 per
 * triangle); two triangles that share an edge may become one GnTriPair, whatever their
 * order in the index buffer. Triangles must have finite vertices (scene_load guarantees it). Returns false
 * only when num_triangles == 0. Deterministic: the same input gives the same tree. */
bool bvh_build(bvh *out, const float *positions, size_t position_stride_floats,
               const uint32_t *indices, uint32_t num_triangles);
void bvh_destroy(bvh *b);

/* Closest hit with t in (tmin, tmax). *steps (may be NULL) receives the number of
 * GnBvhNode visits, counted exactly as the GLSL traversal counts them. */
bvh_hit bvh_intersect(const bvh *b, const float org[3], const float dir[3], float tmin,
                      float tmax, uint32_t *steps);
/* Any hit in (tmin, tmax). */
bool bvh_occluded(const bvh *b, const float org[3], const float dir[3], float tmin, float tmax);

/* Watertight ray-triangle test; true with t, u, v on a hit in (tmin, tmax). Edges shared by
 * two triangles are hit by exactly one or both, never missed. */
bool bvh_tri_intersect(const float org[3], const float dir[3], const float v0[3],
                       const float v1[3], const float v2[3], float tmin, float tmax,
                       float *t, float *u, float *v);

/* Brute force over all triangles (in original order): the independent reference. hit.tri is
 * the ORIGINAL triangle index. */
bvh_hit bvh_brute_force(const float *positions, size_t position_stride_floats,
                        const uint32_t *indices, uint32_t num_triangles, const float org[3],
                        const float dir[3], float tmin, float tmax);

/* ---- two levels: instances of meshes ------------------------------------------------------
 * Each mesh's tree is built once over its triangles in its own object space (bvh_build: the
 * bottom level); a scene places meshes by instances (GnInstance: an object-to-world 3x4
 * transform and a mesh), and a top-level tree over the instances' world boxes, whose leaves
 * are single instances, leads the walk to them (glsl/lib/shared.h: the GPU layout). Memory
 * grows with the number of instances, not with the triangles they place. A new set of
 * transforms (an animated frame) rebuilds only the top tree. */
typedef struct bvh_top {
    bvh tree;               /* over the instances: leaves GN_BVH_INSTANCE | instance */
    const bvh *meshes;      /* the bottom-level trees (not owned) */
    uint32_t num_meshes;
    GnInstance *instances;  /* num_instances, their GPU form */
    uint32_t num_instances;
    uint32_t *node_base, *pair_base; /* per mesh: where its tree starts in the GPU arrays */
    uint32_t num_nodes;     /* of the GPU node array: the top tree's, then every mesh's */
    uint32_t num_pairs;     /* of the GPU pair array: every mesh's */
    uint32_t mesh_depth;    /* the deepest mesh tree's levels */
    double build_seconds;   /* the top tree's last build (bvh_top_build or bvh_top_update) */
} bvh_top;

/* The most levels the top tree may have over a deepest mesh tree of mesh_depth levels: a walk
 * keeps at most one entry a level of each tree, and a marker between them, on a stack of
 * GN_WALK_STACK entries (glsl/lib/bvh.glsl). */
uint32_t bvh_top_max_depth(uint32_t mesh_depth);

/* Places num_instances instances of the meshes (each non-empty): to_world[i] is instance i's
 * 3x4 row-major object-to-world transform, which must be invertible with finite entries;
 * mesh[i] its mesh, custom[i] its GnInstance.custom (may be NULL: 0). False, with an error
 * naming `what`, when there is no instance, a transform is singular, or the trees together are
 * deeper than a walk's stack holds (bvh_top_max_depth). prim_base and root follow from the
 * layout; vcolor_offset is left 0 for the caller. */
bool bvh_top_build(bvh_top *out, const bvh *meshes, uint32_t num_meshes, const float (*to_world)[12],
                   const uint32_t *mesh, const uint32_t *custom, uint32_t num_instances, const char *what);
/* New transforms for the same instances (an animated frame): the instances' GPU form and the
 * top tree are rebuilt; the meshes' trees and the layout stay (the top tree of n instances
 * always has max(n - 1, 1) nodes). False as bvh_top_build. */
bool bvh_top_update(bvh_top *t, const float (*to_world)[12], const char *what);
void bvh_top_destroy(bvh_top *t); /* accepts a zeroed struct */
/* The GPU arrays: num_nodes nodes (the top tree, then each mesh's, indices moved to their
 * place) and num_pairs pairs. */
void bvh_top_gpu_nodes(const bvh_top *t, GnBvhNode *out);
void bvh_top_gpu_pairs(const bvh_top *t, GnTriPair *out);
/* The deepest walk's stack entries (both levels and the marker). */
uint32_t bvh_top_depth(const bvh_top *t);

/* Closest hit and any hit over the instances, by the same top tree, boxes, transforms and
 * triangle test as glsl/lib/bvh.glsl (hit.inst: the instance; hit.tri: in the GPU arrays).
 * *steps: the node visits of both levels. */
bvh_hit bvh_top_intersect(const bvh_top *t, const float org[3], const float dir[3], float tmin,
                          float tmax, uint32_t *steps);
bool bvh_top_occluded(const bvh_top *t, const float org[3], const float dir[3], float tmin, float tmax);
/* The ray in instance i's object space, as the GPU walk transforms it: the same t on both. */
void bvh_instance_ray(const GnInstance *in, const float org[3], const float dir[3], float o[3], float d[3]);

#endif
