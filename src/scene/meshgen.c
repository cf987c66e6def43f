/* meshgen.c: procedural test and benchmark meshes. Randomness is splitmix64 (Steele, Lea &
 * Flood 2014), so every mesh is the same on every machine. */
#include "meshgen.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"
#include "vec.h"

static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 24 random bits. */
static float rand01(uint64_t *state) { return (float)(splitmix64(state) >> 40) * 0x1p-24f; }

static meshgen_mesh mesh_alloc(uint32_t num_vertices, uint32_t num_triangles, int with_normals)
{
    meshgen_mesh m;
    m.num_vertices = num_vertices;
    m.positions = util_malloc(3 * (size_t)num_vertices * sizeof(float));
    m.normals = with_normals ? util_calloc(3 * (size_t)num_vertices, sizeof(float)) : NULL;
    m.num_triangles = num_triangles;
    m.indices = util_malloc(3 * (size_t)num_triangles * sizeof(uint32_t));
    return m;
}

static void set3f(float *p, float x, float y, float z) { p[0] = x, p[1] = y, p[2] = z; }
static void set3u(uint32_t *p, uint32_t a, uint32_t b, uint32_t c) { p[0] = a, p[1] = b, p[2] = c; }

/* Sphere bumps for the benchmark: a smooth wave plus per-vertex noise; 0 for a plain sphere. */
typedef struct bumps {
    float wave, noise, phase;
    uint64_t *rng;
} bumps;

/* Writes a uv sphere at vertex vbase and triangle tbase of m: pole, stacks - 1 rings of
 * slices vertices (the seam wraps around), pole; triangles wound outwards. */
static void sphere_into(meshgen_mesh *m, uint32_t vbase, uint32_t tbase, const float c[3],
                        float radius, uint32_t slices, uint32_t stacks, const bumps *b)
{
    uint32_t last = vbase + 1 + (stacks - 1) * slices; /* south pole */
    for (uint32_t j = 0; j <= stacks; j++) {
        double theta = M_PI * j / stacks;
        uint32_t ring = (j == 0 || j == stacks) ? 1 : slices;
        for (uint32_t i = 0; i < ring; i++) {
            double phi = 2 * M_PI * i / slices;
            double n[3] = {sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi)};
            double r = radius;
            uint32_t vi = j == 0 ? vbase : j == stacks ? last : vbase + 1 + (j - 1) * slices + i;
            if (b)
                r *= 1 + b->wave * sin(7 * phi + b->phase) * sin(5 * theta + b->phase) +
                     b->noise * (rand01(b->rng) - 0.5f);
            set3f(m->positions + 3 * vi, (float)(c[0] + r * n[0]), (float)(c[1] + r * n[1]),
                  (float)(c[2] + r * n[2]));
            if (m->normals && !b)
                set3f(m->normals + 3 * vi, (float)n[0], (float)n[1], (float)n[2]);
        }
    }
    uint32_t *idx = m->indices + 3 * (size_t)tbase;
    for (uint32_t i = 0; i < slices; i++) {
        uint32_t i1 = (i + 1) % slices;
        set3u(idx, vbase, vbase + 1 + i1, vbase + 1 + i), idx += 3;
        for (uint32_t j = 1; j + 1 < stacks; j++) {
            uint32_t a = vbase + 1 + (j - 1) * slices, d = a + slices;
            set3u(idx, a + i, a + i1, d + i), idx += 3;
            set3u(idx, a + i1, d + i1, d + i), idx += 3;
        }
        uint32_t a = vbase + 1 + (stacks - 2) * slices;
        set3u(idx, a + i, a + i1, last), idx += 3;
    }
}

meshgen_mesh meshgen_uv_sphere(const float center[3], float radius, uint32_t slices,
                               uint32_t stacks)
{
    assert(slices >= 3 && stacks >= 2);
    meshgen_mesh m = mesh_alloc(2 + (stacks - 1) * slices, 2 * slices * (stacks - 1), 1);
    sphere_into(&m, 0, 0, center, radius, slices, stacks, NULL);
    return m;
}

meshgen_mesh meshgen_random_triangles(uint32_t n, uint64_t seed, const float box_min[3],
                                      const float box_max[3])
{
    assert(n <= UINT32_MAX / 3);
    meshgen_mesh m = mesh_alloc(3 * n, n, 0);
    uint64_t rng = seed;
    float ext[3], size_max = 0;
    for (int a = 0; a < 3; a++) {
        ext[a] = box_max[a] - box_min[a];
        size_max = ext[a] > size_max ? ext[a] : size_max;
    }
    for (uint32_t t = 0; t < n; t++) {
        float *v = m.positions + 9 * (size_t)t;
        uint32_t kind = (uint32_t)(splitmix64(&rng) % 16);
        /* log-uniform size in [1e-3, 0.3] of the box */
        float size = size_max * 1e-3f * powf(300.0f, rand01(&rng));
        for (int a = 0; a < 3; a++)
            v[a] = box_min[a] + ext[a] * rand01(&rng);
        for (int k = 1; k < 3; k++)
            for (int a = 0; a < 3; a++)
                v[3 * k + a] = v[a] + size * (2 * rand01(&rng) - 1);
        if (kind == 0) { /* two equal corners */
            memcpy(v + 6, v + 3, 3 * sizeof(float));
        } else if (kind == 1) { /* a point */
            memcpy(v + 3, v, 3 * sizeof(float));
            memcpy(v + 6, v, 3 * sizeof(float));
        } else if (kind == 2) { /* exactly collinear: on a line parallel to x */
            set3f(v + 3, v[0] + size, v[1], v[2]);
            set3f(v + 6, v[0] + 0.5f * size, v[1], v[2]);
        } else if (kind <= 4) { /* sliver: the third corner just off the first edge */
            for (int a = 0; a < 3; a++)
                v[6 + a] = 0.5f * (v[a] + v[3 + a]) + 1e-4f * size * (2 * rand01(&rng) - 1);
        }
        for (int k = 0; k < 9; k++) {
            int a = k % 3;
            v[k] = v[k] < box_min[a] ? box_min[a] : v[k] > box_max[a] ? box_max[a] : v[k];
        }
        set3u(m.indices + 3 * (size_t)t, 3 * t, 3 * t + 1, 3 * t + 2);
    }
    return m;
}

meshgen_mesh meshgen_quad_soup(uint32_t n, uint64_t seed, const float box_min[3],
                               const float box_max[3])
{
    assert(n >= 1 && n <= UINT32_MAX / 12);
    meshgen_mesh m = mesh_alloc(4 * n + 3 * (n / 4 + 1), 2 * n + n / 4 + 1, 0);
    uint64_t rng = seed;
    uint32_t nv = 0, nt = 0;
    float ext[3];
    for (int a = 0; a < 3; a++)
        ext[a] = box_max[a] - box_min[a];
    for (uint32_t q = 0; q < n; q++) {
        /* corners c0..c3 of a parallelogram, or bent out of its plane (every third) */
        float o[3], e1[3], e2[3], size = 0.2f * rand01(&rng) + 0.02f;
        uint32_t c = nv, kind = (uint32_t)(splitmix64(&rng) % 6);
        for (int a = 0; a < 3; a++) {
            o[a] = box_min[a] + ext[a] * rand01(&rng);
            e1[a] = size * ext[a] * (2 * rand01(&rng) - 1);
            e2[a] = size * ext[a] * (2 * rand01(&rng) - 1);
        }
        if (kind == 5) /* an axis-aligned rectangle, as walls are */
            e1[1] = e1[2] = e2[0] = e2[2] = 0;
        for (int a = 0; a < 3; a++) {
            float bend = q % 3 == 0 ? 0.5f * size * ext[a] * (2 * rand01(&rng) - 1) : 0;
            m.positions[3 * (nv + 0) + a] = o[a];
            m.positions[3 * (nv + 1) + a] = o[a] + e1[a];
            m.positions[3 * (nv + 2) + a] = o[a] + e1[a] + e2[a] + bend;
            m.positions[3 * (nv + 3) + a] = o[a] + e2[a];
        }
        nv += 4;
        /* triangles (c0 c1 c2) and (c0 c2 c3), each in a random rotation, the second in
         * either winding */
        uint32_t t[2][3] = {{c, c + 1, c + 2}, {c, c + 2, c + 3}};
        if (splitmix64(&rng) & 1) {
            uint32_t x = t[1][1];
            t[1][1] = t[1][2], t[1][2] = x;
        }
        for (int k = 0; k < 2; k++) {
            uint32_t r = (uint32_t)(splitmix64(&rng) % 3);
            set3u(m.indices + 3 * (size_t)nt++, t[k][r], t[k][(r + 1) % 3], t[k][(r + 2) % 3]);
        }
        if (q % 4 == 1) { /* a lone triangle between quads: the pairs shift by one */
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 3; a++)
                    m.positions[3 * (nv + k) + a] = o[a] + size * ext[a] * rand01(&rng);
            set3u(m.indices + 3 * (size_t)nt++, nv, nv + 1, nv + 2);
            nv += 3;
        }
    }
    m.num_vertices = nv;
    m.num_triangles = nt;
    return m;
}

meshgen_mesh meshgen_comb(uint32_t n)
{
    assert(n >= 1 && n <= UINT32_MAX / 3);
    meshgen_mesh m = mesh_alloc(3 * n, n, 0);
    for (uint32_t k = 0; k + 1 < n; k++) {
        float z = (float)k, *v = m.positions + 9 * (size_t)k;
        /* x + y = -0.8 at all three corners: the plane never meets the z axis, yet the box
         * [-1, 0.2] x [-1, 0.2] contains it. */
        set3f(v, -1.0f, 0.2f, z);
        set3f(v + 3, 0.2f, -1.0f, z + 0.5f);
        set3f(v + 6, -0.4f, -0.4f, z + 0.3f);
    }
    float z = (float)(n - 1), *v = m.positions + 9 * (size_t)(n - 1);
    set3f(v, -1.0f, -1.0f, z);
    set3f(v + 3, 2.0f, -1.0f, z);
    set3f(v + 6, -1.0f, 2.0f, z);
    for (uint32_t t = 0; t < n; t++)
        set3u(m.indices + 3 * (size_t)t, 3 * t, 3 * t + 1, 3 * t + 2);
    return m;
}

meshgen_mesh meshgen_edge_on(uint32_t n)
{
    assert(n >= 1 && n <= 256);
    uint32_t side = n + 1, surface = side * side * side - (n - 1) * (n - 1) * (n - 1);
    /* Lattice point (i, j, k) -> vertex, assigned on first use so faces share vertices. */
    uint32_t *id = util_malloc((size_t)side * side * side * sizeof *id);
    memset(id, 0xff, (size_t)side * side * side * sizeof *id);
    meshgen_mesh m = mesh_alloc(surface, 12 * n * n, 0);
    uint32_t nv = 0, *idx = m.indices;
    for (int axis = 0; axis < 3; axis++) {
        for (uint32_t s = 0; s < 2; s++) {
            int ua = (axis + 1) % 3, va = (axis + 2) % 3;
            for (uint32_t u = 0; u < n; u++) {
                for (uint32_t v = 0; v < n; v++) {
                    uint32_t q[4];
                    for (uint32_t c = 0; c < 4; c++) {
                        uint32_t p[3];
                        p[axis] = s * n;
                        p[ua] = u + (c == 1 || c == 2);
                        p[va] = v + (c >= 2);
                        uint32_t *slot = &id[(p[0] * side + p[1]) * side + p[2]];
                        if (*slot == UINT32_MAX) {
                            *slot = nv++;
                            for (int a = 0; a < 3; a++)
                                m.positions[3 * *slot + a] = -1.0f + 2.0f * (float)p[a] / (float)n;
                        }
                        q[c] = *slot;
                    }
                    /* corners 0, 1, 2, 3 go around the quad; flip the winding on the low side
                     * so every face points outwards */
                    uint32_t a = q[0], b = s ? q[1] : q[3], c = q[2], d = s ? q[3] : q[1];
                    if ((u + v) & 1) {
                        set3u(idx, a, b, c), idx += 3;
                        set3u(idx, a, c, d), idx += 3;
                    } else {
                        set3u(idx, a, b, d), idx += 3;
                        set3u(idx, b, c, d), idx += 3;
                    }
                }
            }
        }
    }
    assert(nv == m.num_vertices);
    free(id);
    return m;
}

/* Area-weighted vertex normals (the cross product's length is twice the area). */
static void compute_normals(meshgen_mesh *m)
{
    memset(m->normals, 0, 3 * (size_t)m->num_vertices * sizeof(float));
    for (uint32_t t = 0; t < m->num_triangles; t++) {
        const uint32_t *i = m->indices + 3 * (size_t)t;
        const float *p0 = m->positions + 3 * i[0], *p1 = m->positions + 3 * i[1],
                    *p2 = m->positions + 3 * i[2];
        float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        float n[3];
        vec_cross(e1, e2, n);
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                m->normals[3 * i[k] + a] += n[a];
    }
    for (uint32_t v = 0; v < m->num_vertices; v++) {
        float *n = m->normals + 3 * v, len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 0)
            set3f(n, n[0] / len, n[1] / len, n[2] / len);
        else
            set3f(n, 0, 1, 0);
    }
}

meshgen_mesh meshgen_bench_mesh(uint32_t target_tris)
{
    assert(target_tris >= 1000);
    uint32_t g = (uint32_t)sqrt(target_tris / 200.0);  /* ground: g x g quads, ~1% */
    uint32_t per_sphere = (target_tris - 2 * g * g) / 16;
    /* slices s, stacks s / 2: 2 s (s / 2 - 1) ~ s^2 - 2 s triangles */
    uint32_t s = (uint32_t)(1 + sqrt(1.0 + per_sphere)), st = s / 2;
    uint32_t sv = 2 + (st - 1) * s, stri = 2 * s * (st - 1);
    meshgen_mesh m = mesh_alloc(16 * sv + (g + 1) * (g + 1), 16 * stri + 2 * g * g, 1);
    uint64_t rng = 0x60e10b5eedull;
    for (uint32_t k = 0; k < 16; k++) {
        float radius = 0.5f + 0.9f * rand01(&rng);
        float c[3] = {3.0f * (float)(k % 4) - 4.5f, radius * 1.02f, 3.0f * (float)(k / 4) - 4.5f};
        bumps b = {0.04f + 0.08f * rand01(&rng), 0.01f, 6.2832f * rand01(&rng), &rng};
        sphere_into(&m, k * sv, k * stri, c, radius, s, st, &b);
    }
    uint32_t vbase = 16 * sv, *idx = m.indices + 3 * (size_t)16 * stri;
    for (uint32_t j = 0; j <= g; j++)
        for (uint32_t i = 0; i <= g; i++)
            set3f(m.positions + 3 * (vbase + j * (g + 1) + i), -8.0f + 16.0f * (float)i / (float)g,
                  0.0f, -8.0f + 16.0f * (float)j / (float)g);
    for (uint32_t j = 0; j < g; j++) {
        for (uint32_t i = 0; i < g; i++) {
            uint32_t a = vbase + j * (g + 1) + i, b = a + 1, c = a + g + 1, d = c + 1;
            set3u(idx, a, c, b), idx += 3;
            set3u(idx, b, c, d), idx += 3;
        }
    }
    compute_normals(&m);
    return m;
}

void meshgen_destroy(meshgen_mesh *m)
{
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}
