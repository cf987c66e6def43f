// bvh.glsl: closest-hit and any-hit BVH traversal over GnBvhNode (both children's boxes in
// one node, Aila & Laine 2009) with the watertight ray-triangle test of Woop, Benthin &
// Wald (JCGT 2013). The C traversal in src/accel/bvh.c, the reference in the tests, uses the same
// boxes, triangle test and step count; it tests leaves as it meets them, this walk postpones
// them (below), so the two visit the same nodes in a different order.
//
// llvmpipe ends an invocation's loops silently after 65,535 iterations in total (the count
// is per SIMD group of 8 invocations: docs/architecture.md, The loop cap). A walk is bounded
// by a budget of node visits and, in a kernel specialised with LOOP_CAP > 0 (the path
// tracer on llvmpipe), by its lane's share of the loop passes; a walk stopped by either
// reports `truncated` and keeps its whole state, so the caller can resume it later.
#ifndef GONIO_BVH_GLSL
#define GONIO_BVH_GLSL

#include "scene.glsl"

// The walk's stack: 0, an array (GN_WALK_STACK entries, in memory); K > 0, its entries in K
// registers, for trees of at most K levels (the host sets it from the tree:
// src/render/render_limits.c: walk_regs).
// llvmpipe keeps a private array that is indexed per lane in memory and reads and writes it
// one lane at a time with a branch on each lane's mask; a shift register of K values costs
// it 2K vector selects a node visit instead (the gain: docs/performance.md).
layout(constant_id = GN_SPEC_WALK_REGS) const uint WALK_REGS = 0u;

// LOOP_CAP > 0: the loop passes a SIMD group may run (src/render/render_limits.c sets it below
// llvmpipe's cap), shared out as LOOP_CAP / gl_SubgroupSize to each lane (a subgroup is llvmpipe's SIMD
// group): loop_left is what this lane has left. A loop costs the group its longest lane's
// passes plus the test that ends it, which is at most the sum over the lanes in it of their
// passes plus one; so while every lane stays within its share, the group stays within the
// cap, with no need to know what the other lanes do (the kernel counts its other loops).
layout(constant_id = GN_SPEC_LOOP_CAP) const uint LOOP_CAP = 0u;
uint loop_left = 0u;

GnBvhNode bvh_node(uint i)
{
    int k = int(4u * i);
    uvec4 t0 = texelFetch(node_texels, k), t1 = texelFetch(node_texels, k + 1);
    uvec4 t2 = texelFetch(node_texels, k + 2), t3 = texelFetch(node_texels, k + 3);
    return GnBvhNode(uintBitsToFloat(t0.xyz), t0.w, uintBitsToFloat(t1.xyz), t1.w,
                     uintBitsToFloat(t2.xyz), t2.w, uintBitsToFloat(t3.xyz), t3.w);
}

GnTriPair bvh_pair(uint i)
{
    uint k = 3u * i;
    vec4 a = texel_f(tri_texels, k), b = texel_f(tri_texels, k + 1u), c = texel_f(tri_texels, k + 2u);
    return GnTriPair(a.xyz, vec3(a.w, b.xy), vec3(b.zw, c.x), c.yzw);
}

struct Hit {
    float t, u, v;
    uint tri;       // BVH-order triangle (GnPrim order), GN_INVALID on a miss
    uint steps;     // GnBvhNode visits
    bool truncated; // the budget ran out: the result may be wrong
};

// Per-ray constants of the watertight test. The paper permutes the axes (kx, ky, kz) and
// shears; here the permutation and shear are folded into three row vectors, so that the
// triangle loop has no per-lane dynamic component indexing (costly on SIMD CPUs such as
// lavapipe): Ax = A[kx] - Sx A[kz] = dot(sx, A), and likewise for y and z. Every vertex is
// transformed by the same arithmetic, so shared edges stay watertight.
struct RayPre {
    vec3 o;
    vec3 inv;       // 1 / d, with zero components replaced by a huge finite value
    bvec3 neg;      // inv < 0: a box's near plane on that axis is its max
    vec3 sx, sy, sz;
};

RayPre ray_pre(vec3 o, vec3 d)
{
    RayPre r;
    r.o = o;
    vec3 ad = abs(d);
    int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0) { int tmp = kx; kx = ky; ky = tmp; } // keep the winding
    vec3 ex = vec3(0.0), ey = vec3(0.0), ez = vec3(0.0);
    ex[kx] = 1.0; ey[ky] = 1.0; ez[kz] = 1.0;
    float Sx = d[kx] / d[kz], Sy = d[ky] / d[kz], Sz = 1.0 / d[kz];
    r.sx = ex - Sx * ez;
    r.sy = ey - Sy * ez;
    r.sz = Sz * ez;
    r.inv = vec3(1.0) / mix(d, sign(d) * GN_BVH_PARALLEL_DIR + vec3(equal(d, vec3(0.0))) * GN_BVH_PARALLEL_DIR,
                            lessThan(ad, vec3(GN_BVH_PARALLEL_DIR)));
    r.neg = lessThan(r.inv, vec3(0.0));
    return r;
}

// a * b - c * d with one rounding error at most 1.5 ulp (Kahan; see Jeannerod et al. 2013).
float diff_of_products(float a, float b, float c, float d)
{
    precise float cd = c * d;
    precise float err = fma(-c, d, cd);
    precise float dop = fma(a, b, -cd);
    return dop + err;
}

// Watertight test of a GnTriPair's triangles A = (p0, p1, p2) and B = (p0, p2, p3):
// corners relative to the origin, sheared so the ray is +z; the edge functions decide
// inside-ness exactly consistently on shared edges. Returns the nearer hit in (tmin, tmax)
// (A on a tie, as src/accel/bvh.c's leaf_hit), with which = 1 for B and the barycentrics of p1, p2
// (A) or p2, p3 (B), which are those of the triangle's GnPrim corners. A lone triangle's
// B = (p0, p2, p2) has Ub = 0 and Vb = -Wb exactly, so det 0: never a hit.
// Branch-free (llvmpipe runs every side of every branch anyway, and masks each assignment
// after an early return): one result at the end.
bool pair_intersect(RayPre r, GnTriPair q, float tmin, float tmax,
                    out float t, out float u, out float v, out uint which)
{
    vec3 P0 = q.p0 - r.o, P1 = q.p1 - r.o, P2 = q.p2 - r.o, P3 = q.p3 - r.o;
    float x0 = dot(r.sx, P0), y0 = dot(r.sy, P0), x1 = dot(r.sx, P1), y1 = dot(r.sy, P1);
    float x2 = dot(r.sx, P2), y2 = dot(r.sy, P2), x3 = dot(r.sx, P3), y3 = dot(r.sy, P3);
    // The edge functions in Kahan's FMA form (Woop et al. recompute in double precision when
    // a plain product difference is 0; many GPUs have no fp64). Where fma is fused (GPUs),
    // each is within 1.5 ulp of exact and so has the exact sign. Vulkan lets fma round twice,
    // and llvmpipe does (its JIT code multiplies, then adds): the error term is then 0 and
    // this is the plain difference of the two rounded products, which still keeps shared
    // edges watertight: the neighbour computes the same two products and the difference
    // negates exactly. Either way the form costs llvmpipe less than a zero test and a
    // masked recomputation, which it would run on every triangle.
    // A: U weighs p0, V p1, W p2 (src/accel/bvh.c's tri_hit with v0, v1, v2 = p0, p1, p2).
    float Ua = diff_of_products(x2, y1, y2, x1);
    float Va = diff_of_products(x0, y2, y0, x2);
    float Wa = diff_of_products(x1, y0, y1, x0);
    // B = (p0, p2, p3): its edge (p2, p0) is A's edge (p0, p2) reversed, so B's W is -Va:
    // the exact negation of the plain difference B would compute itself, and of the exact
    // sign where fma is fused.
    float Ub = diff_of_products(x3, y2, y3, x2);
    float Vb = diff_of_products(x0, y3, y0, x3);
    float Wb = -Va;
    bool out_a = (Ua < 0.0 || Va < 0.0 || Wa < 0.0) && (Ua > 0.0 || Va > 0.0 || Wa > 0.0);
    bool out_b = (Ub < 0.0 || Vb < 0.0 || Wb < 0.0) && (Ub > 0.0 || Vb > 0.0 || Wb > 0.0);
    float det_a = Ua + Va + Wa, det_b = Ub + Vb + Wb;
    float z0 = dot(r.sz, P0), z1 = dot(r.sz, P1), z2 = dot(r.sz, P2), z3 = dot(r.sz, P3);
    float ra = 1.0 / det_a, rb = 1.0 / det_b;
    float ta = (Ua * z0 + Va * z1 + Wa * z2) * ra, tb = (Ub * z0 + Vb * z2 + Wb * z3) * rb;
    bool hit_a = !out_a && det_a != 0.0 && ta > tmin && ta < tmax;
    bool hit_b = !out_b && det_b != 0.0 && tb > tmin && tb < tmax;
    bool b_wins = hit_b && (!hit_a || tb < ta);
    t = b_wins ? tb : ta;
    u = b_wins ? Vb * rb : Va * ra;
    v = b_wins ? Wb * rb : Wa * ra;
    which = b_wins ? 1u : 0u;
    return hit_a || hit_b;
}

// max and min of numbers that are never NaN here: GLSL's max and min must return the
// non-NaN operand, which costs llvmpipe a compare and a blend more than a plain select.
precise float max_nn(float a, float b) { return a > b ? a : b; }
precise float min_nn(float a, float b) { return a < b ? a : b; }

// Slab test of one child box: entry distance, or +inf on a miss. The far distance is
// scaled by GN_BVH_TFAR_SCALE so rounding never loses a box the triangle test hits.
float box_enter(RayPre r, vec3 bmin, vec3 bmax, float tmin, float tmax)
{
    // The near and far planes by the sign of the direction: the same values as min and
    // max of the two slab distances (boxes have min <= max), for fewer SIMD instructions.
    vec3 lo = (mix(bmin, bmax, r.neg) - r.o) * r.inv, hi = (mix(bmax, bmin, r.neg) - r.o) * r.inv;
    float enter = max_nn(max_nn(lo.x, lo.y), max_nn(lo.z, tmin));
    float leave = min_nn(min_nn(hi.x, hi.y), min_nn(hi.z, tmax)) * GN_BVH_TFAR_SCALE;
    return enter <= leave ? enter : 1e38;
}

// A walk's position: a child index as GnBvhNode stores it (glsl/lib/shared.h): an inner node's
// index, or a leaf with GN_BVH_LEAF set and its count and first triangle packed.
uint walk_leaf_first(uint entry) { return entry & GN_BVH_FIRST; }
uint walk_leaf_last(uint entry) { return walk_leaf_first(entry) + ((entry >> GN_BVH_COUNT_SHIFT) & 15u); }

// The state of a walk, so one that runs out of budget can be resumed later (the unit tests
// resume walks across dispatches to get exact answers on meshes beyond llvmpipe's loop cap).
struct Walk {
    Hit hit;
    uint node;      // next child index to visit, GN_INVALID when the walk is over
    int sp;         // stack entries in use, the sentinel included
    // stack[0] is a sentinel (GN_INVALID: popping it ends the walk), stack[1, sp) the nodes
    // put off for later; bvh_walk writes stack[sp] on every node visit, so a full stack
    // keeps one entry free: at most GN_WALK_STACK - 2 nodes.
    uint stack[GN_WALK_STACK];
    // WALK_REGS > 0: the stack instead, top first, GN_INVALID below the last entry (popping
    // past the end reads GN_INVALID and ends the walk, like the sentinel). Only constant
    // indices reach it, so the compiler keeps it in registers.
    uint regs[GN_WALK_REGS_MAX];
};

// The walk of this invocation: a private global that bvh_walk works on in place (as a
// function parameter its stack would be copied in and out on every trace).
Walk walk;

void walk_start(float tmax)
{
    walk.hit.t = tmax; walk.hit.u = 0.0; walk.hit.v = 0.0; walk.hit.tri = GN_INVALID;
    walk.hit.steps = 0u; walk.hit.truncated = false;
    walk.node = 0u;
    walk.sp = 1; // (unused with WALK_REGS > 0)
    if (WALK_REGS == 0u)
        walk.stack[0] = GN_INVALID;
    for (uint k = 0u; k < WALK_REGS; k++)
        walk.regs[k] = GN_INVALID;
}

// The register stack after a node visit: push x (push) or pop (pop), else unchanged.
void walk_regs_update(bool push, bool pop, uint x)
{
    uint old[GN_WALK_REGS_MAX];
    for (uint k = 0u; k < WALK_REGS; k++)
        old[k] = walk.regs[k];
    for (uint k = 0u; k < WALK_REGS; k++) {
        uint above = k > 0u ? old[k - 1u] : x, below = k + 1u < WALK_REGS ? old[k + 1u] : GN_INVALID;
        walk.regs[k] = push ? above : pop ? below : old[k];
    }
}

// Continues `walk` for at most `budget` more node visits. Closest hit (any_hit false) or
// the first hit found (any_hit true) with t in (tmin, walk.hit.t). On return either
// walk.node is GN_INVALID (done) or walk.hit.truncated is set (budget spent; call again).
//
// The loop is "while-while" (Aila & Laine 2009): inner nodes until the ray holds a leaf,
// then that leaf's triangles. llvmpipe runs both sides of every branch with lanes masked
// off (it never jumps over an `if`), so a loop body that tested nodes and leaves together
// would pay a triangle test on every node visit; split, a node visit pays only its own
// work, and the triangle loop runs once per leaf.
//
// With LOOP_CAP > 0 the walk also stops (truncated) when the lane's loop_left runs out. It is
// counted in node visits: lim is the step count at which the lane's passes are spent, less
// the other passes (leaves, loop tests) as they come, so the node loop's test stays one
// comparison.
void bvh_walk(RayPre r, float tmin, bool any_hit, uint budget)
{
#define w walk
    uint end = w.hit.steps + budget, lim = w.hit.steps + loop_left;
    w.hit.truncated = false;
    // No early returns and no breaks: llvmpipe masks every later statement of a loop body
    // again after either, so the loop conditions end the walk. An index without
    // GN_BVH_LEAF is an inner node (GN_INVALID has that bit set too).
    while (w.node != GN_INVALID && !w.hit.truncated && (LOOP_CAP == 0u || w.hit.steps < lim)) {
        // Inner nodes while the budget (and the lane's loop passes) last.
        uint e = LOOP_CAP > 0u ? min(end, lim) : end;
        while ((w.node & GN_BVH_LEAF) == 0u && w.hit.steps < e) {
            w.hit.steps++;
            GnBvhNode n = bvh_node(w.node);
            // (an empty child b has an inverted box: box_enter misses it)
            float ea = box_enter(r, n.a_min, n.a_max, tmin, w.hit.t);
            float eb = box_enter(r, n.b_min, n.b_max, tmin, w.hit.t);
            uint ca = n.a_index, cb = n.b_index;
            bool hit_a = ea < 1e38, hit_b = eb < 1e38, both = hit_a && hit_b;
            // Both: go to the nearer (a on a tie), keep the farther; one: go there; none: pop.
            // The stack is read and written by every lane, whatever its case (the write lands
            // above the top when nothing is pushed): llvmpipe stores and loads an array at
            // per-lane indices one lane at a time, branching on each lane's mask, and a mask
            // that follows the case of each lane is one the branch predictor cannot learn.
            bool a_first = hit_a && (!hit_b || ea <= eb);
            uint top;
            if (WALK_REGS > 0u) {
                top = w.regs[0];
                walk_regs_update(both, !(hit_a || hit_b), a_first ? cb : ca);
            } else {
                top = w.stack[w.sp - 1];
                w.stack[w.sp] = a_first ? cb : ca;
                // The stack cannot overflow: the builder's trees are at most BVH_MAX_DEPTH
                // levels deep, which src/accel/bvh.c checks against GN_WALK_STACK at compile time.
                w.sp = both ? w.sp + 1 : (hit_a || hit_b) ? w.sp : max(w.sp - 1, 1);
            }
            w.node = (hit_a || hit_b) ? (a_first ? ca : cb) : top;
        }
        // An inner node here: the budget (or llvmpipe's loop cap) ended the loop above early.
        w.hit.truncated = (w.node & GN_BVH_LEAF) == 0u;
        bool leaf = !w.hit.truncated && w.node != GN_INVALID;
        uint last = walk_leaf_last(w.node), i = walk_leaf_first(w.node), i0 = i;
        for (; leaf && i <= last && !(any_hit && w.hit.tri != GN_INVALID); i++) {
            GnTriPair q = bvh_pair(i);
            float t, u, v;
            uint which;
            if (pair_intersect(r, q, tmin, w.hit.t, t, u, v, which)) {
                w.hit.t = t; w.hit.u = u; w.hit.v = v; w.hit.tri = 2u * i + which;
            }
        }
        // (+ 3: the tests that ended the two loops, and this pass of the enclosing one)
        if (LOOP_CAP > 0u)
            lim -= min(lim, (leaf ? i - i0 : 0u) + 3u);
        bool found = any_hit && w.hit.tri != GN_INVALID; // any hit: the walk is over
        uint top = WALK_REGS > 0u ? w.regs[0] : w.stack[w.sp - 1]; // read by every lane, as above
        if (WALK_REGS > 0u)
            walk_regs_update(false, leaf, 0u);
        else if (leaf)
            w.sp = max(w.sp - 1, 1);
        if (leaf)
            w.node = found ? GN_INVALID : top;
    }
    // The loop ends with the walk over, or else because llvmpipe's loop cap stopped it: the
    // state is still whole (the cap ends loops between iterations), so say so and the
    // caller can resume instead of taking a silent miss.
    if (w.node != GN_INVALID)
        w.hit.truncated = true;
    // (- 1: the test that ended the loop)
    if (LOOP_CAP > 0u)
        loop_left = lim > w.hit.steps ? lim - w.hit.steps - 1u : 0u;
#undef w
}

// Closest hit (any_hit false) or any hit (true) in (tmin, tmax) within frame's budget, on
// every surface (see trace_visible for surfaces cut away).
Hit bvh_trace(vec3 o, vec3 d, float tmin, float tmax, bool any_hit)
{
    walk_start(tmax);
    bvh_walk(ray_pre(o, d), tmin, any_hit, frame.traversal_budget);
    return walk.hit;
}

// ---- rays through surfaces cut away (glTF alphaMode MASK and BLEND) -------------------------
// The random numbers of the BLEND test are rng_uniform4(rng_pixel, rng_sample, dim + k) for
// the ray's k-th crossing (glsl/lib/scene.glsl: the dimensions of a sample); the kernel sets the
// pixel (or vertex) and sample.
uint rng_pixel = 0u, rng_sample = 0u;
#define DIM_ALPHA 0x40000000u // the alpha tests' dimensions: DIM_ALPHA + 4096 ray + crossing
#define DIM_ALPHA_RAY 4096u

// bvh_trace within `budget` node visits in all, on the surfaces not cut away: the walk is
// left as it is (docs/architecture.md) and, when the hit's material is MASK or BLEND and the
// surface is cut there (a uniform number >= its opacity), the same ray goes on from just past
// the hit, without a bounce. Shadow rays then need the nearest hit too: a ray that took any
// hit and went on past it would skip the surfaces before it. Without GN_FEAT_ALPHA (opaque
// scenes) this is bvh_trace. A ray that runs out of budget on the way says so (truncated).
Hit trace_visible(vec3 o, vec3 d, float tmin, float tmax, bool any_hit, uint budget, uint dim)
{
    bool alpha = GN_HAS(GN_FEAT_ALPHA) && (frame.flags & GN_FRAME_ALPHA) != 0u;
    RayPre r = ray_pre(o, d);
    walk_start(tmax);
    bvh_walk(r, tmin, any_hit && !alpha, budget);
    if (GN_HAS(GN_FEAT_ALPHA)) {
        uint steps = walk.hit.steps, k = 0u;
        while (alpha && walk.hit.tri != GN_INVALID && !walk.hit.truncated &&
               rng_uniform4(rng_pixel, rng_sample, dim + (k & (DIM_ALPHA_RAY - 1u)), frame.seed).x >=
                   surface_opacity(walk.hit.tri, walk.hit.u, walk.hit.v)) {
            // (t > the hit's own t: the watertight test gives the same t for the same ray and
            // triangle, so the surface just crossed is not found again)
            float t = walk.hit.t;
            walk_start(tmax);
            bvh_walk(r, t, false, budget - min(steps, budget));
            steps += walk.hit.steps;
            k++;
        }
        walk.hit.steps = steps;
    }
    return walk.hit;
}

#endif
