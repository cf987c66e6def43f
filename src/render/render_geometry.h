/* render_geometry.h: a scene's triangles as the walk reads them (glsl/lib/shared.h: the GPU
 * layout). A scene without instances is one BVH over its world-space triangles, exactly as
 * it always was. A scene with instances has two levels (src/accel/bvh.h: bvh_top): a BVH per
 * mesh, built once in the mesh's own space (the triangles baked into world space are one
 * more mesh, placed by an identity instance), and a top tree over the instances. */
#ifndef GONIO_RENDER_GEOMETRY_H
#define GONIO_RENDER_GEOMETRY_H

#include <stdbool.h>
#include <stdint.h>

#include "bvh.h"
#include "scene.h"

typedef struct render_geometry {
    bool two_levels;        /* the scene has instances */
    bvh world;              /* one level: the tree over sc->vertices' triangles */
    /* two levels: the meshes are the world's triangles (when there are any, placed by
     * instance 0, the identity), then scene.instanced_meshes in order; the scene's instance k
     * is instance k + first_instance, its mesh m mesh m + first_instance */
    uint32_t num_meshes;
    bvh *meshes;
    bvh_top top;
    uint32_t first_instance; /* 1: the scene has world triangles (mesh 0, instance 0); else 0 */
    uint32_t *vertex_base;  /* per mesh: its first vertex in `vertices` */
    uint32_t *mesh_vertices; /* per mesh: its vertices */
    /* two levels: the vertices of every instance's copy of its mesh, one after the other
     * (Gouraud's colours: GnInstance.vcolor_offset is where an instance's copy starts, less
     * its mesh's first vertex) */
    uint64_t instance_vertices;
    /* the GPU arrays (one level: the tree's and the scene's own, not owned) */
    GnBvhNode *nodes;
    uint32_t num_nodes;
    GnTriPair *pairs;
    uint32_t num_pairs;
    GnPrim *prims;          /* owned: BVH order, corners in the walk's order */
    uint32_t num_slots;
    GnVertex *vertices;
    uint32_t num_vertices;
    uint32_t depth;         /* stack entries a walk may need (one level: the tree's depth) */
    double build_seconds;   /* every tree's build */
    double top_seconds;     /* two levels: the top tree's last build */
} render_geometry;

/* Builds the trees and the GPU arrays of sc. False with an error naming the scene (no
 * triangles; more than a leaf or a walk's stack can index). */
bool render_geometry_build(render_geometry *g, const scene *sc);
/* sc has the geometry g was built from but new instance transforms (scene_same_geometry: an
 * animated frame): the instances and the top tree are rebuilt, nothing else. */
bool render_geometry_update(render_geometry *g, const scene *sc);
void render_geometry_destroy(render_geometry *g); /* accepts a zeroed struct */

/* The scene's triangle of GPU slot `slot` (BVH order; GN_INVALID: the empty half of a lone
 * triangle's pair), in its mesh (*mesh: with two levels, its index in meshes; else 0). */
uint32_t render_geometry_triangle(const render_geometry *g, uint32_t slot, uint32_t *mesh);

/* Bytes the GPU holds of each part (gonio info, the renderer's summary). */
typedef struct render_geometry_bytes {
    uint64_t nodes, pairs, prims, vertices, instances;
} render_geometry_bytes;
render_geometry_bytes render_geometry_size(const render_geometry *g);

#endif
