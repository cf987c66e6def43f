/* render.c: scene upload, the progressive pass loop, readback to an image. */
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "local.h" /* spv_local: glsl/local.comp compiled by the build */
#include "util.h"

static const char *const mode_names[GN_MODE_COUNT] = {
    [GN_MODE_PATH] = "path",       [GN_MODE_PHONG] = "phong",   [GN_MODE_GOURAUD] = "gouraud",
    [GN_MODE_FLAT] = "flat",       [GN_MODE_NORMAL] = "normal", [GN_MODE_ALBEDO] = "albedo",
    [GN_MODE_DEPTH] = "depth",     [GN_MODE_COST] = "cost",
};

int render_mode_from_name(const char *name)
{
    for (int i = 0; i < (int)GN_MODE_COUNT; i++)
        if (strcmp(name, mode_names[i]) == 0)
            return i;
    return -1;
}

const char *render_mode_name(uint32_t mode) { return mode < GN_MODE_COUNT ? mode_names[mode] : "?"; }

const char *render_mode_list(void) { return "path, phong, gouraud, flat, normal, albedo, depth, cost"; }

/* Emissive geometry as lights for the local modes when a scene has no punctual light (the
 * Cornell box): one light per emissive material at the power-weighted centroid. A flat
 * emitter of area A and radiance L has radiant intensity L A cos(theta), a GN_LIGHT_COSINE;
 * one whose normals disagree is treated as isotropic with the same power (pi L A / 4 pi). */
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
            double e1[3], e2[3], cr[3], a;
            if (sc->tri_material[t] != m)
                continue;
            for (int k = 0; k < 3; k++)
                p[k] = &sc->vertices[sc->indices[3 * t + k]].position.x;
            for (int k = 0; k < 3; k++) {
                e1[k] = p[1][k] - p[0][k];
                e2[k] = p[2][k] - p[0][k];
            }
            cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
            cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
            cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
            a = 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            area += a;
            for (int k = 0; k < 3; k++) {
                c[k] += a * (p[0][k] + p[1][k] + p[2][k]) / 3.0;
                an[k] += 0.5 * cr[k];
            }
        }
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

void renderer_create(renderer *r, gpu *g, const scene *sc)
{
    double t0 = util_now();
    GnPrim *prims;
    GnTexture *tex;
    uint32_t *texels, total_texels = 0, *image_offset;
    GnLight *lights;

    memset(r, 0, sizeof *r);
    r->g = g;
    r->sc = sc;
    bvh_build(&r->tree, &sc->vertices[0].position.x, sizeof(GnVertex) / sizeof(float), sc->indices,
              sc->num_triangles);

    prims = util_malloc(sizeof *prims * r->tree.num_tris);
    for (uint32_t i = 0; i < r->tree.num_tris; i++) {
        uint32_t t = r->tree.tri_index[i];
        prims[i] = (GnPrim){sc->indices[3 * t], sc->indices[3 * t + 1], sc->indices[3 * t + 2],
                            sc->tri_material[t]};
    }

    image_offset = util_calloc(sc->num_images + 1, sizeof *image_offset);
    for (uint32_t i = 0; i < sc->num_images; i++) {
        image_offset[i] = total_texels;
        total_texels += sc->images[i].width * sc->images[i].height;
    }
    texels = util_malloc(sizeof *texels * (total_texels + 1));
    for (uint32_t i = 0; i < sc->num_images; i++)
        memcpy(texels + image_offset[i], sc->images[i].rgba8,
               (size_t)sc->images[i].width * sc->images[i].height * 4);
    tex = util_calloc(sc->num_textures + 1, sizeof *tex);
    for (uint32_t i = 0; i < sc->num_textures; i++) {
        const scene_image *im = &sc->images[sc->textures[i].image];
        tex[i] = (GnTexture){image_offset[sc->textures[i].image], im->width, im->height,
                             sc->textures[i].flags};
    }

    lights = util_calloc(sc->num_lights + 16, sizeof *lights);
    memcpy(lights, sc->lights, sizeof *lights * sc->num_lights);
    r->num_lights = sc->num_lights ? sc->num_lights : emissive_lights(sc, lights, 16);

    gpu_buffer_create(g, &r->frame, sizeof(GnFrame), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                      GPU_MEMORY_HOST);
    gpu_buffer_create_storage(g, &r->nodes, r->tree.nodes, sizeof(GnBvhNode) * r->tree.num_nodes);
    gpu_buffer_create_storage(g, &r->tris, r->tree.tris, sizeof(GnTri) * r->tree.num_tris);
    gpu_buffer_create_storage(g, &r->prims, prims, sizeof(GnPrim) * r->tree.num_tris);
    gpu_buffer_create_storage(g, &r->vertices, sc->vertices, sizeof(GnVertex) * sc->num_vertices);
    gpu_buffer_create_storage(g, &r->materials, sc->materials, sizeof(GnMaterial) * sc->num_materials);
    gpu_buffer_create_storage(g, &r->lights, lights, sizeof(GnLight) * r->num_lights);
    gpu_buffer_create_storage(g, &r->texels, texels, sizeof(uint32_t) * total_texels);
    gpu_buffer_create_storage(g, &r->textures, tex, sizeof(GnTexture) * sc->num_textures);
    gpu_buffer_create_storage(g, &r->emitters, NULL, sizeof(GnEmitter));
    gpu_buffer_create_storage(g, &r->vcolor, NULL, 16 * (VkDeviceSize)sc->num_vertices);
    gpu_buffer_create(g, &r->status, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    free(prims);
    free(image_offset);
    free(texels);
    free(tex);
    free(lights);
    r->setup_seconds = util_now() - t0;
}

void renderer_destroy(renderer *r)
{
    gpu_buffer *bufs[] = {&r->frame, &r->nodes, &r->tris, &r->prims, &r->vertices,
                          &r->materials, &r->lights, &r->texels, &r->textures, &r->emitters,
                          &r->vcolor, &r->status, &r->accum, &r->aov};
    if (r->g) {
        for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++)
            gpu_buffer_destroy(r->g, bufs[i]);
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            gpu_pipeline_destroy(r->g, &r->pipelines[i]);
    }
    bvh_destroy(&r->tree);
    memset(r, 0, sizeof *r);
}

static vec3 v3(const float *p) { return (vec3){p[0], p[1], p[2]}; }

bool renderer_camera(const renderer *r, const render_settings *s, GnCamera *out)
{
    scene_camera c;
    float aspect = (float)s->width / (float)s->height;
    if (s->camera >= 0) {
        if ((uint32_t)s->camera >= r->sc->num_cameras) {
            util_error("%s: --camera %d: the scene has %u perspective camera(s)", r->sc->path,
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
    VkPhysicalDeviceDriverProperties drv = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                      .pNext = &drv};
    vkGetPhysicalDeviceProperties2(g->physical, &p2);
    if (drv.driverID != VK_DRIVER_ID_MESA_LLVMPIPE)
        return 1u << 30;
    /* A node visit costs at most 1 + 2 * max_leaf_size iterations; 8 is the builder's cap. */
    return 60000u / (rays_per_invocation * 17u);
}

static void progress_bar(int done, int total, double elapsed)
{
    int width = 40, fill = total ? done * width / total : 0;
    fprintf(stderr, "\r[%.*s%*s] %d/%d spp  %.1fs", fill,
            "########################################", width - fill, "", done, total, elapsed);
    fflush(stderr);
}

uint32_t renderer_bindings(const renderer *r, gpu_binding *b)
{
    const gpu_binding all[] = {
        {GN_BIND_FRAME, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, &r->frame},
        {GN_BIND_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->nodes},
        {GN_BIND_TRIS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->tris},
        {GN_BIND_PRIMS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->prims},
        {GN_BIND_VERTICES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->vertices},
        {GN_BIND_MATERIALS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->materials},
        {GN_BIND_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->lights},
        {GN_BIND_TEXELS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->texels},
        {GN_BIND_TEXTURES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->textures},
        {GN_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->accum},
        {GN_BIND_AOV, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->aov},
        {GN_BIND_VCOLOR, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->vcolor},
        {GN_BIND_EMITTERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->emitters},
        {GN_BIND_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->status},
    };
    memcpy(b, all, sizeof all);
    return sizeof all / sizeof *all;
}

bool renderer_begin(renderer *r, const render_settings *s, GnFrame *frame)
{
    gpu *g = r->g;
    const VkDeviceSize pixels = (VkDeviceSize)s->width * s->height;
    memset(frame, 0, sizeof *frame);
    if (!renderer_camera(r, s, &frame->camera))
        return false;
    frame->width = (uint32_t)s->width;
    frame->height = (uint32_t)s->height;
    frame->seed = s->seed;
    frame->mode = s->mode;
    frame->max_depth = (uint32_t)s->max_depth;
    frame->num_lights = r->num_lights;
    frame->flags = (s->aov ? GN_FRAME_AOV : 0u) | (s->shadows ? GN_FRAME_SHADOWS : 0u);
    frame->env_color = (vec3){s->env[0], s->env[1], s->env[2]};
    frame->num_nodes = r->tree.num_nodes;
    frame->bounds_min = v3(r->sc->bounds_min);
    frame->bounds_max = v3(r->sc->bounds_max);
    frame->ambient = v3(r->sc->ambient);
    frame->traversal_budget = traversal_budget(g, 1 + (s->shadows ? r->num_lights : 0));
    gpu_buffer_upload(g, &r->frame, frame, sizeof *frame, 0);

    if (r->width != s->width || r->height != s->height) {
        gpu_buffer_destroy(g, &r->accum);
        gpu_buffer_destroy(g, &r->aov);
        gpu_buffer_create(g, &r->accum, 16 * pixels, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        gpu_buffer_create(g, &r->aov, 48 * pixels, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        r->width = s->width;
        r->height = s->height;
    }
    gpu_buffer_fill_zero(g, &r->accum);
    gpu_buffer_fill_zero(g, &r->aov);
    gpu_buffer_fill_zero(g, &r->status);
    return true;
}

gpu_pipeline *renderer_pipeline(renderer *r, uint32_t mode)
{
    gpu_pipeline *p = &r->pipelines[mode];
    if (!p->pipeline) {
        gpu_binding b[GN_BIND_COUNT];
        VkSpecializationMapEntry entry = {0, 0, sizeof(uint32_t)};
        VkSpecializationInfo spec = {1, &entry, sizeof mode, &mode};
        gpu_pipeline_desc pd = {
            .name = "local", .code = spv_local, .code_size = sizeof spv_local,
            .local_size = {GN_TILE_X, GN_TILE_Y, 1}, .push_size = sizeof(GnPush),
            .bindings = b, .num_bindings = renderer_bindings(r, b), .specialization = &spec};
        gpu_pipeline_create(r->g, p, &pd);
    }
    return p;
}

bool renderer_mode_available(uint32_t mode)
{
    return mode != GN_MODE_PATH && mode != GN_MODE_GOURAUD && mode != GN_MODE_FLAT;
}

void renderer_record_pass(renderer *r, VkCommandBuffer cmd, uint32_t mode, uint32_t sample_index)
{
    GnPush push = {sample_index, 0, 0, 0};
    gpu_dispatch(cmd, renderer_pipeline(r, mode), &push, (uint32_t)r->width, (uint32_t)r->height, 1);
    gpu_barrier(cmd);
}

void renderer_resolve(renderer *r, int spp, bool aov, image *out)
{
    static const char *const names[] = {"R", "G", "B", "A", "normal.X", "normal.Y",
                                        "normal.Z", "albedo.R", "albedo.G", "albedo.B",
                                        "depth.Z"};
    const VkDeviceSize pixels = (VkDeviceSize)r->width * r->height;
    const float *acc = r->accum.mapped, *aovs = r->aov.mapped;
    float inv = 1.0f / (float)spp;
    image_create(out, r->width, r->height, aov ? 11 : 4, names);
    for (VkDeviceSize p = 0; p < pixels; p++) {
        for (int c = 0; c < 4; c++)
            out->planes[c][p] = acc[4 * p + c] * inv;
        if (aov) {
            for (int c = 0; c < 3; c++) {
                out->planes[4 + c][p] = aovs[12 * p + c] * inv;
                out->planes[7 + c][p] = aovs[12 * p + 4 + c] * inv;
            }
            out->planes[10][p] = aovs[12 * p + 8] * inv;
        }
    }
}

bool renderer_render(renderer *r, const render_settings *s, image *out, render_stats *stats)
{
    gpu *g = r->g;
    GnFrame frame;
    const VkDeviceSize pixels = (VkDeviceSize)s->width * s->height;
    double t0, last_progress = 0;
    int done = 0, batch = 1;
    bool show_progress = s->progress && isatty(2);

    memset(stats, 0, sizeof *stats);
    if (!renderer_mode_available(s->mode)) {
        util_error("--mode %s is not available yet", render_mode_name(s->mode));
        return false;
    }
    if (!renderer_begin(r, s, &frame))
        return false;

    /* Passes are submitted in batches sized to take about 0.1 s each: short enough for a
     * responsive progress bar and an early stop, long enough to hide submission costs. */
    t0 = util_now();
    while (s->time_limit > 0 || done < s->spp) {
        VkCommandBuffer cmd = gpu_begin(g);
        double tb = util_now();
        int n = batch;
        if (s->time_limit <= 0 && n > s->spp - done)
            n = s->spp - done;
        for (int i = 0; i < n; i++)
            renderer_record_pass(r, cmd, s->mode, (uint32_t)(done + i));
        gpu_submit_wait(g, cmd);
        done += n;
        if (done == n)
            stats->first_pass_seconds = util_now() - t0;
        tb = util_now() - tb;
        if (tb < 0.05 && batch < 1024)
            batch *= 2;
        else if (tb > 0.2 && batch > 1)
            batch /= 2;
        if (show_progress && util_now() - last_progress > 0.1) {
            last_progress = util_now();
            progress_bar(done, s->time_limit > 0 ? done : s->spp, last_progress - t0);
        }
        if (s->stop && *s->stop)
            break;
        if (s->time_limit > 0 && util_now() - t0 >= s->time_limit)
            break;
    }
    stats->seconds = util_now() - t0;
    if (show_progress) {
        progress_bar(done, done, stats->seconds);
        fputc('\n', stderr);
    }
    stats->spp = done;
    stats->rays = (uint64_t)pixels * (uint64_t)done;
    stats->setup_seconds = r->setup_seconds;
    stats->truncated = ((const uint32_t *)r->status.mapped)[0];
    if (stats->truncated)
        util_warn("%s: %u ray(s) needed more BVH steps than the per-ray budget (%u) and may be "
                  "wrong", r->sc->path, stats->truncated, frame.traversal_budget);
    renderer_resolve(r, done, s->aov, out);
    return true;
}
