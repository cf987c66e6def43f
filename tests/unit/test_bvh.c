/* test_bvh.c: the BVH build, traversal and watertight triangle test, and the mesh generators.
 * References are independent of the code under test: brute force over all triangles, a
 * double-precision Moller-Trumbore test, analytic hit distances, and closed meshes through
 * whose shared edges and vertices no ray may slip. */
#include "bvh.h"
#include "instances.h"
#include "meshgen.h"
#include "test.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- helpers --------------------------------------------------------------------------- */

static uint64_t rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static float rng_float(uint64_t *s) { return (float)(rng_next(s) >> 40) * 0x1p-24f; }

static bool build_mesh(bvh *b, const meshgen_mesh *m)
{
    return bvh_build(b, m->positions, 3, m->indices, m->num_triangles);
}

static const float *corner(const meshgen_mesh *m, uint32_t tri, int k)
{
    return m->positions + 3 * m->indices[3 * tri + k];
}

static void mesh_bounds(const meshgen_mesh *m, float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = INFINITY, hi[a] = -INFINITY;
    for (uint32_t v = 0; v < m->num_vertices; v++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fminf(lo[a], m->positions[3 * v + a]);
            hi[a] = fmaxf(hi[a], m->positions[3 * v + a]);
        }
}

static bool box_has_point(const vec3 *lo, const vec3 *hi, const vec3 *p)
{
    return p->x >= lo->x && p->y >= lo->y && p->z >= lo->z && p->x <= hi->x && p->y <= hi->y &&
           p->z <= hi->z;
}

static bool box_has_box(const vec3 *lo, const vec3 *hi, const vec3 *clo, const vec3 *chi)
{
    return clo->x >= lo->x && clo->y >= lo->y && clo->z >= lo->z && chi->x <= hi->x &&
           chi->y <= hi->y && chi->z <= hi->z;
}

/* Corner k, in the walk's order, of BVH-order triangle `slot`: the mesh's corner
 * (tri_rotation + k) mod 3. */
static const float *slot_corner(const bvh *b, const meshgen_mesh *m, uint32_t slot, int k)
{
    return corner(m, b->tri_index[slot], (int)((b->tri_rotation[slot] + k) % 3));
}

/* Walks the whole tree and checks every invariant of the GnBvhNode and GnTriPair layouts
 * against the mesh. */
static void check_structure(const bvh *b, const meshgen_mesh *m)
{
    uint32_t n = m->num_triangles;
    uint8_t *seen_tri = calloc(n, 1), *seen_node = calloc(b->num_nodes, 1);
    uint8_t *seen_pair = calloc(b->num_pairs, 1);
    uint32_t stack[256], level[256], sp = 0, depth = 0, max_leaf = 0, visited = 0, holes = 0;
    int bad_perm = 0, bad_tri = 0, bad_box = 0, bad_order = 0, bad_leaf = 0, bad_pair = 0;

    CHECK(b->num_tris == n && b->num_pairs <= n && 2 * b->num_pairs >= n &&
          b->num_slots == 2 * b->num_pairs);
    /* the slots hold every triangle once; pair i is triangles 2i and 2i + 1 (a lone one:
     * slot 2i + 1 empty and p3 = p2), B a triangle sharing one edge with A; the
     * corners are the mesh's, rotated by tri_rotation, B's (p0, p2, p3) */
    for (uint32_t i = 0; i < b->num_slots; i++) {
        uint32_t id = b->tri_index[i];
        if (id == GN_INVALID && (i & 1)) {
            holes++;
            continue;
        }
        if (id >= n || seen_tri[id]++ || b->tri_rotation[i] > 2)
            bad_perm++;
    }
    CHECKF(bad_perm == 0 && holes == 2 * b->num_pairs - n,
           "%d tri_index entries are not a permutation (%u holes, %u lone triangles)", bad_perm,
           holes, 2 * b->num_pairs - n);
    for (uint32_t i = 0; i < b->num_pairs && !bad_perm; i++) {
        const GnTriPair *q = &b->pairs[i];
        const vec3 *tc[2][3] = {{&q->p0, &q->p1, &q->p2}, {&q->p0, &q->p2, &q->p3}};
        bool lone = b->tri_index[2 * i + 1] == GN_INVALID;
        if (lone) {
            bad_pair += memcmp(&q->p2, &q->p3, sizeof q->p2) != 0;
        } else { /* A and B share exactly one edge (two points, bit for bit) */
            const uint32_t *ia = m->indices + 3 * (size_t)b->tri_index[2 * i];
            const uint32_t *ib = m->indices + 3 * (size_t)b->tri_index[2 * i + 1];
            int shared = 0;
            for (int j = 0; j < 3; j++)
                for (int k = 0; k < 3; k++)
                    shared += memcmp(m->positions + 3 * (size_t)ia[j], m->positions + 3 * (size_t)ib[k],
                                     3 * sizeof(float)) == 0;
            bad_pair += shared != 2;
        }
        for (int w = 0; w < (lone ? 1 : 2); w++)
            for (int k = 0; k < 3; k++) {
                const float *c = slot_corner(b, m, 2 * i + (uint32_t)w, k);
                bad_tri += tc[w][k]->x != c[0] || tc[w][k]->y != c[1] || tc[w][k]->z != c[2];
            }
    }
    CHECKF(bad_pair == 0, "%d GnTriPair records malformed", bad_pair);
    CHECKF(bad_tri == 0, "%d GnTriPair corners differ from the mesh", bad_tri);

    memset(seen_tri, 0, n);
    stack[sp] = 0, level[sp++] = 1;
    while (sp > 0 && sp < 250) {
        uint32_t i = stack[--sp], lv = level[sp];
        const GnBvhNode *nd = &b->nodes[i];
        const vec3 *lo[2] = {&nd->a_min, &nd->b_min}, *hi[2] = {&nd->a_max, &nd->b_max};
        uint32_t index[2] = {nd->a_index, nd->b_index}, count[2] = {nd->a_count, nd->b_count};
        if (i >= b->num_nodes || seen_node[i]++) {
            bad_order++;
            break;
        }
        visited++;
        depth = lv > depth ? lv : depth;
        for (int c = 0; c < 2; c++) {
            if (index[c] == GN_INVALID) { /* empty: only b of a root leaf, an inverted box */
                bad_leaf += !(c == 1 && i == 0 && count[0] == n && count[1] == 0 &&
                              lo[c]->x > hi[c]->x && lo[c]->y > hi[c]->y && lo[c]->z > hi[c]->z);
                continue;
            }
            if (count[c] > 0) {
                /* a leaf's index is the walk's entry: flag, count - 1, first triangle */
                uint32_t first = index[c] & GN_BVH_FIRST;
                max_leaf = count[c] > max_leaf ? count[c] : max_leaf;
                if (first + count[c] > b->num_pairs ||
                    index[c] != (GN_BVH_LEAF | (count[c] - 1) << GN_BVH_COUNT_SHIFT | first)) {
                    bad_leaf++;
                    continue;
                }
                for (uint32_t t = first; t < first + count[c]; t++) {
                    const GnTriPair *q = &b->pairs[t];
                    const vec3 *v[4] = {&q->p0, &q->p1, &q->p2, &q->p3};
                    bad_leaf += seen_pair[t]++ != 0;
                    for (int k = 0; k < 4; k++)
                        bad_box += !box_has_point(lo[c], hi[c], v[k]);
                }
            } else {
                const GnBvhNode *ch;
                if (index[c] >= b->num_nodes) {
                    bad_order++;
                    continue;
                }
                ch = &b->nodes[index[c]];
                bad_box += !box_has_box(lo[c], hi[c], &ch->a_min, &ch->a_max);
                bad_box += !box_has_box(lo[c], hi[c], &ch->b_min, &ch->b_max);
                bad_order += c == 0 && index[c] != i + 1; /* depth-first: a follows its parent */
                stack[sp] = index[c], level[sp++] = lv + 1;
            }
        }
    }
    for (uint32_t t = 0; t < b->num_pairs; t++)
        bad_leaf += seen_pair[t] != 1;
    CHECKF(bad_order == 0 && visited == b->num_nodes, "%d bad node links, %u of %u nodes reached",
           bad_order, visited, b->num_nodes);
    CHECKF(bad_leaf == 0, "%d leaf slots wrong (each pair in exactly one leaf)", bad_leaf);
    CHECKF(bad_box == 0, "%d boxes do not contain their children or triangles", bad_box);
    CHECKF(depth == b->depth, "depth %u, bvh says %u", depth, b->depth);
    CHECKF(max_leaf == b->max_leaf_size, "largest leaf %u, bvh says %u", max_leaf,
           b->max_leaf_size);
    CHECK(b->depth <= 64 && b->max_leaf_size <= 8);
    free(seen_tri);
    free(seen_node);
    free(seen_pair);
}

/* Zero area up to rounding: |cross| tiny against the squared longest edge. */
static bool flat(const float *p0, const float *p1, const float *p2)
{
    double e1[3], e2[3], e3[3], c[3];
    for (int a = 0; a < 3; a++)
        e1[a] = (double)p1[a] - p0[a], e2[a] = (double)p2[a] - p0[a], e3[a] = (double)p2[a] - p1[a];
    c[0] = e1[1] * e2[2] - e1[2] * e2[1], c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double l = fmax(fmax(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2],
                         e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]),
                    e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2]);
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) <= 1e-6 * l;
}

/* Random rays against brute force: half aimed at a random point of a random triangle (mostly
 * hits), half in random directions. Also checks the barycentrics and bvh_occluded. */
static void check_rays(const bvh *b, const meshgen_mesh *m, int num_rays, uint64_t seed)
{
    float lo[3], hi[3], ext = 0;
    int bad_hit = 0, bad_t = 0, bad_tri = 0, bad_uv = 0, bad_occ = 0, bad_steps = 0, hits = 0;
    uint64_t rng = seed;
    mesh_bounds(m, lo, hi);
    for (int a = 0; a < 3; a++)
        ext = fmaxf(ext, hi[a] - lo[a]);
    for (int r = 0; r < num_rays; r++) {
        float org[3], dir[3];
        for (int a = 0; a < 3; a++)
            org[a] = lo[a] - 0.25f * ext + 1.5f * ext * rng_float(&rng);
        if (r & 1) {
            for (int a = 0; a < 3; a++)
                dir[a] = 2 * rng_float(&rng) - 1;
        } else {
            uint32_t t = (uint32_t)(rng_next(&rng) % m->num_triangles);
            float u = rng_float(&rng), v = rng_float(&rng);
            if (u + v > 1)
                u = 1 - u, v = 1 - v;
            for (int a = 0; a < 3; a++)
                dir[a] = (1 - u - v) * corner(m, t, 0)[a] + u * corner(m, t, 1)[a] +
                         v * corner(m, t, 2)[a] - org[a];
        }
        if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0)
            continue;
        uint32_t steps = 0;
        bvh_hit h = bvh_intersect(b, org, dir, 0, INFINITY, &steps);
        bvh_hit ref = bvh_brute_force(m->positions, 3, m->indices, m->num_triangles, org, dir, 0,
                                      INFINITY);
        bad_steps += steps < 1 || steps > b->num_nodes;
        if ((h.tri == GN_INVALID) != (ref.tri == GN_INVALID)) {
            bad_hit++;
            continue;
        }
        if (ref.tri == GN_INVALID) {
            bad_occ += bvh_occluded(b, org, dir, 0, INFINITY);
            continue;
        }
        hits++;
        bool same_t = fabsf(h.t - ref.t) <= 1e-5f * fabsf(ref.t);
        bad_t += !same_t;
        bad_tri += h.tri >= b->num_slots || (b->tri_index[h.tri] != ref.tri && !same_t);
        /* p = (1-u-v) v0 + u v1 + v v2 is the hit point, except on zero-area triangles (which
         * scene_load drops): their "hits" are rounding noise of a det that should be 0 */
        const float *c0 = slot_corner(b, m, h.tri, 0), *c1 = slot_corner(b, m, h.tri, 1),
                    *c2 = slot_corner(b, m, h.tri, 2);
        for (int a = 0; a < 3 && !flat(c0, c1, c2); a++) {
            float p = (1 - h.u - h.v) * c0[a] + h.u * c1[a] + h.v * c2[a];
            bad_uv += fabsf(p - (org[a] + h.t * dir[a])) > 1e-4f * ext;
        }
        bad_uv += h.u < -1e-6f || h.v < -1e-6f || h.u + h.v > 1 + 1e-6f;
        /* occlusion: nothing before the closest hit, something just beyond it */
        bad_occ += bvh_occluded(b, org, dir, 0, ref.t * 0.999f);
        bad_occ += !bvh_occluded(b, org, dir, 0, ref.t * 1.001f);
    }
    CHECKF(bad_hit == 0, "%d of %d rays: hit/miss differs from brute force", bad_hit, num_rays);
    CHECKF(bad_t == 0, "%d rays: t differs from brute force", bad_t);
    CHECKF(bad_tri == 0, "%d rays: other triangle than brute force", bad_tri);
    CHECKF(bad_uv == 0, "%d barycentric checks failed", bad_uv);
    CHECKF(bad_occ == 0, "%d occlusion queries differ from brute force", bad_occ);
    CHECKF(bad_steps == 0, "%d rays with a step count outside [1, num_nodes]", bad_steps);
    CHECKF(hits > num_rays / 4, "only %d of %d rays hit: the test is too weak", hits, num_rays);
}

/* ---- the triangle test ------------------------------------------------------------------ */

/* Moller & Trumbore 1997 in double: the independent reference away from edges. */
static bool moller_trumbore(const float o[3], const float d[3], const float *p0, const float *p1,
                            const float *p2, double *t, double *u, double *v)
{
    double e1[3], e2[3], s[3], pv[3], qv[3], det;
    for (int a = 0; a < 3; a++)
        e1[a] = (double)p1[a] - p0[a], e2[a] = (double)p2[a] - p0[a], s[a] = (double)o[a] - p0[a];
    pv[0] = d[1] * e2[2] - d[2] * e2[1], pv[1] = d[2] * e2[0] - d[0] * e2[2];
    pv[2] = d[0] * e2[1] - d[1] * e2[0];
    det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
    if (fabs(det) < 1e-12)
        return false;
    *u = (s[0] * pv[0] + s[1] * pv[1] + s[2] * pv[2]) / det;
    qv[0] = s[1] * e1[2] - s[2] * e1[1], qv[1] = s[2] * e1[0] - s[0] * e1[2];
    qv[2] = s[0] * e1[1] - s[1] * e1[0];
    *v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
    *t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
    return *u >= 0 && *v >= 0 && *u + *v <= 1 && *t > 0;
}

TEST(bvh, tri_intersect)
{
    const float v0[3] = {0, 0, 0}, v1[3] = {1, 0, 0}, v2[3] = {0, 1, 0};
    float t, u, v;
    /* from above and from below (no culling), every dominant axis sign */
    const float o1[3] = {0.25f, 0.125f, 2}, d1[3] = {0, 0, -1};
    CHECK(bvh_tri_intersect(o1, d1, v0, v1, v2, 0, INFINITY, &t, &u, &v));
    CHECK(t == 2 && u == 0.25f && v == 0.125f);
    const float o2[3] = {0.25f, 0.125f, -4}, d2[3] = {0, 0, 2};
    CHECK(bvh_tri_intersect(o2, d2, v0, v1, v2, 0, INFINITY, &t, &u, &v));
    CHECK(t == 2 && u == 0.25f && v == 0.125f);
    /* the (tmin, tmax) range is open */
    CHECK(!bvh_tri_intersect(o1, d1, v0, v1, v2, 0, 1.5f, &t, &u, &v));
    CHECK(!bvh_tri_intersect(o1, d1, v0, v1, v2, 2.5f, INFINITY, &t, &u, &v));
    CHECK(!bvh_tri_intersect(o1, d1, v0, v1, v2, 0, 2, &t, &u, &v));
    /* behind the origin, outside, edge-on (in the plane), degenerate */
    const float d3[3] = {0, 0, 1}, o4[3] = {2, 2, 1}, o5[3] = {-1, 0.25f, 0}, d5[3] = {1, 0, 0};
    CHECK(!bvh_tri_intersect(o1, d3, v0, v1, v2, 0, INFINITY, &t, &u, &v));
    CHECK(!bvh_tri_intersect(o4, d1, v0, v1, v2, 0, INFINITY, &t, &u, &v));
    CHECK(!bvh_tri_intersect(o5, d5, v0, v1, v2, 0, INFINITY, &t, &u, &v));
    CHECK(!bvh_tri_intersect(o1, d1, v0, v1, v1, 0, INFINITY, &t, &u, &v));
    /* a degenerate triangle with an unbounded range: det = 0 must stop it (T = 0 would pass
     * the range test and give t = 0 / 0) */
    const float o9[3] = {0.5f, 0, 2}; /* through the degenerate triangle's line: U = V = W = 0 */
    CHECK(!bvh_tri_intersect(o9, d1, v0, v1, v1, -INFINITY, INFINITY, &t, &u, &v));
    /* U rounds to 0 in float, but exactly it is 2.2e-10 > 0 while V, W < 0: the ray passes
     * just outside the edge v1 v2; only the double-precision recomputation sees it */
    const float w0[3] = {-0x1.dfcabp-3f, 0x1.2e89d8p-1f, 1};
    const float w1[3] = {-0x1.3a891p-3f, 0x1.3443p-6f, 1};
    const float w2[3] = {0x1.2fd708p-2f, -0x1.29c794p-5f, 1}, o8[3] = {0, 0, 0};
    CHECK(!bvh_tri_intersect(o8, d3, w0, w1, w2, 0, INFINITY, &t, &u, &v));
    /* exactly through a vertex and an edge: hits (edges count as inside) */
    const float o6[3] = {1, 0, 3}, o7[3] = {0.5f, 0.5f, 3};
    CHECK(bvh_tri_intersect(o6, d1, v0, v1, v2, 0, INFINITY, &t, &u, &v) && u == 1 && v == 0);
    CHECK(bvh_tri_intersect(o7, d1, v0, v1, v2, 0, INFINITY, &t, &u, &v) && u == 0.5f && v == 0.5f);

    /* random triangles and rays against Moller-Trumbore in double, away from edges */
    uint64_t rng = 42;
    int compared = 0, bad = 0;
    for (int i = 0; i < 20000; i++) {
        float p[3][3], o[3], d[3];
        double rt = 0, ru = 0, rv = 0; /* all 0 (skipped below) when det is ~0 */
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                p[k][a] = 4 * rng_float(&rng) - 2;
        for (int a = 0; a < 3; a++)
            o[a] = 8 * rng_float(&rng) - 4, d[a] = 2 * rng_float(&rng) - 1;
        bool ref = moller_trumbore(o, d, p[0], p[1], p[2], &rt, &ru, &rv);
        double margin = fmin(fmin(ru, rv), 1 - ru - rv);
        if (fabs(margin) < 1e-3)
            continue; /* near an edge either answer is right */
        bool hit = bvh_tri_intersect(o, d, p[0], p[1], p[2], 0, INFINITY, &t, &u, &v);
        compared++;
        if (hit != ref || (hit && (fabs(t - rt) > 1e-4 * fmax(1, rt) || fabs(u - ru) > 1e-4 ||
                                   fabs(v - rv) > 1e-4)))
            bad++;
    }
    CHECKF(bad == 0, "%d of %d random cases differ from Moller-Trumbore", bad, compared);
    CHECK(compared > 15000);
}

/* ---- builds ----------------------------------------------------------------------------- */

TEST(bvh, empty)
{
    bvh b;
    const float org[3] = {0, 0, 0}, dir[3] = {0, 0, 1};
    memset(&b, 0xab, sizeof b);
    CHECK(!bvh_build(&b, NULL, 3, NULL, 0));
    CHECK(b.num_nodes == 0 && b.nodes == NULL && b.pairs == NULL);
    CHECK(bvh_intersect(&b, org, dir, 0, INFINITY, NULL).tri == GN_INVALID);
    CHECK(!bvh_occluded(&b, org, dir, 0, INFINITY));
    bvh_destroy(&b);
    bvh_destroy(&b); /* a zeroed struct is fine */
}

TEST(bvh, single_triangle)
{
    const float pos[9] = {0, 0, 0, 2, 0, 0, 0, 2, 0};
    const uint32_t idx[3] = {0, 1, 2};
    const float org[3] = {0.5f, 0.5f, 3}, dir[3] = {0, 0, -1}, miss[3] = {3, 3, 3};
    bvh b;
    uint32_t steps = 0;
    CHECK(bvh_build(&b, pos, 3, idx, 1));
    CHECK(b.num_nodes == 1 && b.depth == 1 && b.max_leaf_size == 1);
    CHECK(b.nodes[0].a_count == 1 && b.nodes[0].a_index == GN_BVH_LEAF); /* first 0, count 1 */
    CHECK(b.nodes[0].b_count == 0 && b.nodes[0].b_index == GN_INVALID);
    CHECKF(fabsf(b.sah_cost - 1) < 1e-5f, "sah %g", b.sah_cost); /* one leaf of one triangle */
    bvh_hit h = bvh_intersect(&b, org, dir, 0, INFINITY, &steps);
    CHECK(h.tri == 0 && h.t == 3 && h.u == 0.25f && h.v == 0.25f && steps == 1);
    CHECK(bvh_intersect(&b, miss, dir, 0, INFINITY, NULL).tri == GN_INVALID);
    CHECK(bvh_occluded(&b, org, dir, 0, 10) && !bvh_occluded(&b, org, dir, 0, 2.5f));
    bvh_destroy(&b);
    CHECK(b.nodes == NULL && b.num_nodes == 0);
}

TEST(bvh, random_soup)
{
    const float lo[3] = {-3, -1, -2}, hi[3] = {5, 1, 2};
    for (uint64_t seed = 1; seed <= 3; seed++) {
        meshgen_mesh m = meshgen_random_triangles(seed == 1 ? 3000 : 300, seed, lo, hi);
        bvh b;
        CHECK(build_mesh(&b, &m));
        check_structure(&b, &m);
        check_rays(&b, &m, 1000, seed);
        bvh_destroy(&b);
        meshgen_destroy(&m);
    }
}

/* Triangle pairs in every corner rotation and both relative windings (pairs only when wound
 * alike), lone triangles that shift the pairing by one, and bent quads: tri_rotation must
 * give each hit's barycentrics their corners (check_rays rebuilds the hit point from them). */
TEST(bvh, pairs)
{
    const float lo[3] = {-2, -1, -1}, hi[3] = {2, 1, 3};
    for (uint64_t seed = 1; seed <= 3; seed++) {
        uint32_t quads = seed == 1 ? 2000 : 60;
        meshgen_mesh m = meshgen_quad_soup(quads, seed, lo, hi);
        bvh b;
        CHECK(build_mesh(&b, &m));
        check_structure(&b, &m);
        check_rays(&b, &m, 2000, seed);
        /* the quads wound alike (half) pair, but for the most folded; lone triangles do not */
        uint32_t paired = m.num_triangles - b.num_pairs;
        CHECKF(paired > quads / 4 && paired <= quads * 3 / 4, "%u pairs of %u quads", paired, quads);
        bvh_destroy(&b);
        meshgen_destroy(&m);
    }
}

/* Identical centroids (no SAH plane exists), zero-area triangles, a point-like scene and a
 * geometric series of nested triangles that makes the SAH peel one triangle per level. */
TEST(bvh, degenerate)
{
    enum { N = 300 };
    float *pos = malloc(9 * N * sizeof(float));
    uint32_t *idx = malloc(3 * N * sizeof(uint32_t));
    meshgen_mesh m = {3 * N, pos, NULL, N, idx};
    bvh b;
    for (uint32_t i = 0; i < 3 * N; i++)
        idx[i] = i;

    /* N copies of one triangle */
    for (int t = 0; t < N; t++) {
        const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 1};
        memcpy(pos + 9 * t, tri, sizeof tri);
    }
    CHECK(build_mesh(&b, &m));
    check_structure(&b, &m);
    check_rays(&b, &m, 300, 7);
    bvh_destroy(&b);

    /* all corners at one point: zero root area, every ray misses */
    for (int i = 0; i < 9 * N; i++)
        pos[i] = (i % 3) == 1 ? 1.5f : 0.25f;
    CHECK(build_mesh(&b, &m));
    check_structure(&b, &m);
    CHECK(isfinite(b.sah_cost) && b.sah_cost > 0);
    const float org[3] = {0.25f, 1.5f, -1}, dir[3] = {0, 0, 1};
    CHECK(bvh_intersect(&b, org, dir, 0, INFINITY, NULL).tri == GN_INVALID);
    bvh_destroy(&b);

    /* nested triangles growing by 5% each: the SAH cuts a few off per level, deeper than 64
     * levels without the limit; the depth stays bounded and the answers exact */
    for (int t = 0; t < N; t++) {
        float s = powf(1.05f, (float)t);
        const float tri[9] = {0, 0, 0.001f * t, s, 0, 0.001f * t, 0, s, 0.001f * t + s};
        memcpy(pos + 9 * t, tri, sizeof tri);
    }
    CHECK(build_mesh(&b, &m));
    check_structure(&b, &m);
    CHECKF(b.depth <= 64, "depth %u", b.depth);
    check_rays(&b, &m, 300, 8);
    bvh_destroy(&b);
    free(pos);
    free(idx);
}

/* Closed meshes: a ray from outside towards the inside must hit, also exactly through shared
 * edges and vertices, and rays lying in a face plane (edge-on, direction components 0) must
 * still find the neighbouring face at its edge. */
TEST(bvh, watertight)
{
    meshgen_mesh cube = meshgen_edge_on(4);
    bvh b;
    int misses = 0, wrong_t = 0, rays = 0;
    CHECK(cube.num_triangles == 12 * 16 && cube.num_vertices == 6 * 16 + 2);
    CHECK(build_mesh(&b, &cube));
    check_structure(&b, &cube);
    /* grid lines are at -1 + k / 2: every ray below runs exactly through edges or vertices */
    for (int i = 0; i <= 8; i++) {
        for (int j = 0; j <= 8; j++) {
            float x = -1 + 0.25f * (float)i, y = -1 + 0.25f * (float)j;
            for (int axis = 0; axis < 3; axis++) {
                for (int sign = -1; sign <= 1; sign += 2) {
                    float org[3], dir[3] = {0, 0, 0};
                    org[axis] = -3.0f * (float)sign;
                    org[(axis + 1) % 3] = x;
                    org[(axis + 2) % 3] = y;
                    dir[axis] = (float)sign;
                    bvh_hit h = bvh_intersect(&b, org, dir, 0, INFINITY, NULL);
                    bvh_hit ref = bvh_brute_force(cube.positions, 3, cube.indices,
                                                  cube.num_triangles, org, dir, 0, INFINITY);
                    rays++;
                    misses += (h.tri == GN_INVALID) + (ref.tri == GN_INVALID);
                    wrong_t += h.tri != GN_INVALID && h.t != 2;
                    /* the same ray from a shadow-ray origin just off the surface */
                    misses += !bvh_occluded(&b, org, dir, 1e-3f, 100);
                }
            }
        }
    }
    CHECKF(misses == 0 && wrong_t == 0, "%d misses, %d wrong t of %d rays through edges", misses,
           wrong_t, rays);
    /* in the plane y = 1 of the top face, along x: the top face is edge-on (missed) and the
     * face x = -1 is hit exactly on its top edge at t = 2 */
    misses = 0;
    for (int k = 0; k <= 8; k++) {
        const float org[3] = {-3, 1, -1 + 0.25f * (float)k}, dir[3] = {1, 0, 0};
        bvh_hit h = bvh_intersect(&b, org, dir, 0, INFINITY, NULL);
        misses += h.tri == GN_INVALID || h.t != 2;
        misses += bvh_brute_force(cube.positions, 3, cube.indices, cube.num_triangles, org, dir, 0,
                                  INFINITY).t != 2;
    }
    CHECKF(misses == 0, "%d edge-on rays missed the neighbouring face", misses);
    bvh_destroy(&b);
    meshgen_destroy(&cube);

    /* a sphere: rays aimed at its vertices and edge midpoints, from near the centre (every
     * such ray crosses the surface) and from outside where the ray enters the surface at an
     * angle (a ray grazing the silhouette may rightly pass by) */
    const float c[3] = {0.3f, -0.2f, 0.1f};
    meshgen_mesh s = meshgen_uv_sphere(c, 1.3f, 24, 12);
    uint64_t rng = 3;
    misses = 0;
    rays = 0;
    CHECK(build_mesh(&b, &s));
    for (uint32_t t = 0; t < s.num_triangles; t++) {
        for (int k = 0; k < 3; k++) {
            const float *p = corner(&s, t, k), *q = corner(&s, t, (k + 1) % 3);
            float target[3], inner[3], outer[3], d_in[3], d_out[3], cos_in = 0, len = 0;
            for (int a = 0; a < 3; a++) {
                target[a] = (t + k) & 1 ? p[a] : 0.5f * (p[a] + q[a]);
                inner[a] = c[a] + 0.2f * (2 * rng_float(&rng) - 1);
                outer[a] = c[a] + 6 * (2 * rng_float(&rng) - 1);
                d_in[a] = target[a] - inner[a];
                d_out[a] = target[a] - outer[a];
                cos_in -= d_out[a] * (target[a] - c[a]) / 1.3f;
                len += d_out[a] * d_out[a];
            }
            rays++;
            misses += bvh_intersect(&b, inner, d_in, 0, INFINITY, NULL).tri == GN_INVALID;
            if (cos_in > 0.2f * sqrtf(len)) {
                rays++;
                misses += bvh_intersect(&b, outer, d_out, 0, INFINITY, NULL).tri == GN_INVALID;
            }
        }
    }
    CHECKF(misses == 0, "%d of %d rays at sphere vertices and edges missed", misses, rays);
    CHECK(rays > 2000);
    bvh_destroy(&b);
    meshgen_destroy(&s);
}

TEST(bvh, sphere)
{
    const float c[3] = {1, 2, 3};
    meshgen_mesh s = meshgen_uv_sphere(c, 2, 64, 32);
    bvh b;
    int bad = 0, bad_normal = 0;
    uint64_t rng = 11;
    CHECK(s.num_triangles == 2 * 64 * 31 && s.num_vertices == 2 + 31 * 64);
    for (uint32_t v = 0; v < s.num_vertices; v++) {
        const float *p = s.positions + 3 * v, *n = s.normals + 3 * v;
        float r = sqrtf((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                        (p[2] - c[2]) * (p[2] - c[2]));
        bad_normal += fabsf(r - 2) > 1e-5f;
        for (int a = 0; a < 3; a++)
            bad_normal += fabsf(n[a] - (p[a] - c[a]) / 2) > 1e-5f;
    }
    CHECK(bad_normal == 0);
    CHECK(build_mesh(&b, &s));
    check_structure(&b, &s);
    /* towards the centre from distance 10: the mesh's inscribed radius is 2 cos(pi / 32) */
    for (int i = 0; i < 500; i++) {
        float dir[3], org[3], len = 0;
        for (int a = 0; a < 3; a++)
            dir[a] = 2 * rng_float(&rng) - 1, len += dir[a] * dir[a];
        len = sqrtf(len);
        for (int a = 0; a < 3; a++)
            dir[a] /= len, org[a] = c[a] - 10 * dir[a];
        bvh_hit h = bvh_intersect(&b, org, dir, 0, INFINITY, NULL);
        bad += h.tri == GN_INVALID || h.t < 8 - 1e-4f ||
               h.t > 10 - 2 * cosf(3.14159265f / 32) + 1e-4f;
    }
    CHECKF(bad == 0, "%d rays at the sphere's centre off the analytic distance", bad);
    check_rays(&b, &s, 500, 12);
    bvh_destroy(&b);
    meshgen_destroy(&s);
}

/* The worst case for the walk: the ray down the z axis visits every node (what the GPU test of
 * llvmpipe's loop cap relies on) and hits only the last triangle. */
TEST(bvh, comb)
{
    enum { N = 40000 };
    meshgen_mesh m = meshgen_comb(N);
    const float org[3] = {0, 0, -1}, dir[3] = {0, 0, 1};
    bvh b;
    uint32_t steps = 0, misses = 0;
    CHECK(build_mesh(&b, &m));
    check_structure(&b, &m);
    bvh_hit h = bvh_intersect(&b, org, dir, 0, INFINITY, &steps);
    CHECK(h.tri != GN_INVALID && b.tri_index[h.tri] == N - 1 && h.t == (float)N);
    CHECKF(steps == b.num_nodes, "%u steps, %u nodes", steps, b.num_nodes);
    CHECK(bvh_brute_force(m.positions, 3, m.indices, N, org, dir, 0, INFINITY).tri == N - 1);
    /* from the far end the near child is taken first and every pushed node lies beyond the
     * hit: one path down, no more */
    const float back_org[3] = {0, 0, N + 1}, back_dir[3] = {0, 0, -1};
    h = bvh_intersect(&b, back_org, back_dir, 0, INFINITY, &steps);
    CHECK(h.tri != GN_INVALID && b.tri_index[h.tri] == N - 1 && h.t == 2);
    CHECKF(steps <= b.depth, "%u steps from the far end, depth %u", steps, b.depth);
    /* rays parallel to the axis next to it miss every sliver and hit the end */
    for (int i = 0; i < 50; i++) {
        const float o[3] = {0.01f * (float)i - 0.25f, 0.1f, -1};
        misses += bvh_intersect(&b, o, dir, 0, INFINITY, NULL).tri == GN_INVALID;
    }
    CHECK(misses == 0);
    check_rays(&b, &m, 100, 21);
    bvh_destroy(&b);
    meshgen_destroy(&m);
}

TEST(bvh, bench_mesh)
{
    meshgen_mesh m = meshgen_bench_mesh(20000);
    bvh b;
    CHECKF(m.num_triangles > 18000 && m.num_triangles <= 20000, "%u triangles", m.num_triangles);
    CHECK(build_mesh(&b, &m));
    check_structure(&b, &m);
    check_rays(&b, &m, 400, 31);
    bvh_destroy(&b);
    meshgen_destroy(&m);

    /* the benchmark size: build rate printed, not asserted (benchmarks measure speed) */
    m = meshgen_bench_mesh(250000);
    CHECK(m.num_triangles > 225000 && m.num_triangles <= 250000);
    CHECK(build_mesh(&b, &m));
    printf("    bench mesh: %u triangles, built in %.1f ms (%.2f M triangles/s), %u nodes, "
           "depth %u, largest leaf %u, SAH cost %.2f\n",
           m.num_triangles, b.build_seconds * 1e3, m.num_triangles / b.build_seconds * 1e-6,
           b.num_nodes, b.depth, b.max_leaf_size, b.sah_cost);
    bvh_destroy(&b);
    meshgen_destroy(&m);
}

/* Same input, same bytes: also for a build big enough to use threads, and whatever the
 * position stride. */
TEST(bvh, determinism)
{
    meshgen_mesh m = meshgen_bench_mesh(60000);
    float *wide = malloc(8 * (size_t)m.num_vertices * sizeof(float));
    bvh a, b, c;
    for (uint32_t v = 0; v < m.num_vertices; v++)
        for (int k = 0; k < 8; k++)
            wide[8 * v + k] = k < 3 ? m.positions[3 * v + k] : -1e30f;
    CHECK(build_mesh(&a, &m) && build_mesh(&b, &m));
    CHECK(bvh_build(&c, wide, 8, m.indices, m.num_triangles));
    check_structure(&a, &m); /* big enough for the threaded build: its packing of the nodes */
    check_rays(&a, &m, 100, 41);
    const bvh *other[2] = {&b, &c};
    for (int i = 0; i < 2; i++) {
        const bvh *o = other[i];
        CHECK(a.num_nodes == o->num_nodes && a.depth == o->depth && a.sah_cost == o->sah_cost &&
              a.max_leaf_size == o->max_leaf_size);
        CHECK(!memcmp(a.nodes, o->nodes, a.num_nodes * sizeof *a.nodes));
        CHECK(a.num_pairs == o->num_pairs && !memcmp(a.pairs, o->pairs, a.num_pairs * sizeof *a.pairs));
        CHECK(!memcmp(a.tri_rotation, o->tri_rotation, a.num_slots * sizeof *a.tri_rotation));
        CHECK(!memcmp(a.tri_index, o->tri_index, a.num_slots * sizeof *a.tri_index));
    }
    meshgen_mesh m2 = meshgen_bench_mesh(60000);
    CHECK(!memcmp(m.positions, m2.positions, 3 * (size_t)m.num_vertices * sizeof(float)));
    bvh_destroy(&a);
    bvh_destroy(&b);
    bvh_destroy(&c);
    free(wide);
    meshgen_destroy(&m);
    meshgen_destroy(&m2);
}

/* The pairs do not depend on the order of the index buffer: the bench mesh (quads listed
 * together) and the same triangles in random order pair about as well, with the structure
 * valid either way. (With pairing of index-buffer neighbours only, the shuffled mesh had
 * almost no pairs: 4 of the 14,637 pairs of the Stanford bunny's 69,451 triangles.) */
TEST(bvh, pairs_any_order)
{
    meshgen_mesh m = meshgen_bench_mesh(20000), s = m;
    uint64_t rng = 5;
    s.indices = malloc(3 * sizeof *s.indices * m.num_triangles);
    memcpy(s.indices, m.indices, 3 * sizeof *s.indices * m.num_triangles);
    for (uint32_t i = m.num_triangles - 1; i > 0; i--) { /* Fisher-Yates over the triangles */
        uint32_t j = (uint32_t)(rng_next(&rng) % (i + 1)), t[3];
        memcpy(t, s.indices + 3 * i, sizeof t);
        memcpy(s.indices + 3 * i, s.indices + 3 * j, sizeof t);
        memcpy(s.indices + 3 * j, t, sizeof t);
    }
    bvh a, b;
    CHECK(build_mesh(&a, &m) && build_mesh(&b, &s));
    check_structure(&a, &m);
    check_structure(&b, &s);
    uint32_t pa = a.num_tris - a.num_pairs, pb = b.num_tris - b.num_pairs; /* pairs made */
    CHECKF(pb >= 0.97 * pa, "shuffled: %u pairs, in order: %u (of %u triangles)", pb, pa, m.num_triangles);
    CHECKF(2 * pa >= 0.9 * m.num_triangles, "in order: only %u pairs of %u triangles", pa, m.num_triangles);
    bvh_destroy(&a);
    bvh_destroy(&b);
    free(s.indices);
    meshgen_destroy(&m);
}

/* A flat-shaded mesh repeats each point once per triangle (no vertex is shared): pairs are
 * made by position, so it pairs as the welded mesh does, and its answers stay exact. */
TEST(bvh, pairs_by_position)
{
    meshgen_mesh m = meshgen_bench_mesh(20000), s = m;
    s.num_vertices = 3 * m.num_triangles;
    s.positions = malloc(3 * sizeof *s.positions * s.num_vertices);
    s.normals = NULL;
    s.indices = malloc(3 * sizeof *s.indices * m.num_triangles);
    for (uint32_t i = 0; i < 3 * m.num_triangles; i++) {
        memcpy(s.positions + 3 * i, m.positions + 3 * (size_t)m.indices[i], 3 * sizeof *s.positions);
        s.indices[i] = i;
    }
    bvh a, b;
    CHECK(build_mesh(&a, &m) && build_mesh(&b, &s));
    check_structure(&b, &s);
    check_rays(&b, &s, 2000, 11);
    uint32_t pa = a.num_tris - a.num_pairs, pb = b.num_tris - b.num_pairs; /* pairs made */
    CHECKF(pb >= 0.97 * pa, "flat-shaded: %u pairs, welded: %u (of %u triangles)", pb, pa, m.num_triangles);
    bvh_destroy(&a);
    bvh_destroy(&b);
    free(s.positions);
    free(s.indices);
    meshgen_destroy(&m);
}

/* ---- two levels: instances of meshes ----------------------------------------------------- */

/* The top tree: each instance in exactly one leaf of one, every box holding its children and
 * its instance's world-space triangles; the GPU arrays: each mesh's tree at its place, its
 * indices moved there. */
static void check_top_structure(const inst_scene *s)
{
    const bvh_top *t = &s->top;
    uint8_t *seen = calloc(t->num_instances, 1);
    int bad_leaf = 0, bad_box = 0, bad_gpu = 0;
    CHECK(t->tree.num_nodes == (t->num_instances > 1 ? t->num_instances - 1 : 1));
    for (uint32_t i = 0; i < t->tree.num_nodes; i++) {
        const GnBvhNode *n = &t->tree.nodes[i];
        const vec3 *lo[2] = {&n->a_min, &n->b_min}, *hi[2] = {&n->a_max, &n->b_max};
        uint32_t index[2] = {n->a_index, n->b_index}, count[2] = {n->a_count, n->b_count};
        for (int c = 0; c < 2; c++) {
            if (index[c] == GN_INVALID)
                continue;
            if (count[c] == 0) {
                const GnBvhNode *ch = &t->tree.nodes[index[c]];
                bad_box += !box_has_box(lo[c], hi[c], &ch->a_min, &ch->a_max);
                bad_box += ch->b_index != GN_INVALID && !box_has_box(lo[c], hi[c], &ch->b_min, &ch->b_max);
                continue;
            }
            uint32_t inst = index[c] & GN_BVH_FIRST;
            if (count[c] != 1 || index[c] != (GN_BVH_LEAF | GN_BVH_INSTANCE | inst) ||
                inst >= t->num_instances || seen[inst]++) {
                bad_leaf++;
                continue;
            }
            const float *p = s->positions + 9 * (size_t)s->first_tri[inst];
            for (uint32_t k = 0; k < 3 * s->mesh[s->mesh_of[inst]].num_triangles; k++) {
                vec3 v = {p[3 * k], p[3 * k + 1], p[3 * k + 2]};
                bad_box += !box_has_point(lo[c], hi[c], &v);
            }
        }
    }
    for (uint32_t i = 0; i < t->num_instances; i++)
        bad_leaf += seen[i] != 1;
    CHECKF(bad_leaf == 0, "%d instance leaves wrong", bad_leaf);
    CHECKF(bad_box == 0, "%d top boxes do not hold their children or instances", bad_box);
    GnBvhNode *nodes = malloc(t->num_nodes * sizeof *nodes);
    GnTriPair *pairs = malloc(t->num_pairs * sizeof *pairs);
    bvh_top_gpu_nodes(t, nodes);
    bvh_top_gpu_pairs(t, pairs);
    bad_gpu += memcmp(nodes, t->tree.nodes, t->tree.num_nodes * sizeof *nodes) != 0;
    for (uint32_t m = 0; m < t->num_meshes; m++) {
        const bvh *b = &t->meshes[m];
        bad_gpu += memcmp(pairs + t->pair_base[m], b->pairs, b->num_pairs * sizeof *pairs) != 0;
        for (uint32_t i = 0; i < b->num_nodes; i++) {
            const GnBvhNode *g = &nodes[t->node_base[m] + i], *n = &b->nodes[i];
            uint32_t gi[2] = {g->a_index, g->b_index}, ni[2] = {n->a_index, n->b_index}, nc[2] = {n->a_count, n->b_count};
            for (int c = 0; c < 2; c++)
                bad_gpu += ni[c] != GN_INVALID &&
                           gi[c] != (nc[c] ? ni[c] + t->pair_base[m] : ni[c] + t->node_base[m]);
        }
    }
    CHECKF(bad_gpu == 0, "%d differences in the GPU arrays", bad_gpu);
    free(nodes);
    free(pairs);
    free(seen);
}

/* Random rays through the instances: the two-level walk against brute force over the
 * flattened triangles. The walk tests the mesh's own triangles with the ray transformed to
 * the instance's space (rounded to float), the reference the triangles transformed to world
 * space (rounded once from double): the two may differ only within rounding of an edge
 * (where either answer is right) or in t within rounding. */
static void check_instance_rays(const inst_scene *s, int num_rays, uint64_t seed)
{
    int bad_hit = 0, bad_t = 0, bad_tri = 0, bad_point = 0, bad_occ = 0, edge = 0, hits = 0;
    uint64_t rng = seed;
    float ext = 0;
    for (int a = 0; a < 3; a++)
        ext = fmaxf(ext, s->hi[a] - s->lo[a]);
    for (int r = 0; r < num_rays; r++) {
        float org[3], dir[3];
        for (int a = 0; a < 3; a++)
            org[a] = s->lo[a] - 0.25f * ext + 1.5f * ext * rng_float(&rng);
        if (r & 1) {
            for (int a = 0; a < 3; a++)
                dir[a] = 2 * rng_float(&rng) - 1;
        } else {
            uint32_t t = (uint32_t)(rng_next(&rng) % s->num_triangles);
            float u = rng_float(&rng), v = rng_float(&rng);
            const float *p = s->positions + 9 * (size_t)t;
            if (u + v > 1)
                u = 1 - u, v = 1 - v;
            for (int a = 0; a < 3; a++)
                dir[a] = (1 - u - v) * p[a] + u * p[3 + a] + v * p[6 + a] - org[a];
        }
        if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0)
            continue;
        uint32_t steps = 0;
        bvh_hit h = bvh_top_intersect(&s->top, org, dir, 0, INFINITY, &steps);
        bvh_hit ref = bvh_brute_force(s->positions, 3, s->indices, s->num_triangles, org, dir, 0, INFINITY);
        /* within rounding of an edge: the transforms' rounding moves a ray by some ulps of the
         * coordinates (about 1e-6 of the scene here), a hundredth of this */
        bool near_edge = (ref.tri != GN_INVALID && inst_edge_margin(s, ref.tri, org, dir, ref.t) < 1e-4 * ext) ||
                         (h.tri != GN_INVALID &&
                          inst_edge_margin(s, inst_flat_triangle(s, h.tri, h.inst), org, dir, h.t) < 1e-4 * ext);
        if ((h.tri == GN_INVALID) != (ref.tri == GN_INVALID)) {
            edge += near_edge;
            bad_hit += !near_edge;
            continue;
        }
        if (h.tri == GN_INVALID) {
            bad_occ += bvh_top_occluded(&s->top, org, dir, 0, INFINITY);
            continue;
        }
        hits++;
        bool same_t = fabsf(h.t - ref.t) <= 1e-4f * fabsf(ref.t);
        bad_t += !same_t && !near_edge;
        bad_tri += h.inst >= s->num_instances || (inst_flat_triangle(s, h.tri, h.inst) != ref.tri && !same_t && !near_edge);
        float p[3];
        inst_hit_point(s, h.tri, h.inst, h.u, h.v, p);
        for (int a = 0; a < 3; a++)
            bad_point += fabsf(p[a] - (org[a] + h.t * dir[a])) > 1e-4f * ext;
        bad_occ += bvh_top_occluded(&s->top, org, dir, 0, h.t * 0.999f);
        bad_occ += !bvh_top_occluded(&s->top, org, dir, 0, h.t * 1.001f);
        bad_occ += steps < 1;
    }
    CHECKF(bad_hit == 0, "%d of %d rays: hit or miss differs from brute force (%d more within rounding of an edge)",
           bad_hit, num_rays, edge);
    /* (the soup's slivers, at which half the rays aim, are narrower than that tolerance) */
    CHECKF(edge <= num_rays / 20, "%d of %d rays decided within rounding of an edge: too many to be rounding",
           edge, num_rays);
    CHECKF(bad_t == 0, "%d rays: t differs from brute force", bad_t);
    CHECKF(bad_tri == 0, "%d rays: other triangle than brute force", bad_tri);
    CHECKF(bad_point == 0, "%d hit points off their triangle", bad_point);
    CHECKF(bad_occ == 0, "%d occlusion queries wrong", bad_occ);
    CHECKF(hits > num_rays / 4, "only %d of %d rays hit: the test is too weak", hits, num_rays);
}

/* Instances of three meshes under random transforms with shears and mirrors, against the
 * same triangles flattened; then an animated frame (new transforms: bvh_top_update). */
TEST(bvh, instances)
{
    inst_scene s;
    CHECK(inst_scene_make(&s, 60, 4.0, 3, false));
    check_top_structure(&s);
    check_instance_rays(&s, 4000, 5);
    printf("    %u instances of %u meshes: %u triangles placed, %u stored; top tree %u nodes, depth %u, "
           "built in %.3f ms\n", s.num_instances, s.num_meshes, s.num_triangles, s.top.num_pairs * 2,
           s.top.tree.num_nodes, s.top.tree.depth, s.top.build_seconds * 1e3);
    uint64_t rng = 77;
    for (uint32_t i = 0; i < s.num_instances; i++)
        inst_transform(&rng, i % 3 == 0, 3.0, s.to_world[i]);
    inst_flatten(&s);
    CHECK(bvh_top_update(&s.top, (const float(*)[12])s.to_world, "test instances"));
    check_top_structure(&s);
    check_instance_rays(&s, 2000, 6);
    /* a single instance (the top tree is one leaf) and coincident instances (no SAH plane) */
    inst_scene_destroy(&s);
    CHECK(inst_scene_make(&s, 1, 1.0, 9, false));
    check_top_structure(&s);
    check_instance_rays(&s, 500, 8);
    inst_scene_destroy(&s);
    CHECK(inst_scene_make(&s, 30, 0.0, 10, false));
    for (uint32_t i = 1; i < s.num_instances; i++)
        memcpy(s.to_world[i], s.to_world[0], sizeof s.to_world[0]);
    inst_flatten(&s);
    CHECK(bvh_top_update(&s.top, (const float(*)[12])s.to_world, "test instances"));
    check_top_structure(&s);
    check_instance_rays(&s, 500, 12);
    /* a singular or non-finite transform is refused, saying which instance */
    s.to_world[5][0] = s.to_world[5][1] = s.to_world[5][2] = 0;
    fprintf(stderr, "    (an error about instance 5 is expected:)\n");
    CHECK(!bvh_top_update(&s.top, (const float(*)[12])s.to_world, "test instances"));
    inst_scene_destroy(&s);
}

/* Trees too deep together for a walk's stack are refused, not walked wrongly. A mesh tree
 * of 60 levels takes a mesh beyond what a unit test builds quickly (the SAH keeps real ones
 * shallow: nested triangles growing by half make 24): a sphere's tree says it has them. */
TEST(bvh, instances_too_deep)
{
    const float c[3] = {0, 0, 0};
    meshgen_mesh m = meshgen_uv_sphere(c, 1, 8, 4);
    bvh b;
    CHECK(build_mesh(&b, &m));
    uint32_t n = 1u << 16;
    float (*xf)[12] = calloc(n, sizeof *xf);
    uint32_t *mesh = calloc(n, sizeof *mesh);
    for (uint32_t i = 0; i < n; i++) {
        xf[i][0] = xf[i][5] = xf[i][10] = 1;
        xf[i][3] = (float)(i % 256) * 3, xf[i][7] = (float)(i / 256) * 3;
    }
    bvh_top t;
    bool ok = bvh_top_build(&t, &b, 1, (const float(*)[12])xf, mesh, NULL, n, "deep instances");
    CHECKF(ok && bvh_top_depth(&t) <= GN_WALK_STACK - 2, "%u instances of a tree of %u levels: built %d", n, b.depth, ok);
    bvh_top_destroy(&t);
    b.depth = 60;
    fprintf(stderr, "    (an error about the walk's stack is expected:)\n");
    ok = bvh_top_build(&t, &b, 1, (const float(*)[12])xf, mesh, NULL, n, "deep instances");
    CHECKF(!ok, "%u instances of a tree of %u levels: built", n, b.depth);
    ok = bvh_top_build(&t, &b, 1, (const float(*)[12])xf, mesh, NULL, 4, "deep instances"); /* fewer fit */
    CHECKF(ok && bvh_top_depth(&t) <= GN_WALK_STACK - 2, "4 instances of a tree of %u levels: built %d", b.depth, ok);
    bvh_top_destroy(&t);
    bvh_destroy(&b);
    meshgen_destroy(&m);
    free(xf);
    free(mesh);
}
