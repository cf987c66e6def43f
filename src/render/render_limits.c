/* render_limits.c: what the device allows and how a render keeps within it: the scene's
 * buffers against the texel buffer limit, llvmpipe's loop cap (the samples a path dispatch
 * takes, the walk budget of a ray, the path kernel's loop cap and saved state), and the
 * walk's stack. The accumulation buffers' limits are render_accum.c's (band_rows). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "brdf.h"
#include "render_internal.h"
#include "util.h"


/* llvmpipe (lavapipe) ends an invocation's loops silently after 65,535 iterations; real
 * GPUs have no such cap. */
static bool loop_capped(const gpu *g)
{
    VkPhysicalDeviceDriverProperties drv = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                      .pNext = &drv};
    vkGetPhysicalDeviceProperties2(g->physical, &p2);
    return drv.driverID == VK_DRIVER_ID_MESA_LLVMPIPE;
}

/* How many samples one invocation of the path kernel takes per dispatch, 1 to
 * GN_PATH_SAMPLES. More keep the SIMD lanes busier (glsl/kernels/path.comp): the Cornell box's
 * paths run faster with 31 than 16 on lavapipe (docs/performance.md). Each path has its own
 * walk budget, but on llvmpipe all of them share the loop cap (65,535 iterations per SIMD
 * group), so the number is what fits half the cap for typical paths: 16 rays (8 vertices,
 * each with a shadow ray) of sah_cost node visits, about 3 loop iterations a visit, and 2
 * for the lanes of a group not walking in step. Paths that go beyond are saved and finished
 * by the next dispatch (glsl/kernels/path.comp), so the number is a matter of speed only. */
uint32_t path_samples(const renderer *r)
{
    /* GPUs: 16, which kept the lanes busy there too, and keeps one dispatch of a large
     * image short enough for a display watchdog. */
    if (!loop_capped(r->g))
        return GN_PATH_SAMPLES / 2;
    double per_path = 16.0 * (r->tree.sah_cost > 1 ? r->tree.sah_cost : 1) * 3 * 2;
    double n = floor(30000.0 / per_path);
    return n < 1 ? 1u : n > GN_PATH_SAMPLES ? GN_PATH_SAMPLES : (uint32_t)n;
}


/* The per-ray walk budget. llvmpipe ends an invocation's loops after 65,535 iterations in
 * total, and a walk's node visits and triangle tests are loop iterations; so on lavapipe a
 * ray gets a share of that which leaves room for its shadow rays. Real GPUs have no such cap. */
uint32_t traversal_budget(const gpu *g, uint32_t rays_per_invocation)
{
    if (!loop_capped(g))
        return 1u << 30;
    /* A node visit costs at most GN_WALK_VISIT_PASSES iterations. The count is shared by
     * the 8 invocations of a SIMD group, so this keeps typical work well under the cap, not
     * every case; a walk the cap stops says so (glsl/lib/bvh.glsl) rather than lie. */
    return 60000u / (rays_per_invocation * GN_WALK_VISIT_PASSES);
}


/* Whether `count` texels fit one texel buffer (maxTexelBufferElements); an error naming
 * the scene, the buffer and the numbers when not. */
static bool texels_fit(const renderer *r, const char *what, uint64_t count)
{
    const char *name;
    uint32_t limit = gpu_max_texels(r->g, &name);
    if (count <= limit)
        return true;
    util_error("%s: %s need %llu texels, more than the %u of one texel buffer on this device "
               "(%s)", r->sc->path, what, (unsigned long long)count, limit, name);
    return false;
}

/* Texels of the sheen's albedo table (brdf_sheen_table) at the head of the texel buffer,
 * where a material has layers (glsl/kernels/path.comp reads it from there); 0 elsewhere, so other
 * scenes keep their buffer as it was. */
uint32_t sheen_prefix(const renderer *r)
{
    return r->material_features & GN_FEAT_LAYERS ? BRDF_SHEEN_TABLE_SIZE : 0;
}

/* The scene's buffers against the device's limits, before any is made. */
bool scene_fits(renderer *r)
{
    const scene *sc = r->sc;
    uint64_t texels = 1 + sheen_prefix(r); /* the texel buffer's trailing zero */
    uint32_t largest = 0;
    for (uint32_t i = 0; i < sc->num_images; i++) {
        texels += (uint64_t)sc->images[i].width * sc->images[i].height;
        if ((uint64_t)sc->images[i].width * sc->images[i].height >
            (uint64_t)sc->images[largest].width * sc->images[largest].height)
            largest = i;
    }
    const char *name;
    const uint32_t limit = gpu_max_texels(r->g, &name);
    if (texels > limit) {
        util_error("%s: the %u texture image(s) hold %llu texels (the largest, image %u, is %ux%u), "
                   "more than the %u of one texel buffer on this device (%s)", sc->path,
                   sc->num_images, (unsigned long long)texels, largest, sc->images[largest].width,
                   sc->images[largest].height, limit, name);
        return false;
    }
    /* RGBA32UI texels: 16 bytes each */
    return texels_fit(r, "the BVH nodes", (uint64_t)r->tree.num_nodes * sizeof(GnBvhNode) / 16) &&
           texels_fit(r, "the BVH triangles", (uint64_t)r->tree.num_pairs * sizeof(GnTriPair) / 16) &&
           texels_fit(r, "the triangles' shading data", (uint64_t)r->tree.num_slots) &&
           texels_fit(r, "the vertices", (uint64_t)sc->num_vertices * sizeof(GnVertex) / 16) &&
           texels_fit(r, "the materials", (uint64_t)sc->num_materials * sizeof(GnMaterial) / 16) &&
           texels_fit(r, "the texture table", (uint64_t)sc->num_textures + 1) &&
           texels_fit(r, "the light table", (uint64_t)r->tree.num_slots + sc->num_lights + 1);
}

/* The walk's stack in registers for trees of at most GN_WALK_REGS_MAX levels (a walk puts
 * off at most one node per level), else in memory (0); GONIO_WALK_ARRAY=1 forces memory, so
 * that tests/regress/path.sh can check that both give the same pixels. */
uint32_t walk_regs(const renderer *r)
{
    const char *array = getenv("GONIO_WALK_ARRAY");
    if (array && !strcmp(array, "1"))
        return 0;
    return r->tree.depth <= GN_WALK_REGS_MAX ? r->tree.depth : 0;
}

/* Words a pixel of the path kernel's saved state (glsl/kernels/path.comp: path_save) takes under a
 * loop cap, 0 without one: the path, and the walk's stack, which holds at most one entry a
 * tree level (plus the sentinel). */
uint32_t state_stride(const renderer *r, uint32_t mode)
{
    uint32_t regs = walk_regs(r), stack = r->tree.depth + 2 < GN_WALK_STACK ? r->tree.depth + 2 : GN_WALK_STACK;
    if (mode != GN_MODE_PATH || !loop_capped(r->g))
        return 0;
    return GN_PATH_STATE_WORDS + (regs ? regs : stack);
}

static uint32_t log2_up(uint32_t n)
{
    uint32_t k = 0;
    while (k < 32 && (1ull << k) < n)
        k++;
    return k;
}

/* The path kernel's loop cap (glsl/kernels/path.comp, glsl/lib/bvh.glsl: LOOP_CAP) on llvmpipe, and what
 * the kernel needs for it: the loop passes one path vertex may cost besides its walks'
 * counted ones (frame->loop_overhead: the binary searches of the light table and of the
 * environment map, each loop's final test, the walks' loops reached with no lane left in
 * them), and the words of a saved path. The cap leaves room under llvmpipe's 65,535 for two
 * more vertices once the walks stop and for saving and loading a path with its stack.
 * GONIO_LOOP_CAP=N lowers it (tests: paths interrupted and resumed many times). */
/* The most loop_setup's overhead can be (log2_up is at most 32): the fixed cap leaves room
 * for it. */
#define PATH_OVERHEAD_MAX (32u + (32u + 2) + (32u + 32u + 4))
void loop_setup(renderer *r, GnFrame *frame)
{
    const char *forced = getenv("GONIO_LOOP_CAP");
    uint32_t overhead = 32 + (frame->num_emitters > 1 ? log2_up(frame->num_emitters) + 2 : 0) +
                        (frame->flags & GN_FRAME_ENV_MAP ? log2_up(frame->env_width) + log2_up(frame->env_height) + 4 : 0);
    frame->loop_overhead = overhead;
    frame->state_stride = r->state_stride = state_stride(r, GN_MODE_PATH);
    /* One value for every render of the process, so the cached kernel stays valid. */
    r->loop_cap = r->state_stride ? GN_LLVMPIPE_LOOP_LIMIT - 4096u - 4 * PATH_OVERHEAD_MAX : 0;
    if (r->loop_cap && forced && atol(forced) > 0 && (uint32_t)atol(forced) < r->loop_cap) {
        /* each lane's share (of up to 8) at least two vertices' overhead and then a node
         * visit or a leaf: progress */
        uint32_t least = 8 * (2 * PATH_OVERHEAD_MAX + 64);
        r->loop_cap = (uint32_t)atol(forced) > least ? (uint32_t)atol(forced) : least;
    }
}
