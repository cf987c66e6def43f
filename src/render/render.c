/* render.c: the renderer: the scene's upload, the frame constants of a render, its kernels
 * and the progressive pass loop. It composes the parts that own the rest (render.h). */
#include "render.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brdf.h"
#include "render_limits.h"
#include "render_material.h"
#include "util.h"
#include "vec.h"

/* The GN_FEAT_* the scene's materials and vertex data can need in the kernels. */
static GnFeatures scene_features(const scene *sc)
{
    GnFeatures f = GN_FEAT_NONE;
    for (uint32_t i = 0; i < sc->num_materials; i++)
        f |= material_features(&sc->materials[i]);
    if (sc->vertex_colors)
        f |= GN_FEAT_VERTEX_COLOR;
    for (uint32_t i = 0; i < sc->num_textures; i++) {
        const float *t = sc->textures[i].transform;
        if (t[0] != 1 || t[1] != 0 || t[2] != 0 || t[3] != 0 || t[4] != 1 || t[5] != 0)
            f |= GN_FEAT_TEX_TRANSFORM;
        if (sc->textures[i].flags & GN_TEX_UV1)
            f |= GN_FEAT_UV1;
    }
    return f;
}

/* Texels of the sheen's albedo table (brdf_sheen_table) at the head of the texel buffer,
 * where a material has layers (glsl/kernels/path.comp reads it from there); 0 elsewhere, so
 * other scenes keep their buffer as it was. */
static uint32_t sheen_texels(GnFeatures features)
{
    return features & GN_FEAT_LAYERS ? BRDF_SHEEN_TABLE_SIZE : 0;
}

/* The texture images packed into one texel buffer after the sheen's table (the total fits:
 * render_scene_fits), and the table of textures that index it. */
static void upload_textures(renderer *r)
{
    const scene *sc = r->sc;
    const uint32_t sheen = sheen_texels(r->material_features);
    uint32_t *image_offset = util_calloc(sc->num_images + 1, sizeof *image_offset), total = sheen;
    for (uint32_t i = 0; i < sc->num_images; i++) {
        image_offset[i] = total;
        total += sc->images[i].width * sc->images[i].height;
    }
    uint32_t *texels = util_malloc(sizeof *texels * (total + 1));
    texels[total] = 0; /* the buffer is never empty */
    memcpy(texels, brdf_sheen_table, sizeof *texels * sheen);
    for (uint32_t i = 0; i < sc->num_images; i++)
        memcpy(texels + image_offset[i], sc->images[i].rgba8, (size_t)sc->images[i].width * sc->images[i].height * 4);
    GnTexture *tex = util_calloc(sc->num_textures + 1, sizeof *tex);
    for (uint32_t i = 0; i < sc->num_textures; i++) {
        const scene_image *im = &sc->images[sc->textures[i].image];
        const float *t = sc->textures[i].transform;
        tex[i] = (GnTexture){image_offset[sc->textures[i].image], im->width, im->height,
                             sc->textures[i].flags, {t[0], t[1], t[2]}, 0, {t[3], t[4], t[5]}, 0};
    }
    gpu_buffer_create_texels_as(r->g, &r->texels, texels, sizeof(uint32_t) * (total + 1), VK_FORMAT_R32_UINT);
    gpu_buffer_create_texels(r->g, &r->textures, tex, sizeof(GnTexture) * (sc->num_textures + 1));
    free(image_offset);
    free(texels);
    free(tex);
}

/* The renderer's own buffers: the frame, the counters and the scene's arrays. */
static void upload_scene(renderer *r)
{
    gpu *g = r->g;
    const render_geometry *geo = &r->geo;
    gpu_buffer_create(g, &r->frame, sizeof(GnFrame), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_create(g, &r->status, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_create_texels(g, &r->nodes, geo->nodes, sizeof(GnBvhNode) * geo->num_nodes);
    gpu_buffer_create_texels(g, &r->tris, geo->pairs, sizeof(GnTriPair) * geo->num_pairs);
    gpu_buffer_create_texels(g, &r->prims, geo->prims, sizeof(GnPrim) * geo->num_slots);
    gpu_buffer_create_texels(g, &r->vertices, geo->vertices, sizeof(GnVertex) * geo->num_vertices);
    gpu_buffer_create_texels(g, &r->materials, r->sc->materials, sizeof(GnMaterial) * r->sc->num_materials);
    upload_textures(r);
    if (geo->two_levels)
        gpu_buffer_create_texels(g, &r->instances, geo->top.instances, sizeof(GnInstance) * geo->top.num_instances);
    else
        gpu_buffer_create_texels(g, &r->instances, NULL, 16);
}

bool renderer_create(renderer *r, gpu *g, const scene *sc)
{
    double t0 = util_now();
    memset(r, 0, sizeof *r);
    r->g = g;
    r->sc = sc;
    if (!render_geometry_build(&r->geo, sc)) {
        r->failed = true;
        return false;
    }
    r->material_features = r->path_features = scene_features(sc);
    if (!render_scene_fits(g, sc, &r->geo, sheen_texels(r->material_features), render_lights_room(sc, &r->geo))) {
        r->failed = true;
        return false;
    }
    r->path_samples = render_path_samples(g, &r->geo);
    upload_scene(r);
    render_lights_create(&r->lights, g, sc, &r->geo);
    render_gouraud_create(&r->gouraud, g, sc, &r->geo);
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
    render_lights_update(&r->lights, r->g, sc, &r->geo);
    r->setup_seconds = util_now() - t0;
    return true;
}

void renderer_destroy(renderer *r)
{
    gpu_buffer *bufs[] = {&r->frame, &r->status, &r->nodes, &r->tris, &r->prims, &r->vertices,
                          &r->materials, &r->texels, &r->textures, &r->instances};
    for (size_t i = 0; r->g && i < sizeof bufs / sizeof *bufs; i++)
        gpu_buffer_destroy(r->g, bufs[i]);
    render_kernels_destroy(&r->kernels, r->g);
    render_gouraud_destroy(&r->gouraud, r->g);
    render_lights_destroy(&r->lights, r->g);
    render_accum_destroy(&r->accum, r->g);
    render_geometry_destroy(&r->geo);
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
        {GN_BIND_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->lights.lights},
        {GN_BIND_TEXELS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->texels},
        {GN_BIND_TEXTURES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->textures},
        {GN_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->accum.accum},
        {GN_BIND_AOV, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->accum.aov},
        {GN_BIND_VCOLOR, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->gouraud.vcolor},
        {GN_BIND_EMITTERS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->lights.emitters},
        {GN_BIND_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->status},
        {GN_BIND_SQUARES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->accum.squares},
        {GN_BIND_ENV, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->lights.env},
        {GN_BIND_PSTATE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->accum.pstate},
        {GN_BIND_INSTANCES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->instances},
    };
    _Static_assert(sizeof all / sizeof *all <= GN_BIND_COUNT, "more bindings than GN_BIND_COUNT");
    memcpy(b, all, sizeof all);
    return sizeof all / sizeof *all;
}

/* How often the parts have made a buffer the kernels bind anew: a kernel whose descriptor
 * set was written at another count is pointed at the current buffers (render_kernels_get). */
static uint32_t buffers_generation(const renderer *r)
{
    return r->accum.replaced + r->lights.replaced;
}

/* The path tracer's frame: its lights (render_lights.h), the GN_FEAT_* its kernel is
 * specialised on, and the loop cap. */
static bool path_begin(renderer *r, const render_settings *s, GnFrame *frame)
{
    double env;
    if (!render_lights_path(&r->lights, r->g, r->sc, &r->geo, s->env_map, s->env, frame, &env))
        return false;
    const uint32_t n = frame->num_emitters;
    frame->flags |= s->strategy;
    r->path_features = r->material_features | (s->aov & RENDER_AOV_GPU ? GN_FEAT_AOV : 0u) |
                       (s->aov & RENDER_AOV_VARIANCE ? GN_FEAT_VARIANCE : 0u) |
                       (s->strategy ? GN_FEAT_STRATEGY : 0u) | (n > 1 ? GN_FEAT_LIGHT_SEARCH : 0u) |
                       (env > 0 || s->env[0] != 0 || s->env[1] != 0 || s->env[2] != 0 ? GN_FEAT_ENV : 0u) |
                       (s->env_map ? GN_FEAT_ENV | GN_FEAT_ENV_MAP : 0u);
    if (r->lights.num_emitters > r->lights.num_area) /* punctual lights follow the triangles */
        r->path_features |= GN_FEAT_PUNCTUAL;
    /* The unspecialised kernel, for checking that specialisation changes nothing
     * (tests/regress/path.sh) and for ruling it out when chasing a bug. */
    if (getenv("GONIO_ALL_FEATURES"))
        r->path_features = GN_FEAT_ALL;
    frame->traversal_budget = render_traversal_budget(r->g, 1); /* (unused: path.comp has loop_cap) */
    r->state_stride = render_state_stride(r->g, &r->geo);
    r->loop_cap = render_loop_setup(r->state_stride, frame);
    r->sampler = s->sampler;
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
    frame->num_lights = r->lights.num_lights;
    frame->flags = (s->aov & RENDER_AOV_GPU ? GN_FRAME_AOV : 0u) | (!s->no_shadows ? GN_FRAME_SHADOWS : 0u) |
                   (s->aov & RENDER_AOV_VARIANCE ? GN_FRAME_VARIANCE : 0u) |
                   (r->sc->vertex_colors ? GN_FRAME_VERTEX_COLOR : 0u) |
                   (r->material_features & GN_FEAT_ALPHA ? GN_FRAME_ALPHA : 0u) |
                   (r->material_features & GN_FEAT_CULL ? GN_FRAME_CULL : 0u);
    frame->env_color = (vec3){s->env[0], s->env[1], s->env[2]};
    frame->env_cos = (float)cos(s->env_rotation * M_PI / 180);
    frame->env_sin = (float)-sin(s->env_rotation * M_PI / 180);
    frame->ambient = vec3_of(s->ambient_set ? s->ambient : r->sc->ambient);
    frame->traversal_budget = render_traversal_budget(r->g, 1 + (!s->no_shadows ? r->lights.num_lights : 0));
    r->state_stride = 0; /* path_begin sets it, and the loop cap, for the path kernel */
    return s->mode != GN_MODE_PATH || path_begin(r, s, frame);
}

/* The rows of a region one set of accumulation buffers holds (render_accum_rows). */
static int region_rows(const renderer *r, const render_settings *s, int rw, int rh, char *why, size_t why_size)
{
    const uint32_t stride = s->mode == GN_MODE_PATH ? render_state_stride(r->g, &r->geo) : 0;
    return render_accum_rows(r->g, r->sc->path, rw, rh, s->aov, stride, why, why_size);
}

/* Gouraud's vertex pass, where the mode has one (GN_MODEF_VERTEX_LIGHT), for the frame just
 * uploaded. */
static bool light_vertices(renderer *r, uint32_t mode)
{
    gpu_binding b[GN_BIND_COUNT];
    if (!(render_modes[mode].flags & GN_MODEF_VERTEX_LIGHT))
        return true;
    return render_gouraud_light(&r->gouraud, r->g, r->sc->path, r->geo.two_levels, b, renderer_bindings(r, b),
                                buffers_generation(r));
}

bool renderer_begin(renderer *r, const render_settings *s, GnFrame *frame)
{
    int region[4];
    render_region(s, region);
    const int rw = region[2] - region[0], rh = region[3] - region[1];
    char why[256];
    assert(rw > 0 && rh > 0 && region[0] >= 0 && region[1] >= 0 && region[2] <= s->width &&
           region[3] <= s->height);
    if (r->failed)
        return false;
    int rows = region_rows(r, s, rw, rh, why, sizeof why);
    if (rows == 0)
        return false;
    if (rows < rh) {
        util_error("%s: %dx%d pixels in one piece: %s (gonio render renders it in bands)",
                   r->sc->path, rw, rh, why);
        return false;
    }
    if (!frame_setup(r, s, region, frame))
        return false;
    gpu_buffer_upload(r->g, &r->frame, frame, sizeof *frame, 0);
    render_accum_begin(&r->accum, r->g, rw, rh, s->aov, r->state_stride);
    gpu_buffer_fill_zero(r->g, &r->status);
    return light_vertices(r, s->mode);
}

/* A render in bands of `rows` rows: the frame for the first band (each band's is uploaded
 * before its passes), one set of buffers for all, the whole region's sums on the host. */
static bool begin_bands(renderer *r, const render_settings *s, const int region[4], int rows, GnFrame *frame)
{
    if (!frame_setup(r, s, region, frame))
        return false;
    render_accum_begin_bands(&r->accum, r->g, region[2] - region[0], region[3] - region[1], rows, s->aov,
                             r->state_stride);
    gpu_buffer_fill_zero(r->g, &r->status);
    return light_vertices(r, s->mode);
}

/* Band b's frame uploaded and its sums loaded into the buffers (load), or its sums put back
 * (!load). */
static void band_swap(renderer *r, GnFrame *frame, const int region[4], int rows, int b, bool load)
{
    const int y0 = b * rows, rh = region[3] - region[1], bh = rh - y0 < rows ? rh - y0 : rows;
    if (load) {
        frame->crop_y = (uint32_t)(region[1] + y0);
        frame->crop_height = (uint32_t)bh;
        gpu_buffer_upload(r->g, &r->frame, frame, sizeof *frame, 0);
    }
    render_accum_band_swap(&r->accum, y0, bh, load);
}

/* The key of mode's kernel for r's scene and current render. */
static render_kernel_key kernel_key(const renderer *r, uint32_t mode)
{
    return (render_kernel_key){mode, r->path_features, render_walk_regs(&r->geo), r->loop_cap, r->geo.two_levels,
                               r->sampler};
}

const VkSpecializationInfo *renderer_specialize(const renderer *r, uint32_t mode, render_spec *spec)
{
    render_kernel_key key = kernel_key(r, mode);
    key.loop_cap = 0; /* (only the renderer's own batched kernels resume past the cap) */
    return render_kernel_specialize(&key, spec);
}

gpu_pipeline *renderer_pipeline(renderer *r, uint32_t mode)
{
    gpu_binding b[GN_BIND_COUNT];
    const render_kernel_key key = kernel_key(r, mode);
    return render_kernels_get(&r->kernels, r->g, &key, b, renderer_bindings(r, b), buffers_generation(r));
}

void renderer_record_samples(renderer *r, VkCommandBuffer cmd, uint32_t mode, uint32_t first,
                             uint32_t count)
{
    /* A batched kernel takes up to path_samples samples per dispatch (glsl/kernels/path.comp: a lane
     * whose path ends starts its next one); the others one. */
    uint32_t per = render_mode_kernel(mode)->batched ? r->path_samples : 1u;
    for (uint32_t i = 0; i < count; i += per) {
        GnPush push = {first + i, 0, count - i < per ? count - i : per, 0};
        gpu_dispatch(cmd, renderer_pipeline(r, mode), &push, (uint32_t)r->accum.width, (uint32_t)r->accum.height, 1);
        gpu_barrier(cmd);
    }
}

uint32_t renderer_finish(renderer *r, uint32_t mode, uint32_t next)
{
    uint32_t n = 0;
    /* status[1]: the pixels pending after the last dispatch. Each dispatch that takes no new
     * samples gives every pending pixel one more invocation's worth of loop passes. */
    volatile const uint32_t *pending = (const uint32_t *)r->status.mapped + 1;
    while (render_mode_kernel(mode)->batched && r->loop_cap && *pending) {
        VkCommandBuffer cmd = gpu_begin(r->g);
        GnPush push = {next, 0, 0, 0};
        gpu_dispatch(cmd, renderer_pipeline(r, mode), &push, (uint32_t)r->accum.width, (uint32_t)r->accum.height, 1);
        gpu_barrier(cmd);
        gpu_submit_wait(r->g, cmd);
        n++;
    }
    return n;
}

void renderer_resolve(renderer *r, int spp, uint32_t aov, image *out)
{
    render_accum_resolve(&r->accum, spp, aov, out);
}

void renderer_sums(const renderer *r, int spp, uint32_t aov, image *out)
{
    render_accum_sums(&r->accum, spp, aov, out);
}

/* A render's region as bands of `rows` rows (one band: the whole region). */
typedef struct render_bands {
    int region[4];
    int rows, count;
} render_bands;

/* The bands the region of s needs, its buffers and frame set up for the first pass, the
 * sums of s->resume loaded: false (with an error) when it cannot start. */
static bool render_start(renderer *r, const render_settings *s, render_bands *bands, GnFrame *frame)
{
    char why[256];
    render_region(s, bands->region);
    const int rw = bands->region[2] - bands->region[0], rh = bands->region[3] - bands->region[1];
    if ((bands->rows = region_rows(r, s, rw, rh, why, sizeof why)) == 0)
        return false;
    bands->count = (rh + bands->rows - 1) / bands->rows;
    if (bands->count > 1) {
        /* Bands of about equal height, whole 8-row tiles where that stays within the limit. */
        int even = (rh + bands->count - 1) / bands->count;
        int tiled = (even + (int)GN_TILE_Y - 1) / (int)GN_TILE_Y * (int)GN_TILE_Y;
        bands->rows = tiled <= bands->rows ? tiled : even;
        bands->count = (rh + bands->rows - 1) / bands->rows;
        util_info("%dx%d rendered in %d bands of %d rows: %s", rw, rh, bands->count, bands->rows, why);
        if (!begin_bands(r, s, bands->region, bands->rows, frame))
            return false;
    } else if (!renderer_begin(r, s, frame)) {
        return false;
    }
    return !s->resume || render_accum_load(&r->accum, s->resume, s->aov);
}

/* Passes are submitted in batches sized to take 0.1 to 0.4 s each (per band): short enough
 * for a responsive progress bar and an early stop, long enough to hide submission costs and
 * to let the path kernel take several samples per dispatch (renderer_record_samples). The
 * kernels add each sample to the buffers' sums in sample order (glsl/kernels/path.comp), so
 * the bits do not depend on how the batches, dispatches and bands split the samples: the
 * same command gives the same bits, and so do a render resumed from its sums (s->resume), a
 * crop of it (GnFrame) and one in bands. A batch goes through every band before the next, so
 * all pixels always have the same samples: a stop or --time ends the render after a whole
 * round. Returns the samples per pixel taken, from `done`. */
static int render_passes(renderer *r, const render_settings *s, const render_bands *bands, GnFrame *frame,
                         int done, render_stats *stats)
{
    const int per = render_mode_kernel(s->mode)->batched ? (int)r->path_samples : 1, first = done;
    int batch = 1;
    double t0 = util_now();
    if (s->progress)
        s->progress(s->progress_user, s, RENDER_PROGRESS_START, done, 0);
    while (s->time_limit > 0 || done < s->spp) {
        double tb = util_now();
        int n = batch * per;
        if (s->time_limit <= 0 && n > s->spp - done)
            n = s->spp - done;
        for (int b = 0; b < bands->count; b++) {
            if (bands->count > 1)
                band_swap(r, frame, bands->region, bands->rows, b, true);
            VkCommandBuffer cmd = gpu_begin(r->g);
            renderer_record_samples(r, cmd, s->mode, (uint32_t)done, (uint32_t)n);
            gpu_submit_wait(r->g, cmd);
            stats->resumes += renderer_finish(r, s->mode, (uint32_t)(done + n));
            if (bands->count > 1)
                band_swap(r, frame, bands->region, bands->rows, b, false);
        }
        done += n;
        if (done == first + n)
            stats->first_pass_seconds = util_now() - t0;
        tb = (util_now() - tb) / bands->count;
        if (tb < 0.1 && batch < 1024)
            batch *= 2;
        else if (tb > 0.4 && batch > 1)
            batch /= 2;
        if (s->progress)
            s->progress(s->progress_user, s, RENDER_PROGRESS_BATCH, done, util_now() - t0);
        if ((s->stop && *s->stop) || (s->time_limit > 0 && util_now() - t0 >= s->time_limit))
            break;
    }
    stats->seconds = util_now() - t0;
    if (s->progress)
        s->progress(s->progress_user, s, RENDER_PROGRESS_END, done, stats->seconds);
    return done;
}

/* The kernels' counters after the passes: walks cut short. */
static void render_check(const renderer *r, const render_settings *s, const GnFrame *frame, render_stats *stats)
{
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
                  "wrong", r->sc->path, stats->truncated, frame->traversal_budget);
}

bool renderer_render(renderer *r, const render_settings *s, image *out, render_stats *stats)
{
    GnFrame frame;
    render_bands bands;
    memset(stats, 0, sizeof *stats);
    assert(s->mode < GN_MODE_COUNT);
    if (r->failed || !render_start(r, s, &bands, &frame))
        return false;
    stats->bands = bands.count;
    const int resumed = s->resume ? s->resume_spp : 0;
    /* The kernel is compiled first, so that --time, the progress and the rates count
     * rendering, not the driver's compiler (the setup time includes it). */
    double t0 = util_now();
    renderer_pipeline(r, s->mode);
    stats->setup_seconds = r->setup_seconds + (util_now() - t0);
    stats->spp = render_passes(r, s, &bands, &frame, resumed, stats);
    const VkDeviceSize pixels = (VkDeviceSize)(bands.region[2] - bands.region[0]) * (bands.region[3] - bands.region[1]);
    stats->rays = (uint64_t)pixels * (uint64_t)(stats->spp - resumed);
    render_check(r, s, &frame, stats);
    renderer_resolve(r, stats->spp, s->aov, out);
    return true;
}
