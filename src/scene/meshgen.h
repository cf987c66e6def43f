/* meshgen.h: deterministic procedural triangle meshes for tests and benchmarks (spheres,
 * random soups with degenerate triangles, worst cases for BVH traversal, closed meshes for
 * watertightness). Output is plain arrays owned by the caller: free with meshgen_destroy. */
#ifndef GONIO_MESHGEN_H
#define GONIO_MESHGEN_H

#include <stdint.h>

typedef struct meshgen_mesh {
    uint32_t num_vertices;
    float *positions;       /* 3 per vertex */
    float *normals;         /* 3 per vertex, unit length; NULL when the mesh has none */
    uint32_t num_triangles;
    uint32_t *indices;      /* 3 per triangle */
} meshgen_mesh;

/* Closed sphere (y is the polar axis) with shared vertices: one vertex per pole, the seam
 * shared, 2 * slices * (stacks - 1) triangles; analytic normals. slices >= 3, stacks >= 2. */
meshgen_mesh meshgen_uv_sphere(const float center[3], float radius, uint32_t slices,
                               uint32_t stacks);

/* n independent triangles (3 vertices each, no normals) inside [box_min, box_max]: sizes
 * from 1/1000 to 3/10 of the box, plus slivers and zero-area ones (two equal corners, three
 * equal corners, three collinear corners). The same seed gives the same mesh. */
meshgen_mesh meshgen_random_triangles(uint32_t n, uint64_t seed, const float box_min[3],
                                      const float box_max[3]);

/* n quads inside [box_min, box_max] (no normals), each two triangles sharing a diagonal,
 * listed one after the other in random corner rotations and either relative winding:
 * parallelograms, axis-aligned rectangles and quads bent out of their plane; a lone
 * triangle after every fourth quad. For the BVH's pairing of triangles (src/accel/bvh.c). */
meshgen_mesh meshgen_quad_soup(uint32_t n, uint64_t seed, const float box_min[3],
                               const float box_max[3]);

/* Worst case for traversal: n - 1 slanted slivers stacked along +z (triangle k in the
 * vertical plane x + y = -0.8, z in [k, k + 0.5]) whose boxes all contain the line x = y = 0
 * while the triangles do not, then one triangle at z = n - 1 crossing that line. The ray
 * org (0, 0, -1), dir (0, 0, 1) visits every BVH node and hits only the last triangle, at
 * t = n. n >= 1. */
meshgen_mesh meshgen_comb(uint32_t n);

/* Closed axis-aligned cube [-1, 1]^3, each face an n x n grid of quads split in two (the
 * diagonal alternates), vertices shared between faces: 12 n^2 triangles. Grid lines lie at
 * -1 + 2 k / n, exact floats when n is a power of two, so axis-aligned rays can run exactly
 * through shared edges and vertices and exactly within face planes (edge-on). 1 <= n <= 256. */
meshgen_mesh meshgen_edge_on(uint32_t n);

/* Benchmark scene of about target_tris triangles (>= 1000): a 4 x 4 grid of bumpy spheres of
 * different sizes on a ground grid, with area-weighted vertex normals. 250000 gives
 * ~247k triangles. */
meshgen_mesh meshgen_bench_mesh(uint32_t target_tris);

/* Frees the arrays; accepts a zeroed struct. */
void meshgen_destroy(meshgen_mesh *m);

#endif
