/* bvh_traverse.c: the C reference traversal of a built BVH (bvh.h): robust slab test (Ize
 * 2013, "Robust BVH ray traversal") and the watertight ray-triangle test (Woop, Benthin &
 * Wald 2013, JCGT 2(1)), written to be transcribed line for line into glsl/lib/bvh.glsl. */
#include "bvh.h"
#include "bvh_internal.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

/* Traversal constants. A direction component smaller than BVH_PARALLEL_DIR is treated as
 * parallel to its slabs: the inverse becomes +-BVH_PARALLEL_INV (finite, so no 0 * inf NaN
 * and no inf on GPUs that assume none). Boxes are padded (bvh.c: pad_up, BVH_BOX_PAD) so
 * that a parallel ray lying exactly in a box face still gets a slab interval of at least
 * +-(0.5e-20 * 1e30) = +-5e9: hits farther than that along a ray with a zero direction
 * component are not guaranteed. */
#define BVH_PARALLEL_DIR GN_BVH_PARALLEL_DIR
#define BVH_PARALLEL_INV 1e30f

/* Per-ray constants: the slab test's inverse direction and the watertight test's axis
 * permutation and shear (Woop et al. 2013, section 3). */
typedef struct ray {
    float org[3], inv[3];
    int kx, ky, kz;
    float sx, sy, sz;
} ray;

static void ray_init(ray *r, const float org[3], const float dir[3])
{
    float ax = fabsf(dir[0]), ay = fabsf(dir[1]), az = fabsf(dir[2]);
    assert(ax > 0 || ay > 0 || az > 0); /* a ray needs a direction */
    /* kz: the dominant axis, so the shear divides by the largest component (never 0 for a
     * non-zero direction). kx, ky follow cyclically and swap when dir[kz] < 0 so that the
     * sheared triangle keeps its winding; with culling off that only fixes det's sign. */
    r->kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    r->kx = r->kz == 2 ? 0 : r->kz + 1;
    r->ky = r->kx == 2 ? 0 : r->kx + 1;
    if (dir[r->kz] < 0) {
        int tmp = r->kx;
        r->kx = r->ky;
        r->ky = tmp;
    }
    /* The shear maps the ray to the +z axis through the origin: x' = x - Sx z, y' = y - Sy z,
     * z' = Sz z. */
    r->sx = dir[r->kx] / dir[r->kz];
    r->sy = dir[r->ky] / dir[r->kz];
    r->sz = 1.0f / dir[r->kz];
    for (int a = 0; a < 3; a++) {
        r->org[a] = org[a];
        r->inv[a] = fabsf(dir[a]) >= BVH_PARALLEL_DIR ? 1.0f / dir[a]
                    : dir[a] < 0                        ? -BVH_PARALLEL_INV
                                                        : BVH_PARALLEL_INV;
    }
}

/* Woop, Benthin & Wald 2013, without backface culling. */
static bool tri_hit(const ray *r, const float *v0, const float *v1, const float *v2,
                    float tmin, float tmax, float *t, float *u, float *v)
{
    /* 1. Vertices relative to the ray origin. */
    const float A[3] = {v0[0] - r->org[0], v0[1] - r->org[1], v0[2] - r->org[2]};
    const float B[3] = {v1[0] - r->org[0], v1[1] - r->org[1], v1[2] - r->org[2]};
    const float C[3] = {v2[0] - r->org[0], v2[1] - r->org[1], v2[2] - r->org[2]};
    /* 2. Shear and scale so the ray becomes the unit +z axis; the test is then 2D. */
    const float Ax = A[r->kx] - r->sx * A[r->kz], Ay = A[r->ky] - r->sy * A[r->kz];
    const float Bx = B[r->kx] - r->sx * B[r->kz], By = B[r->ky] - r->sy * B[r->kz];
    const float Cx = C[r->kx] - r->sx * C[r->kz], Cy = C[r->ky] - r->sy * C[r->kz];
    /* 3. Edge functions: twice the signed areas of the sub-triangles (origin, edge). Two
     * triangles sharing an edge compute that edge's function from the same two sheared
     * vertices, so its value is the same number with opposite sign: no ray slips between. */
    float U = Cx * By - Cy * Bx;
    float V = Ax * Cy - Ay * Cx;
    float W = Bx * Ay - By * Ax;
    /* 4. A zero may be a rounded-away sign: redo all three exactly. float * float is exact in
     * double, so the one rounding of the difference keeps the sign exact. (glsl/lib/bvh.glsl
     * uses Kahan's FMA form instead, which is this plain difference where fma rounds twice,
     * as on llvmpipe, and has the exact sign where it is fused.) */
    if (U == 0.0f || V == 0.0f || W == 0.0f) {
        U = (float)((double)Cx * (double)By - (double)Cy * (double)Bx);
        V = (float)((double)Ax * (double)Cy - (double)Ay * (double)Cx);
        W = (float)((double)Bx * (double)Ay - (double)By * (double)Ax);
    }
    /* 5. Inside when all three have the same sign (either sign: both faces hit); zeros are
     * edges and count as inside. */
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f))
        return false;
    /* 6. det = 0: the ray lies in the triangle's plane (edge-on) or the triangle is
     * degenerate: no hit. */
    float det = U + V + W;
    if (det == 0.0f)
        return false;
    /* 7. Scaled hit distance T = t * det from the sheared z; compare it with the range
     * scaled by |det| (sign trick: multiply both by the sign of det) and divide only for a hit.
     * t = T / det is then within one rounding of (tmin, tmax). */
    const float Az = r->sz * A[r->kz], Bz = r->sz * B[r->kz], Cz = r->sz * C[r->kz];
    float T = U * Az + V * Bz + W * Cz;
    float s = det < 0.0f ? -1.0f : 1.0f;
    if (T * s <= tmin * (det * s) || T * s >= tmax * (det * s))
        return false;
    /* 8. Barycentrics: U weighs v0, V v1, W v2, so p = (1-u-v) v0 + u v1 + v v2. */
    *t = T / det;
    *u = V / det;
    *v = W / det;
    return true;
}

bool bvh_tri_intersect(const float org[3], const float dir[3], const float v0[3],
                       const float v1[3], const float v2[3], float tmin, float tmax,
                       float *t, float *u, float *v)
{
    ray r;
    ray_init(&r, org, dir);
    return tri_hit(&r, v0, v1, v2, tmin, tmax, t, u, v);
}

/* Slab test (Ize 2013): *enter = entry distance; hit when the entry is not past the exit,
 * the exit scaled by 1 + 2 gamma(3) to cover rounding. Zero direction components give
 * +-BVH_PARALLEL_INV and rely on the box padding (see there): no inf, no NaN. The GPU picks
 * the near and far planes by the direction's sign instead of min/max: the same values for
 * boxes with lo <= hi. */
static inline bool box_enter(const ray *r, const vec3 *lo, const vec3 *hi, float tmin,
                             float tmax, float *enter)
{
    float x0 = (lo->x - r->org[0]) * r->inv[0], x1 = (hi->x - r->org[0]) * r->inv[0];
    float y0 = (lo->y - r->org[1]) * r->inv[1], y1 = (hi->y - r->org[1]) * r->inv[1];
    float z0 = (lo->z - r->org[2]) * r->inv[2], z1 = (hi->z - r->org[2]) * r->inv[2];
    float tn = maxf(maxf(minf(x0, x1), minf(y0, y1)), maxf(minf(z0, z1), tmin));
    float tf = minf(minf(maxf(x0, x1), maxf(y0, y1)), maxf(z0, z1)) * GN_BVH_TFAR_SCALE;
    *enter = tn;
    return tn <= minf(tf, tmax);
}

/* Tests leaf pairs [first, first + count): A = (p0, p1, p2), then B = (p0, p2, p3) against
 * the range A's hit left (as the GPU keeps A on a tie); true when one was hit. */
static bool leaf_hit(const bvh *b, const ray *r, uint32_t first, uint32_t count, float tmin,
                     bool any_hit, bvh_hit *hit)
{
    bool found = false;
    for (uint32_t i = first; i < first + count; i++) {
        const GnTriPair *q = &b->pairs[i];
        const float *p0 = &q->p0.x, *p1 = &q->p1.x, *p2 = &q->p2.x, *p3 = &q->p3.x;
        float t, u, v;
        if (tri_hit(r, p0, p1, p2, tmin, hit->t, &t, &u, &v)) {
            *hit = (bvh_hit){t, u, v, 2 * i};
            found = true;
            if (any_hit)
                break;
        }
        if (b->tri_index[2 * i + 1] != GN_INVALID && tri_hit(r, p0, p2, p3, tmin, hit->t, &t, &u, &v)) {
            *hit = (bvh_hit){t, u, v, 2 * i + 1};
            found = true;
            if (any_hit)
                break;
        }
    }
    return found;
}

/* The reference walk for glsl/lib/bvh.glsl: the same tree, boxes and triangle test, so the
 * same closest hit (up to ties between triangles at one t).
 *   node = 0; loop: read node (ONE STEP), slab-test child a and child b (b only when
 *   b_index != GN_INVALID) against (tmin, closest t);
 *   a hit leaf child is intersected at once (a before b; b skipped if a's hits moved the
 *   closest t before b's entry); then each hit inner child is kept if its entry <= closest t;
 *   two kept: go to the nearer (a on a tie), push the farther with its entry; one kept: go
 *   there; none: pop until an entry <= closest t is found (dropped entries are not read and
 *   not counted), or end when the stack is empty.
 * So *steps = number of GnBvhNode reads = loop iterations, node 0 included; triangle tests
 * are not steps. Any-hit walks stop at the first triangle hit. The GPU walk differs in
 * order only: it postpones leaves (pushing them like nodes) and tests them between runs of
 * node visits, which suits SIMD lanes that execute both sides of every branch. */
static bvh_hit traverse(const bvh *b, const float org[3], const float dir[3], float tmin,
                        float tmax, bool any_hit, uint32_t *steps)
{
    bvh_hit hit = {tmax, 0, 0, GN_INVALID};
    uint32_t stack_node[BVH_MAX_DEPTH], sp = 0, node = 0, nsteps = 0;
    float stack_t[BVH_MAX_DEPTH];
    ray r;
    if (b->num_nodes == 0) /* the zeroed bvh of an empty scene */
        return hit;
    ray_init(&r, org, dir);
    for (;;) {
        const GnBvhNode *n = &b->nodes[node];
        float ea = 0, eb = 0;
        nsteps++;
        bool ha = box_enter(&r, &n->a_min, &n->a_max, tmin, hit.t, &ea);
        bool hb = n->b_index != GN_INVALID &&
                  box_enter(&r, &n->b_min, &n->b_max, tmin, hit.t, &eb);
        if (ha && n->a_count > 0) {
            if (leaf_hit(b, &r, n->a_index & GN_BVH_FIRST, n->a_count, tmin, any_hit, &hit) &&
                any_hit)
                break;
            ha = false;
        }
        if (hb && n->b_count > 0) {
            if (eb <= hit.t &&
                leaf_hit(b, &r, n->b_index & GN_BVH_FIRST, n->b_count, tmin, any_hit, &hit) &&
                any_hit)
                break;
            hb = false;
        }
        ha = ha && ea <= hit.t;
        hb = hb && eb <= hit.t;
        if (ha && hb) {
            bool a_near = ea <= eb;
            assert(sp < BVH_MAX_DEPTH); /* depth <= BVH_MAX_DEPTH keeps sp < depth */
            stack_node[sp] = a_near ? n->b_index : n->a_index;
            stack_t[sp++] = a_near ? eb : ea;
            node = a_near ? n->a_index : n->b_index;
        } else if (ha || hb) {
            node = ha ? n->a_index : n->b_index;
        } else {
            while (sp > 0 && stack_t[sp - 1] > hit.t)
                sp--;
            if (sp == 0)
                break;
            node = stack_node[--sp];
        }
    }
    if (steps)
        *steps = nsteps;
    return hit;
}

bvh_hit bvh_intersect(const bvh *b, const float org[3], const float dir[3], float tmin,
                      float tmax, uint32_t *steps)
{
    return traverse(b, org, dir, tmin, tmax, false, steps);
}

bool bvh_occluded(const bvh *b, const float org[3], const float dir[3], float tmin, float tmax)
{
    return traverse(b, org, dir, tmin, tmax, true, NULL).tri != GN_INVALID;
}

bvh_hit bvh_brute_force(const float *positions, size_t position_stride_floats,
                        const uint32_t *indices, uint32_t num_triangles, const float org[3],
                        const float dir[3], float tmin, float tmax)
{
    bvh_hit hit = {tmax, 0, 0, GN_INVALID};
    for (uint32_t i = 0; i < num_triangles; i++) {
        const float *p[3];
        float t, u, v;
        for (int k = 0; k < 3; k++)
            p[k] = positions + (size_t)indices[3 * (size_t)i + k] * position_stride_floats;
        if (bvh_tri_intersect(org, dir, p[0], p[1], p[2], tmin, hit.t, &t, &u, &v))
            hit = (bvh_hit){t, u, v, i};
    }
    return hit;
}
