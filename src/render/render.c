/* render.c: scene upload, the progressive pass loop, readback to an image. */
#include "render.h"
#include <assert.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "brdf.h"
#include "local.h" /* spv_local: glsl/kernels/local.comp compiled by the build */
#include "path.h"  /* spv_path: glsl/kernels/path.comp */
#include "vertex.h" /* spv_vertex: glsl/kernels/vertex.comp */
#include "util.h"

/* ---- the registry of modes and kernels ---------------------------------------------------- */

#define MODE_ENTRY(id, value, kernel, flags, name, help) [value] = {name, help, kernel, flags},
const render_mode_info render_modes[GN_MODE_COUNT] = {GN_MODES(MODE_ENTRY)};
#undef MODE_ENTRY

/* The kernels the modes name. specialised: the GN_FEAT_* the kernel is built for as the
 * scene needs them (the others compiled in); the path kernel is specialised on all, the
 * local one only on what its lookups test per pixel (surfaces cut away: glsl/lib/bvh.glsl;
 * texture transforms and TEXCOORD_1: glsl/lib/scene.glsl). batched: it takes up to
 * renderer.path_samples samples a dispatch and is resumed past llvmpipe's loop cap (the
 * GN_SPEC_LOOP_CAP constant, renderer_finish); otherwise one sample a dispatch. */
typedef struct render_kernel {
    const char *name;
    const uint32_t *code;
    size_t code_size;
    uint32_t specialised;
    bool batched;
} render_kernel;

static const render_kernel kernels[] = {
    [GN_KERNEL_PATH] = {"path", spv_path, sizeof spv_path, GN_FEAT_ALL, true},
    [GN_KERNEL_LOCAL] = {"local", spv_local, sizeof spv_local, GN_FEAT_ALPHA | GN_FEAT_TEX_TRANSFORM | GN_FEAT_UV1,
                         false},
};

static const render_kernel *mode_kernel(uint32_t mode) { return &kernels[render_modes[mode].kernel]; }

int render_mode_from_name(const char *name)
{
    for (int i = 0; i < (int)GN_MODE_COUNT; i++)
        if (strcmp(name, render_modes[i].name) == 0)
            return i;
    return -1;
}

const char *render_mode_name(uint32_t mode) { return mode < GN_MODE_COUNT ? render_modes[mode].name : "?"; }

const char *render_mode_list(void)
{
    static char list[256];
    if (!list[0])
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", render_modes[i].name);
    return list;
}

const char *render_mode_help(void)
{
    static char help[2048];
    if (!help[0])
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            snprintf(help + strlen(help), sizeof help - strlen(help), "%s%-8s %s", i ? "\n" : "",
                     render_modes[i].name, render_modes[i].help);
    return help;
}

/* Emissive geometry as lights for the local modes when a scene has no punctual light (the
 * Cornell box): one light per emissive material at the power-weighted centroid. A flat
 * emitter of area A and radiance L has radiant intensity L A cos(theta), a GN_LIGHT_COSINE;
 * one whose normals disagree is treated as isotropic with the same power (pi L A / 4 pi). */
static void instanced_emission(const scene *sc, uint32_t m, double *area, double c[3], double an[3]);
static uint32_t emissive_lights(const scene *sc, GnLight *out, uint32_t cap)
{
    uint32_t n = 0;
    for (uint32_t m = 0; m < sc->num_materials && n < cap; m++) {
        const float *L = &sc->materials[m].emissive.x;
        double lum = (L[0] + L[1] + L[2]) / 3.0, area = 0, c[3] = {0}, an[3] = {0};
        if (lum <= 0)
            continue;
        for (uint32_t t = 0; t < sc->num_triangles; t++) {
            const float *p[3];
            double cr[3], a;
            if (sc->tri_material[t] != m)
                continue;
            for (int k = 0; k < 3; k++)
                p[k] = &sc->vertices[sc->indices[3 * t + k]].position.x;
            scene_triangle_cross(sc, t, cr);
            a = 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            area += a;
            for (int k = 0; k < 3; k++) {
                c[k] += a * (p[0][k] + p[1][k] + p[2][k]) / 3.0;
                an[k] += 0.5 * cr[k];
            }
        }
        instanced_emission(sc, m, &area, c, an);
        if (area <= 0)
            continue;
        GnLight *l = &out[n++];
        double len = sqrt(an[0] * an[0] + an[1] * an[1] + an[2] * an[2]);
        memset(l, 0, sizeof *l);
        l->position = (vec3){(float)(c[0] / area), (float)(c[1] / area), (float)(c[2] / area)};
        if (len > 0.9 * area) {
            l->type = GN_LIGHT_COSINE;
            l->direction = (vec3){(float)(an[0] / len), (float)(an[1] / len), (float)(an[2] / len)};
            l->color = (vec3){(float)(L[0] * area), (float)(L[1] * area), (float)(L[2] * area)};
        } else {
            l->type = GN_LIGHT_POINT;
            l->color = (vec3){(float)(L[0] * area / 4), (float)(L[1] * area / 4),
                              (float)(L[2] * area / 4)};
        }
        /* Lift the light off its own surface so shadow rays do not end on the emitter. */
        float off = 1e-3f * (float)sqrt(area);
        l->position.x += l->direction.x * off;
        l->position.y += l->direction.y * off;
        l->position.z += l->direction.z * off;
    }
    return n;
}

static double luminance(const float *c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* Does instanced mesh m have a triangle of material `material`? */
static bool mesh_has_material(const scene_instanced_mesh *m, uint32_t material)
{
    for (uint32_t t = 0; t < m->num_triangles; t++)
        if (m->tri_material[t] == material)
            return true;
    return false;
}

/* emissive_lights' sums over the instances' triangles of material m: area, area-weighted
 * centroid and area vector (the cross products as the corners are stored, turned by a
 * mirroring instance, whose front is the other side: GN_INSTANCE_MIRROR). */
static void instanced_emission(const scene *sc, uint32_t m, double *area, double c[3], double an[3])
{
    for (uint32_t j = 0; j < sc->num_instanced_meshes; j++) {
        const scene_instanced_mesh *im = &sc->instanced_meshes[j];
        if (!mesh_has_material(im, m))
            continue;
        for (uint32_t i = 0; i < sc->num_instances; i++) {
            const scene_instance *in = &sc->instances[i];
            const float *w = in->to_world;
            double det = w[0] * (w[5] * w[10] - w[6] * w[9]) - w[1] * (w[4] * w[10] - w[6] * w[8]) +
                         w[2] * (w[4] * w[9] - w[5] * w[8]);
            if (in->mesh != j)
                continue;
            for (uint32_t t = 0; t < im->num_triangles; t++) {
                double cr[3], p[3] = {0, 0, 0};
                if (im->tri_material[t] != m)
                    continue;
                scene_instance_triangle_cross(sc, i, t, cr);
                double a = 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
                for (int k = 0; k < 3; k++) {
                    const float *q = &im->vertices[im->indices[3 * t + k]].position.x;
                    for (int r = 0; r < 3; r++)
                        p[r] += (w[4 * r] * (double)q[0] + w[4 * r + 1] * (double)q[1] + w[4 * r + 2] * (double)q[2] +
                                 w[4 * r + 3]) / 3.0;
                }
                *area += a;
                for (int k = 0; k < 3; k++) {
                    c[k] += a * p[k];
                    an[k] += (det < 0 ? -0.5 : 0.5) * cr[k];
                }
            }
        }
    }
}

/* Squared radius of the scene's bounding sphere (1 when empty): the area through which
 * distant lights (directional, environment) reach the scene. */
static double scene_radius2(const scene *sc)
{
    double r2 = 0;
    for (int k = 0; k < 3; k++) {
        double e = 0.5 * ((double)sc->bounds_max[k] - sc->bounds_min[k]);
        r2 += e > 0 ? e * e : 0;
    }
    return r2 > 0 ? r2 : 1;
}

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
static uint32_t path_samples(const renderer *r)
{
    /* GPUs: 16, which kept the lanes busy there too, and keeps one dispatch of a large
     * image short enough for a display watchdog. */
    if (!loop_capped(r->g))
        return GN_PATH_SAMPLES / 2;
    double sah = r->geo.world.sah_cost; /* (two levels: the top tree's and the costliest mesh's) */
    for (uint32_t m = 0; r->geo.two_levels && m < r->geo.num_meshes; m++)
        sah = fmax(sah, r->geo.top.tree.sah_cost + r->geo.meshes[m].sah_cost);
    double per_path = 16.0 * (sah > 1 ? sah : 1) * 3 * 2;
    double n = floor(30000.0 / per_path);
    return n < 1 ? 1u : n > GN_PATH_SAMPLES ? GN_PATH_SAMPLES : (uint32_t)n;
}

static float clamp01(float x) { return x < 0 ? 0 : x > 1 ? 1 : x; }

/* The GN_FEAT_* that material m can need in the path kernel: the parts of the Bsdf that
 * bsdf_gltf or bsdf_from_model (glsl/lib/brdf.glsl) can build from it with a nonzero weight,
 * its textures, emission and unlit flag. Where a texture can change a value (roughness,
 * metalness) every value it can reach counts. */
static uint32_t material_features(const GnMaterial *m)
{
    uint32_t f = 0;
    bool textured = m->tex_base != GN_INVALID || m->tex_mr != GN_INVALID ||
                    m->tex_emissive != GN_INVALID || m->tex_occlusion != GN_INVALID;
    if (textured)
        f |= GN_FEAT_TEXTURES;
    if (m->tex_normal != GN_INVALID)
        f |= GN_FEAT_NORMAL_MAP | GN_FEAT_TEXTURES;
    if (m->flags & GN_MAT_UNLIT)
        f |= GN_FEAT_UNLIT;
    if (m->flags & (GN_MAT_MASK | GN_MAT_BLEND))
        f |= GN_FEAT_ALPHA;
    if (luminance(&m->emissive.x) > 0)
        f |= GN_FEAT_EMISSIVE;
    switch (m->brdf) {
    case BRDF_GLTF: {
        /* bsdf_gltf: a GGX lobe (a mirror below BRDF_ALPHA_MIN) with Schlick's F of weight
         * wd f0 + m base and F90 wd specular + m; the diffuse coupled to that layer when
         * specular > 0; glass of weight (1 - m) t. The texture scales roughness and
         * metalness by [0, 1]. */
        float metal_hi = clamp01(m->metallic), metal_lo = m->tex_mr != GN_INVALID ? 0 : metal_hi;
        float rough_hi = clamp01(m->roughness), rough_lo = m->tex_mr != GN_INVALID ? 0 : rough_hi;
        float t = clamp01(m->transmission);
        bool smooth = rough_lo * rough_lo < BRDF_ALPHA_MIN, rough = rough_hi * rough_hi >= BRDF_ALPHA_MIN;
        f |= GN_FEAT_GLTF;
        if (m->specular != 0 || metal_hi > 0) {
            f |= GN_FEAT_FRESNEL_SCHLICK | (smooth ? GN_FEAT_MIRROR : 0u) | (rough ? GN_FEAT_GGX : 0u);
            if (m->specular != 0)
                f |= GN_FEAT_COUPLED;
        }
        if (t > 0 && metal_lo < 1)
            f |= (smooth ? GN_FEAT_SMOOTH_GLASS : 0u) | (rough ? GN_FEAT_ROUGH_GLASS : 0u);
        /* KHR_materials_volume acts only where the surface transmits (glass or a diffuse
         * transmission), _dispersion only where it refracts */
        if (metal_lo < 1 && ((t > 0 && (m->volume || m->dispersion > 0)) || (m->diffuse_transmission > 0 && m->volume)))
            f |= GN_FEAT_VOLUME;
        /* bsdf_layers: a coat or a sheen (their textures only scale the factors) */
        if (m->clearcoat > 0 || m->sheen_color.x > 0 || m->sheen_color.y > 0 || m->sheen_color.z > 0) {
            f |= GN_FEAT_LAYERS;
            if (m->tex_clearcoat != GN_INVALID || m->tex_clearcoat_roughness != GN_INVALID ||
                m->tex_clearcoat_normal != GN_INVALID || m->tex_sheen_color != GN_INVALID ||
                m->tex_sheen_roughness != GN_INVALID)
                f |= GN_FEAT_TEXTURES;
        }
        /* bsdf_anisotropy: the lobe and the glass stay GGX where roughness 0 would make them
         * Dirac (the texture only scales the strength) */
        if (m->anisotropy_strength > 0) {
            f |= GN_FEAT_ANISO | (m->tex_anisotropy != GN_INVALID ? GN_FEAT_TEXTURES : 0u);
            if (m->specular != 0 || metal_hi > 0)
                f |= GN_FEAT_GGX;
            if (t > 0 && metal_lo < 1)
                f |= GN_FEAT_ROUGH_GLASS;
        }
        /* bsdf_gltf_film: an iridescent film, a diffuse transmission (textures as above) */
        if (m->iridescence > 0 || m->diffuse_transmission > 0) {
            f |= GN_FEAT_LAYERS;
            if ((m->iridescence > 0 && (m->tex_iridescence != GN_INVALID || m->tex_iridescence_thickness != GN_INVALID)) ||
                (m->diffuse_transmission > 0 && (m->tex_diffuse_transmission != GN_INVALID ||
                                                 m->tex_diffuse_transmission_color != GN_INVALID)))
                f |= GN_FEAT_TEXTURES;
        }
        break;
    }
    default: {
        /* an override model: its row of the table (glsl/lib/brdf_models.h); an id unknown to it
         * keeps every feature */
        uint32_t mf = GN_FEAT_ALL;
        for (int i = 0; i < brdf_num_models; i++)
            if (brdf_models[i].id == m->brdf)
                mf = brdf_models[i].features;
        f |= mf | GN_FEAT_MODELS;
    }
    }
    return f;
}

/* The path tracer's light table: each emissive triangle (BVH order) and punctual light with
 * a selection weight proportional to its power, flux / pi: L A per emitting side for a
 * triangle (so picking one and then a uniform point has area density lum(L) sides / total),
 * 4 I for a point light, 2 (1 - cos outer) I for a spot, E r^2 for a directional light.
 * renderer_begin adds the environment and normalises. */
/* With two levels: each mesh's emissive triangles, as GPU slots (*count: how many), listed
 * once so that placing them costs only the instances' emitters. */
static uint32_t *emissive_slots(const renderer *r, uint32_t *first, uint32_t *count)
{
    const render_geometry *geo = &r->geo;
    uint32_t n = 0;
    uint32_t *list = util_calloc(geo->num_slots + 1, sizeof *list);
    for (uint32_t m = 0; m < geo->num_meshes; m++) {
        uint32_t base = 2 * geo->top.pair_base[m];
        first[m] = n;
        for (uint32_t j = 0; j < geo->meshes[m].num_slots; j++) {
            const GnMaterial *mat = &r->sc->materials[geo->prims[base + j].material];
            if (geo->meshes[m].tri_index[j] != GN_INVALID && luminance(&mat->emissive.x) > 0 &&
                !(mat->flags & GN_MAT_UNLIT))
                list[n++] = base + j;
        }
        count[m] = n - first[m];
    }
    return list;
}

/* With instances, each instance's emissive triangles, their areas in world space (a scale
 * changes them), and in r->emitter_instance the instance of each; returns the count. */
static uint32_t instanced_emitters(renderer *r, uint32_t n)
{
    const render_geometry *geo = &r->geo;
    uint32_t *first = util_calloc(geo->num_meshes, sizeof *first), *count = util_calloc(geo->num_meshes, sizeof *count);
    uint32_t *slots = emissive_slots(r, first, count);
    for (uint32_t i = 0; i < geo->top.num_instances; i++) {
        const GnInstance *in = &geo->top.instances[i];
        for (uint32_t k = first[in->mesh]; k < first[in->mesh] + count[in->mesh]; k++) {
            uint32_t j = slots[k];
            const GnPrim *pr = &geo->prims[j];
            const GnMaterial *m = &r->sc->materials[pr->material];
            double lum = luminance(&m->emissive.x), p[3][3];
            const uint32_t v[3] = {pr->i0, pr->i1, pr->i2};
            for (int c3 = 0; c3 < 3; c3++) {
                const float *q = &geo->vertices[v[c3]].position.x;
                for (int c = 0; c < 3; c++) {
                    const float *w = &in->to_world[c].x;
                    p[c3][c] = w[0] * (double)q[0] + w[1] * (double)q[1] + w[2] * (double)q[2] + w[3];
                }
            }
            double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
            double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
            double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
            double area = 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            if (!(area > 0))
                continue;
            r->emitter_table[n] = (GnEmitter){j, (float)area, 0, 0};
            r->emitter_instance[n] = i;
            r->emitter_weight[n++] = lum * area * (m->flags & GN_MAT_DOUBLE_SIDED ? 2 : 1);
        }
    }
    free(slots);
    free(first);
    free(count);
    return n;
}

/* The light table's triangle entries at most: each instance's emissive triangles (counted
 * without their areas), or the scene's slots. */
static uint64_t emitter_room(const renderer *r)
{
    if (!r->geo.two_levels)
        return r->geo.num_slots;
    uint64_t n = 0;
    uint32_t *first = util_calloc(r->geo.num_meshes, sizeof *first), *count = util_calloc(r->geo.num_meshes, sizeof *count);
    free(emissive_slots(r, first, count));
    for (uint32_t i = 0; i < r->geo.top.num_instances; i++)
        n += count[r->geo.top.instances[i].mesh];
    free(first);
    free(count);
    return n;
}

static void build_emitters(renderer *r, const GnPrim *prims)
{
    const scene *sc = r->sc;
    uint32_t cap = (uint32_t)emitter_room(r) + sc->num_lights + 1, n = 0;
    r->emitter_table = util_calloc(cap, sizeof *r->emitter_table);
    r->emitter_weight = util_calloc(cap, sizeof *r->emitter_weight);
    r->emitter_instance = r->geo.two_levels ? util_calloc(cap, sizeof *r->emitter_instance) : NULL;
    if (r->geo.two_levels)
        n = instanced_emitters(r, n);
    for (uint32_t i = 0; i < r->geo.num_slots && !r->geo.two_levels; i++) {
        if (r->geo.world.tri_index[i] == GN_INVALID) /* the missing B of a lone triangle */
            continue;
        const GnMaterial *m = &sc->materials[prims[i].material];
        const vec3 *p0 = &sc->vertices[prims[i].i0].position, *p1 = &sc->vertices[prims[i].i1].position,
                   *p2 = &sc->vertices[prims[i].i2].position;
        double e1[3] = {p1->x - p0->x, p1->y - p0->y, p1->z - p0->z};
        double e2[3] = {p2->x - p0->x, p2->y - p0->y, p2->z - p0->z};
        double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double area = 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double lum = luminance(&m->emissive.x);
        if (lum <= 0 || !(area > 0) || (m->flags & GN_MAT_UNLIT))
            continue;
        r->emitter_table[n] = (GnEmitter){i, (float)area, 0, 0};
        r->emitter_weight[n++] = lum * area * (m->flags & GN_MAT_DOUBLE_SIDED ? 2 : 1);
    }
    r->num_area_emitters = n;
    for (uint32_t i = 0; i < sc->num_lights; i++) {
        const GnLight *l = &sc->lights[i];
        double w = luminance(&l->color.x);
        w *= l->type == GN_LIGHT_POINT ? 4 : l->type == GN_LIGHT_SPOT ? 2 * (1 - l->outer_cos)
                                                                         : scene_radius2(sc);
        if (w <= 0)
            continue;
        if (r->emitter_instance)
            r->emitter_instance[n] = GN_INVALID;
        r->emitter_table[n] = (GnEmitter){GN_EMITTER_LIGHT | i, 0, 0, 0};
        r->emitter_weight[n++] = w;
    }
    r->num_emitters = n;
    r->emitter_cap = cap;
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
static uint32_t sheen_prefix(const renderer *r)
{
    return r->material_features & GN_FEAT_LAYERS ? BRDF_SHEEN_TABLE_SIZE : 0;
}

/* The scene's buffers against the device's limits, before any is made. */
static bool scene_fits(renderer *r)
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
    /* RGBA32UI texels: 16 bytes each (the light table: with instances, twice) */
    const render_geometry *geo = &r->geo;
    return texels_fit(r, "the BVH nodes", (uint64_t)geo->num_nodes * sizeof(GnBvhNode) / 16) &&
           texels_fit(r, "the BVH triangles", (uint64_t)geo->num_pairs * sizeof(GnTriPair) / 16) &&
           texels_fit(r, "the triangles' shading data", (uint64_t)geo->num_slots) &&
           texels_fit(r, "the vertices", (uint64_t)geo->num_vertices * sizeof(GnVertex) / 16) &&
           texels_fit(r, "the materials", (uint64_t)sc->num_materials * sizeof(GnMaterial) / 16) &&
           texels_fit(r, "the texture table", (uint64_t)sc->num_textures + 1) &&
           texels_fit(r, "the instances", (uint64_t)geo->top.num_instances * sizeof(GnInstance) / 16) &&
           texels_fit(r, "the light table", (emitter_room(r) + sc->num_lights + 1) * (geo->two_levels ? 2 : 1));
}

/* Gouraud's colours with instances: each instance's copy of its mesh's vertices, the
 * instances one after the other (GnInstance.vcolor_offset: where its copy starts, less its
 * mesh's first vertex). Sets the offsets; returns the count. */
static uint64_t gouraud_vertices(renderer *r)
{
    uint64_t n = 0;
    for (uint32_t i = 0; i < r->geo.top.num_instances; i++) {
        GnInstance *in = &r->geo.top.instances[i];
        in->vcolor_offset = (uint32_t)n - r->geo.vertex_base[in->mesh]; /* (uint arithmetic) */
        n += r->geo.mesh_vertices[in->mesh];
    }
    return n;
}

/* The vertex pass's inputs with instances: [2j].w each copy's material (from its mesh's
 * triangles), [2j + 1].w its instance (glsl/kernels/vertex.comp). */
static void gouraud_materials(renderer *r, vec4 *vcolor)
{
    const render_geometry *geo = &r->geo;
    for (uint32_t i = 0; i < geo->top.num_instances; i++) {
        const GnInstance *in = &geo->top.instances[i];
        uint32_t first = in->prim_base, slots = geo->meshes[in->mesh].num_slots;
        for (uint32_t j = first; j < first + slots; j++) {
            uint32_t mesh;
            if (render_geometry_triangle(geo, j, &mesh) == GN_INVALID)
                continue;
            const GnPrim *pr = &geo->prims[j];
            const uint32_t v[3] = {pr->i0, pr->i1, pr->i2};
            for (int k = 0; k < 3; k++)
                memcpy(&vcolor[2 * (size_t)(v[k] + in->vcolor_offset)].w, &pr->material, 4);
        }
        for (uint32_t k = 0; k < geo->mesh_vertices[in->mesh]; k++)
            memcpy(&vcolor[2 * ((size_t)geo->vertex_base[in->mesh] + in->vcolor_offset + k) + 1].w, &i, 4);
    }
}

/* The lights r uploads: the scene's punctual ones, or stand-ins for its emissive meshes in
 * the local modes (emissive_lights); sets r->num_lights. */
static GnLight *scene_lights(renderer *r)
{
    const scene *sc = r->sc;
    GnLight *lights = util_calloc(sc->num_lights + 16, sizeof *lights);
    if (sc->num_lights)
        memcpy(lights, sc->lights, sizeof *lights * sc->num_lights);
    r->num_lights = sc->num_lights ? sc->num_lights : emissive_lights(sc, lights, 16);
    return lights;
}

/* With instances, the light table's entries' instances, after the table (GnFrame.emitter_instances). */
static void upload_emitter_instances(renderer *r)
{
    if (!r->geo.two_levels)
        return;
    uvec4 *inst = util_calloc(r->emitter_cap, sizeof *inst);
    for (uint32_t i = 0; i < r->num_emitters; i++)
        inst[i].x = r->emitter_instance[i];
    gpu_buffer_upload(r->g, &r->emitters, inst, sizeof *inst * r->emitter_cap, sizeof(GnEmitter) * r->emitter_cap);
    free(inst);
}

bool renderer_create(renderer *r, gpu *g, const scene *sc)
{
    double t0 = util_now();
    GnPrim *prims;
    GnTexture *tex;
    uint32_t *texels, total_texels = 0, *image_offset; /* the total fits: scene_fits */
    vec4 *vcolor;
    GnLight *lights;

    memset(r, 0, sizeof *r);
    r->g = g;
    r->sc = sc;
    if (!render_geometry_build(&r->geo, sc)) {
        r->failed = true;
        return false;
    }
    for (uint32_t i = 0; i < sc->num_materials; i++)
        r->material_features |= material_features(&sc->materials[i]);
    if (!scene_fits(r)) {
        r->failed = true;
        return false;
    }
    if (sc->vertex_colors)
        r->material_features |= GN_FEAT_VERTEX_COLOR;
    for (uint32_t i = 0; i < sc->num_textures; i++) {
        const float *t = sc->textures[i].transform;
        if (t[0] != 1 || t[1] != 0 || t[2] != 0 || t[3] != 0 || t[4] != 1 || t[5] != 0)
            r->material_features |= GN_FEAT_TEX_TRANSFORM;
        if (sc->textures[i].flags & GN_TEX_UV1)
            r->material_features |= GN_FEAT_UV1;
    }
    r->path_samples = path_samples(r);
    r->path_features = r->material_features;

    prims = r->geo.prims; /* (render_geometry.c: BVH order, corners in the walk's order) */

    image_offset = util_calloc(sc->num_images + 1, sizeof *image_offset);
    total_texels = sheen_prefix(r);
    for (uint32_t i = 0; i < sc->num_images; i++) {
        image_offset[i] = total_texels;
        total_texels += sc->images[i].width * sc->images[i].height;
    }
    texels = util_malloc(sizeof *texels * (total_texels + 1));
    texels[total_texels] = 0; /* the buffer is never empty */
    memcpy(texels, brdf_sheen_table, sizeof *texels * sheen_prefix(r));
    for (uint32_t i = 0; i < sc->num_images; i++)
        memcpy(texels + image_offset[i], sc->images[i].rgba8,
               (size_t)sc->images[i].width * sc->images[i].height * 4);
    tex = util_calloc(sc->num_textures + 1, sizeof *tex);
    for (uint32_t i = 0; i < sc->num_textures; i++) {
        const scene_image *im = &sc->images[sc->textures[i].image];
        const float *t = sc->textures[i].transform;
        tex[i] = (GnTexture){image_offset[sc->textures[i].image], im->width, im->height,
                             sc->textures[i].flags, {t[0], t[1], t[2]}, 0, {t[3], t[4], t[5]}, 0};
    }

    lights = scene_lights(r);

    gpu_buffer_create(g, &r->frame, sizeof(GnFrame), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                      GPU_MEMORY_HOST);
    gpu_buffer_create_texels(g, &r->nodes, r->geo.nodes, sizeof(GnBvhNode) * r->geo.num_nodes);
    gpu_buffer_create_texels(g, &r->tris, r->geo.pairs, sizeof(GnTriPair) * r->geo.num_pairs);
    gpu_buffer_create_texels(g, &r->prims, prims, sizeof(GnPrim) * r->geo.num_slots);
    gpu_buffer_create_texels(g, &r->vertices, r->geo.vertices, sizeof(GnVertex) * r->geo.num_vertices);
    gpu_buffer_create_texels(g, &r->materials, sc->materials, sizeof(GnMaterial) * sc->num_materials);
    gpu_buffer_create_storage(g, &r->lights, lights, sizeof(GnLight) * r->num_lights);
    gpu_buffer_create_texels_as(g, &r->texels, texels, sizeof(uint32_t) * (total_texels + 1),
                                VK_FORMAT_R32_UINT);
    gpu_buffer_create_texels(g, &r->textures, tex, sizeof(GnTexture) * (sc->num_textures + 1));
    build_emitters(r, prims);
    if (r->geo.two_levels) { /* the table, then each entry's instance (GnFrame.emitter_instances) */
        gpu_buffer_create_texels(g, &r->emitters, NULL, 2 * sizeof(GnEmitter) * r->emitter_cap);
        upload_emitter_instances(r);
    } else {
        gpu_buffer_create_texels(g, &r->emitters, NULL, sizeof(GnEmitter) * (r->num_emitters + 1));
    }
    gpu_buffer_create_texels_as(g, &r->env, NULL, 16, VK_FORMAT_R32_UINT);
    /* Gouraud colours, two sides per vertex; the material of each vertex rides in the bits of
     * the first one's w for glsl/kernels/vertex.comp (a vertex belongs to one glTF primitive).
     * With instances each has its own copy of its mesh's vertices (gouraud_vertices). */
    uint64_t nv = r->geo.two_levels ? gouraud_vertices(r) : sc->num_vertices;
    r->vcolor_bytes = 2 * sizeof *vcolor * (VkDeviceSize)nv;
    r->vcolor_count = (uint32_t)(nv < UINT32_MAX ? nv : UINT32_MAX);
    if (r->vcolor_bytes <= gpu_storage_limit(g, NULL)) {
        vcolor = util_calloc(2 * (size_t)nv, sizeof *vcolor);
        if (r->geo.two_levels)
            gouraud_materials(r, vcolor);
        for (uint32_t t = 0; t < sc->num_triangles && !r->geo.two_levels; t++)
            for (int k = 0; k < 3; k++)
                memcpy(&vcolor[2 * (size_t)sc->indices[3 * t + k]].w, &sc->tri_material[t], 4);
        gpu_buffer_create_storage(g, &r->vcolor, vcolor, r->vcolor_bytes);
        free(vcolor);
    } else { /* too many vertices for Gouraud here (light_vertices says so); the rest renders */
        gpu_buffer_create_storage(g, &r->vcolor, NULL, 16);
    }
    gpu_buffer_create(g, &r->status, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    if (r->geo.two_levels)
        gpu_buffer_create_texels(g, &r->instances, r->geo.top.instances, sizeof(GnInstance) * r->geo.top.num_instances);
    else
        gpu_buffer_create_texels(g, &r->instances, NULL, 16);
    free(image_offset);
    free(texels);
    free(tex);
    free(lights);
    r->setup_seconds = util_now() - t0;
    return true;
}

bool renderer_update(renderer *r, const scene *sc)
{
    double t0 = util_now();
    if (r->failed)
        return false;
    r->sc = sc;
    if (!render_geometry_update(&r->geo, sc)) {
        r->failed = true;
        return false;
    }
    if (r->geo.two_levels) { /* the top tree's nodes lead the array; the instances' transforms */
        gpu_buffer_upload(r->g, &r->nodes, r->geo.nodes, sizeof(GnBvhNode) * r->geo.top.tree.num_nodes, 0);
        gpu_buffer_upload(r->g, &r->instances, r->geo.top.instances, sizeof(GnInstance) * r->geo.top.num_instances, 0);
    }
    uint32_t before = r->num_lights;
    GnLight *lights = scene_lights(r);
    if (r->num_lights <= before) {
        gpu_buffer_upload(r->g, &r->lights, lights, sizeof(GnLight) * r->num_lights, 0);
    } else { /* (more of the stand-ins for emissive meshes than before: a new buffer) */
        gpu_buffer_destroy(r->g, &r->lights);
        gpu_buffer_create_storage(r->g, &r->lights, lights, sizeof(GnLight) * r->num_lights);
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++) /* their descriptor sets name the old buffer */
            gpu_pipeline_destroy(r->g, &r->pipelines[i]);
        gpu_pipeline_destroy(r->g, &r->vertex_pass);
    }
    free(lights);
    free(r->emitter_table);
    free(r->emitter_weight);
    free(r->emitter_instance);
    build_emitters(r, r->geo.prims); /* (the same room: the same triangles and lights) */
    upload_emitter_instances(r);
    r->env_source = NULL; /* the environment's weight follows the scene's bounds */
    r->setup_seconds = util_now() - t0;
    return true;
}

/* The host copies of a render in bands (renderer_render). */
static void free_bands(renderer *r)
{
    free(r->band_accum);
    free(r->band_aov);
    free(r->band_squares);
    r->band_accum = r->band_aov = r->band_squares = NULL;
}

void renderer_destroy(renderer *r)
{
    gpu_buffer *bufs[] = {&r->frame, &r->nodes, &r->tris, &r->prims, &r->vertices,
                          &r->materials, &r->lights, &r->texels, &r->textures, &r->emitters,
                          &r->vcolor, &r->status, &r->accum, &r->aov,
                          &r->squares, &r->env, &r->pstate, &r->instances};
    if (r->g) {
        for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++)
            gpu_buffer_destroy(r->g, bufs[i]);
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            gpu_pipeline_destroy(r->g, &r->pipelines[i]);
        gpu_pipeline_destroy(r->g, &r->vertex_pass);
    }
    render_geometry_destroy(&r->geo);
    free_bands(r);
    free(r->emitter_table);
    free(r->emitter_weight);
    free(r->emitter_instance);
    memset(r, 0, sizeof *r);
}

static vec3 v3(const float *p) { return (vec3){p[0], p[1], p[2]}; }

bool renderer_camera(const renderer *r, const render_settings *s, GnCamera *out)
{
    scene_camera c;
    float aspect = (float)s->width / (float)s->height;
    if (s->camera_override) {
        *out = *s->camera_override;
        out->aspect = aspect;
        return true;
    }
    if (s->view) {
        c = *s->view;
    } else if (s->camera >= 0) {
        if ((uint32_t)s->camera >= r->sc->num_cameras) {
            util_error("%s: --camera %d: the scene has %u camera(s)", r->sc->path,
                       s->camera, r->sc->num_cameras);
            return false;
        }
        c = r->sc->cameras[s->camera];
    } else {
        scene_default_camera(r->sc, aspect, &c);
    }
    out->position = v3(c.position);
    out->right = v3(c.right);
    out->up = v3(c.up);
    out->forward = v3(c.forward);
    out->tan_half_fovy = tanf(0.5f * c.yfov);
    out->ortho_half_height = c.ortho_half_height;
    out->aspect = aspect; /* the image's: a camera's own aspect only suggests the size */
    out->znear = c.znear;
    out->zfar = c.zfar;
    return true;
}

/* The per-ray walk budget. llvmpipe ends an invocation's loops after 65,535 iterations in
 * total, and a walk's node visits and triangle tests are loop iterations; so on lavapipe a
 * ray gets a share of that which leaves room for its shadow rays. Real GPUs have no such cap. */
static uint32_t traversal_budget(const gpu *g, uint32_t rays_per_invocation)
{
    if (!loop_capped(g))
        return 1u << 30;
    /* A node visit costs at most GN_WALK_VISIT_PASSES iterations. The count is shared by
     * the 8 invocations of a SIMD group, so this keeps typical work well under the cap, not
     * every case; a walk the cap stops says so (glsl/lib/bvh.glsl) rather than lie. */
    return 60000u / (rays_per_invocation * GN_WALK_VISIT_PASSES);
}

/* Progress on stderr. On a terminal, a bar redrawn in place; otherwise (a log) plain lines,
 * one when a render has run for a second and one at each further tenth of the work, so
 * short renders print none. With a time limit the work is the time, not the spp. */
typedef struct progress {
    bool tty;
    int tenth;      /* plain lines: the last tenth printed, -1 = none yet */
    double last;    /* terminal: when the bar was last drawn */
} progress;

static double progress_fraction(const render_settings *s, int done, double elapsed)
{
    double f = s->time_limit > 0 ? elapsed / s->time_limit : (double)done / s->spp;
    return f < 1 ? f : 1;
}

/* One report: the bar or a line; `end` replaces the ETA ("done", "interrupted"). */
static void progress_show(const render_settings *s, const progress *p, int done, double elapsed,
                          const char *end)
{
    const double pixels = (double)s->width * s->height, rate = elapsed > 0 ? done / elapsed : 0;
    const double frac = progress_fraction(s, done, elapsed);
    const int width = 30, fill = (int)(frac * width);
    char spp[48], eta[48];
    if (s->time_limit > 0)
        snprintf(spp, sizeof spp, "%d spp", done);
    else
        snprintf(spp, sizeof spp, "%d/%d spp", done, s->spp);
    if (end)
        snprintf(eta, sizeof eta, "%s", end);
    else if (s->time_limit > 0)
        snprintf(eta, sizeof eta, "ETA %.1f s", s->time_limit > elapsed ? s->time_limit - elapsed : 0);
    else
        snprintf(eta, sizeof eta, "ETA %.1f s", rate > 0 ? (s->spp - done) / rate : 0);
    if (p->tty)
        fprintf(stderr, "\r[%.*s%*s] ", fill, "##############################", width - fill, "");
    else
        fputs("gonio: ", stderr);
    /* Camera rays per second: whole paths in path mode, as in the summary line. */
    fprintf(stderr, "%3d%%  %s  %.1f spp/s  %.2f %s  %.1f s  %s%s", (int)(frac * 100), spp, rate,
            rate * pixels * 1e-6, s->mode == GN_MODE_PATH ? "M paths/s" : "Mrays/s", elapsed, eta,
            p->tty ? "\x1b[K" : "\n");
    fflush(stderr);
}

/* After a batch: the bar at most ten times a second, a plain line when one is due. */
static void progress_update(const render_settings *s, progress *p, int done, double elapsed)
{
    double frac = progress_fraction(s, done, elapsed);
    int tenth = (int)(frac * 10);
    if (p->tty && elapsed - p->last >= 0.1) {
        p->last = elapsed;
        progress_show(s, p, done, elapsed, NULL);
    } else if (!p->tty && elapsed >= 1 && tenth > p->tenth && frac < 1) {
        p->tenth = tenth;
        progress_show(s, p, done, elapsed, NULL);
    }
}

uint32_t renderer_bindings(const renderer *r, gpu_binding *b)
{
    const gpu_binding all[] = {
        {GN_BIND_FRAME, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->frame},
        {GN_BIND_NODES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->nodes},
        {GN_BIND_TRIS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->tris},
        {GN_BIND_PRIMS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->prims},
        {GN_BIND_VERTICES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->vertices},
        {GN_BIND_MATERIALS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->materials},
        {GN_BIND_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->lights},
        {GN_BIND_TEXELS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->texels},
        {GN_BIND_TEXTURES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->textures},
        {GN_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->accum},
        {GN_BIND_AOV, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->aov},
        {GN_BIND_VCOLOR, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->vcolor},
        {GN_BIND_EMITTERS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->emitters},
        {GN_BIND_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->status},
        {GN_BIND_SQUARES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->squares},
        {GN_BIND_ENV, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->env},
        {GN_BIND_PSTATE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->pstate},
        {GN_BIND_INSTANCES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->instances},
    };
    memcpy(b, all, sizeof all);
    return sizeof all / sizeof *all;
}

/* Gouraud's vertex pass: lights every vertex for the frame just uploaded, one dispatch per
 * side (glsl/kernels/vertex.comp), in rows of work groups when one row would have more than
 * maxComputeWorkGroupCount[0]. False (with an error) when the device cannot hold them. */
static bool light_vertices(renderer *r)
{
    VkCommandBuffer cmd;
    const uint32_t max_x = gpu_max_groups(r->g, 0), max_y = gpu_max_groups(r->g, 1);
    const uint32_t groups = (r->vcolor_count + 63) / 64;
    const uint32_t groups_x = groups < max_x ? groups : max_x;
    const uint32_t groups_y = groups_x ? (groups + groups_x - 1) / groups_x : 0;
    const char *limit;
    VkDeviceSize bytes = gpu_storage_limit(r->g, &limit);
    if (r->vcolor_bytes > bytes) {
        util_error("%s: --mode gouraud: the %u vertices' colours need %llu bytes, more than one "
                   "storage buffer may hold on this device (%s: %llu)", r->sc->path,
                   r->vcolor_count, (unsigned long long)r->vcolor_bytes, limit,
                   (unsigned long long)bytes);
        return false;
    }
    if (groups_y > max_y) {
        util_error("%s: --mode gouraud: the %u vertices need %u work groups, more than this device "
                   "dispatches (maxComputeWorkGroupCount %u x %u)", r->sc->path, r->vcolor_count,
                   groups, max_x, max_y);
        return false;
    }
    if (!r->vertex_pass.pipeline) {
        gpu_binding b[GN_BIND_COUNT];
        const uint32_t instances = r->geo.two_levels;
        const VkSpecializationMapEntry entry = {GN_SPEC_INSTANCES, 0, sizeof instances};
        const VkSpecializationInfo spec = {1, &entry, sizeof instances, &instances};
        gpu_pipeline_desc pd = {
            .name = "vertex", .code = spv_vertex, .code_size = sizeof spv_vertex,
            .local_size = {64, 1, 1}, .push_size = sizeof(GnPush), .specialization = &spec,
            .bindings = b, .num_bindings = renderer_bindings(r, b)};
        gpu_pipeline_create(r->g, &r->vertex_pass, &pd);
    }
    cmd = gpu_begin(r->g);
    for (uint32_t side = 0; side < 2; side++) {
        GnPush push = {0, side, 0, 0};
        gpu_dispatch(cmd, &r->vertex_pass, &push, 64 * groups_x, groups_y, 1);
        gpu_barrier(cmd);
    }
    gpu_submit_wait(r->g, cmd);
    return true;
}

/* IEEE half from float (truncating; the map's values are finite and >= 0). */
static uint16_t half_from_float(float f)
{
    uint32_t x, m;
    int e;
    memcpy(&x, &f, 4);
    m = x & 0x7fffff;
    e = (int)((x >> 23) & 0xff) - 127 + 15;
    if (e >= 31)
        return 0x7c00;
    if (e <= 0)
        return e < -10 ? 0 : (uint16_t)((m | 0x800000) >> (14 - e));
    return (uint16_t)((uint32_t)e << 10 | m >> 13);
}

/* Uploads a lat-long map for path.comp (layout there): texels as half RGB, then the
 * marginal CDF of the rows and each row's conditional CDF, over the weights
 * lum(texel) sin(theta) (the solid angle a texel covers). Its selection weight is the
 * environment's flux / pi onto the bounding sphere, 4 pi r^2 mean(L), as for a constant one. */
static bool upload_env_map(renderer *r, const image *map)
{
    const int w = map->width, h = map->height;
    int cr = image_channel(map, "R"), cg = image_channel(map, "G"), cb = image_channel(map, "B");
    const size_t n = (size_t)w * h, words = 3 * n + (size_t)h;
    uint32_t *data;
    float *marg, *cond;
    double total = 0, *row = util_calloc((size_t)h, sizeof *row);
    if (cr < 0 || cg < 0 || cb < 0)
        cr = cg = cb = image_channel(map, "Y");
    if (cr < 0) {
        util_error("--env: the map has no R, G, B (or Y) channels");
        free(row);
        return false;
    }
    if (words > gpu_max_texels(r->g, NULL)) {
        util_error("--env: the map's %dx%d texels and tables need %zu words, more than the %u "
                   "of a texel buffer on this device", w, h, words, gpu_max_texels(r->g, NULL));
        free(row);
        return false;
    }
    data = util_calloc(words, sizeof *data);
    marg = (float *)(data + 2 * n);
    cond = marg + h;
    for (int y = 0; y < h; y++) {
        double st = sin(M_PI * (y + 0.5) / h), sum = 0;
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            float c[3] = {map->planes[cr][i], map->planes[cg][i], map->planes[cb][i]};
            uint16_t hc[3];
            for (int k = 0; k < 3; k++) {
                c[k] = c[k] >= 0 && c[k] < 65504.0f ? c[k] : c[k] >= 65504.0f ? 65504.0f : 0;
                hc[k] = half_from_float(c[k]);
            }
            data[2 * i] = hc[0] | (uint32_t)hc[1] << 16;
            data[2 * i + 1] = hc[2];
            sum += luminance(c) * st;
            cond[i] = (float)sum;
        }
        for (int x = 0; x < w; x++) /* an unlit row is never picked; keep its CDF valid */
            cond[(size_t)y * w + x] = sum > 0 ? (float)(cond[(size_t)y * w + x] / sum) : (float)(x + 1) / w;
        cond[(size_t)y * w + w - 1] = 1;
        row[y] = sum;
        total += sum;
    }
    for (int y = 0; y < h; y++) {
        double acc = 0;
        for (int k = 0; k <= y; k++)
            acc += row[k];
        marg[y] = total > 0 ? (float)(acc / total) : (float)(y + 1) / h;
    }
    marg[h - 1] = 1;
    if (r->env.buffer && r->env.size == words * 4) { /* (the same map again: an animation's next frame) */
        gpu_buffer_upload(r->g, &r->env, data, words * 4, 0);
    } else {
        gpu_buffer_destroy(r->g, &r->env);
        gpu_buffer_create_texels_as(r->g, &r->env, data, words * 4, VK_FORMAT_R32_UINT);
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++) /* their descriptor sets name the old buffer */
            gpu_pipeline_destroy(r->g, &r->pipelines[i]);
    }
    /* mean L over the sphere = sum(L sin dtheta dphi) / 4 pi, dtheta dphi = 2 pi^2 / n */
    r->env_weight = scene_radius2(r->sc) * 2 * M_PI * M_PI * total / (double)n;
    r->env_source = map;
    free(data);
    free(row);
    return true;
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
static uint32_t state_stride(const renderer *r, uint32_t mode);
/* The most loop_setup's overhead can be (log2_up is at most 32): the fixed cap leaves room
 * for it. */
#define PATH_OVERHEAD_MAX (32u + (32u + 2) + (32u + 32u + 4))
static void loop_setup(renderer *r, GnFrame *frame)
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

/* The path tracer's frame: the environment, the normalised light table and the budget. */
static bool path_begin(renderer *r, const render_settings *s, GnFrame *frame)
{
    uint32_t n = r->num_emitters;
    double total = 0, acc = 0, env = 0;
    if (s->env_map) {
        if (s->env_map != r->env_source && !upload_env_map(r, s->env_map))
            return false;
        frame->flags |= GN_FRAME_ENV_MAP;
        frame->env_width = (uint32_t)s->env_map->width;
        frame->env_height = (uint32_t)s->env_map->height;
        env = r->env_weight;
    } else {
        env = 4 * M_PI * scene_radius2(r->sc) * luminance(s->env);
    }
    if (env > 0) {
        r->emitter_table[n] = (GnEmitter){GN_INVALID, 0, 0, 0};
        r->emitter_weight[n++] = env;
    }
    for (uint32_t i = 0; i < n; i++)
        total += r->emitter_weight[i];
    for (uint32_t i = 0; i < n; i++) {
        acc += r->emitter_weight[i];
        r->emitter_table[i].pdf = (float)(r->emitter_weight[i] / total);
        r->emitter_table[i].cdf = i + 1 == n ? 1.0f : (float)(acc / total);
    }
    if (n)
        gpu_buffer_upload(r->g, &r->emitters, r->emitter_table, sizeof(GnEmitter) * n, 0);
    frame->num_emitters = n;
    frame->emitter_power = (float)total;
    frame->emitter_instances = r->geo.two_levels ? r->emitter_cap : 0;
    frame->env_select = env > 0 ? (float)(env / total) : 0;
    frame->flags |= s->strategy;
    r->path_features = r->material_features | (s->aov & RENDER_AOV_GPU ? GN_FEAT_AOV : 0u) |
                       (s->aov & RENDER_AOV_VARIANCE ? GN_FEAT_VARIANCE : 0u) |
                       (s->strategy ? GN_FEAT_STRATEGY : 0u) | (n > 1 ? GN_FEAT_LIGHT_SEARCH : 0u) |
                       (env > 0 || s->env[0] != 0 || s->env[1] != 0 || s->env[2] != 0 ? GN_FEAT_ENV : 0u) |
                       (s->env_map ? GN_FEAT_ENV | GN_FEAT_ENV_MAP : 0u);
    if (r->num_emitters > r->num_area_emitters) /* punctual lights follow the triangles */
        r->path_features |= GN_FEAT_PUNCTUAL;
    /* The unspecialised kernel, for checking that specialisation changes nothing
     * (tests/regress/path.sh) and for ruling it out when chasing a bug. */
    if (getenv("GONIO_ALL_FEATURES"))
        r->path_features = GN_FEAT_ALL;
    frame->traversal_budget = traversal_budget(r->g, 1); /* (unused: path.comp has loop_cap) */
    loop_setup(r, frame);
    return true;
}

void render_region(const render_settings *s, int region[4])
{
    if (s->crop_x1 > 0) {
        region[0] = s->crop_x0;
        region[1] = s->crop_y0;
        region[2] = s->crop_x1;
        region[3] = s->crop_y1;
    } else {
        region[0] = region[1] = 0;
        region[2] = s->width;
        region[3] = s->height;
    }
}

/* The frame constants of s for the pixels `region` (no upload); false when the camera is bad. */
static bool frame_setup(renderer *r, const render_settings *s, const int region[4], GnFrame *frame)
{
    memset(frame, 0, sizeof *frame);
    if (!renderer_camera(r, s, &frame->camera))
        return false;
    frame->width = (uint32_t)s->width;
    frame->height = (uint32_t)s->height;
    frame->crop_x = (uint32_t)region[0];
    frame->crop_y = (uint32_t)region[1];
    frame->crop_width = (uint32_t)(region[2] - region[0]);
    frame->crop_height = (uint32_t)(region[3] - region[1]);
    frame->seed = s->seed;
    frame->max_depth = (uint32_t)s->max_depth;
    frame->num_lights = r->num_lights;
    frame->flags = (s->aov & RENDER_AOV_GPU ? GN_FRAME_AOV : 0u) | (!s->no_shadows ? GN_FRAME_SHADOWS : 0u) |
                   (s->aov & RENDER_AOV_VARIANCE ? GN_FRAME_VARIANCE : 0u) |
                   (r->sc->vertex_colors ? GN_FRAME_VERTEX_COLOR : 0u) |
                   (r->material_features & GN_FEAT_ALPHA ? GN_FRAME_ALPHA : 0u);
    frame->env_color = (vec3){s->env[0], s->env[1], s->env[2]};
    frame->env_cos = (float)cos(s->env_rotation * M_PI / 180);
    frame->env_sin = (float)-sin(s->env_rotation * M_PI / 180);
    frame->ambient = v3(s->ambient_set ? s->ambient : r->sc->ambient);
    frame->traversal_budget = traversal_budget(r->g, 1 + (!s->no_shadows ? r->num_lights : 0));
    r->state_stride = 0; /* path_begin sets it, and the loop cap, for the path kernel */
    return s->mode != GN_MODE_PATH || path_begin(r, s, frame);
}

/* Bytes per pixel of the accumulation buffers a render with the AOVs `aov` writes: accum
 * always, the GPU AOVs' buffer and the squares only when asked for. */
static VkDeviceSize aov_pixel_bytes(uint32_t aov) { return aov & RENDER_AOV_GPU ? 48 : 0; }
static VkDeviceSize squares_pixel_bytes(uint32_t aov) { return aov & RENDER_AOV_VARIANCE ? 16 : 0; }

/* How many rows of a w x h region one set of accumulation buffers holds within the device's
 * limits: each buffer within gpu_storage_limit, all of them within half the host heap (the
 * rest for the scene and the image), at most 8 maxComputeWorkGroupCount[1] rows and each row
 * within maxComputeWorkGroupCount[0] work groups. 0 (with an error naming the limit and the
 * numbers) when not even one row fits; *why (may be NULL) names what bounds it, else NULL. */
/* Words a pixel of the path kernel's saved state (glsl/kernels/path.comp: path_save) takes under a
 * loop cap, 0 without one: the path, and the walk's stack, which holds at most one entry a
 * tree level (plus the sentinel). */
static uint32_t walk_regs(const renderer *r);
static uint32_t state_stride(const renderer *r, uint32_t mode)
{
    uint32_t regs = walk_regs(r), stack = r->geo.depth + 2 < GN_WALK_STACK ? r->geo.depth + 2 : GN_WALK_STACK;
    if (mode != GN_MODE_PATH || !loop_capped(r->g))
        return 0;
    /* (with instances, two words more: the hit's instance and the walk's, path_save) */
    return GN_PATH_STATE_WORDS + (regs ? regs : stack) + (r->geo.two_levels ? 2 : 0);
}

static int band_rows(const renderer *r, int w, int h, uint32_t aov, uint32_t mode, char *why,
                     size_t why_size)
{
    const char *limit_name;
    const VkDeviceSize limit = gpu_storage_limit(r->g, &limit_name), heap = gpu_host_heap(r->g) / 2;
    const VkDeviceSize largest = aov_pixel_bytes(aov) > 16 ? aov_pixel_bytes(aov) : 16;
    const VkDeviceSize all = 16 + aov_pixel_bytes(aov) + squares_pixel_bytes(aov);
    const uint32_t groups_x = (uint32_t)(w + GN_TILE_X - 1) / GN_TILE_X;
    VkDeviceSize rows = limit / (largest * (VkDeviceSize)w);
    const VkDeviceSize heap_rows = heap / (all * (VkDeviceSize)w);
    const VkDeviceSize group_rows = (VkDeviceSize)gpu_max_groups(r->g, 1) * GN_TILE_Y;
    if (why)
        why[0] = 0;
    if (groups_x > gpu_max_groups(r->g, 0)) {
        util_error("%s: a row of %d pixels needs %u work groups, more than the %u this device "
                   "dispatches (maxComputeWorkGroupCount[0])", r->sc->path, w, groups_x,
                   gpu_max_groups(r->g, 0));
        return 0;
    }
    if (rows < (VkDeviceSize)h && why)
        snprintf(why, why_size, "its %llu-byte %s buffer exceeds the device's %s (%llu bytes)",
                 (unsigned long long)(largest * (VkDeviceSize)w * (VkDeviceSize)h),
                 largest > 16 ? "AOV" : "accumulation", limit_name, (unsigned long long)limit);
    if (heap_rows < rows) {
        rows = heap_rows;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %llu bytes of accumulation buffers exceed half the "
                     "device's memory heap (%llu bytes)",
                     (unsigned long long)(all * (VkDeviceSize)w * (VkDeviceSize)h),
                     (unsigned long long)heap);
    }
    if (group_rows < rows) {
        rows = group_rows;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %d rows need more work groups than the device's "
                     "maxComputeWorkGroupCount[1] (%u)", h, gpu_max_groups(r->g, 1));
    }
    /* The path kernel's saved paths (state_stride) are one more storage buffer, within the
     * device's own limit (GONIO_MAX_BUFFER_BYTES is for the accumulation buffers' bands). */
    const VkDeviceSize state = 4 * (VkDeviceSize)state_stride(r, mode) * (VkDeviceSize)w;
    VkDeviceSize state_limit = r->g->props.limits.maxStorageBufferRange;
    if (r->g->max_allocation && r->g->max_allocation < state_limit)
        state_limit = r->g->max_allocation;
    if (state && state_limit / state < rows) {
        rows = state_limit / state;
        if (rows < (VkDeviceSize)h && why)
            snprintf(why, why_size, "its %llu-byte buffer of paths left for the next pass exceeds "
                     "the device's storage buffer range (%llu bytes)",
                     (unsigned long long)(state * (VkDeviceSize)h), (unsigned long long)state_limit);
    }
    if (rows == 0) {
        util_error("%s: a row of %d pixels needs %llu bytes of accumulation buffers, more than this "
                   "device allows (%s: %llu bytes; half the memory heap: %llu bytes)", r->sc->path, w,
                   (unsigned long long)(largest * (VkDeviceSize)w), limit_name,
                   (unsigned long long)limit, (unsigned long long)heap);
        return 0;
    }
    return rows < (VkDeviceSize)h ? (int)rows : h;
}

/* (Re)allocates the accumulation buffers for w x h pixels: accum always, the AOV and squares
 * buffers only when the render writes them (16-byte dummies otherwise: every descriptor
 * must name a buffer). A buffer is kept while it holds the pixels and is at most twice the
 * size needed, so the bands of a tiled render share one set. */
static void size_buffers(renderer *r, int w, int h, uint32_t aov)
{
    const VkDeviceSize pixels = (VkDeviceSize)w * h;
    gpu_buffer *bufs[4] = {&r->accum, &r->aov, &r->squares, &r->pstate};
    const VkDeviceSize need[4] = {16 * pixels, aov_pixel_bytes(aov) ? aov_pixel_bytes(aov) * pixels : 16,
                                  squares_pixel_bytes(aov) ? squares_pixel_bytes(aov) * pixels : 16,
                                  r->state_stride ? 4 * (VkDeviceSize)r->state_stride * pixels : 16};
    bool changed = false;
    for (int i = 0; i < 4; i++) {
        if (bufs[i]->buffer && bufs[i]->size >= need[i] && bufs[i]->size / 2 <= need[i])
            continue;
        gpu_buffer_destroy(r->g, bufs[i]);
        gpu_buffer_create(r->g, bufs[i], need[i], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        assert(bufs[i]->mapped); /* resolve, resume and bands read and write them directly */
        changed = true;
    }
    if (changed && getenv("GONIO_DEBUG_BUFFERS")) /* tests/regress/limits.sh */
        fprintf(stderr, "gonio: debug: buffers for %dx%d: accum %llu, aov %llu, squares %llu bytes\n",
                w, h, (unsigned long long)r->accum.size, (unsigned long long)r->aov.size,
                (unsigned long long)r->squares.size);
    r->width = w;
    r->height = h;
    if (changed) { /* the cached kernels' descriptor sets name the old buffers */
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            gpu_pipeline_destroy(r->g, &r->pipelines[i]);
        gpu_pipeline_destroy(r->g, &r->vertex_pass);
    }
}

bool renderer_begin(renderer *r, const render_settings *s, GnFrame *frame)
{
    gpu *g = r->g;
    int region[4];
    render_region(s, region);
    const int rw = region[2] - region[0], rh = region[3] - region[1];
    char why[256];
    assert(rw > 0 && rh > 0 && region[0] >= 0 && region[1] >= 0 && region[2] <= s->width &&
           region[3] <= s->height);
    free_bands(r);
    if (r->failed)
        return false;
    int rows = band_rows(r, rw, rh, s->aov, s->mode, why, sizeof why);
    if (rows == 0)
        return false;
    if (rows < rh) {
        util_error("%s: %dx%d pixels in one piece: %s (gonio render renders it in bands)",
                   r->sc->path, rw, rh, why);
        return false;
    }
    if (!frame_setup(r, s, region, frame))
        return false;
    gpu_buffer_upload(g, &r->frame, frame, sizeof *frame, 0);
    size_buffers(r, rw, rh, s->aov);
    gpu_buffer_fill_zero(g, &r->accum);
    gpu_buffer_fill_zero(g, &r->aov);
    gpu_buffer_fill_zero(g, &r->squares);
    gpu_buffer_fill_zero(g, &r->pstate);
    gpu_buffer_fill_zero(g, &r->status);
    return !(render_modes[s->mode].flags & GN_MODEF_VERTEX_LIGHT) || light_vertices(r);
}

/* The GN_FEAT_* a mode's kernel is built for: those it is specialised on as the scene and
 * settings need them, every other one compiled in. */
static uint32_t kernel_features(const renderer *r, uint32_t mode)
{
    const uint32_t spec = mode_kernel(mode)->specialised;
    return (GN_FEAT_ALL & ~spec) | (r->path_features & spec);
}

/* The walk's stack in registers for trees of at most GN_WALK_REGS_MAX levels (a walk puts
 * off at most one node per level), else in memory (0); GONIO_WALK_ARRAY=1 forces memory, so
 * that tests/regress/path.sh can check that both give the same pixels. */
static uint32_t walk_regs(const renderer *r)
{
    const char *array = getenv("GONIO_WALK_ARRAY");
    if (array && !strcmp(array, "1"))
        return 0;
    return r->geo.depth <= GN_WALK_REGS_MAX ? r->geo.depth : 0;
}

const VkSpecializationInfo *renderer_specialize(const renderer *r, uint32_t mode, renderer_spec *spec)
{
    spec->values[0] = mode;
    spec->values[1] = kernel_features(r, mode);
    spec->values[2] = walk_regs(r);
    spec->values[3] = 0; /* the loop cap: only the path kernel's (renderer_pipeline) */
    spec->values[4] = r->geo.two_levels; /* INSTANCES */
    for (uint32_t i = 0; i < 4; i++)
        spec->entries[i] = (VkSpecializationMapEntry){i, i * (uint32_t)sizeof(uint32_t), sizeof(uint32_t)};
    spec->entries[4] = (VkSpecializationMapEntry){GN_SPEC_INSTANCES, 4 * (uint32_t)sizeof(uint32_t), sizeof(uint32_t)};
    assert(spec->entries[2].constantID == GN_SPEC_WALK_REGS && spec->entries[3].constantID == GN_SPEC_LOOP_CAP);
    spec->info = (VkSpecializationInfo){5, spec->entries, sizeof spec->values, spec->values};
    return &spec->info;
}

gpu_pipeline *renderer_pipeline(renderer *r, uint32_t mode)
{
    gpu_pipeline *p = &r->pipelines[mode];
    uint32_t features = kernel_features(r, mode);
    if (p->pipeline && r->pipeline_features[mode] != features)
        gpu_pipeline_destroy(r->g, p); /* built for other features: a new kernel */
    if (!p->pipeline) {
        r->pipeline_features[mode] = features;
        gpu_binding b[GN_BIND_COUNT];
        renderer_spec spec;
        gpu_pipeline_desc pd = {
            .name = mode_kernel(mode)->name, .code = mode_kernel(mode)->code,
            .code_size = mode_kernel(mode)->code_size,
            .local_size = {GN_TILE_X, GN_TILE_Y, 1}, .push_size = sizeof(GnPush),
            .bindings = b, .num_bindings = renderer_bindings(r, b),
            .specialization = renderer_specialize(r, mode, &spec)};
        spec.values[3] = mode_kernel(mode)->batched ? r->loop_cap : 0u;
        gpu_pipeline_create(r->g, p, &pd);
    }
    return p;
}

void renderer_record_samples(renderer *r, VkCommandBuffer cmd, uint32_t mode, uint32_t first,
                             uint32_t count)
{
    /* A batched kernel takes up to path_samples samples per dispatch (glsl/kernels/path.comp: a lane
     * whose path ends starts its next one); the others one. */
    uint32_t per = mode_kernel(mode)->batched ? r->path_samples : 1u;
    for (uint32_t i = 0; i < count; i += per) {
        GnPush push = {first + i, 0, count - i < per ? count - i : per, 0};
        gpu_dispatch(cmd, renderer_pipeline(r, mode), &push, (uint32_t)r->width, (uint32_t)r->height, 1);
        gpu_barrier(cmd);
    }
}

uint32_t renderer_finish(renderer *r, uint32_t mode, uint32_t next)
{
    uint32_t n = 0;
    /* status[1]: the pixels pending after the last dispatch. Each dispatch that takes no new
     * samples gives every pending pixel one more invocation's worth of loop passes. */
    volatile const uint32_t *pending = (const uint32_t *)r->status.mapped + 1;
    while (mode_kernel(mode)->batched && r->loop_cap && *pending) {
        VkCommandBuffer cmd = gpu_begin(r->g);
        GnPush push = {next, 0, 0, 0};
        gpu_dispatch(cmd, renderer_pipeline(r, mode), &push, (uint32_t)r->width, (uint32_t)r->height, 1);
        gpu_barrier(cmd);
        gpu_submit_wait(r->g, cmd);
        n++;
    }
    return n;
}

uint32_t render_aov_from_name(const char *name)
{
    static const char *const names[] = {"normal", "albedo", "depth", "variance"};
    for (uint32_t i = 0; i < 4; i++)
        if (!strcmp(name, names[i]))
            return 1u << i;
    return 0;
}

/* Appends one zeroed channel and returns its plane. */
static float *add_channel(image *out, const char *name)
{
    const size_t pixels = (size_t)out->width * (size_t)out->height;
    assert(out->num_channels < IMAGE_MAX_CHANNELS);
    snprintf(out->names[out->num_channels], sizeof out->names[0], "%s", name);
    return out->planes[out->num_channels++] = util_calloc(pixels, sizeof(float));
}

/* Where a render's sums are: its buffers, or the host copies of a render in bands. */
typedef struct sums_at {
    float *accum, *aov, *squares;
    int width, height;
} sums_at;

static sums_at sums_of(const renderer *r)
{
    if (r->band_accum)
        return (sums_at){r->band_accum, r->band_aov, r->band_squares, r->region_width, r->region_height};
    return (sums_at){r->accum.mapped, r->aov.mapped, r->squares.mapped, r->width, r->height};
}

/* aov_offset: where the AOV is in each pixel's 12 floats of the aov buffer (GN_BIND_AOV). */
static void add_gpu_aov(const renderer *r, int spp, const char *const *names, int n, int aov_offset, image *out)
{
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *aovs = at.aov;
    float inv = 1.0f / (float)spp;
    for (int c = 0; c < n; c++) {
        float *plane = add_channel(out, names[c]);
        for (VkDeviceSize p = 0; p < pixels; p++)
            plane[p] = aovs[12 * p + (VkDeviceSize)(aov_offset + c)] * inv;
    }
}

/* Appends variance.R/G/B: the unbiased variance estimate of each pixel's mean,
 * (sum x^2 / n - mean^2) / (n - 1) (0 for n = 1), from the sums of squares. */
static void add_variance(const renderer *r, int spp, image *out)
{
    static const char *const names[] = {"variance.R", "variance.G", "variance.B"};
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *acc = at.accum, *sq = at.squares;
    for (int c = 0; c < 3; c++) {
        float *plane = add_channel(out, names[c]);
        for (VkDeviceSize p = 0; spp > 1 && p < pixels; p++) {
            double m = (double)acc[4 * p + c] / spp, v = ((double)sq[4 * p + c] / spp - m * m) / (spp - 1);
            plane[p] = v > 0 ? (float)v : 0;
        }
    }
}

void renderer_resolve(renderer *r, int spp, uint32_t aov, image *out)
{
    static const char *const names[] = {"R", "G", "B", "A"};
    static const char *const normal[] = {"normal.X", "normal.Y", "normal.Z"};
    static const char *const albedo[] = {"albedo.R", "albedo.G", "albedo.B"};
    static const char *const depth[] = {"depth.Z"};
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    const float *acc = at.accum;
    float inv = 1.0f / (float)spp;
    image_create(out, at.width, at.height, 4, names);
    for (VkDeviceSize p = 0; p < pixels; p++)
        for (int c = 0; c < 4; c++)
            out->planes[c][p] = acc[4 * p + c] * inv;
    if (aov & RENDER_AOV_NORMAL)
        add_gpu_aov(r, spp, normal, 3, 0, out);
    if (aov & RENDER_AOV_ALBEDO)
        add_gpu_aov(r, spp, albedo, 3, 4, out);
    if (aov & RENDER_AOV_DEPTH)
        add_gpu_aov(r, spp, depth, 1, 8, out);
    if (aov & RENDER_AOV_VARIANCE)
        add_variance(r, spp, out);
}

/* The channels of renderer_sums: name, buffer (0 accum, 1 aov, 2 squares), float offset
 * in a pixel's entry of that buffer, and the AOV bit that needs it (0: always). */
static const struct sum_channel {
    const char *name;
    int buffer, offset;
    uint32_t aov;
} sum_channels[] = {
    {"sum.R", 0, 0, 0}, {"sum.G", 0, 1, 0}, {"sum.B", 0, 2, 0}, {"sum.A", 0, 3, 0},
    {"sum.normal.X", 1, 0, RENDER_AOV_NORMAL}, {"sum.normal.Y", 1, 1, RENDER_AOV_NORMAL},
    {"sum.normal.Z", 1, 2, RENDER_AOV_NORMAL}, {"sum.albedo.R", 1, 4, RENDER_AOV_ALBEDO},
    {"sum.albedo.G", 1, 5, RENDER_AOV_ALBEDO}, {"sum.albedo.B", 1, 6, RENDER_AOV_ALBEDO},
    {"sum.depth.Z", 1, 8, RENDER_AOV_DEPTH}, {"sum2.R", 2, 0, RENDER_AOV_VARIANCE},
    {"sum2.G", 2, 1, RENDER_AOV_VARIANCE}, {"sum2.B", 2, 2, RENDER_AOV_VARIANCE},
};

static float *sum_buffer(const renderer *r, int buffer, int *stride)
{
    const sums_at at = sums_of(r);
    *stride = buffer == 1 ? 12 : 4;
    return buffer == 0 ? at.accum : buffer == 1 ? at.aov : at.squares;
}

void renderer_sums(const renderer *r, int spp, uint32_t aov, image *out)
{
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    float *n = add_channel(out, "sum.N");
    for (VkDeviceSize p = 0; p < pixels; p++)
        n[p] = (float)spp; /* exact: spp <= 2^24 */
    for (size_t k = 0; k < sizeof sum_channels / sizeof *sum_channels; k++) {
        const struct sum_channel *c = &sum_channels[k];
        int stride;
        const float *buf = sum_buffer(r, c->buffer, &stride);
        float *plane;
        if (c->aov && !(aov & c->aov))
            continue;
        plane = add_channel(out, c->name);
        for (VkDeviceSize p = 0; p < pixels; p++)
            plane[p] = buf[(VkDeviceSize)stride * p + (VkDeviceSize)c->offset];
    }
}

/* Loads the sums of s->resume into the freshly cleared buffers; false (with an error) when
 * a channel the render needs is missing or the size differs. */
static bool load_sums(renderer *r, const render_settings *s)
{
    const sums_at at = sums_of(r);
    const VkDeviceSize pixels = (VkDeviceSize)at.width * at.height;
    if (s->resume->width != at.width || s->resume->height != at.height) {
        util_error("--resume: the file's %dx%d pixels are not the %dx%d region rendered",
                   s->resume->width, s->resume->height, at.width, at.height);
        return false;
    }
    for (size_t k = 0; k < sizeof sum_channels / sizeof *sum_channels; k++) {
        const struct sum_channel *c = &sum_channels[k];
        int stride, ch;
        float *buf = sum_buffer(r, c->buffer, &stride);
        if (c->aov && !(s->aov & c->aov))
            continue;
        if ((ch = image_channel(s->resume, c->name)) < 0) {
            util_error("--resume: the file has no channel '%s' (not written with --resumable, or "
                       "with other --aov)", c->name);
            return false;
        }
        for (VkDeviceSize p = 0; p < pixels; p++)
            buf[(VkDeviceSize)stride * p + (VkDeviceSize)c->offset] = s->resume->planes[ch][p];
    }
    return true;
}

/* A render in bands of `rows` rows: the frame and buffers for the first band (the others
 * share them), and the whole region's sums on the host, zeroed. */
static bool begin_bands(renderer *r, const render_settings *s, const int region[4], int rows,
                        GnFrame *frame)
{
    const int rw = region[2] - region[0], rh = region[3] - region[1];
    const size_t pixels = (size_t)rw * (size_t)rh;
    free_bands(r);
    if (!frame_setup(r, s, region, frame))
        return false;
    size_buffers(r, rw, rows, s->aov);
    gpu_buffer_fill_zero(r->g, &r->pstate);
    gpu_buffer_fill_zero(r->g, &r->status);
    r->band_accum = util_calloc(4 * pixels, sizeof(float));
    if (s->aov & RENDER_AOV_GPU)
        r->band_aov = util_calloc(12 * pixels, sizeof(float));
    if (s->aov & RENDER_AOV_VARIANCE)
        r->band_squares = util_calloc(4 * pixels, sizeof(float));
    r->region_width = rw;
    r->region_height = rh;
    return !(render_modes[s->mode].flags & GN_MODEF_VERTEX_LIGHT) || light_vertices(r);
}

/* Band b's frame uploaded and its sums (host) copied into the buffers (load), or the
 * buffers' sums copied back to the host (!load). */
static void band_swap(renderer *r, GnFrame *frame, const int region[4], int rows, int b, bool load)
{
    const int y0 = b * rows, rh = region[3] - region[1], bh = rh - y0 < rows ? rh - y0 : rows;
    const size_t first = (size_t)r->region_width * (size_t)y0, n = (size_t)r->region_width * (size_t)bh;
    struct { float *host; gpu_buffer *buf; size_t floats; } parts[3] = {
        {r->band_accum, &r->accum, 4}, {r->band_aov, &r->aov, 12}, {r->band_squares, &r->squares, 4}};
    if (load) {
        frame->crop_y = (uint32_t)(region[1] + y0);
        frame->crop_height = (uint32_t)bh;
        gpu_buffer_upload(r->g, &r->frame, frame, sizeof *frame, 0);
        r->height = bh; /* the dispatch's rows; the buffers hold `rows` */
    }
    for (int i = 0; i < 3; i++) {
        float *host = parts[i].host ? parts[i].host + parts[i].floats * first : NULL;
        if (host && load)
            memcpy(parts[i].buf->mapped, host, parts[i].floats * sizeof(float) * n);
        else if (host)
            memcpy(host, parts[i].buf->mapped, parts[i].floats * sizeof(float) * n);
    }
}

bool renderer_render(renderer *r, const render_settings *s, image *out, render_stats *stats)
{
    gpu *g = r->g;
    GnFrame frame;
    double t0;
    int done = 0, batch = 1, region[4], rows, bands;
    const int per = mode_kernel(s->mode)->batched ? (int)r->path_samples : 1;
    progress prog = {.tty = isatty(2), .tenth = -1};
    char why[256];

    memset(stats, 0, sizeof *stats);
    assert(s->mode < GN_MODE_COUNT);
    if (r->failed)
        return false;
    render_region(s, region);
    const int rw = region[2] - region[0], rh = region[3] - region[1];
    const VkDeviceSize pixels = (VkDeviceSize)rw * rh;
    if ((rows = band_rows(r, rw, rh, s->aov, s->mode, why, sizeof why)) == 0)
        return false;
    bands = (rh + rows - 1) / rows;
    if (bands > 1) {
        /* Bands of about equal height, whole 8-row tiles where that stays within the limit. */
        int even = (rh + bands - 1) / bands, tiled = (even + (int)GN_TILE_Y - 1) / (int)GN_TILE_Y * (int)GN_TILE_Y;
        rows = tiled <= rows ? tiled : even;
        bands = (rh + rows - 1) / rows;
        util_info("%dx%d rendered in %d bands of %d rows: %s", rw, rh, bands, rows, why);
        if (!begin_bands(r, s, region, rows, &frame))
            return false;
    } else if (!renderer_begin(r, s, &frame)) {
        return false;
    }
    stats->bands = bands;
    if (s->resume) {
        if (!load_sums(r, s))
            return false;
        done = s->resume_spp;
    }

    /* Passes are submitted in batches sized to take 0.1 to 0.4 s each (per band): short
     * enough for a responsive progress bar and an early stop, long enough to hide submission
     * costs and to let the path kernel take several samples per dispatch
     * (renderer_record_samples). The kernels add each sample to the buffers' sums in sample
     * order (glsl/kernels/path.comp), so the bits do not depend on how the batches, dispatches and
     * bands split the samples: the same command gives the same bits, and so do a render
     * resumed from its sums (s->resume), a crop of it (GnFrame) and one in bands. A batch
     * goes through every band before the next, so all pixels always have the same samples:
     * a stop or --time ends the render after a whole round. The kernel is compiled first,
     * so that --time, the progress and the rates count rendering, not the driver's compiler
     * (the setup time includes it). */
    t0 = util_now();
    renderer_pipeline(r, s->mode);
    double compile_seconds = util_now() - t0;
    t0 = util_now();
    while (s->time_limit > 0 || done < s->spp) {
        double tb = util_now();
        int n = batch * per;
        if (s->time_limit <= 0 && n > s->spp - done)
            n = s->spp - done;
        for (int b = 0; b < bands; b++) {
            VkCommandBuffer cmd;
            if (bands > 1)
                band_swap(r, &frame, region, rows, b, true);
            cmd = gpu_begin(g);
            renderer_record_samples(r, cmd, s->mode, (uint32_t)done, (uint32_t)n);
            gpu_submit_wait(g, cmd);
            stats->resumes += renderer_finish(r, s->mode, (uint32_t)(done + n));
            if (bands > 1)
                band_swap(r, &frame, region, rows, b, false);
        }
        done += n;
        if (done == n + (s->resume ? s->resume_spp : 0))
            stats->first_pass_seconds = util_now() - t0;
        tb = (util_now() - tb) / bands;
        if (tb < 0.1 && batch < 1024)
            batch *= 2;
        else if (tb > 0.4 && batch > 1)
            batch /= 2;
        if (s->progress)
            progress_update(s, &prog, done, util_now() - t0);
        if (s->stop && *s->stop)
            break;
        if (s->time_limit > 0 && util_now() - t0 >= s->time_limit)
            break;
    }
    stats->seconds = util_now() - t0;
    /* The last state: where an interrupt left it, or done (a log only hears of it when it
     * heard of the render at all). */
    if (s->progress && (prog.tty || prog.tenth >= 0)) {
        progress_show(s, &prog, done, stats->seconds, s->stop && *s->stop ? "interrupted" : "done");
        if (prog.tty)
            fputc('\n', stderr);
    }
    stats->spp = done;
    stats->rays = (uint64_t)pixels * (uint64_t)(done - (s->resume ? s->resume_spp : 0));
    stats->setup_seconds = r->setup_seconds + compile_seconds;
    stats->truncated = ((const uint32_t *)r->status.mapped)[0];
    if (getenv("GONIO_DEBUG_RESUMES")) /* tests/regress/path.sh: the interrupted paths were there */
        fprintf(stderr, "gonio: debug: %u dispatch(es) finished paths the loop cap interrupted\n",
                stats->resumes);
    /* The path kernel resumes what the loop cap interrupts (glsl/kernels/path.comp): a count here
     * means its count of loop passes is wrong, a bug, and the image may be too dark. */
    if (stats->truncated && s->mode == GN_MODE_PATH)
        util_warn("%s: internal error: in %u pixel pass(es) llvmpipe's loop cap stopped a path "
                  "that the kernel did not stop first; the image may be too dark there",
                  r->sc->path, stats->truncated);
    else if (stats->truncated)
        util_warn("%s: %u ray(s) needed more BVH steps than the per-ray budget (%u) and may be "
                  "wrong", r->sc->path, stats->truncated, frame.traversal_budget);
    renderer_resolve(r, done, s->aov, out);
    return true;
}

/* Sets m's model from a setting: the glTF model writes the material's own fields back. */
static void apply_setting(GnMaterial *m, const brdf_setting *st)
{
    memcpy(&m->base_color.x, st->v, 3 * sizeof(float));
    memcpy(&m->brdf_params.x, st->v + BRDF_SLOT_PARAMS, 4 * sizeof(float));
    m->brdf = st->model->id;
    if (st->model->id == BRDF_GLTF) {
        m->metallic = st->v[BRDF_SLOT_PARAMS];
        m->roughness = st->v[BRDF_SLOT_PARAMS + 1];
        m->specular = st->v[BRDF_SLOT_PARAMS + 2];
        m->ior = st->v[BRDF_SLOT_PARAMS + 3];
        memcpy(&m->specular_color.x, st->v + BRDF_SLOT_EXTRA, 3 * sizeof(float));
        m->transmission = st->v[BRDF_SLOT_EXTRA + 3];
        m->clearcoat = st->v[BRDF_SLOT_LAYER];
        m->clearcoat_roughness = st->v[BRDF_SLOT_LAYER + 1];
        m->sheen_roughness = st->v[BRDF_SLOT_LAYER + 2];
        memcpy(&m->sheen_color.x, st->v + BRDF_SLOT_SHEEN, 3 * sizeof(float));
        m->anisotropy_strength = st->v[BRDF_SLOT_ANISO];
        m->anisotropy_rotation = st->v[BRDF_SLOT_ANISO + 1];
        m->iridescence = st->v[BRDF_SLOT_IRID];
        m->iridescence_ior = st->v[BRDF_SLOT_IRID + 1];
        m->iridescence_thickness_max = st->v[BRDF_SLOT_IRID + 2];
        memcpy(&m->diffuse_transmission_color.x, st->v + BRDF_SLOT_DT, 3 * sizeof(float));
        m->diffuse_transmission = st->v[BRDF_SLOT_DT + 3];
    }
}

/* A setting of `model` that starts from m: its colour is the material's base colour (but a
 * conductor's, its complex index, keeps the model's default); glTF starts from every field. */
static void setting_from_material(brdf_setting *st, const brdf_model *model, const GnMaterial *m)
{
    brdf_setting_init(st, model);
    if (model->id != BRDF_CONDUCTOR)
        memcpy(st->v, &m->base_color.x, 3 * sizeof(float));
    if (model->id == BRDF_GLTF) {
        st->v[BRDF_SLOT_PARAMS] = m->metallic;
        st->v[BRDF_SLOT_PARAMS + 1] = m->roughness;
        st->v[BRDF_SLOT_PARAMS + 2] = m->specular;
        st->v[BRDF_SLOT_PARAMS + 3] = m->ior;
        memcpy(st->v + BRDF_SLOT_EXTRA, &m->specular_color.x, 3 * sizeof(float));
        st->v[BRDF_SLOT_EXTRA + 3] = m->transmission;
        st->v[BRDF_SLOT_LAYER] = m->clearcoat;
        st->v[BRDF_SLOT_LAYER + 1] = m->clearcoat_roughness;
        st->v[BRDF_SLOT_LAYER + 2] = m->sheen_roughness;
        memcpy(st->v + BRDF_SLOT_SHEEN, &m->sheen_color.x, 3 * sizeof(float));
        st->v[BRDF_SLOT_ANISO] = m->anisotropy_strength;
        st->v[BRDF_SLOT_ANISO + 1] = m->anisotropy_rotation;
        st->v[BRDF_SLOT_IRID] = m->iridescence;
        st->v[BRDF_SLOT_IRID + 1] = m->iridescence_ior;
        st->v[BRDF_SLOT_IRID + 2] = m->iridescence_thickness_max;
        memcpy(st->v + BRDF_SLOT_DT, &m->diffuse_transmission_color.x, 3 * sizeof(float));
        st->v[BRDF_SLOT_DT + 3] = m->diffuse_transmission;
    }
}

bool render_material_overrides(scene *sc, const char *brdf)
{
    const brdf_model *global = NULL;
    if (brdf && !(global = brdf_spec_model(brdf)))
        return false;
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        GnMaterial *m = &sc->materials[i];
        const scene_material_extras *x = &sc->material_extras[i];
        brdf_setting st;
        if (global) {
            setting_from_material(&st, global, m);
            if (!brdf_spec_apply(&st, brdf))
                return false;
        } else if (x->brdf[0]) {
            const brdf_model *model = brdf_model_find(x->brdf);
            if (!model) {
                util_error("%s: material '%s': extras.gonio.brdf names no BRDF model", sc->path,
                           sc->material_names[i]);
                return false;
            }
            setting_from_material(&st, model, m);
            for (int k = 0; k < x->num_params; k++) {
                char value[32];
                snprintf(value, sizeof value, "%.9g", x->param_values[k]);
                if (!brdf_setting_set(&st, x->param_names[k], value)) {
                    util_error("%s: material '%s': bad extras.gonio parameter '%s'", sc->path,
                               sc->material_names[i], x->param_names[k]);
                    return false;
                }
            }
        } else {
            continue;
        }
        apply_setting(m, &st);
    }
    return true;
}
