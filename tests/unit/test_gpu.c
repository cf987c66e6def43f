/* test_gpu.c: the GLSL traversal (glsl/lib/bvh.glsl, run by tests/kernels/trace_test.comp on the
 * Vulkan device) against the C traversal of the same GnBvhNode layout and against brute
 * force, on random, degenerate, edge-on and deep meshes; and the renderer end to end on a
 * scene with an analytic answer. */
#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "gpu.h"
#include "instances.h"
#include "meshgen.h"
#include "render.h"
#include "scene_mesh.h"
#include "test.h"
#include "trace_test.h" /* spv_trace_test: tests/kernels/trace_test.comp compiled by the build */
#include "wrap_test.h"  /* spv_wrap_test: tests/kernels/wrap_test.comp */
#include "render_kernels.h"
#include "spirv_specialise.h"

typedef struct ray {
    float o[3], tmin, d[3], tmax;
} ray;

typedef struct gpu_hit {
    float t, u, v;
    uint32_t tri;
    float steps, unfinished;
    uint32_t inst;
    float pad1;
} gpu_hit;

/* A Walk of bvh.glsl in std430: Hit (7 words), node, inst, sp, stack, regs. */
#define WALK_BYTES (4 * (7 + 3 + GN_WALK_STACK + GN_WALK_REGS_MAX))

/* What gpu_trace walks: one tree (instances NULL) or two levels (the GPU arrays of a
 * bvh_top and its instances). */
typedef struct trace_scene {
    const GnBvhNode *nodes;
    uint32_t num_nodes;
    const GnTriPair *pairs;
    uint32_t num_pairs;
    const GnInstance *instances;
    uint32_t num_instances;
    uint32_t depth; /* stack entries a walk may need (walk_regs may be used up to it) */
} trace_scene;

static trace_scene one_tree(const bvh *b)
{
    return (trace_scene){b->nodes, b->num_nodes, b->pairs, b->num_pairs, NULL, 0, b->depth};
}

/* The walk's stack for gpu_trace: 0, the array; K, K registers (trees of <= K levels). */
static uint32_t walk_regs;

bool test_open_gpu(gpu *g)
{
    const char *env = getenv("GONIO_VALIDATE");
    gpu_desc d = {.device_index = -1, .validate = env && !strcmp(env, "1")};
    bool ok = gpu_create(g, &d);
    CHECKF(ok, "no Vulkan device");
    return ok;
}

/* Traces rays on the GPU with a per-dispatch budget of `budget` node visits, resuming
 * unfinished walks until all are done (resume = false: one dispatch only). Returns the
 * number of dispatches. */
static int gpu_trace_scene(gpu *g, const trace_scene *b, const ray *rays, uint32_t n, bool any_hit,
                           uint32_t budget, bool resume, gpu_hit *out)
{
    gpu_buffer frame, nodes, tris, rbuf, hbuf, wbuf, status, inst;
    gpu_pipeline p;
    GnFrame f = {0};
    int dispatches = 0;
    f.traversal_budget = budget;
    gpu_buffer_create(g, &frame, sizeof f, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_upload(g, &frame, &f, sizeof f, 0);
    gpu_buffer_create_texels(g, &nodes, b->nodes, sizeof(GnBvhNode) * b->num_nodes);
    gpu_buffer_create_texels(g, &tris, b->pairs, sizeof(GnTriPair) * b->num_pairs);
    if (b->instances)
        gpu_buffer_create_texels(g, &inst, b->instances, sizeof(GnInstance) * b->num_instances);
    else
        gpu_buffer_create_texels(g, &inst, NULL, 16);
    gpu_buffer_create_storage(g, &rbuf, rays, sizeof(ray) * n);
    gpu_buffer_create(g, &hbuf, sizeof(gpu_hit) * n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_create_storage(g, &wbuf, NULL, (VkDeviceSize)WALK_BYTES * n);
    gpu_buffer_create(g, &status, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    {
        const gpu_binding bind[] = {
            {GN_BIND_FRAME, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &frame},
            {GN_BIND_NODES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &nodes},
            {GN_BIND_TRIS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &tris},
            {GN_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &rbuf},
            {GN_BIND_AOV, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &hbuf},
            {GN_BIND_VCOLOR, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &wbuf},
            {GN_BIND_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &status},
            {GN_BIND_INSTANCES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &inst},
        };
        const uint32_t values[2] = {walk_regs, b->instances != NULL};
        const VkSpecializationMapEntry entries[2] = {{GN_SPEC_WALK_REGS, 0, sizeof(uint32_t)},
                                                     {GN_SPEC_INSTANCES, sizeof(uint32_t), sizeof(uint32_t)}};
        const VkSpecializationInfo spec = {2, entries, sizeof values, values};
        assert(walk_regs == 0 || b->depth <= walk_regs);
        gpu_pipeline_desc pd = {.name = "trace_test", .code = spv_trace_test, .specialization = &spec,
                                .code_size = sizeof spv_trace_test, .local_size = {64, 1, 1},
                                .push_size = sizeof(GnPush), .bindings = bind,
                                .num_bindings = sizeof bind / sizeof *bind};
        gpu_pipeline_create(g, &p, &pd);
    }
    for (;;) {
        GnPush push = {n, (dispatches > 0 ? GN_PASS_RESUME : 0u) | (any_hit ? GN_PASS_ANY_HIT : 0u), 0, 0};
        VkCommandBuffer cmd;
        memset(status.mapped, 0, 16);
        cmd = gpu_begin(g);
        gpu_dispatch(cmd, &p, &push, n, 1, 1);
        gpu_submit_wait(g, cmd);
        dispatches++;
        if (!resume || ((uint32_t *)status.mapped)[0] == 0 || dispatches > 10000)
            break;
    }
    memcpy(out, hbuf.mapped, sizeof(gpu_hit) * n);
    gpu_pipeline_destroy(g, &p);
    gpu_buffer_destroy(g, &frame);
    gpu_buffer_destroy(g, &nodes);
    gpu_buffer_destroy(g, &tris);
    gpu_buffer_destroy(g, &rbuf);
    gpu_buffer_destroy(g, &hbuf);
    gpu_buffer_destroy(g, &wbuf);
    gpu_buffer_destroy(g, &status);
    gpu_buffer_destroy(g, &inst);
    return dispatches;
}

static int gpu_trace(gpu *g, const bvh *b, const ray *rays, uint32_t n, bool any_hit,
                     uint32_t budget, bool resume, gpu_hit *out)
{
    trace_scene t = one_tree(b);
    return gpu_trace_scene(g, &t, rays, n, any_hit, budget, resume, out);
}

static uint64_t rng_state = 88172645463325252ull;
static float frand(void) /* xorshift64*, [0, 1) */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (float)((rng_state * 2685821657736338717ull) >> 40) / 16777216.0f;
}

static void random_rays(ray *r, uint32_t n, const float lo[3], const float hi[3])
{
    for (uint32_t i = 0; i < n; i++) {
        float len = 0, target[3];
        for (int k = 0; k < 3; k++) {
            float ext = hi[k] - lo[k] + 1e-3f;
            r[i].o[k] = lo[k] - 0.5f * ext + 2.0f * ext * frand();
            target[k] = lo[k] + (hi[k] - lo[k]) * frand();
            r[i].d[k] = target[k] - r[i].o[k];
            len += r[i].d[k] * r[i].d[k];
        }
        len = sqrtf(len);
        for (int k = 0; k < 3; k++)
            r[i].d[k] = len > 0 ? r[i].d[k] / len : (k == 2);
        r[i].tmin = 0;
        r[i].tmax = 1e30f;
    }
}

static bool same_t(float a, float b) { return fabsf(a - b) <= 1e-5f * fmaxf(1.0f, fabsf(b)); }

/* Is the GPU's hit point o + t d the point of BVH-order triangle `slot` at its barycentrics
 * (corner k: the mesh's (tri_rotation + k) mod 3)? Zero-area triangles pass: their hits
 * are rounding noise of a det that should be 0. */
static bool on_triangle(const bvh *b, const meshgen_mesh *m, uint32_t slot, const ray *r,
                        const gpu_hit *h)
{
    const float *c[3];
    float e1[3], e2[3], n[3], ext = 1;
    for (int k = 0; k < 3; k++)
        c[k] = m->positions + 3 * m->indices[3 * b->tri_index[slot] + (b->tri_rotation[slot] + k) % 3];
    for (int a = 0; a < 3; a++)
        e1[a] = c[1][a] - c[0][a], e2[a] = c[2][a] - c[0][a];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] < 1e-20f)
        return true;
    for (int a = 0; a < 3; a++)
        ext = fmaxf(ext, fabsf(r->o[a]) + fabsf(h->t * r->d[a]));
    for (int a = 0; a < 3; a++) {
        float p = (1 - h->u - h->v) * c[0][a] + h->u * c[1][a] + h->v * c[2][a];
        if (fabsf(p - (r->o[a] + h->t * r->d[a])) > 1e-4f * ext)
            return false;
    }
    return true;
}

/* GPU closest hits equal the C traversal's and brute force's (t within rounding; the same
 * triangle, at the same barycentrics, unless two tie at that t); any-hit agrees on
 * occlusion. Trees of at most GN_WALK_REGS_MAX levels are walked three ways: with the stack
 * in memory, in registers, and in registers resumed every two node visits (the registers
 * saved and restored with the walk). */
static void compare_mesh(gpu *g, const char *what, const meshgen_mesh *m, const ray *rays,
                         uint32_t n)
{
    bvh b = {0};
    gpu_hit *closest = calloc(n, sizeof *closest), *any = calloc(n, sizeof *any);
    int bad = 0, hits = 0;
    CHECK(bvh_build(&b, m->positions, 3, m->indices, m->num_triangles));
    int ways = b.depth <= GN_WALK_REGS_MAX ? 3 : 1;
    for (int way = 0; way < ways; way++) {
        uint32_t budget = way == 2 ? 2 : 1u << 30;
        walk_regs = way > 0 ? b.depth : 0;
        gpu_trace(g, &b, rays, n, false, budget, way == 2, closest);
        gpu_trace(g, &b, rays, n, true, budget, way == 2, any);
        for (uint32_t i = 0; i < n && bad < 5; i++) {
            uint32_t steps;
            bvh_hit c = bvh_intersect(&b, rays[i].o, rays[i].d, rays[i].tmin, rays[i].tmax, &steps);
            bvh_hit bf = bvh_brute_force(m->positions, 3, m->indices, m->num_triangles, rays[i].o,
                                         rays[i].d, rays[i].tmin, rays[i].tmax);
            uint32_t gtri = closest[i].tri;
            bool ok = (gtri == GN_INVALID) == (c.tri == GN_INVALID) &&
                      (c.tri == GN_INVALID) == (bf.tri == GN_INVALID);
            if (ok && c.tri != GN_INVALID) {
                hits++;
                ok = same_t(closest[i].t, c.t) && same_t(c.t, bf.t) &&
                     (b.tri_index[gtri] == b.tri_index[c.tri] || same_t(closest[i].t, bf.t));
                /* the same triangle: the same point on it, in its own corner order */
                ok = ok && (gtri != c.tri || (fabsf(closest[i].u - c.u) <= 1e-4f &&
                                              fabsf(closest[i].v - c.v) <= 1e-4f));
                /* whichever triangle: its corners (in the walk's order) at the GPU's
                 * barycentrics are the hit point, so a wrong triangle cannot pass as a tie */
                ok = ok && gtri < b.num_slots && b.tri_index[gtri] != GN_INVALID &&
                     on_triangle(&b, m, gtri, &rays[i], &closest[i]);
            }
            ok = ok && ((any[i].tri != GN_INVALID) == (c.tri != GN_INVALID));
            ok = ok && closest[i].unfinished == 0.0f;
            if (!ok) {
                bad++;
                fprintf(stderr, "  %s (%s) ray %u: gpu tri %u t %.9g uv %g %g, C tri %u t %.9g uv %g %g, "
                        "brute tri %u t %.9g, any %u\n", what, way == 0 ? "stack array" : way == 1 ?
                        "stack in registers" : "registers, resumed", i, gtri, closest[i].t,
                        closest[i].u, closest[i].v, c.tri, c.t, c.u, c.v, bf.tri, bf.t, any[i].tri);
            }
        }
    }
    walk_regs = 0;
    CHECKF(bad == 0, "%s: %d rays disagree", what, bad);
    CHECKF(hits > 0, "%s: no ray hit anything: the test would prove nothing", what);
    bvh_destroy(&b);
    free(closest);
    free(any);
}

TEST(gpu, traversal_random)
{
    gpu g;
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    meshgen_mesh m = meshgen_random_triangles(3000, 7, lo, hi);
    ray *r = malloc(sizeof *r * 8192);
    if (!test_open_gpu(&g))
        return;
    random_rays(r, 8192, lo, hi);
    compare_mesh(&g, "random", &m, r, 8192);
    meshgen_destroy(&m);
    free(r);
    CHECK(gpu_validation_message_count() == 0);
    gpu_destroy(&g);
}

TEST(gpu, traversal_sphere)
{
    gpu g;
    const float c[3] = {0.1f, -0.2f, 0.3f}, lo[3] = {-0.9f, -1.2f, -0.7f}, hi[3] = {1.1f, 0.8f, 1.3f};
    meshgen_mesh m = meshgen_uv_sphere(c, 1.0f, 64, 32);
    ray *r = malloc(sizeof *r * 8192);
    if (!test_open_gpu(&g))
        return;
    random_rays(r, 8192, lo, hi);
    compare_mesh(&g, "sphere", &m, r, 8192);
    meshgen_destroy(&m);
    free(r);
    gpu_destroy(&g);
}

/* Trees shallow enough for the walk's stack in registers: a small soup, a coarse sphere and
 * triangle pairs in every corner order (compare_mesh walks them all three ways). */
TEST(gpu, traversal_shallow)
{
    gpu g;
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0, 0, 0};
    meshgen_mesh m[3] = {meshgen_random_triangles(40, 3, lo, hi), meshgen_uv_sphere(c, 0.8f, 8, 5),
                         meshgen_quad_soup(24, 5, lo, hi)};
    const char *name[3] = {"small soup", "coarse sphere", "pairs"};
    ray *r = malloc(sizeof *r * 4096);
    if (!test_open_gpu(&g))
        return;
    random_rays(r, 4096, lo, hi);
    for (int i = 0; i < 3; i++) {
        bvh b;
        CHECK(bvh_build(&b, m[i].positions, 3, m[i].indices, m[i].num_triangles));
        CHECKF(b.depth <= GN_WALK_REGS_MAX, "%s: depth %u, too deep for the register stack", name[i], b.depth);
        bvh_destroy(&b);
        compare_mesh(&g, name[i], &m[i], r, 4096);
        meshgen_destroy(&m[i]);
    }
    free(r);
    CHECK(gpu_validation_message_count() == 0);
    gpu_destroy(&g);
}

/* Rays aimed exactly at shared edges and vertices of a closed mesh, and rays parallel to
 * faces (edge-on): a watertight walk never lets the first kind through. */
TEST(gpu, traversal_edges)
{
    gpu g;
    meshgen_mesh m = meshgen_edge_on(4);
    uint32_t n = 0, cap = 6 * m.num_triangles + 64;
    ray *r = malloc(sizeof *r * cap);
    gpu_hit *h = malloc(sizeof *h * cap);
    bvh b = {0};
    int leaks = 0;
    float center[3] = {0, 0, 0};
    if (!test_open_gpu(&g))
        return;
    for (uint32_t v = 0; v < m.num_vertices; v++)
        for (int k = 0; k < 3; k++)
            center[k] += m.positions[3 * v + k] / (float)m.num_vertices;
    /* from outside through every vertex and every edge midpoint, towards the centre */
    for (uint32_t t = 0; t < m.num_triangles && n + 6 <= cap; t++)
        for (int e = 0; e < 3; e++) {
            const float *a = &m.positions[3 * m.indices[3 * t + e]];
            const float *bb = &m.positions[3 * m.indices[3 * t + (e + 1) % 3]];
            for (int kind = 0; kind < 2; kind++) {
                float p[3], len = 0;
                for (int k = 0; k < 3; k++) {
                    p[k] = kind ? 0.5f * (a[k] + bb[k]) : a[k];
                    r[n].d[k] = center[k] - p[k];
                    len += r[n].d[k] * r[n].d[k];
                }
                len = sqrtf(len);
                for (int k = 0; k < 3; k++) {
                    r[n].d[k] /= len;
                    r[n].o[k] = p[k] - 3.0f * r[n].d[k];
                }
                r[n].tmin = 0;
                r[n].tmax = 1e30f;
                n++;
            }
        }
    CHECK(bvh_build(&b, m.positions, 3, m.indices, m.num_triangles));
    gpu_trace(&g, &b, r, n, false, 1u << 30, false, h);
    for (uint32_t i = 0; i < n; i++)
        leaks += h[i].tri == GN_INVALID;
    CHECKF(leaks == 0, "%d of %u rays through shared edges/vertices missed", leaks, n);
    /* the same rays, and random ones, agree with the C walk and brute force */
    compare_mesh(&g, "edges", &m, r, n);
    bvh_destroy(&b);
    meshgen_destroy(&m);
    free(r);
    free(h);
    gpu_destroy(&g);
}

/* The comb: a ray down its axis must visit every node. Its walk needs more loop iterations
 * than llvmpipe lets one invocation run (65,535 in total, silently), so with the budget a
 * walk stops, says so, and is resumed by the next dispatch: the answer is still exact. The
 * same holds where the cap itself stops a walk. */
TEST(gpu, traversal_deep)
{
    gpu g;
    meshgen_mesh m = meshgen_comb(50000);
    bvh b = {0};
    ray r[64];
    gpu_hit h[64];
    uint32_t steps_c = 0;
    int dispatches;
    if (!test_open_gpu(&g))
        return;
    CHECK(bvh_build(&b, m.positions, 3, m.indices, m.num_triangles));
    for (int i = 0; i < 64; i++) {
        /* along the axis (the worst case), then slightly off it */
        float dx = i ? 1e-4f * (float)(i % 8) : 0, dy = i ? 1e-4f * (float)(i / 8) : 0;
        r[i] = (ray){{dx, dy, -1.0f}, 0, {0, 0, 1}, 1e30f};
    }
    dispatches = gpu_trace(&g, &b, r, 64, false, 2000, true, h);
    CHECKF(dispatches > 1, "the comb did not need resuming (%d dispatch): it tests nothing", dispatches);
    for (int i = 0; i < 64; i++) {
        bvh_hit c = bvh_intersect(&b, r[i].o, r[i].d, r[i].tmin, r[i].tmax, i ? NULL : &steps_c);
        bvh_hit bf = bvh_brute_force(m.positions, 3, m.indices, m.num_triangles, r[i].o, r[i].d,
                                     r[i].tmin, r[i].tmax);
        CHECKF(h[i].tri != GN_INVALID && c.tri != GN_INVALID && same_t(h[i].t, c.t) &&
                   same_t(c.t, bf.t) && h[i].unfinished == 0.0f,
               "comb ray %d: gpu tri %u t %g, C tri %u t %g, brute t %g", i, h[i].tri, h[i].t,
               c.tri, c.t, bf.t);
    }
    printf("    comb: %u nodes, C walk %u steps, GPU resumed over %d dispatches\n", b.num_nodes,
           steps_c, dispatches);
    CHECKF(steps_c * 2 > b.num_nodes, "the comb walk visits only %u of %u nodes", steps_c,
           b.num_nodes);
    /* Without a budget, llvmpipe's loop cap stops the walk instead (other devices finish
     * it). Either way the walk must not answer wrongly: it finishes right or says it is
     * unfinished, and resuming it past the cap gives the exact answer. */
    gpu_trace(&g, &b, r, 1, false, 1u << 30, false, h);
    printf("    comb: one unbounded dispatch on %s: %s after %g steps\n", g.props.deviceName,
           h[0].unfinished != 0.0f ? "unfinished (the loop cap), reported" :
           h[0].tri == GN_INVALID ? "a silent MISS" : "hit", h[0].steps);
    bvh_hit c0 = bvh_intersect(&b, r[0].o, r[0].d, r[0].tmin, r[0].tmax, NULL);
    CHECKF(h[0].unfinished != 0.0f || (h[0].tri != GN_INVALID && same_t(h[0].t, c0.t)),
           "an unbounded walk ended wrongly without saying so: tri %u t %g", h[0].tri, h[0].t);
    dispatches = gpu_trace(&g, &b, r, 1, false, 1u << 30, true, h);
    CHECKF(h[0].tri != GN_INVALID && same_t(h[0].t, c0.t) && h[0].unfinished == 0.0f,
           "an unbounded walk resumed over %d dispatches: tri %u t %g, C t %g", dispatches,
           h[0].tri, h[0].t, c0.t);
    bvh_destroy(&b);
    meshgen_destroy(&m);
    gpu_destroy(&g);
}

/* ---- two levels: instances ------------------------------------------------------------- */

/* The GPU arrays of a scene of instances, as the renderer uploads them. */
static trace_scene two_levels(const bvh_top *t, GnBvhNode **nodes, GnTriPair **pairs)
{
    *nodes = malloc(t->num_nodes * sizeof **nodes);
    *pairs = malloc(t->num_pairs * sizeof **pairs);
    bvh_top_gpu_nodes(t, *nodes);
    bvh_top_gpu_pairs(t, *pairs);
    return (trace_scene){*nodes, t->num_nodes, *pairs, t->num_pairs, t->instances, t->num_instances,
                         bvh_top_depth(t)};
}

/* The GPU's two-level walk against the C one (bvh_top_intersect, itself checked against brute
 * force over the flattened triangles in test_bvh.c): the same instance and triangle, or a tie
 * at the same t; the hit point on the triangle the GPU names; any hit agreeing. Walked with
 * the stack in memory and (trees shallow enough) in registers, each whole and resumed every
 * two node visits, so that walks stop inside meshes and go on there. */
static void compare_instances(gpu *g, const char *what, const inst_scene *s, const ray *rays, uint32_t n)
{
    GnBvhNode *nodes;
    GnTriPair *pairs;
    trace_scene t = two_levels(&s->top, &nodes, &pairs);
    gpu_hit *closest = calloc(n, sizeof *closest), *any = calloc(n, sizeof *any);
    int bad = 0, hits = 0, ways = t.depth <= GN_WALK_REGS_MAX ? 4 : 2, resumed = 0;
    float ext = 0;
    for (int a = 0; a < 3; a++)
        ext = fmaxf(ext, s->hi[a] - s->lo[a]);
    for (int way = 0; way < ways; way++) {
        uint32_t budget = way & 1 ? 2 : 1u << 30;
        walk_regs = way >= 2 ? t.depth : 0;
        resumed += gpu_trace_scene(g, &t, rays, n, false, budget, way & 1, closest) > 1;
        gpu_trace_scene(g, &t, rays, n, true, budget, way & 1, any);
        for (uint32_t i = 0; i < n && bad < 5; i++) {
            bvh_hit c = bvh_top_intersect(&s->top, rays[i].o, rays[i].d, rays[i].tmin, rays[i].tmax, NULL);
            const gpu_hit *h = &closest[i];
            bool ok = (h->tri == GN_INVALID) == (c.tri == GN_INVALID) && h->unfinished == 0.0f &&
                      (any[i].tri != GN_INVALID) == (c.tri != GN_INVALID);
            if (ok && c.tri != GN_INVALID) {
                hits++;
                ok = same_t(h->t, c.t) && h->inst < s->num_instances &&
                     ((h->inst == c.inst && h->tri == c.tri &&
                       fabsf(h->u - c.u) <= 1e-4f && fabsf(h->v - c.v) <= 1e-4f) ||
                      h->t == c.t);
                /* whichever triangle: the GPU's at its barycentrics is the hit point */
                float p[3];
                const GnInstance *in = &s->top.instances[h->inst];
                ok = ok && h->tri >= in->prim_base && h->tri - in->prim_base < s->tree[in->mesh].num_slots;
                if (ok) {
                    inst_hit_point(s, h->tri, h->inst, h->u, h->v, p);
                    for (int a = 0; a < 3; a++)
                        ok = ok && fabsf(p[a] - (rays[i].o[a] + h->t * rays[i].d[a])) <= 1e-4f * ext;
                }
            }
            if (!ok) {
                bad++;
                fprintf(stderr, "  %s (%s%s) ray %u: gpu inst %u tri %u t %.9g uv %g %g unfinished %g any %u, "
                        "C inst %u tri %u t %.9g uv %g %g\n", what, way >= 2 ? "registers" : "stack array",
                        way & 1 ? ", resumed" : "", i, h->inst, h->tri, h->t, h->u, h->v, h->unfinished,
                        any[i].tri, c.inst, c.tri, c.t, c.u, c.v);
            }
        }
    }
    walk_regs = 0;
    CHECKF(bad == 0, "%s: %d rays disagree", what, bad);
    CHECKF(hits > (int)n / 8, "%s: only %d hits: the test would prove little", what, hits);
    CHECKF(resumed == ways / 2, "%s: the walks resumed every two visits needed no second dispatch", what);
    free(closest);
    free(any);
    free(nodes);
    free(pairs);
}

TEST(gpu, traversal_instances)
{
    gpu g;
    inst_scene s;
    if (!test_open_gpu(&g))
        return;
    ray *r = malloc(sizeof *r * 4096);
    CHECK(inst_scene_make(&s, 60, 4.0, 3, false));
    random_rays(r, 4096, s.lo, s.hi);
    compare_instances(&g, "60 instances", &s, r, 4096);
    inst_scene_destroy(&s);
    /* small meshes: trees shallow enough for the stack in registers */
    CHECK(inst_scene_make(&s, 3, 1.0, 4, true));
    CHECKF(bvh_top_depth(&s.top) <= GN_WALK_REGS_MAX, "%u stack entries: too many for registers", bvh_top_depth(&s.top));
    random_rays(r, 2048, s.lo, s.hi);
    compare_instances(&g, "3 small instances", &s, r, 2048);
    inst_scene_destroy(&s);
    free(r);
    CHECK(gpu_validation_message_count() == 0);
    gpu_destroy(&g);
}

/* The comb (gpu.traversal_deep) placed three times: a ray down one copy's axis walks the
 * whole of its mesh's tree, longer than one invocation may run, so the walk stops inside the
 * instance, is saved and resumed there by later dispatches, and still gives the exact hit. */
TEST(gpu, traversal_instances_deep)
{
    gpu g;
    meshgen_mesh m = meshgen_comb(50000);
    bvh b;
    bvh_top t;
    ray r[16];
    gpu_hit h[16];
    float xf[3][12] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}, {0, 0, 1, 5, 0, 1, 0, 0, -1, 0, 0, 0},
                       {0, 0, -1, -5, 0, 1, 0, 0, -1, 0, 0, 0}};
    uint32_t mesh[3] = {0, 0, 0};
    if (!test_open_gpu(&g))
        return;
    CHECK(bvh_build(&b, m.positions, 3, m.indices, m.num_triangles));
    CHECK(bvh_top_build(&t, &b, 1, (const float(*)[12])xf, mesh, NULL, 3, "combs"));
    GnBvhNode *nodes;
    GnTriPair *pairs;
    trace_scene ts = two_levels(&t, &nodes, &pairs);
    for (int i = 0; i < 16; i++) {
        /* down the axis of instance 1 (its comb turned to run along +x from x = 5; mirrored
         * copy 2's along -x), then slightly off it */
        float dy = i ? 1e-4f * (float)(i % 4) : 0, dz = i ? 1e-4f * (float)(i / 4) : 0;
        r[i] = i < 8 ? (ray){{4.0f, dy, dz}, 0, {1, 0, 0}, 1e30f} : (ray){{-4.0f, dy, dz}, 0, {-1, 0, 0}, 1e30f};
    }
    int dispatches = gpu_trace_scene(&g, &ts, r, 16, false, 2000, true, h);
    CHECKF(dispatches > 1, "the combs did not need resuming (%d dispatch): it tests nothing", dispatches);
    for (int i = 0; i < 16; i++) {
        bvh_hit c = bvh_top_intersect(&t, r[i].o, r[i].d, r[i].tmin, r[i].tmax, NULL);
        CHECKF(h[i].tri != GN_INVALID && c.tri != GN_INVALID && same_t(h[i].t, c.t) && h[i].inst == c.inst &&
                   h[i].inst == (i < 8 ? 1u : 2u) && h[i].unfinished == 0.0f,
               "comb ray %d: gpu inst %u tri %u t %g, C inst %u tri %u t %g", i, h[i].inst, h[i].tri, h[i].t,
               c.inst, c.tri, c.t);
    }
    printf("    combs: %u instances, GPU walks resumed over %d dispatches\n", t.num_instances, dispatches);
    free(nodes);
    free(pairs);
    bvh_top_destroy(&t);
    bvh_destroy(&b);
    meshgen_destroy(&m);
    CHECK(gpu_validation_message_count() == 0);
    gpu_destroy(&g);
}

/* Texture wrapping (glsl/lib/wrap.glsl computes the modulo through a float quotient) against
 * integer arithmetic: every mode, texture sizes from 1 to 2^13 + 1, indices around multiples
 * of the period, negative ones and ones near 2^24 (the function's exact range). */
static int wrap_reference(int i, int n, int mode)
{
    int p = mode == 2 ? 2 * n : n, m;
    if (mode == 1)
        return i < 0 ? 0 : i >= n ? n - 1 : i;
    m = i % p;
    m = m < 0 ? m + p : m;
    return mode == 2 && m >= n ? p - 1 - m : m;
}

TEST(gpu, texture_wrap)
{
    static const int sizes[] = {1, 2, 3, 5, 7, 64, 100, 255, 1000, 2048, 4095, 8193};
    static const int centres[] = {0, 1, -1, 1 << 12, -(1 << 12), (1 << 24) - 20000, -(1 << 24) + 20000};
    enum { SPAN = 40 };
    const uint32_t n = 3 * (sizeof sizes / sizeof *sizes) * (sizeof centres / sizeof *centres) * 3 * SPAN;
    gpu g = {0};
    gpu_buffer q, out;
    gpu_pipeline p;
    uint32_t k = 0, bad = 0, first_bad = 0;
    if (!test_open_gpu(&g))
        return;
    gpu_buffer_create(&g, &q, 16 * (VkDeviceSize)n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_create(&g, &out, 4 * (VkDeviceSize)n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    int32_t *qs = q.mapped;
    for (int mode = 0; mode < 3; mode++)
        for (size_t a = 0; a < sizeof sizes / sizeof *sizes; a++)
            for (size_t c = 0; c < sizeof centres / sizeof *centres; c++)
                for (int j = -SPAN; j < 2 * SPAN; j++) {
                    /* around the centre and around the centre's multiple of the period */
                    int per = mode == 2 ? 2 * sizes[a] : sizes[a];
                    int base = j < SPAN / 2 ? centres[c] : centres[c] - centres[c] % per;
                    qs[4 * k] = base + j;
                    qs[4 * k + 1] = sizes[a];
                    qs[4 * k + 2] = mode;
                    qs[4 * k + 3] = 0;
                    k++;
                }
    {
        const gpu_binding bind[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &q},
                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &out}};
        gpu_pipeline_desc pd = {.name = "wrap_test", .code = spv_wrap_test, .code_size = sizeof spv_wrap_test,
                                .local_size = {64, 1, 1}, .push_size = 4, .bindings = bind, .num_bindings = 2};
        VkCommandBuffer cmd;
        gpu_pipeline_create(&g, &p, &pd);
        cmd = gpu_begin(&g);
        gpu_dispatch(cmd, &p, &k, k, 1, 1);
        gpu_submit_wait(&g, cmd);
    }
    for (uint32_t i = 0; i < k; i++)
        if (((int32_t *)out.mapped)[i] != wrap_reference(qs[4 * i], qs[4 * i + 1], qs[4 * i + 2]))
            first_bad = bad++ ? first_bad : i;
    CHECKF(bad == 0, "%u of %u wraps wrong, first: mode %d, i %d, n %d: %d, not %d", bad, k,
           qs[4 * first_bad + 2], qs[4 * first_bad], qs[4 * first_bad + 1],
           ((int32_t *)out.mapped)[first_bad],
           wrap_reference(qs[4 * first_bad], qs[4 * first_bad + 1], qs[4 * first_bad + 2]));
    printf("    texture wrap: %u queries\n", k);
    gpu_pipeline_destroy(&g, &p);
    gpu_buffer_destroy(&g, &out);
    gpu_buffer_destroy(&g, &q);
    gpu_destroy(&g);
}

/* The device compiles a kernel once (gpu.c: the kernel cache): two pipelines of the same
 * SPIR-V, specialisation and bindings share it, each with its own descriptor set, and each
 * computes over its own buffers, also once repointed at others (gpu_pipeline_bind); another
 * specialisation is another kernel; idle kernels are kept, up to a bound. */
TEST(gpu, kernels_shared)
{
    enum { N = 256 };
    gpu g = {0};
    gpu_buffer q[2], out[3];
    gpu_pipeline p[2];
    if (!test_open_gpu(&g))
        return;
    for (int b = 0; b < 2; b++) {
        gpu_buffer_create(&g, &q[b], 16 * N, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        int32_t *qs = q[b].mapped;
        for (int i = 0; i < N; i++) { /* wrap mode 0 (repeat) of i - 100 + 37 b into 7 + b */
            qs[4 * i] = i - 100 + 37 * b;
            qs[4 * i + 1] = 7 + b;
            qs[4 * i + 2] = 0;
            qs[4 * i + 3] = 0;
        }
    }
    for (int b = 0; b < 3; b++)
        gpu_buffer_create(&g, &out[b], 4 * N, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    const uint32_t before = gpu_kernel_count(&g);
    for (int b = 0; b < 2; b++) {
        const gpu_binding bind[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &q[b]},
                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &out[b]}};
        gpu_pipeline_desc pd = {.name = "wrap_test", .code = spv_wrap_test, .code_size = sizeof spv_wrap_test,
                                .local_size = {64, 1, 1}, .push_size = 4, .bindings = bind, .num_bindings = 2};
        gpu_pipeline_create(&g, &p[b], &pd);
    }
    CHECKF(gpu_kernel_count(&g) == before + 1, "%u kernels for one kernel twice", gpu_kernel_count(&g) - before);
    CHECK(p[0].pipeline == p[1].pipeline && p[0].set != p[1].set);
    /* p[0] over q[0] into out[0], p[1] over q[1] into out[1]; then p[0] repointed: q[1] into out[2] */
    uint32_t n = N;
    VkCommandBuffer cmd = gpu_begin(&g);
    gpu_dispatch(cmd, &p[0], &n, n, 1, 1);
    gpu_dispatch(cmd, &p[1], &n, n, 1, 1);
    gpu_submit_wait(&g, cmd);
    const gpu_binding rebind[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &q[1]},
                                  {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &out[2]}};
    gpu_pipeline_bind(&g, &p[0], rebind, 2);
    cmd = gpu_begin(&g);
    gpu_dispatch(cmd, &p[0], &n, n, 1, 1);
    gpu_submit_wait(&g, cmd);
    int bad = 0;
    for (int b = 0; b < 3; b++) {
        const int32_t *qs = q[b == 0 ? 0 : 1].mapped, *o = out[b].mapped;
        for (int i = 0; i < N; i++)
            bad += o[i] != wrap_reference(qs[4 * i], qs[4 * i + 1], qs[4 * i + 2]);
    }
    CHECKF(bad == 0, "%d of %d wraps wrong through the shared kernel", bad, 3 * N);
    gpu_pipeline_destroy(&g, &p[1]);
    CHECK(gpu_kernel_count(&g) == before + 1); /* kept: p[0] uses it */
    /* Other specialisations (of a constant the kernel does not read): other kernels, kept
     * up to the bound, the idle ones beyond it let go, and never the one p[0] uses. */
    for (uint32_t v = 0; v < 80; v++) {
        const gpu_binding bind[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &q[0]},
                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &out[0]}};
        const VkSpecializationMapEntry entry = {99, 0, sizeof v};
        const VkSpecializationInfo spec = {1, &entry, sizeof v, &v};
        gpu_pipeline_desc pd = {.name = "wrap_test", .code = spv_wrap_test, .code_size = sizeof spv_wrap_test,
                                .local_size = {64, 1, 1}, .push_size = 4, .bindings = bind, .num_bindings = 2,
                                .specialization = &spec};
        gpu_pipeline q0;
        gpu_pipeline_create(&g, &q0, &pd);
        if (v == 0)
            CHECKF(gpu_kernel_count(&g) == before + 2, "%u kernels", gpu_kernel_count(&g) - before);
        gpu_pipeline_destroy(&g, &q0);
    }
    CHECKF(gpu_kernel_count(&g) == 64, "%u kernels kept (64 expected)", gpu_kernel_count(&g));
    memset(out[2].mapped, 0, 4 * N);
    cmd = gpu_begin(&g);
    gpu_dispatch(cmd, &p[0], &n, n, 1, 1);
    gpu_submit_wait(&g, cmd);
    bad = 0;
    for (int i = 0; i < N; i++) {
        const int32_t *qs = q[1].mapped;
        bad += ((const int32_t *)out[2].mapped)[i] != wrap_reference(qs[4 * i], qs[4 * i + 1], qs[4 * i + 2]);
    }
    CHECKF(bad == 0, "%d of %d wraps wrong after 80 other kernels came and went", bad, N);
    gpu_pipeline_destroy(&g, &p[0]);
    for (int b = 0; b < 3; b++)
        gpu_buffer_destroy(&g, &out[b]);
    for (int b = 0; b < 2; b++)
        gpu_buffer_destroy(&g, &q[b]);
    CHECK(gpu_validation_message_count() == 0);
    gpu_destroy(&g);
}

/* The SpecId decorations a SPIR-V module has (OpDecorate id SpecId n: opcode 71, decoration 1). */
static int spec_ids(const uint32_t *w, size_t words)
{
    int n = 0;
    for (size_t i = 5; i < words && (w[i] >> 16); i += w[i] >> 16)
        n += (w[i] & 0xffff) == 71 && (w[i] >> 16) >= 3 && i + 2 < words && w[i + 2] == 1;
    return n;
}

/* The kernels reach the driver with their constants folded in by the host (gpu.c:
 * kernel_get, src/core/spirv_specialise.h): the path kernel specialised as for the Cornell
 * box folds, has no specialisation constant left and is smaller; tests/regress/path.sh
 * checks that its pixels are the driver-specialised kernel's. */
TEST(gpu, specialise_folds)
{
    render_kernel_key key = {.mode = GN_MODE_PATH, .scene_features = 0, .walk_regs = 3, .loop_cap = 0};
    render_spec spec;
    const render_kernel *kernel = render_mode_kernel(GN_MODE_PATH);
    const size_t words = kernel->code_size / 4;
    uint32_t *out = NULL;
    size_t size = 0;
    char why[256];
    const VkSpecializationInfo *info = render_kernel_specialize(&key, &spec);
    CHECKF(spec_ids(kernel->code, words) >= RENDER_SPEC_COUNT - 1, "the path kernel as built has %d SpecIds",
           spec_ids(kernel->code, words));
    bool ok = spirv_specialise(kernel->code, kernel->code_size, info, &out, &size, why, sizeof why);
    CHECKF(ok, "not folded: %s", why);
    if (ok) {
        CHECKF(spec_ids(out, size / 4) == 0, "%d SpecIds left", spec_ids(out, size / 4));
        CHECKF(size < kernel->code_size, "folded %zu bytes, as built %zu", size, kernel->code_size);
        printf("    the path kernel for the Cornell box's features: %zu bytes as built, %zu folded\n",
               kernel->code_size, size);
    }
    free(out);
    CHECK(!spirv_specialise(kernel->code, kernel->code_size, NULL, &out, &size, why, sizeof why) && !why[0]);
}
