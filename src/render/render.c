/* render.c: the renderer: the scene's upload, the frame constants of a render, the kernels
 * (created and specialised on first use) and the progressive pass loop. Its other concerns
 * have their own files (render_internal.h lists them). */
#include "render.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brdf.h"
#include "render_internal.h"
#include "render_material.h"
#include "util.h"
#include "vec.h"

bool renderer_create(renderer *r, gpu *g, const scene *sc)
{
    double t0 = util_now();
    GnPrim *prims;
    GnTexture *tex;
    uint32_t *texels, total_texels = 0, *image_offset; /* the total fits: scene_fits */
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
    vertex_colors_create(r);
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
        renderer_buffers_replaced(r);
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
    out->position = vec3_of(c.position);
    out->right = vec3_of(c.right);
    out->up = vec3_of(c.up);
    out->forward = vec3_of(c.forward);
    out->tan_half_fovy = tanf(0.5f * c.yfov);
    out->ortho_half_height = c.ortho_half_height;
    out->aspect = aspect; /* the image's: a camera's own aspect only suggests the size */
    out->znear = c.znear;
    out->zfar = c.zfar;
    return true;
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


/* The path tracer's frame: its lights (render_lights.c), the GN_FEAT_* its kernel is
 * specialised on, and the loop cap. */
static bool path_begin(renderer *r, const render_settings *s, GnFrame *frame)
{
    double env;
    if (!path_lights(r, s, frame, &env))
        return false;
    const uint32_t n = frame->num_emitters;
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
bool frame_setup(renderer *r, const render_settings *s, const int region[4], GnFrame *frame)
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
                   (r->material_features & GN_FEAT_ALPHA ? GN_FRAME_ALPHA : 0u) |
                   (r->material_features & GN_FEAT_CULL ? GN_FRAME_CULL : 0u);
    frame->env_color = (vec3){s->env[0], s->env[1], s->env[2]};
    frame->env_cos = (float)cos(s->env_rotation * M_PI / 180);
    frame->env_sin = (float)-sin(s->env_rotation * M_PI / 180);
    frame->ambient = vec3_of(s->ambient_set ? s->ambient : r->sc->ambient);
    frame->traversal_budget = traversal_budget(r->g, 1 + (!s->no_shadows ? r->num_lights : 0));
    r->state_stride = 0; /* path_begin sets it, and the loop cap, for the path kernel */
    return s->mode != GN_MODE_PATH || path_begin(r, s, frame);
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
static GnFeatures kernel_features(const renderer *r, uint32_t mode)
{
    const GnFeatures spec = mode_kernel(mode)->specialised;
    return (GN_FEAT_ALL & ~spec) | (r->path_features & spec);
}

const VkSpecializationInfo *renderer_specialize(const renderer *r, uint32_t mode, renderer_spec *spec)
{
    spec->values[0] = mode;
    spec->values[1] = (uint32_t)kernel_features(r, mode);
    spec->values[2] = walk_regs(r);
    spec->values[3] = 0; /* the loop cap: only the path kernel's (renderer_pipeline) */
    spec->values[4] = (uint32_t)(kernel_features(r, mode) >> 32);
    spec->values[5] = r->geo.two_levels; /* INSTANCES */
    for (uint32_t i = 0; i < 6; i++)
        spec->entries[i] = (VkSpecializationMapEntry){i, i * (uint32_t)sizeof(uint32_t), sizeof(uint32_t)};
    assert(spec->entries[GN_SPEC_FEATURES].constantID == GN_SPEC_FEATURES &&
           spec->entries[GN_SPEC_FEATURES_HI].constantID == GN_SPEC_FEATURES_HI &&
           spec->entries[2].constantID == GN_SPEC_WALK_REGS && spec->entries[3].constantID == GN_SPEC_LOOP_CAP &&
           spec->entries[5].constantID == GN_SPEC_INSTANCES);
    spec->info = (VkSpecializationInfo){6, spec->entries, sizeof spec->values, spec->values};
    return &spec->info;
}

gpu_pipeline *renderer_pipeline(renderer *r, uint32_t mode)
{
    gpu_pipeline *p = &r->pipelines[mode];
    renderer_spec spec;
    const VkSpecializationInfo *info = renderer_specialize(r, mode, &spec);
    spec.values[3] = mode_kernel(mode)->batched ? r->loop_cap : 0u;
    if (p->pipeline && memcmp(r->pipeline_spec[mode], spec.values, sizeof spec.values))
        gpu_pipeline_destroy(r->g, p); /* built for other features: a new kernel */
    if (!p->pipeline) {
        gpu_binding b[GN_BIND_COUNT];
        gpu_pipeline_desc pd = {
            .name = mode_kernel(mode)->name, .code = mode_kernel(mode)->code,
            .code_size = mode_kernel(mode)->code_size,
            .local_size = {GN_TILE_X, GN_TILE_Y, 1}, .push_size = sizeof(GnPush),
            .bindings = b, .num_bindings = renderer_bindings(r, b), .specialization = info};
        gpu_pipeline_create(r->g, p, &pd);
        memcpy(r->pipeline_spec[mode], spec.values, sizeof spec.values);
        r->pipeline_bound[mode] = r->buffers_replaced;
    } else {
        renderer_rebind(r, p, &r->pipeline_bound[mode]);
    }
    return p;
}

void renderer_buffers_replaced(renderer *r)
{
    r->buffers_replaced++;
}

void renderer_rebind(renderer *r, gpu_pipeline *p, uint32_t *bound)
{
    gpu_binding b[GN_BIND_COUNT];
    if (*bound == r->buffers_replaced)
        return;
    gpu_pipeline_bind(r->g, p, b, renderer_bindings(r, b));
    *bound = r->buffers_replaced;
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

bool renderer_render(renderer *r, const render_settings *s, image *out, render_stats *stats)
{
    gpu *g = r->g;
    GnFrame frame;
    double t0;
    int done = 0, batch = 1, region[4], rows, bands;
    const int per = mode_kernel(s->mode)->batched ? (int)r->path_samples : 1;
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
    if (s->progress)
        s->progress(s->progress_user, s, RENDER_PROGRESS_START, done, 0);
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
            s->progress(s->progress_user, s, RENDER_PROGRESS_BATCH, done, util_now() - t0);
        if (s->stop && *s->stop)
            break;
        if (s->time_limit > 0 && util_now() - t0 >= s->time_limit)
            break;
    }
    stats->seconds = util_now() - t0;
    if (s->progress)
        s->progress(s->progress_user, s, RENDER_PROGRESS_END, done, stats->seconds);
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
