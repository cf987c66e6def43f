/* render_limits.c: what the device allows and how a render keeps within it
 * (render_limits.h). */
#include "render_limits.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"


bool render_loop_capped(const gpu *g)
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
uint32_t render_path_samples(const gpu *g, const render_geometry *geo)
{
    /* GPUs: 16, which kept the lanes busy there too, and keeps one dispatch of a large
     * image short enough for a display watchdog. */
    if (!render_loop_capped(g))
        return GN_PATH_SAMPLES / 2;
    double sah = geo->world.sah_cost; /* (two levels: the top tree's and the costliest mesh's) */
    for (uint32_t m = 0; geo->two_levels && m < geo->num_meshes; m++)
        sah = fmax(sah, geo->top.tree.sah_cost + geo->meshes[m].sah_cost);
    double per_path = 16.0 * (sah > 1 ? sah : 1) * 3 * 2;
    double n = floor(30000.0 / per_path);
    return n < 1 ? 1u : n > GN_PATH_SAMPLES ? GN_PATH_SAMPLES : (uint32_t)n;
}


/* The per-ray walk budget. llvmpipe ends an invocation's loops after 65,535 iterations in
 * total, and a walk's node visits and triangle tests are loop iterations; so on lavapipe a
 * ray gets a share of that which leaves room for its shadow rays. Real GPUs have no such cap. */
uint32_t render_traversal_budget(const gpu *g, uint32_t rays_per_invocation)
{
    if (!render_loop_capped(g))
        return 1u << 30;
    /* A node visit costs at most GN_WALK_VISIT_PASSES iterations. The count is shared by
     * the 8 invocations of a SIMD group, so this keeps typical work well under the cap, not
     * every case; a walk the cap stops says so (glsl/lib/bvh.glsl) rather than lie. */
    return 60000u / (rays_per_invocation * GN_WALK_VISIT_PASSES);
}


/* Whether `count` texels fit one texel buffer (maxTexelBufferElements); an error naming
 * the scene, the buffer and the numbers when not. */
static bool texels_fit(const gpu *g, const scene *sc, const char *what, uint64_t count)
{
    const char *name;
    uint32_t limit = gpu_max_texels(g, &name);
    if (count <= limit)
        return true;
    util_error("%s: %s need %llu texels, more than the %u of one texel buffer on this device "
               "(%s)", sc->path, what, (unsigned long long)count, limit, name);
    return false;
}

bool render_scene_fits(const gpu *g, const scene *sc, const render_geometry *geo, uint32_t sheen_texels,
                       uint64_t light_room)
{
    uint64_t texels = 1 + (uint64_t)sheen_texels; /* the texel buffer's trailing zero */
    uint32_t largest = 0;
    for (uint32_t i = 0; i < sc->num_images; i++) {
        texels += (uint64_t)sc->images[i].width * sc->images[i].height;
        if ((uint64_t)sc->images[i].width * sc->images[i].height >
            (uint64_t)sc->images[largest].width * sc->images[largest].height)
            largest = i;
    }
    const char *name;
    const uint32_t limit = gpu_max_texels(g, &name);
    if (texels > limit) {
        util_error("%s: the %u texture image(s) hold %llu texels (the largest, image %u, is %ux%u), "
                   "more than the %u of one texel buffer on this device (%s)", sc->path,
                   sc->num_images, (unsigned long long)texels, largest, sc->images[largest].width,
                   sc->images[largest].height, limit, name);
        return false;
    }
    /* RGBA32UI texels: 16 bytes each (the light table: with instances, twice) */
    return texels_fit(g, sc, "the BVH nodes", (uint64_t)geo->num_nodes * sizeof(GnBvhNode) / 16) &&
           texels_fit(g, sc, "the BVH triangles", (uint64_t)geo->num_pairs * sizeof(GnTriPair) / 16) &&
           texels_fit(g, sc, "the triangles' shading data", (uint64_t)geo->num_slots) &&
           texels_fit(g, sc, "the vertices", (uint64_t)geo->num_vertices * sizeof(GnVertex) / 16) &&
           texels_fit(g, sc, "the materials", (uint64_t)sc->num_materials * sizeof(GnMaterial) / 16) &&
           texels_fit(g, sc, "the texture table", (uint64_t)sc->num_textures + 1) &&
           texels_fit(g, sc, "the instances", (uint64_t)geo->top.num_instances * sizeof(GnInstance) / 16) &&
           texels_fit(g, sc, "the light table", (light_room + sc->num_lights + 1) * (geo->two_levels ? 2 : 1));
}

/* The walk's stack in registers for trees of at most GN_WALK_REGS_MAX levels (a walk puts
 * off at most one node per level), else in memory (0); GONIO_WALK_ARRAY=1 forces memory, so
 * that tests/regress/path.sh can check that both give the same pixels. */
uint32_t render_walk_regs(const render_geometry *geo)
{
    const char *array = getenv("GONIO_WALK_ARRAY");
    if (array && !strcmp(array, "1"))
        return 0;
    return geo->depth <= GN_WALK_REGS_MAX ? geo->depth : 0;
}

/* Words a pixel of the path kernel's saved state (glsl/kernels/path.comp: path_save) takes under a
 * loop cap, 0 without one: the path, and the walk's stack, which holds at most one entry a
 * tree level (plus the sentinel). */
uint32_t render_state_stride(const gpu *g, const render_geometry *geo)
{
    uint32_t regs = render_walk_regs(geo), stack = geo->depth + 2 < GN_WALK_STACK ? geo->depth + 2 : GN_WALK_STACK;
    if (!render_loop_capped(g))
        return 0;
    /* (with instances, two words more: the hit's instance and the walk's, path_save) */
    return GN_PATH_STATE_WORDS + (regs ? regs : stack) + (geo->two_levels ? 2 : 0);
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
uint32_t render_loop_setup(uint32_t state_stride, GnFrame *frame)
{
    const char *forced = getenv("GONIO_LOOP_CAP");
    uint32_t overhead = 32 + (frame->num_emitters > 1 ? log2_up(frame->num_emitters) + 2 : 0) +
                        (frame->flags & GN_FRAME_ENV_MAP ? log2_up(frame->env_width) + log2_up(frame->env_height) + 4 : 0);
    frame->loop_overhead = overhead;
    frame->state_stride = state_stride;
    /* One value for every render of the process, so the cached kernel stays valid. */
    uint32_t cap = state_stride ? GN_LLVMPIPE_LOOP_LIMIT - 4096u - 4 * PATH_OVERHEAD_MAX : 0;
    if (cap && forced && atol(forced) > 0 && (uint32_t)atol(forced) < cap) {
        /* each lane's share (of up to 8) at least two vertices' overhead and then a node
         * visit or a leaf: progress */
        uint32_t least = 8 * (2 * PATH_OVERHEAD_MAX + 64);
        cap = (uint32_t)atol(forced) > least ? (uint32_t)atol(forced) : least;
    }
    return cap;
}
