/* bvh.c: binned SAH BVH build (Wald 2007, "On fast construction of SAH-based bounding volume
 * hierarchies"; subtrees on all cores, same bytes whatever the thread count), written
 * straight into the two-boxes-per-node GPU layout (GnBvhNode); the C reference traversal is
 * bvh_traverse.c. */
#include "bvh.h"
#include "bvh_internal.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include "util.h"

/* Build tunables. The build's primitives are GnTriPairs (a triangle or two). SAH constants
 * C_trav = 1, C_isect = 1 per pair: on lavapipe a GnBvhNode visit costs four texel fetches
 * and a pair test three, which is most of either (with single triangles, C_trav = 2 had
 * measured best). Leaves of 2-4 or 1-4 pairs and C_trav 1.3-2 were tried: no better on the
 * Cornell box's paths or the 250k mesh's rays, and slower to build.
 * (`gonio info` reports the SAH cost with both constants 1, for comparing trees.) */
#define BVH_SAH_TRAVERSAL 1.0f
#define BVH_BINS 16      /* per axis; Wald 2007 finds 16 as good as a full sweep */
#define BVH_MIN_LEAF 4   /* up to this many pairs always a leaf; above, the SAH decides
                            (4 rather than 2: a faster build, and lavapipe traces as fast) */
#define BVH_MAX_LEAF GN_BVH_MAX_LEAF /* above this a node is split even when the SAH prefers a leaf */
_Static_assert(GN_WALK_STACK - 2 >= BVH_MAX_DEPTH - 1, "glsl/lib/bvh.glsl's stack must hold a deepest walk");
/* Threads: the top levels are built on one thread until there are a few subtrees per thread
 * (at most BVH_SUBTREES), which the threads then share; below BVH_PARALLEL_MIN triangles
 * threads cost more than they save. */
#define BVH_MAX_THREADS 8
#define BVH_SUBTREES 16
#define BVH_PARALLEL_MIN 50000
#define BVH_SETUP_CHUNK 16384 /* triangles */
#define BVH_EDGE_FAN 8        /* pair_by_edges: candidates looked at per edge of a triangle */
/* builder.rec: the record holds triangles (index) and (index + 1) */
#define BVH_REC_PAIR 0x80000000u

/* Boxes are padded (pad_up) by at least this much, so that a ray parallel to a face and
 * lying in it still gets a slab interval (bvh_traverse.c: BVH_PARALLEL_INV). */
#define BVH_BOX_PAD 1e-20f

/* Four-lane floats (GCC/Clang vector extension; SSE or NEON code): the build handles a box
 * corner or a centroid as one vector. Lane 3 is unused and kept at 0. */
typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));

/* Lane-wise a < b ? a : b and a > b ? a : b: minps/maxps on x86 (exactly these semantics),
 * compare + blend elsewhere (C has no vector ?:). */
#if defined(__SSE__)
static inline v4f vmin(v4f a, v4f b) { return (v4f)_mm_min_ps((__m128)a, (__m128)b); }
static inline v4f vmax(v4f a, v4f b) { return (v4f)_mm_max_ps((__m128)a, (__m128)b); }
#else
static inline v4f vmin(v4f a, v4f b)
{
    v4i m = a < b;
    return (v4f)(((v4i)a & m) | ((v4i)b & ~m));
}
static inline v4f vmax(v4f a, v4f b)
{
    v4i m = a > b;
    return (v4f)(((v4i)a & m) | ((v4i)b & ~m));
}
#endif

/* a < b ? a : b is one instruction (fminf is a libm call without -ffast-math) and is what
 * GLSL's min/max do on the NaN-free values used here. */

typedef struct aabb {
    v4f lo, hi;
} aabb;

/* Triangle reference during the build: its box, with the triangle's index in lane 3 of lo
 * (masked off before any arithmetic). 32 bytes. */
typedef union prim {
    struct {
        v4f lo, hi;
    };
    struct {
        float lo3[3];
        uint32_t id;
        float hi3[3];
        uint32_t pad;
    };
} prim;

static const v4i xyz_mask = {-1, -1, -1, 0};
static const aabb empty_box = {{INFINITY, INFINITY, INFINITY, 0},
                               {-INFINITY, -INFINITY, -INFINITY, 0}};

/* A node range still to be processed; parent == GN_INVALID for the root. */
typedef struct task {
    aabb box, cbox; /* bounds of the triangles and of their centroids */
    uint32_t begin, end, level, parent, slot;
} task;

static inline v4f prim_lo(const prim *p) { return (v4f)((v4i)p->lo & xyz_mask); }

static inline v4f centroid(const prim *p) { return 0.5f * prim_lo(p) + 0.5f * p->hi; }

static inline void grow_box(aabb *b, v4f lo, v4f hi)
{
    b->lo = vmin(b->lo, lo);
    b->hi = vmax(b->hi, hi);
}

/* Half the surface area: only ratios of areas matter. */
static float half_area(const aabb *b)
{
    v4f d = b->hi - b->lo;
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

/* The bins of a triangle's centroid on all three axes (lane 3 unused). Binning and partition
 * both call this, so they agree exactly. A NaN (only from centroid ranges beyond FLT_MAX)
 * lands in the last bin: minps returns its second operand then. */
static inline v4i bins_of(const prim *p, v4f cmin, v4f scale)
{
    const v4f last = {BVH_BINS - 1, BVH_BINS - 1, BVH_BINS - 1, BVH_BINS - 1};
    return __builtin_convertvector(vmin((centroid(p) - cmin) * scale, last), v4i);
}

typedef struct split {
    int axis;
    uint32_t bin;      /* left side: bins [0, bin) */
    v4f cmin, scale;   /* bins_of's parameters */
    float cost;        /* A(node) C_trav + A(left) N(left) + A(right) N(right), unnormalised */
    aabb left, right;
} split;

/* Best binned SAH split over all three axes; false when all centroids share one bin. */
static bool find_split(const prim *prims, const task *t, split *best)
{
    aabb bins[3][BVH_BINS];
    uint32_t counts[3][BVH_BINS] = {{0}};
    v4f scale = {0, 0, 0, 0}, cmin = t->cbox.lo;
    for (int a = 0; a < 3; a++) {
        float extent = t->cbox.hi[a] - t->cbox.lo[a];
        scale[a] = extent > 0 ? (float)BVH_BINS / extent : 0;
        for (int k = 0; k < BVH_BINS; k++)
            bins[a][k] = empty_box;
    }
    for (uint32_t i = t->begin; i < t->end; i++) {
        /* constant lane indices keep k in registers */
        v4f lo = prim_lo(&prims[i]), hi = prims[i].hi;
        v4i k = bins_of(&prims[i], cmin, scale);
        grow_box(&bins[0][k[0]], lo, hi);
        grow_box(&bins[1][k[1]], lo, hi);
        grow_box(&bins[2][k[2]], lo, hi);
        counts[0][k[0]]++;
        counts[1][k[1]]++;
        counts[2][k[2]]++;
    }
    best->cost = INFINITY;
    best->axis = -1;
    /* Sweep only the non-empty bins: small nodes (most of them) fill few, and a plane
     * between two empty bins splits like the plane next to it. */
    for (int a = 0; a < 3; a++) {
        uint32_t used[BVH_BINS], m = 0, n = 0;
        float right_cost[BVH_BINS]; /* A * N of used bins [j, m) */
        aabb acc = empty_box;
        for (uint32_t k = 0; k < BVH_BINS; k++) { /* branch-free: the pattern is random */
            used[m] = k;
            m += counts[a][k] != 0;
        }
        for (uint32_t j = m - 1; j > 0; j--) {
            grow_box(&acc, bins[a][used[j]].lo, bins[a][used[j]].hi);
            n += counts[a][used[j]];
            right_cost[j] = half_area(&acc) * (float)n;
        }
        acc = empty_box;
        n = 0;
        for (uint32_t j = 1; j < m; j++) {
            grow_box(&acc, bins[a][used[j - 1]].lo, bins[a][used[j - 1]].hi);
            n += counts[a][used[j - 1]];
            float c = half_area(&acc) * (float)n + right_cost[j];
            if (c < best->cost) {
                best->cost = c;
                best->axis = a;
                best->bin = used[j];
            }
        }
    }
    if (best->axis < 0)
        return false;
    best->cmin = cmin;
    best->scale = scale;
    best->left = best->right = empty_box;
    for (uint32_t k = 0; k < BVH_BINS; k++) {
        const aabb *b = &bins[best->axis][k];
        grow_box(k < best->bin ? &best->left : &best->right, b->lo, b->hi);
    }
    best->cost += BVH_SAH_TRAVERSAL * half_area(&t->box);
    return true;
}

static uint32_t ceil_log2(uint32_t n)
{
    uint32_t l = 0;
    while ((1ull << l) < n)
        l++;
    return l;
}

/* Rounds a box bound outwards by at least one ulp and at least ~BVH_BOX_PAD, so that the slab
 * test of a ray parallel to a face and lying exactly in it gets a wide interval instead of
 * 0 * huge = 0 (see BVH_PARALLEL_INV). Monotone, so parents still contain children. */
static float next_up(float x) /* nextafterf(x, INFINITY) for finite x, without the libm call */
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    u = x == 0 ? 1 : x > 0 ? u + 1 : u - 1;
    memcpy(&x, &u, sizeof x);
    return x;
}
static float pad_up(float x) { return maxf(next_up(x), x + BVH_BOX_PAD); }
static float pad_down(float x) { return -pad_up(-x); }

/* Writes child `slot` (0 = a, 1 = b) of a node: a leaf's index is the walk's entry for it
 * (glsl/lib/shared.h). */
static void set_child(GnBvhNode *n, uint32_t slot, const aabb *box, uint32_t index, uint32_t count)
{
    if (count > 0)
        index |= GN_BVH_LEAF | (count - 1) << GN_BVH_COUNT_SHIFT;
    vec3 lo = {pad_down(box->lo[0]), pad_down(box->lo[1]), pad_down(box->lo[2])};
    vec3 hi = {pad_up(box->hi[0]), pad_up(box->hi[1]), pad_up(box->hi[2])};
    if (slot == 0) {
        n->a_min = lo, n->a_max = hi, n->a_index = index, n->a_count = count;
    } else {
        n->b_min = lo, n->b_max = hi, n->b_index = index, n->b_count = count;
    }
}

/* Boxes and centroid boxes of the triangles [begin, end). */
static void range_bounds(const prim *prims, uint32_t begin, uint32_t end, aabb *box, aabb *cbox)
{
    *box = *cbox = empty_box;
    for (uint32_t i = begin; i < end; i++) {
        grow_box(box, prim_lo(&prims[i]), prims[i].hi);
        v4f c = centroid(&prims[i]);
        grow_box(cbox, c, c);
    }
}

/* In-place partition by the split's bins (Hoare: only misplaced pairs move); also gathers
 * each side's centroid box so that no extra pass over the children is needed. Returns the
 * first index of the right side. */
static uint32_t partition(prim *prims, const task *t, const split *s, aabb *lc, aabb *rc)
{
    uint32_t i = t->begin, j = t->end;
    *lc = *rc = empty_box;
    for (;;) {
        v4f ci = {0, 0, 0, 0}, cj = {0, 0, 0, 0};
        for (; i < j; i++) {
            ci = centroid(&prims[i]);
            if ((uint32_t)bins_of(&prims[i], s->cmin, s->scale)[s->axis] >= s->bin)
                break;
            grow_box(lc, ci, ci);
        }
        for (; i < j; j--) {
            cj = centroid(&prims[j - 1]);
            if ((uint32_t)bins_of(&prims[j - 1], s->cmin, s->scale)[s->axis] < s->bin)
                break;
            grow_box(rc, cj, cj);
        }
        if (i == j)
            return i;
        /* prims[i] belongs right, prims[j - 1] left */
        prim tmp = prims[i];
        prims[i++] = prims[--j];
        prims[j] = tmp;
        grow_box(lc, cj, cj);
        grow_box(rc, ci, ci);
    }
}

/* Shared state of one build. The top levels are built on one thread, their nodes in
 * nodes[0, num_top); each subtree below them is built depth-first by one thread into its own
 * region, nodes[num_top + its first triangle, ...) (n triangles make at most n - 1 nodes, so
 * regions never overlap); pack_nodes() then lays everything out depth-first. No index
 * depends on the thread scheduling. */
typedef struct builder {
    const float *positions;
    size_t stride;
    const uint32_t *indices;
    uint32_t num_tris, num_recs, threads;
    /* Leaves: up to min_leaf records always one, above max_leaf never; no deeper than
     * max_depth levels. instances: the records are instances (a top-level tree: leaves of one,
     * GN_BVH_INSTANCE | the instance), not triangle pairs. */
    uint32_t min_leaf, max_leaf, max_depth;
    bool instances;
    uint32_t *rec;         /* record (the build's primitive) -> A's triangle | BVH_REC_PAIR */
    uint32_t *chunk_first; /* setup chunk -> its first record */
    uint32_t *mate;        /* triangle -> the other triangle of its pair, GN_INVALID: single */
    prim *prims;
    GnBvhNode *nodes;
    GnTriPair *pairs;
    uint32_t *tri_index;
    uint8_t *tri_rotation;
    uint32_t num_top, num_pending;
    task pending[BVH_SUBTREES];
    uint32_t subtree_size[BVH_SUBTREES];
    atomic_uint next_work; /* chunk of the setup, then pending subtree, claimed next */
} builder;

/* One thread's part of a parallel phase. */
typedef struct worker {
    builder *bd;
    aabb box, cbox; /* setup: bounds of the triangles it read */
} worker;

static void run_workers(builder *bd, void *(*fn)(void *), worker *w)
{
    pthread_t tid[BVH_MAX_THREADS];
    bool started[BVH_MAX_THREADS] = {false};
    atomic_store(&bd->next_work, 0);
    for (uint32_t i = 0; i < bd->threads; i++)
        w[i] = (worker){bd, empty_box, empty_box};
    /* a thread that cannot start leaves its share to the others */
    for (uint32_t i = 1; i < bd->threads; i++)
        started[i] = pthread_create(&tid[i], NULL, fn, &w[i]) == 0;
    fn(&w[0]);
    for (uint32_t i = 1; i < bd->threads; i++)
        if (started[i])
            pthread_join(tid[i], NULL);
}

static const float *vertex(const builder *bd, uint32_t tri, int k)
{
    return bd->positions + (size_t)bd->indices[3 * (size_t)tri + k] * bd->stride;
}

/* Do vertices i and j sit at the same point, bit for bit? Pairs are made by positions, not
 * vertex indices: a flat-shaded or UV-seamed mesh repeats a point once per face that meets
 * it, and the pair test needs only the shared corners' positions to be the same floats (its
 * shared edge function is then the exact negation of the neighbour's). */
static bool same_point(const builder *bd, uint32_t i, uint32_t j)
{
    if (i == j)
        return true;
    uint32_t x[3], y[3];
    memcpy(x, bd->positions + (size_t)i * bd->stride, sizeof x);
    memcpy(y, bd->positions + (size_t)j * bd->stride, sizeof y);
    return x[0] == y[0] && x[1] == y[1] && x[2] == y[2];
}

/* Triangles t and u make one GnTriPair when they share exactly one
 * edge (by position: same_point; neither repeats a point), are wound alike (so that GnPrim can
 * list B's corners in the test's order by a rotation, keeping its winding), and the pair's
 * box is no larger (in surface area) than the two boxes together: the SAH's view, since a
 * pair costs the walk about what one triangle does (three texel fetches) and is entered
 * whenever a ray enters its box (docs/performance.md: what folded pairs cost). */
static bool pairs_with(const builder *bd, uint32_t t, uint32_t u)
{
    const uint32_t *a = bd->indices + 3 * (size_t)t, *b = bd->indices + 3 * (size_t)u;
    for (int k = 0; k < 3; k++)
        if (same_point(bd, a[k], a[(k + 1) % 3]) || same_point(bd, b[k], b[(k + 1) % 3]))
            return false;
    int shared = 0;
    for (int k = 0; k < 3; k++)
        for (int m = 0; m < 3; m++)
            shared += same_point(bd, a[k], b[m]);
    if (shared != 2)
        return false;
    /* wound alike: B runs the shared edge the other way (then B's own corner order is a
     * rotation of the order the pair's test takes, and GnPrim keeps the winding) */
    bool alike = false;
    for (int k = 0; k < 3; k++)
        for (int m = 0; m < 3; m++)
            alike |= same_point(bd, a[k], b[(m + 1) % 3]) && same_point(bd, a[(k + 1) % 3], b[m]);
    if (!alike)
        return false;
    aabb ba = empty_box, bb = empty_box, bu;
    for (int k = 0; k < 3; k++) {
        const float *x = vertex(bd, t, k), *y = vertex(bd, u, k);
        v4f vx = {x[0], x[1], x[2], 0}, vy = {y[0], y[1], y[2], 0};
        grow_box(&ba, vx, vx);
        grow_box(&bb, vy, vy);
    }
    bu = ba;
    grow_box(&bu, bb.lo, bb.hi);
    return half_area(&bu) <= half_area(&ba) + half_area(&bb);
}

/* Pairing, in two passes. First, BVH_SETUP_CHUNK triangles at a time in parallel, each with
 * the next one in the index buffer: meshes built from quads list a quad's two triangles
 * together, so this finds most pairs with no search (pair_worker; greedy from a chunk's first
 * triangle, so it depends on the chunk boundaries only, not on the threads). Then the
 * triangles left single meet the others of their edges (pair_by_edges), so that a mesh's
 * pairs do not depend on the order of its index buffer. Setup then makes, from each chunk's
 * first record, the records and their boxes (setup_worker). */
static uint32_t chunk_range(builder *bd, uint32_t *begin, uint32_t *end)
{
    uint64_t c = atomic_fetch_add(&bd->next_work, 1), b = c * BVH_SETUP_CHUNK;
    if (b >= bd->num_tris)
        return GN_INVALID;
    *begin = (uint32_t)b;
    *end = b + BVH_SETUP_CHUNK < bd->num_tris ? (uint32_t)(b + BVH_SETUP_CHUNK) : bd->num_tris;
    return (uint32_t)c;
}

static void *pair_worker(void *arg)
{
    builder *bd = ((worker *)arg)->bd;
    uint32_t begin, end;
    while (chunk_range(bd, &begin, &end) != GN_INVALID)
        for (uint32_t t = begin; t < end;) {
            bool pair = t + 1 < end && pairs_with(bd, t, t + 1);
            bd->mate[t] = pair ? t + 1 : GN_INVALID;
            if (pair)
                bd->mate[t + 1] = t;
            t += pair ? 2 : 1;
        }
    return NULL;
}

/* An edge of a single triangle: its two points (as the vertex indices pair_by_edges gives
 * them), the smaller first, and the triangle. */
typedef struct edge_ref {
    uint64_t key;
    uint32_t tri;
} edge_ref;

static int edge_order(const void *pa, const void *pb)
{
    const edge_ref *a = pa, *b = pb;
    return a->key != b->key ? (a->key < b->key ? -1 : 1) : (a->tri > b->tri) - (a->tri < b->tri);
}

/* A corner of a single triangle: its position's bits, its vertex and its place in the list. */
typedef struct corner_ref {
    uint32_t bits[3];
    uint32_t vertex, corner;
} corner_ref;

static int corner_order(const void *pa, const void *pb)
{
    const corner_ref *a = pa, *b = pb;
    int d = memcmp(a->bits, b->bits, sizeof a->bits);
    return d ? d : (a->vertex > b->vertex) - (a->vertex < b->vertex);
}

static uint64_t edge_key(uint32_t x, uint32_t y)
{
    return x < y ? (uint64_t)x << 32 | y : (uint64_t)y << 32 | x;
}

/* The single triangles' edges, sorted, give each single triangle the (at most three) others
 * pairs_with accepts; then a greedy matching of fewest options first (a triangle with one
 * candidate takes it before a neighbour with three can), each taking its candidate with the
 * fewest options left: on the shuffled bench mesh this pairs as well as index order does,
 * where plain first-come pairing lost one pair in seven. Deterministic: ties go by index. */
typedef struct single_tri {
    uint32_t tri, degree;
} single_tri;

static int by_degree(const void *pa, const void *pb)
{
    const single_tri *a = pa, *b = pb;
    return a->degree != b->degree ? (a->degree < b->degree ? -1 : 1) : (a->tri > b->tri) - (a->tri < b->tri);
}

static void pair_by_edges(builder *bd)
{
    size_t n = 0;
    for (uint32_t t = 0; t < bd->num_tris; t++)
        n += bd->mate[t] == GN_INVALID;
    if (n < 2)
        return;
    /* each corner's point as one vertex index (the least of the corners at that point), so
     * that an edge is keyed by its two points */
    corner_ref *c = util_malloc(3 * n * sizeof *c);
    uint32_t *point = util_malloc(3 * n * sizeof *point);
    size_t m = 0;
    for (uint32_t t = 0; t < bd->num_tris; t++)
        if (bd->mate[t] == GN_INVALID)
            for (int k = 0; k < 3; k++, m++) {
                uint32_t v = bd->indices[3 * (size_t)t + k];
                c[m].vertex = v;
                c[m].corner = (uint32_t)m;
                memcpy(c[m].bits, bd->positions + (size_t)v * bd->stride, sizeof c[m].bits);
            }
    qsort(c, m, sizeof *c, corner_order);
    for (size_t lo = 0, hi; lo < m; lo = hi) {
        for (hi = lo + 1; hi < m && !memcmp(c[hi].bits, c[lo].bits, sizeof c[lo].bits); hi++)
            ;
        for (size_t i = lo; i < hi; i++)
            point[c[i].corner] = c[lo].vertex;
    }
    free(c);
    edge_ref *e = util_malloc(3 * n * sizeof *e);
    m = 0;
    for (uint32_t t = 0, i = 0; t < bd->num_tris; t++)
        if (bd->mate[t] == GN_INVALID) {
            for (int k = 0; k < 3; k++)
                e[m++] = (edge_ref){edge_key(point[3 * i + k], point[3 * i + (k + 1) % 3]), t};
            i++;
        }
    free(point);
    qsort(e, m, sizeof *e, edge_order);
    /* candidates: for each single triangle (in order), up to 3 others */
    uint32_t *slot = util_malloc(bd->num_tris * sizeof *slot), *cand = util_malloc(3 * n * sizeof *cand);
    uint32_t *degree = util_calloc(n, sizeof *degree);
    single_tri *order = util_malloc(n * sizeof *order);
    for (uint32_t t = 0, i = 0; t < bd->num_tris; t++)
        slot[t] = bd->mate[t] == GN_INVALID ? i++ : GN_INVALID;
    /* An edge of a manifold mesh has two triangles; one that many share (copies of one
     * triangle stacked, a fan of sheets on one edge, a mesh collapsed to a point) offers
     * each of them only the first BVH_EDGE_FAN others (in index order), so that pairing stays
     * linear in the triangles however many meet at one edge. */
    for (size_t lo = 0, hi; lo < m; lo = hi) {
        for (hi = lo + 1; hi < m && e[hi].key == e[lo].key; hi++)
            ;
        for (size_t i = lo; i < hi; i++)
            for (size_t j = lo, seen = 0; j < hi && seen < BVH_EDGE_FAN; j++) {
                uint32_t t = e[i].tri, u = e[j].tri, st = slot[t];
                if (t == u)
                    continue;
                seen++;
                if (degree[st] < 3 && pairs_with(bd, t, u))
                    cand[3 * (size_t)st + degree[st]++] = u;
            }
    }
    for (uint32_t t = 0; t < bd->num_tris; t++)
        if (slot[t] != GN_INVALID)
            order[slot[t]] = (single_tri){t, degree[slot[t]]};
    qsort(order, n, sizeof *order, by_degree);
    /* Karp-Sipser: a triangle left with one candidate takes it at once (a stack of them),
     * else the next of fewest options takes its candidate with the fewest left. live: the
     * candidates still single. */
    uint32_t *live = util_malloc(n * sizeof *live), *stack = util_malloc(n * sizeof *stack), sp = 0;
    memcpy(live, degree, n * sizeof *live);
    for (size_t i = 0; i < n || sp;) {
        uint32_t t;
        if (sp) {
            t = stack[--sp];
        } else {
            t = order[i++].tri;
        }
        uint32_t st = slot[t], best = GN_INVALID, best_left = UINT32_MAX;
        if (bd->mate[t] != GN_INVALID || live[st] == 0)
            continue;
        for (uint32_t k = 0; k < degree[st]; k++) {
            uint32_t u = cand[3 * (size_t)st + k];
            if (bd->mate[u] == GN_INVALID && (live[slot[u]] < best_left || (live[slot[u]] == best_left && u < best)))
                best = u, best_left = live[slot[u]];
        }
        if (best == GN_INVALID)
            continue;
        bd->mate[t] = best;
        bd->mate[best] = t;
        uint32_t ends[2] = {t, best};
        for (int w = 0; w < 2; w++) /* the partners' other candidates lose an option */
            for (uint32_t k = 0; k < degree[slot[ends[w]]]; k++) {
                uint32_t v = cand[3 * (size_t)slot[ends[w]] + k];
                if (bd->mate[v] == GN_INVALID && live[slot[v]] > 0 && --live[slot[v]] == 1)
                    stack[sp++] = v;
            }
    }
    free(stack);
    free(live);
    free(order);
    free(degree);
    free(cand);
    free(slot);
    free(e);
}

/* Does triangle t begin a record (a single, or the first of its pair in index order)? */
static bool record_start(const builder *bd, uint32_t t)
{
    return bd->mate[t] == GN_INVALID || bd->mate[t] > t;
}

static void *setup_worker(void *arg)
{
    worker *w = arg;
    builder *bd = w->bd;
    uint32_t begin, end, c;
    while ((c = chunk_range(bd, &begin, &end)) != GN_INVALID) {
        uint32_t r = bd->chunk_first[c];
        for (uint32_t t = begin; t < end; t++) {
            if (!record_start(bd, t))
                continue;
            uint32_t u = bd->mate[t];
            bool pair = u != GN_INVALID;
            prim *p = &bd->prims[r];
            bd->rec[r] = t | (pair ? BVH_REC_PAIR : 0u);
            for (int a = 0; a < 3; a++)
                p->lo3[a] = INFINITY, p->hi3[a] = -INFINITY;
            for (uint32_t j = 0; j <= (uint32_t)pair; j++)
                for (int v = 0; v < 3; v++) {
                    const float *x = vertex(bd, j ? u : t, v);
                    for (int a = 0; a < 3; a++) {
                        p->lo3[a] = minf(p->lo3[a], x[a]);
                        p->hi3[a] = maxf(p->hi3[a], x[a]);
                    }
                }
            p->id = r;
            p->pad = 0;
            v4f c4 = centroid(p);
            grow_box(&w->box, prim_lo(p), p->hi);
            grow_box(&w->cbox, c4, c4);
            r++;
        }
    }
    return NULL;
}

/* Writes record `rec` as pair i: A rotated so that the shared edge is (p2, p0), B's third
 * corner as p3 (B's own order is then a rotation of (p0, p2, p3)), and the BVH-order
 * triangles 2i and 2i + 1 with their rotations. */
static void write_pair(const builder *bd, uint32_t rec, uint32_t i, GnTriPair *q,
                       uint32_t *tri_index, uint8_t *tri_rotation)
{
    uint32_t ta = rec & ~BVH_REC_PAIR;
    bool pair = (rec & BVH_REC_PAIR) != 0;
    uint32_t tb = pair ? bd->mate[ta] : GN_INVALID;
    const uint32_t *a = bd->indices + 3 * (size_t)ta, *b = pair ? bd->indices + 3 * (size_t)tb : a;
    uint32_t rot = 0, rot_b = 0, idx[4];
    /* (corners are the same by position: pairs_with) */
#define SAME(x, y) same_point(bd, x, y)
    if (pair) /* the edge (a[k], a[k + 1]) that B has: rotate it to (p2, p0) */
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t x = a[k], y = a[(k + 1) % 3];
            if ((SAME(x, b[0]) || SAME(x, b[1]) || SAME(x, b[2])) && (SAME(y, b[0]) || SAME(y, b[1]) || SAME(y, b[2])))
                rot = (k + 1) % 3;
        }
    for (uint32_t k = 0; k < 3; k++)
        idx[k] = a[(rot + k) % 3];
    idx[3] = idx[2];
    if (pair)
        for (uint32_t k = 0; k < 3; k++) {
            if (!SAME(b[k], idx[0]) && !SAME(b[k], idx[2]))
                idx[3] = b[k];
            if (SAME(b[k], idx[0])) /* B's own corner k is the test's p0 */
                rot_b = k;
        }
#undef SAME
    vec3 *p[4] = {&q->p0, &q->p1, &q->p2, &q->p3};
    for (int k = 0; k < 4; k++) {
        const float *x = bd->positions + (size_t)idx[k] * bd->stride;
        *p[k] = (vec3){x[0], x[1], x[2]};
    }
    tri_index[2 * (size_t)i] = ta;
    tri_rotation[2 * (size_t)i] = (uint8_t)rot;
    tri_index[2 * (size_t)i + 1] = tb;
    tri_rotation[2 * (size_t)i + 1] = (uint8_t)rot_b;
}

/* Decides and performs one node, numbering new nodes from *next_node: a leaf goes into its
 * parent's slot and its records into pairs (0 returned); an inner node is created, the
 * range partitioned and the two children returned in l, r (2). */
static int process(builder *bd, const task *t, task *l, task *r, uint32_t *next_node)
{
    uint32_t n = t->end - t->begin;
    float area = half_area(&t->box);
    split s;
    /* Near the depth limit only halving by index is left: it reaches single triangles in
     * exactly ceil_log2(n) more levels, so the depth never passes max_depth (unless the
     * root is already that close: a top tree over too many instances, bvh_top_build). */
    bool median_only = t->level + ceil_log2(n) >= bd->max_depth;
    bool found = n > bd->min_leaf && !median_only && find_split(bd->prims, t, &s);
    if (n <= bd->min_leaf || (!(found && s.cost < area * (float)n) && n <= bd->max_leaf)) {
        GnBvhNode *parent;
        if (t->parent == GN_INVALID) { /* the whole scene is one leaf: node 0, b empty */
            parent = &bd->nodes[(*next_node)++];
            parent->b_index = GN_INVALID;
            parent->b_min = (vec3){FLT_MAX, FLT_MAX, FLT_MAX}; /* inverted: never hit */
            parent->b_max = (vec3){-FLT_MAX, -FLT_MAX, -FLT_MAX};
        } else {
            parent = &bd->nodes[t->parent];
        }
        if (bd->instances) { /* (n == 1: min_leaf = max_leaf = 1) */
            set_child(parent, t->slot, &t->box, GN_BVH_INSTANCE | bd->prims[t->begin].id, 1);
            return 0;
        }
        set_child(parent, t->slot, &t->box, t->begin, n);
        for (uint32_t i = t->begin; i < t->end; i++)
            write_pair(bd, bd->rec[bd->prims[i].id], i, &bd->pairs[i], bd->tri_index, bd->tri_rotation);
        return 0;
    }
    uint32_t self = (*next_node)++;
    if (t->parent != GN_INVALID)
        set_child(&bd->nodes[t->parent], t->slot, &t->box, self, 0);
    l->begin = t->begin, r->end = t->end;
    l->level = r->level = t->level + 1;
    l->parent = r->parent = self;
    l->slot = 0, r->slot = 1;
    if (found) {
        l->end = r->begin = partition(bd->prims, t, &s, &l->cbox, &r->cbox);
        assert(l->end > t->begin && l->end < t->end); /* both sides as binned */
        l->box = s.left;
        r->box = s.right;
    } else { /* no usable plane (e.g. identical centroids) or depth limit: halve by index */
        l->end = r->begin = t->begin + n / 2;
        range_bounds(bd->prims, l->begin, l->end, &l->box, &l->cbox);
        range_bounds(bd->prims, r->begin, r->end, &r->box, &r->cbox);
    }
    return 2;
}

/* Builds pending subtrees, largest first, each depth-first into its region. */
static void *subtree_worker(void *arg)
{
    builder *bd = ((worker *)arg)->bd;
    uint32_t k;
    while ((k = atomic_fetch_add(&bd->next_work, 1)) < bd->num_pending) {
        task stack[2 * BVH_MAX_DEPTH + 2];
        uint32_t sp = 0, start = bd->num_top + bd->pending[k].begin, next = start;
        stack[sp++] = bd->pending[k];
        while (sp > 0) {
            task t = stack[--sp];
            assert(sp + 2 <= sizeof stack / sizeof stack[0]);
            /* the left child is popped first, so a node's child a is numbered right after it */
            sp += (uint32_t)process(bd, &t, &stack[sp + 1], &stack[sp], &next);
        }
        bd->subtree_size[k] = next - start;
    }
    return NULL;
}

static int task_larger(const void *a, const void *b)
{
    uint32_t na = ((const task *)a)->end - ((const task *)a)->begin;
    uint32_t nb = ((const task *)b)->end - ((const task *)b)->begin;
    return na < nb ? 1 : na > nb ? -1 : 0;
}

/* Splits the largest range until there are enough subtrees to share among the threads:
 * 4 per thread balance well, and each further level of the top runs on one thread. */
static void build_top(builder *bd, const task *root)
{
    uint32_t np = 0, want = 4 * bd->threads < BVH_SUBTREES ? 4 * bd->threads : BVH_SUBTREES;
    bd->num_top = 0;
    bd->pending[np++] = *root;
    while (bd->threads > 1 && np > 0 && np < want && bd->num_top < BVH_SUBTREES) {
        uint32_t big = 0;
        for (uint32_t i = 1; i < np; i++)
            big = bd->pending[i].end - bd->pending[i].begin >
                          bd->pending[big].end - bd->pending[big].begin ? i : big;
        if (bd->pending[big].end - bd->pending[big].begin < BVH_PARALLEL_MIN / BVH_SUBTREES)
            break;
        task t = bd->pending[big];
        bd->pending[big] = bd->pending[--np];
        np += (uint32_t)process(bd, &t, &bd->pending[np], &bd->pending[np + 1], &bd->num_top);
    }
    qsort(bd->pending, np, sizeof *bd->pending, task_larger);
    bd->num_pending = np;
}

/* Where pack_nodes puts the top nodes and the subtree blocks: depth-first from `ref`. */
typedef struct layout {
    uint32_t top[BVH_SUBTREES], block[BVH_SUBTREES], next;
} layout;

static uint32_t subtree_of(const builder *bd, uint32_t region)
{
    uint32_t k = 0;
    for (; k < bd->num_pending && bd->num_top + bd->pending[k].begin != region; k++)
        ;
    assert(k < bd->num_pending);
    return k;
}

/* ref: a top node below num_top, else the region of a subtree (which starts with its root) */
static uint32_t relocated(const builder *bd, const layout *lay, uint32_t ref)
{
    return ref < bd->num_top ? lay->top[ref] : lay->block[subtree_of(bd, ref)];
}

static void lay_out(const builder *bd, const GnBvhNode *top, uint32_t ref, layout *lay)
{
    if (ref >= bd->num_top) {
        uint32_t k = subtree_of(bd, ref);
        lay->block[k] = lay->next;
        lay->next += bd->subtree_size[k];
        return;
    }
    lay->top[ref] = lay->next++;
    if (top[ref].a_count == 0 && top[ref].a_index != GN_INVALID)
        lay_out(bd, top, top[ref].a_index, lay);
    if (top[ref].b_count == 0 && top[ref].b_index != GN_INVALID)
        lay_out(bd, top, top[ref].b_index, lay);
}

/* Moves the subtree blocks down (in depth-first order each lands at or before where it
 * was, past the blocks already moved) and the top nodes into the gaps; returns the count. */
static uint32_t pack_nodes(builder *bd)
{
    GnBvhNode top[BVH_SUBTREES];
    uint32_t order[BVH_SUBTREES];
    layout lay = {{0}, {0}, 0};
    memcpy(top, bd->nodes, bd->num_top * sizeof *top);
    lay_out(bd, top, 0, &lay); /* the root: top node 0, or the one subtree's region at 0 */
    for (uint32_t k = 0; k < bd->num_pending; k++) { /* depth-first = by first triangle */
        uint32_t j = k;
        for (; j > 0 && bd->pending[order[j - 1]].begin > bd->pending[k].begin; j--)
            order[j] = order[j - 1];
        order[j] = k;
    }
    for (uint32_t i = 0; i < bd->num_pending; i++) {
        uint32_t k = order[i], from = bd->num_top + bd->pending[k].begin, to = lay.block[k];
        GnBvhNode *n = bd->nodes + to;
        assert(to <= from);
        if (to == from) /* always so for a build on one thread */
            continue;
        memmove(n, bd->nodes + from, bd->subtree_size[k] * sizeof *n);
        for (uint32_t j = 0; j < bd->subtree_size[k]; j++) {
            if (n[j].a_count == 0 && n[j].a_index != GN_INVALID)
                n[j].a_index -= from - to;
            if (n[j].b_count == 0 && n[j].b_index != GN_INVALID)
                n[j].b_index -= from - to;
        }
    }
    for (uint32_t t = 0; t < bd->num_top; t++) {
        GnBvhNode n = top[t];
        if (n.a_count == 0 && n.a_index != GN_INVALID)
            n.a_index = relocated(bd, &lay, n.a_index);
        if (n.b_count == 0 && n.b_index != GN_INVALID)
            n.b_index = relocated(bd, &lay, n.b_index);
        bd->nodes[lay.top[t]] = n;
    }
    return lay.next;
}

static double box_area(const vec3 *lo, const vec3 *hi)
{
    double dx = (double)hi->x - lo->x, dy = (double)hi->y - lo->y, dz = (double)hi->z - lo->z;
    return dx * dy + dy * dz + dz * dx;
}

/* Measures the tree as the GPU sees it: depth, largest leaf and SAH cost from the stored
 * (padded) boxes. */
static void measure(bvh *out)
{
    uint32_t stack[2 * BVH_MAX_DEPTH + 2], level[2 * BVH_MAX_DEPTH + 2], sp = 0;
    double inner = 0, leaves = 0;
    stack[sp] = 0, level[sp++] = 1;
    out->depth = 0;
    out->max_leaf_size = 0;
    while (sp > 0) {
        uint32_t lv = level[--sp];
        const GnBvhNode *n = &out->nodes[stack[sp]];
        const vec3 *lo[2] = {&n->a_min, &n->b_min}, *hi[2] = {&n->a_max, &n->b_max};
        const uint32_t index[2] = {n->a_index, n->b_index}, count[2] = {n->a_count, n->b_count};
        out->depth = lv > out->depth ? lv : out->depth;
        for (int c = 0; c < 2; c++) {
            if (index[c] == GN_INVALID)
                continue;
            if (count[c] > 0) {
                leaves += box_area(lo[c], hi[c]) * count[c];
                out->max_leaf_size = count[c] > out->max_leaf_size ? count[c] : out->max_leaf_size;
            } else {
                inner += box_area(lo[c], hi[c]);
                assert(sp < sizeof stack / sizeof stack[0]);
                stack[sp] = index[c], level[sp++] = lv + 1;
            }
        }
    }
    /* The root's own box is the union of node 0's boxes; a root leaf is no inner node. A flat
     * root (all triangles on a line or a point) has no area to divide by: every box counts 1. */
    const GnBvhNode *r = &out->nodes[0];
    bool root_leaf = r->b_index == GN_INVALID;
    vec3 rlo = r->a_min, rhi = r->a_max;
    if (!root_leaf) {
        rlo = (vec3){minf(rlo.x, r->b_min.x), minf(rlo.y, r->b_min.y), minf(rlo.z, r->b_min.z)};
        rhi = (vec3){maxf(rhi.x, r->b_max.x), maxf(rhi.y, r->b_max.y), maxf(rhi.z, r->b_max.z)};
    }
    double root_area = box_area(&rlo, &rhi);
    if (root_area > 0)
        out->sah_cost = (float)(((root_leaf ? 0 : root_area) + inner + leaves) / root_area);
    else
        out->sah_cost = (float)((root_leaf ? 0 : out->num_nodes) + out->num_tris);
}

/* The tree over the records set up in bd->prims (root: their bounds), parallel below the
 * top levels, packed depth-first into out->nodes. */
static void build_nodes(builder *bd, const task *root, worker *w, bvh *out)
{
    build_top(bd, root);
    run_workers(bd, subtree_worker, w);
    out->num_nodes = pack_nodes(bd);
    out->nodes = util_realloc(bd->nodes, out->num_nodes * sizeof *out->nodes);
}

bool bvh_build(bvh *out, const float *positions, size_t position_stride_floats,
               const uint32_t *indices, uint32_t num_triangles)
{
    double t0 = util_now();
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    worker w[BVH_MAX_THREADS];
    memset(out, 0, sizeof *out);
    if (num_triangles == 0)
        return false;
    assert(position_stride_floats >= 3);

    builder bd = {.positions = positions, .stride = position_stride_floats, .indices = indices,
                  .num_tris = num_triangles, .min_leaf = BVH_MIN_LEAF, .max_leaf = BVH_MAX_LEAF,
                  .max_depth = BVH_MAX_DEPTH};
    bd.threads = num_triangles < BVH_PARALLEL_MIN || cpus <= 1 ? 1
                 : cpus > BVH_MAX_THREADS                     ? BVH_MAX_THREADS
                                                              : (uint32_t)cpus;
    uint32_t chunks = (uint32_t)(((uint64_t)num_triangles + BVH_SETUP_CHUNK - 1) / BVH_SETUP_CHUNK);
    bd.chunk_first = util_malloc(chunks * sizeof *bd.chunk_first);
    bd.mate = util_malloc(num_triangles * sizeof *bd.mate);
    atomic_init(&bd.next_work, 0);
    run_workers(&bd, pair_worker, w);
    pair_by_edges(&bd);
    for (uint32_t c = 0; c < chunks; c++) {
        uint32_t end = c + 1 < chunks ? (c + 1) * BVH_SETUP_CHUNK : num_triangles;
        bd.chunk_first[c] = bd.num_recs;
        for (uint32_t t = c * BVH_SETUP_CHUNK; t < end; t++)
            bd.num_recs += record_start(&bd, t);
    }
    bd.rec = util_malloc(bd.num_recs * sizeof *bd.rec);
    bd.prims = util_malloc(bd.num_recs * sizeof *bd.prims);
    assert((uintptr_t)bd.prims % sizeof(v4f) == 0);
    bd.nodes = util_calloc(BVH_SUBTREES + (size_t)bd.num_recs, sizeof *bd.nodes);
    bd.pairs = util_malloc(bd.num_recs * sizeof *bd.pairs);
    bd.tri_index = util_malloc(2 * (size_t)bd.num_recs * sizeof *bd.tri_index);
    bd.tri_rotation = util_malloc(2 * (size_t)bd.num_recs * sizeof *bd.tri_rotation);

    task root = {.begin = 0, .end = bd.num_recs, .level = 1, .parent = GN_INVALID,
                 .box = empty_box, .cbox = empty_box};
    run_workers(&bd, setup_worker, w);
    for (uint32_t i = 0; i < bd.threads; i++) {
        grow_box(&root.box, w[i].box.lo, w[i].box.hi);
        grow_box(&root.cbox, w[i].cbox.lo, w[i].cbox.hi);
    }
    build_nodes(&bd, &root, w, out);
    out->pairs = bd.pairs;
    out->num_pairs = bd.num_recs;
    out->num_tris = num_triangles;
    out->num_slots = 2 * bd.num_recs;
    out->tri_index = bd.tri_index;
    out->tri_rotation = bd.tri_rotation;
    free(bd.prims);
    free(bd.rec);
    free(bd.chunk_first);
    free(bd.mate);
    measure(out);
    out->build_seconds = util_now() - t0;
    return true;
}

void bvh_destroy(bvh *b)
{
    free(b->nodes);
    free(b->pairs);
    free(b->tri_index);
    free(b->tri_rotation);
    memset(b, 0, sizeof *b);
}

/* ---- the top level's tree (bvh_top.c places the instances) ------------------------------ */

/* The top tree over n instance boxes (lo xyz, hi xyz): leaves of one instance, binned SAH,
 * at most max_depth levels where the count allows. */
void bvh_build_instance_tree(bvh *out, const float (*boxes)[6], uint32_t n, uint32_t max_depth)
{
    double t0 = util_now();
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    worker w[BVH_MAX_THREADS];
    builder bd = {.num_recs = n, .min_leaf = 1, .max_leaf = 1, .instances = true,
                  .max_depth = max_depth < BVH_MAX_DEPTH ? max_depth : BVH_MAX_DEPTH};
    bd.threads = n < BVH_PARALLEL_MIN || cpus <= 1 ? 1 : cpus > BVH_MAX_THREADS ? BVH_MAX_THREADS : (uint32_t)cpus;
    bd.prims = util_malloc(n * sizeof *bd.prims);
    bd.nodes = util_calloc(BVH_SUBTREES + (size_t)n, sizeof *bd.nodes);
    task root = {.begin = 0, .end = n, .level = 1, .parent = GN_INVALID, .box = empty_box, .cbox = empty_box};
    for (uint32_t i = 0; i < n; i++) {
        prim *p = &bd.prims[i];
        for (int a = 0; a < 3; a++)
            p->lo3[a] = boxes[i][a], p->hi3[a] = boxes[i][3 + a];
        p->id = i;
        p->pad = 0;
        v4f c = centroid(p);
        grow_box(&root.box, prim_lo(p), p->hi);
        grow_box(&root.cbox, c, c);
    }
    memset(out, 0, sizeof *out);
    build_nodes(&bd, &root, w, out);
    out->num_tris = n;
    free(bd.prims);
    measure(out);
    out->build_seconds = util_now() - t0;
}

