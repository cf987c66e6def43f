/* instances.h: a scene of instances for the tests of the two-level walk (test_bvh.c: the C
 * walk against brute force; test_gpu.c: the GPU walk against the C walk): a few meshes, each
 * placed many times by random transforms (rotations, shears, non-uniform scales, mirrors and
 * translations), and the same scene flattened: every instance's triangles transformed to
 * world space in double, the independent reference. */
#ifndef GONIO_TEST_INSTANCES_H
#define GONIO_TEST_INSTANCES_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "meshgen.h"
#include "util.h"

#define INST_MAX_MESHES 4

typedef struct inst_scene {
    uint32_t num_meshes;
    meshgen_mesh mesh[INST_MAX_MESHES];
    bvh tree[INST_MAX_MESHES];
    uint32_t num_instances;
    float (*to_world)[12];
    uint32_t *mesh_of;
    bvh_top top;
    /* flattened: world-space triangles, instance by instance, each mesh's in its own order */
    uint32_t num_triangles;
    float *positions;        /* 9 per triangle */
    uint32_t *indices;       /* 0, 1, 2, 3, ... */
    uint32_t *tri_instance;  /* flattened triangle -> instance */
    uint32_t *tri_local;     /* flattened triangle -> the mesh's triangle */
    uint32_t *first_tri;     /* instance -> its first flattened triangle */
    float lo[3], hi[3];      /* world bounds of the flattened triangles */
} inst_scene;

static inline uint64_t inst_rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline double inst_rng_unit(uint64_t *s) { return (double)(inst_rng_next(s) >> 11) * 0x1p-53; }

/* A random rotation (a uniform unit quaternion's matrix). */
static inline void inst_rotation(uint64_t *rng, double r[3][3])
{
    double q[4], len = 0;
    for (int k = 0; k < 4; k++) {
        q[k] = 2 * inst_rng_unit(rng) - 1;
        len += q[k] * q[k];
    }
    len = sqrt(len);
    double w = q[0] / len, x = q[1] / len, y = q[2] / len, z = q[3] / len;
    double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                      {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                      {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    memcpy(r, m, sizeof m);
}

/* T R1 S R2 (row-major 3x4): a shear from the non-uniform scale S between two rotations, a
 * mirror when `mirror` (one axis of S negative), translated within +-spread. */
static inline void inst_transform(uint64_t *rng, bool mirror, double spread, float out[12])
{
    double r1[3][3], r2[3][3], s[3], m[3][3];
    inst_rotation(rng, r1);
    inst_rotation(rng, r2);
    for (int k = 0; k < 3; k++)
        s[k] = 0.4 + 1.2 * inst_rng_unit(rng);
    if (mirror)
        s[inst_rng_next(rng) % 3] *= -1;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            m[i][j] = 0;
            for (int k = 0; k < 3; k++)
                m[i][j] += r1[i][k] * s[k] * r2[k][j];
        }
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            out[4 * i + j] = (float)m[i][j];
        out[4 * i + 3] = (float)(spread * (2 * inst_rng_unit(rng) - 1));
    }
}

/* world = M p, in double, rounded once */
static inline void inst_apply(const float m[12], const float p[3], float out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = (float)((double)m[4 * r] * p[0] + (double)m[4 * r + 1] * p[1] +
                         (double)m[4 * r + 2] * p[2] + m[4 * r + 3]);
}

/* The flattened triangles of the current transforms. */
static inline void inst_flatten(inst_scene *s)
{
    uint32_t t = 0;
    for (int k = 0; k < 3; k++)
        s->lo[k] = INFINITY, s->hi[k] = -INFINITY;
    for (uint32_t i = 0; i < s->num_instances; i++) {
        const meshgen_mesh *m = &s->mesh[s->mesh_of[i]];
        s->first_tri[i] = t;
        for (uint32_t j = 0; j < m->num_triangles; j++, t++) {
            for (int c = 0; c < 3; c++) {
                float *w = s->positions + 9 * (size_t)t + 3 * c;
                inst_apply(s->to_world[i], m->positions + 3 * (size_t)m->indices[3 * j + c], w);
                for (int k = 0; k < 3; k++) {
                    s->lo[k] = fminf(s->lo[k], w[k]);
                    s->hi[k] = fmaxf(s->hi[k], w[k]);
                }
            }
            s->tri_instance[t] = i;
            s->tri_local[t] = j;
        }
    }
}

/* n instances of three meshes (a soup with slivers and degenerate triangles, a sphere, quads
 * that pair; small: a few triangles each, for trees shallow enough for the walk's stack in
 * registers), a quarter of them mirrored, spread over +-spread, and the top tree over them. */
static inline bool inst_scene_make(inst_scene *s, uint32_t n, double spread, uint64_t seed, bool small)
{
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0.1f, 0, -0.1f};
    uint64_t rng = seed;
    memset(s, 0, sizeof *s);
    s->num_meshes = 3;
    s->mesh[0] = meshgen_random_triangles(small ? 12 : 150, seed, lo, hi);
    s->mesh[1] = small ? meshgen_uv_sphere(c, 0.8f, 4, 3) : meshgen_uv_sphere(c, 0.8f, 16, 8);
    s->mesh[2] = meshgen_quad_soup(small ? 6 : 40, seed + 1, lo, hi);
    for (uint32_t m = 0; m < s->num_meshes; m++)
        if (!bvh_build(&s->tree[m], s->mesh[m].positions, 3, s->mesh[m].indices, s->mesh[m].num_triangles))
            return false;
    s->num_instances = n;
    s->to_world = util_calloc(n, sizeof *s->to_world);
    s->mesh_of = util_calloc(n, sizeof *s->mesh_of);
    s->first_tri = util_calloc(n, sizeof *s->first_tri);
    for (uint32_t i = 0; i < n; i++) {
        s->mesh_of[i] = i % s->num_meshes;
        inst_transform(&rng, i % 4 == 3, spread, s->to_world[i]);
        s->num_triangles += s->mesh[s->mesh_of[i]].num_triangles;
    }
    s->positions = util_calloc(9 * (size_t)s->num_triangles, sizeof *s->positions);
    s->indices = util_calloc(3 * (size_t)s->num_triangles, sizeof *s->indices);
    s->tri_instance = util_calloc(s->num_triangles, sizeof *s->tri_instance);
    s->tri_local = util_calloc(s->num_triangles, sizeof *s->tri_local);
    for (uint32_t k = 0; k < 3 * s->num_triangles; k++)
        s->indices[k] = k;
    inst_flatten(s);
    return bvh_top_build(&s->top, s->tree, s->num_meshes, (const float(*)[12])s->to_world, s->mesh_of,
                         NULL, n, "test instances");
}

static inline void inst_scene_destroy(inst_scene *s)
{
    bvh_top_destroy(&s->top);
    for (uint32_t m = 0; m < s->num_meshes; m++) {
        bvh_destroy(&s->tree[m]);
        meshgen_destroy(&s->mesh[m]);
    }
    free(s->to_world);
    free(s->mesh_of);
    free(s->first_tri);
    free(s->positions);
    free(s->indices);
    free(s->tri_instance);
    free(s->tri_local);
    memset(s, 0, sizeof *s);
}

/* The flattened triangle of a two-level hit (its GPU-array slot and instance). */
static inline uint32_t inst_flat_triangle(const inst_scene *s, uint32_t slot, uint32_t inst)
{
    const GnInstance *g = &s->top.instances[inst];
    return s->first_tri[inst] + s->tree[g->mesh].tri_index[slot - g->prim_base];
}

/* The world point of a two-level hit: the mesh triangle's corners in the walk's order
 * (tri_rotation) at its barycentrics, transformed. */
static inline void inst_hit_point(const inst_scene *s, uint32_t slot, uint32_t inst, float u, float v, float out[3])
{
    const GnInstance *g = &s->top.instances[inst];
    const bvh *b = &s->tree[g->mesh];
    const meshgen_mesh *m = &s->mesh[g->mesh];
    uint32_t local = slot - g->prim_base, t = b->tri_index[local], r = b->tri_rotation[local];
    float p[3];
    for (int k = 0; k < 3; k++) {
        const float *c0 = m->positions + 3 * (size_t)m->indices[3 * t + r];
        const float *c1 = m->positions + 3 * (size_t)m->indices[3 * t + (r + 1) % 3];
        const float *c2 = m->positions + 3 * (size_t)m->indices[3 * t + (r + 2) % 3];
        p[k] = (1 - u - v) * c0[k] + u * c1[k] + v * c2[k];
    }
    inst_apply(s->to_world[inst], p, out);
}

/* How far inside flattened triangle tri the point o + t d lies: the least distance to an
 * edge's line, in double, negative outside. Within rounding of 0 either answer is right. */
static inline double inst_edge_margin(const inst_scene *s, uint32_t tri, const float o[3], const float d[3], double t)
{
    const float *a = s->positions + 9 * (size_t)tri, *b = a + 3, *c = a + 6;
    double p[3], e1[3], e2[3], ep[3], n[3], nn = 0, w[3], len[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        p[k] = o[k] + t * d[k];
        e1[k] = (double)b[k] - a[k];
        e2[k] = (double)c[k] - a[k];
        ep[k] = p[k] - a[k];
        len[0] += ((double)c[k] - b[k]) * ((double)c[k] - b[k]); /* the edge opposite each corner */
        len[1] += e2[k] * e2[k];
        len[2] += e1[k] * e1[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(nn > 0))
        return 0;
    /* barycentrics by sub-triangle areas along n; corner k's, times the height over the
     * opposite edge (|n| / its length), is the distance to that edge */
    double c1[3] = {ep[1] * e2[2] - ep[2] * e2[1], ep[2] * e2[0] - ep[0] * e2[2], ep[0] * e2[1] - ep[1] * e2[0]};
    double c2[3] = {e1[1] * ep[2] - e1[2] * ep[1], e1[2] * ep[0] - e1[0] * ep[2], e1[0] * ep[1] - e1[1] * ep[0]};
    w[1] = (c1[0] * n[0] + c1[1] * n[1] + c1[2] * n[2]) / nn;
    w[2] = (c2[0] * n[0] + c2[1] * n[1] + c2[2] * n[2]) / nn;
    w[0] = 1 - w[1] - w[2];
    double m = INFINITY;
    for (int k = 0; k < 3; k++)
        m = fmin(m, w[k] * sqrt(nn) / sqrt(len[k]));
    return m;
}

#endif
