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
    uint32_t tri;           /* BVH-order triangle (GnPrim order, tri_index), GN_INVALID: miss */
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

#endif
