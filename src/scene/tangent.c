/* tangent.c: MikkTSpace tangents (Mikkelsen 2008), written here because Debian packages no
 * implementation of it, following the published method:
 *
 *  1. vertices with identical position, normal and uv are one vertex (MikkTSpace compares
 *     attribute values, not indices);
 *  2. every triangle gets the direction of dP/ds from its uv derivatives and an orientation,
 *     the sign of its uv area (t = -v: glTF's v runs down the image, MikkTSpace's t up);
 *  3. around each vertex, its triangles fall into groups: those joined through edges at the
 *     vertex (wound consistently) whose orientations agree. Each group is one output vertex,
 *     so a vertex on a mirror seam or a uv cut is split;
 *  4. a group's tangent is the sum of its triangles' tangents, each projected into the
 *     plane of the vertex normal and weighted by the triangle's angle at the vertex (also in
 *     that plane), normalised; w is the group's orientation.
 *
 * Simplifications, which leave meshes of well-formed uv charts unchanged: the reference
 * also splits a group whose tangents point in exactly opposite directions (its default
 * angular threshold keeps everything else together), which is left out; a triangle with no
 * uv area joins no group and takes the tangent of another group at the same vertex, or any
 * unit vector orthogonal to the normal when there is none. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tangent.h"
#include "util.h"
#include "vec.h"

typedef struct {
    float attr[8]; /* position, normal, uv */
    uint32_t v;
} weld_key;

static int cmp_weld(const void *pa, const void *pb)
{
    const weld_key *a = pa, *b = pb;
    int c = memcmp(a->attr, b->attr, sizeof a->attr);
    return c ? c : (a->v > b->v) - (a->v < b->v);
}

typedef struct {
    uint32_t lo, hi; /* welded vertices of the edge */
    uint32_t corner; /* the corner it starts at (3 face + k) */
} edge_key;

static int cmp_edge(const void *pa, const void *pb)
{
    const edge_key *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    return (a->corner > b->corner) - (a->corner < b->corner);
}

static int cmp_u64(const void *pa, const void *pb)
{
    uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

static uint32_t find(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

static void unite(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = find(parent, a);
    b = find(parent, b);
    if (a != b)
        parent[a > b ? a : b] = a < b ? a : b;
}

/* x minus its component along unit n, normalised; false when nothing is left. */
static int project(const double *x, const double *n, double *out)
{
    double d = vec_dot_d(x, n), len;
    for (int k = 0; k < 3; k++)
        out[k] = x[k] - d * n[k];
    len = sqrt(vec_dot_d(out, out));
    if (!(len > 1e-20))
        return 0;
    for (int k = 0; k < 3; k++)
        out[k] /= len;
    return 1;
}

size_t tangent_generate(size_t nv, const float *pos, const float *nrm, const float *uv, size_t nt,
                        uint32_t *idx, uint32_t **remap, float **tangents)
{
    size_t nc = 3 * nt;
    uint32_t *weld = util_malloc(sizeof *weld * (nv ? nv : 1));
    weld_key *wk = util_malloc(sizeof *wk * (nv ? nv : 1));
    for (size_t v = 0; v < nv; v++) {
        memcpy(wk[v].attr, &pos[3 * v], 3 * sizeof(float));
        memcpy(wk[v].attr + 3, &nrm[3 * v], 3 * sizeof(float));
        memcpy(wk[v].attr + 6, &uv[2 * v], 2 * sizeof(float));
        wk[v].v = (uint32_t)v;
    }
    qsort(wk, nv, sizeof *wk, cmp_weld);
    for (size_t i = 0; i < nv; i++)
        weld[wk[i].v] = i > 0 && !memcmp(wk[i].attr, wk[i - 1].attr, sizeof wk[i].attr) ? weld[wk[i - 1].v] : wk[i].v;
    free(wk);

    /* Per triangle: unit dP/ds (0 when degenerate) and orientation. */
    double *ftan = util_calloc(3 * (nt ? nt : 1), sizeof *ftan);
    signed char *orient = util_calloc(nt ? nt : 1, 1); /* +1, -1; 0: no uv area */
    for (size_t f = 0; f < nt; f++) {
        const uint32_t *c = &idx[3 * f];
        double e1[3], e2[3], s1 = uv[2 * c[1]] - uv[2 * c[0]], s2 = uv[2 * c[2]] - uv[2 * c[0]];
        double t1 = -((double)uv[2 * c[1] + 1] - uv[2 * c[0] + 1]), t2 = -((double)uv[2 * c[2] + 1] - uv[2 * c[0] + 1]);
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)pos[3 * c[1] + k] - pos[3 * c[0] + k];
            e2[k] = (double)pos[3 * c[2] + k] - pos[3 * c[0] + k];
        }
        double area = s1 * t2 - s2 * t1, t[3], len;
        if (area == 0)
            continue;
        for (int k = 0; k < 3; k++)
            t[k] = (t2 * e1[k] - t1 * e2[k]) * (area > 0 ? 1 : -1);
        len = sqrt(vec_dot_d(t, t));
        if (!(len > 0) || !isfinite(len))
            continue;
        for (int k = 0; k < 3; k++)
            ftan[3 * f + k] = t[k] / len;
        orient[f] = area > 0 ? 1 : -1;
    }

    /* Groups: corners joined through the edges their triangles share (a -> b in one, b -> a
     * in the other), orientations alike. */
    uint32_t *parent = util_malloc(sizeof *parent * (nc ? nc : 1));
    for (size_t i = 0; i < nc; i++)
        parent[i] = (uint32_t)i;
    edge_key *ek = util_malloc(sizeof *ek * (nc ? nc : 1));
    for (size_t i = 0; i < nc; i++) {
        uint32_t a = weld[idx[i]], b = weld[idx[i - i % 3 + (i % 3 + 1) % 3]];
        ek[i] = (edge_key){a < b ? a : b, a < b ? b : a, (uint32_t)i};
    }
    qsort(ek, nc, sizeof *ek, cmp_edge);
    for (size_t i = 0; i < nc;) {
        size_t j = i;
        while (j < nc && ek[j].lo == ek[i].lo && ek[j].hi == ek[i].hi)
            j++;
        /* An edge of more than a few triangles is not a surface: only neighbours in the run
         * are tried, so a pathological mesh costs no quadratic time. */
        for (size_t x = i; x < j; x++)
            for (size_t y = x + 1; y < j && y < x + 4; y++) {
                uint32_t ca = ek[x].corner, cb = ek[y].corner;
                uint32_t fa = ca / 3, fb = cb / 3;
                uint32_t na = fa * 3 + (ca % 3 + 1) % 3, nb = fb * 3 + (cb % 3 + 1) % 3;
                if (fa == fb || orient[fa] == 0 || orient[fa] != orient[fb])
                    continue;
                if (weld[idx[ca]] != weld[idx[nb]] || weld[idx[na]] != weld[idx[cb]])
                    continue; /* wound the same way: the surface folds over there */
                unite(parent, ca, nb);
                unite(parent, na, cb);
            }
        i = j;
    }
    free(ek);

    /* Angle-weighted sums per group (at its root corner). */
    double *sum = util_calloc(3 * (nc ? nc : 1), sizeof *sum);
    for (size_t i = 0; i < nc; i++) {
        size_t f = i / 3;
        if (orient[f] == 0)
            continue;
        uint32_t v = idx[i], p = idx[3 * f + (i % 3 + 1) % 3], q = idx[3 * f + (i % 3 + 2) % 3];
        double n[3] = {nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]}, t[3], a[3], b[3], pa[3], pb[3];
        for (int k = 0; k < 3; k++) {
            a[k] = (double)pos[3 * p + k] - pos[3 * v + k];
            b[k] = (double)pos[3 * q + k] - pos[3 * v + k];
        }
        if (!project(&ftan[3 * f], n, t) || !project(a, n, pa) || !project(b, n, pb))
            continue;
        double c = vec_dot_d(pa, pb), angle = acos(c < -1 ? -1 : c > 1 ? 1 : c);
        uint32_t r = find(parent, (uint32_t)i);
        for (int k = 0; k < 3; k++)
            sum[3 * r + k] += angle * t[k];
    }

    /* Each corner's source group: its own, or (no tangent there) another at the same vertex. */
    uint32_t *src = util_malloc(sizeof *src * (nc ? nc : 1));
    uint64_t *order = util_malloc(sizeof *order * (nc ? nc : 1));
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = find(parent, (uint32_t)i);
        src[i] = r;
        order[i] = (uint64_t)weld[idx[i]] << 32 | i;
    }
    qsort(order, nc, sizeof *order, cmp_u64);
    for (size_t i = 0; i < nc;) {
        size_t j = i, good = nc;
        while (j < nc && order[j] >> 32 == order[i] >> 32) {
            uint32_t r = src[(uint32_t)order[j]];
            if (good == nc && vec_dot_d(&sum[3 * r], &sum[3 * r]) > 0)
                good = r;
            j++;
        }
        for (size_t k = i; k < j && good != nc; k++) {
            uint32_t c = (uint32_t)order[k], r = src[c];
            if (!(vec_dot_d(&sum[3 * r], &sum[3 * r]) > 0))
                src[c] = (uint32_t)good;
        }
        i = j;
    }

    /* Output vertices: one per (input vertex, source group). */
    for (size_t i = 0; i < nc; i++)
        order[i] = (uint64_t)idx[i] << 32 | src[i];
    uint64_t *keys = util_malloc(sizeof *keys * (nc ? nc : 1));
    memcpy(keys, order, sizeof *keys * nc);
    qsort(keys, nc, sizeof *keys, cmp_u64);
    size_t n = 0;
    for (size_t i = 0; i < nc; i++)
        if (i == 0 || keys[i] != keys[i - 1])
            keys[n++] = keys[i];
    *remap = util_malloc(sizeof **remap * (n ? n : 1));
    *tangents = util_malloc(sizeof **tangents * 4 * (n ? n : 1));
    for (size_t k = 0; k < n; k++) {
        uint32_t v = (uint32_t)(keys[k] >> 32), r = (uint32_t)keys[k];
        double t[3], nn[3] = {nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]};
        float w = orient[r / 3] < 0 ? -1.0f : 1.0f;
        if (!project(&sum[3 * r], nn, t)) {
            /* No group with uv area at this vertex: any tangent orthogonal to the normal. */
            double axis[3] = {fabs(nn[0]) < 0.9 ? 1 : 0, fabs(nn[0]) < 0.9 ? 0 : 1, 0};
            project(axis, nn, t);
            w = 1;
        }
        (*remap)[k] = v;
        for (int j = 0; j < 3; j++)
            (*tangents)[4 * k + j] = (float)t[j];
        (*tangents)[4 * k + 3] = w;
    }
    for (size_t i = 0; i < nc; i++) {
        /* binary search of the corner's key among the output vertices */
        size_t lo = 0, hi = n;
        while (lo + 1 < hi) {
            size_t mid = (lo + hi) / 2;
            if (keys[mid] <= order[i])
                lo = mid;
            else
                hi = mid;
        }
        idx[i] = (uint32_t)lo;
    }
    free(keys);
    free(order);
    free(src);
    free(sum);
    free(parent);
    free(orient);
    free(ftan);
    free(weld);
    return n;
}
