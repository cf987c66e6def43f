/* render_lights.c: the lights of a render (render_lights.h). */
#include "render_lights.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"
#include "vec.h"


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
                double a = 0.5 * vec_length_d(cr);
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
            double cr[3], a;
            if (sc->tri_material[t] != m)
                continue;
            for (int k = 0; k < 3; k++)
                p[k] = &sc->vertices[sc->indices[3 * t + k]].position.x;
            scene_triangle_cross(sc, t, cr);
            a = 0.5 * vec_length_d(cr);
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
        double len = vec_length_d(an);
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

/* With two levels: each mesh's emissive triangles, as GPU slots (*count: how many), listed
 * once so that placing them costs only the instances' emitters. */
static uint32_t *emissive_slots(const scene *sc, const render_geometry *geo, uint32_t *first, uint32_t *count)
{
    uint32_t n = 0;
    uint32_t *list = util_calloc(geo->num_slots + 1, sizeof *list);
    for (uint32_t m = 0; m < geo->num_meshes; m++) {
        uint32_t base = 2 * geo->top.pair_base[m];
        first[m] = n;
        for (uint32_t j = 0; j < geo->meshes[m].num_slots; j++) {
            const GnMaterial *mat = &sc->materials[geo->prims[base + j].material];
            if (geo->meshes[m].tri_index[j] != GN_INVALID && vec_luminance(&mat->emissive.x) > 0 &&
                !(mat->flags & GN_MAT_UNLIT))
                list[n++] = base + j;
        }
        count[m] = n - first[m];
    }
    return list;
}

/* With instances, each instance's emissive triangles, their areas in world space (a scale
 * changes them), and in l->instance the instance of each; returns the count. */
static uint32_t instanced_emitters(render_lights *l, const scene *sc, const render_geometry *geo, uint32_t n)
{
    uint32_t *first = util_calloc(geo->num_meshes, sizeof *first), *count = util_calloc(geo->num_meshes, sizeof *count);
    uint32_t *slots = emissive_slots(sc, geo, first, count);
    for (uint32_t i = 0; i < geo->top.num_instances; i++) {
        const GnInstance *in = &geo->top.instances[i];
        for (uint32_t k = first[in->mesh]; k < first[in->mesh] + count[in->mesh]; k++) {
            uint32_t j = slots[k];
            const GnPrim *pr = &geo->prims[j];
            const GnMaterial *m = &sc->materials[pr->material];
            double lum = vec_luminance(&m->emissive.x), p[3][3];
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
            l->table[n] = (GnEmitter){j, (float)area, 0, 0};
            l->instance[n] = i;
            l->weight[n++] = lum * area * (m->flags & GN_MAT_DOUBLE_SIDED ? 2 : 1);
        }
    }
    free(slots);
    free(first);
    free(count);
    return n;
}

/* (each instance's emissive triangles counted without their areas) */
uint64_t render_lights_room(const scene *sc, const render_geometry *geo)
{
    if (!geo->two_levels)
        return geo->num_slots;
    uint64_t n = 0;
    uint32_t *first = util_calloc(geo->num_meshes, sizeof *first), *count = util_calloc(geo->num_meshes, sizeof *count);
    free(emissive_slots(sc, geo, first, count));
    for (uint32_t i = 0; i < geo->top.num_instances; i++)
        n += count[geo->top.instances[i].mesh];
    free(first);
    free(count);
    return n;
}

/* The path tracer's light table: each emissive triangle (BVH order) and punctual light with
 * a selection weight proportional to its power, flux / pi: L A per emitting side for a
 * triangle (so picking one and then a uniform point has area density lum(L) sides / total),
 * 4 I for a point light, 2 (1 - cos outer) I for a spot, E r^2 for a directional light.
 * render_lights_path adds the environment and normalises. */
static void build_emitters(render_lights *l, const scene *sc, const render_geometry *geo)
{
    const GnPrim *prims = geo->prims; /* (BVH order, corners in the walk's order) */
    uint32_t cap = (uint32_t)render_lights_room(sc, geo) + sc->num_lights + 1, n = 0;
    l->table = util_calloc(cap, sizeof *l->table);
    l->weight = util_calloc(cap, sizeof *l->weight);
    l->instance = geo->two_levels ? util_calloc(cap, sizeof *l->instance) : NULL;
    if (geo->two_levels)
        n = instanced_emitters(l, sc, geo, n);
    for (uint32_t i = 0; i < geo->num_slots && !geo->two_levels; i++) {
        if (geo->world.tri_index[i] == GN_INVALID) /* the missing B of a lone triangle */
            continue;
        const GnMaterial *m = &sc->materials[prims[i].material];
        const vec3 *p0 = &sc->vertices[prims[i].i0].position, *p1 = &sc->vertices[prims[i].i1].position,
                   *p2 = &sc->vertices[prims[i].i2].position;
        double e1[3] = {p1->x - p0->x, p1->y - p0->y, p1->z - p0->z};
        double e2[3] = {p2->x - p0->x, p2->y - p0->y, p2->z - p0->z};
        double c[3];
        vec_cross_d(e1, e2, c);
        double area = 0.5 * vec_length_d(c);
        double lum = vec_luminance(&m->emissive.x);
        if (lum <= 0 || !(area > 0) || (m->flags & GN_MAT_UNLIT))
            continue;
        l->table[n] = (GnEmitter){i, (float)area, 0, 0};
        l->weight[n++] = lum * area * (m->flags & GN_MAT_DOUBLE_SIDED ? 2 : 1);
    }
    l->num_area = n;
    for (uint32_t i = 0; i < sc->num_lights; i++) {
        const GnLight *light = &sc->lights[i];
        double w = vec_luminance(&light->color.x);
        w *= light->type == GN_LIGHT_POINT ? 4 : light->type == GN_LIGHT_SPOT ? 2 * (1 - light->outer_cos)
                                                                                 : scene_radius2(sc);
        if (w <= 0)
            continue;
        if (l->instance)
            l->instance[n] = GN_INVALID;
        l->table[n] = (GnEmitter){GN_EMITTER_LIGHT | i, 0, 0, 0};
        l->weight[n++] = w;
    }
    l->num_emitters = n;
    l->cap = cap;
}

static void free_emitters(render_lights *l)
{
    free(l->table);
    free(l->weight);
    free(l->instance);
    l->table = NULL;
    l->weight = NULL;
    l->instance = NULL;
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
static bool upload_env_map(render_lights *l, gpu *g, const scene *sc, const image *map)
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
    if (words > gpu_max_texels(g, NULL)) {
        util_error("--env: the map's %dx%d texels and tables need %zu words, more than the %u "
                   "of a texel buffer on this device", w, h, words, gpu_max_texels(g, NULL));
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
            sum += vec_luminance(c) * st;
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
    if (l->env.buffer && l->env.size == words * 4) { /* (the same map again: an animation's next frame) */
        gpu_buffer_upload(g, &l->env, data, words * 4, 0);
    } else {
        gpu_buffer_destroy(g, &l->env);
        gpu_buffer_create_texels_as(g, &l->env, data, words * 4, VK_FORMAT_R32_UINT);
        l->replaced++; /* the kernels' descriptor sets name the old buffer */
    }
    /* mean L over the sphere = sum(L sin dtheta dphi) / 4 pi, dtheta dphi = 2 pi^2 / n */
    l->env_weight = scene_radius2(sc) * 2 * M_PI * M_PI * total / (double)n;
    l->env_source = map;
    free(data);
    free(row);
    return true;
}

/* The table of build_emitters, then the environment, with each one's selection pdf and CDF
 * over the weights. */
bool render_lights_path(render_lights *l, gpu *g, const scene *sc, const render_geometry *geo, const image *env_map,
                        const float env_color[3], GnFrame *frame, double *env_weight)
{
    uint32_t n = l->num_emitters;
    double total = 0, acc = 0, env = 0;
    if (env_map) {
        if (env_map != l->env_source && !upload_env_map(l, g, sc, env_map))
            return false;
        frame->flags |= GN_FRAME_ENV_MAP;
        frame->env_width = (uint32_t)env_map->width;
        frame->env_height = (uint32_t)env_map->height;
        env = l->env_weight;
    } else {
        env = 4 * M_PI * scene_radius2(sc) * vec_luminance(env_color);
    }
    if (env > 0) {
        l->table[n] = (GnEmitter){GN_INVALID, 0, 0, 0};
        l->weight[n++] = env;
    }
    for (uint32_t i = 0; i < n; i++)
        total += l->weight[i];
    for (uint32_t i = 0; i < n; i++) {
        acc += l->weight[i];
        l->table[i].pdf = (float)(l->weight[i] / total);
        l->table[i].cdf = i + 1 == n ? 1.0f : (float)(acc / total);
    }
    if (n)
        gpu_buffer_upload(g, &l->emitters, l->table, sizeof(GnEmitter) * n, 0);
    frame->num_emitters = n;
    frame->emitter_power = (float)total;
    frame->emitter_instances = geo->two_levels ? l->cap : 0;
    frame->env_select = env > 0 ? (float)(env / total) : 0;
    *env_weight = env;
    return true;
}

/* The local modes' lights: the scene's punctual ones, or stand-ins for its emissive meshes
 * (emissive_lights); sets l->num_lights (the caller frees them). */
static GnLight *local_lights(render_lights *l, const scene *sc)
{
    GnLight *lights = util_calloc(sc->num_lights + 16, sizeof *lights);
    if (sc->num_lights)
        memcpy(lights, sc->lights, sizeof *lights * sc->num_lights);
    l->num_lights = sc->num_lights ? sc->num_lights : emissive_lights(sc, lights, 16);
    return lights;
}

/* With instances, the light table's entries' instances, after the table (GnFrame.emitter_instances). */
static void upload_emitter_instances(render_lights *l, gpu *g, const render_geometry *geo)
{
    if (!geo->two_levels)
        return;
    uvec4 *inst = util_calloc(l->cap, sizeof *inst);
    for (uint32_t i = 0; i < l->num_emitters; i++)
        inst[i].x = l->instance[i];
    gpu_buffer_upload(g, &l->emitters, inst, sizeof *inst * l->cap, sizeof(GnEmitter) * l->cap);
    free(inst);
}

void render_lights_create(render_lights *l, gpu *g, const scene *sc, const render_geometry *geo)
{
    memset(l, 0, sizeof *l);
    GnLight *lights = local_lights(l, sc);
    gpu_buffer_create_storage(g, &l->lights, lights, sizeof(GnLight) * l->num_lights);
    free(lights);
    build_emitters(l, sc, geo);
    if (geo->two_levels) { /* the table, then each entry's instance (GnFrame.emitter_instances) */
        gpu_buffer_create_texels(g, &l->emitters, NULL, 2 * sizeof(GnEmitter) * l->cap);
        upload_emitter_instances(l, g, geo);
    } else {
        gpu_buffer_create_texels(g, &l->emitters, NULL, sizeof(GnEmitter) * (l->num_emitters + 1));
    }
    gpu_buffer_create_texels_as(g, &l->env, NULL, 16, VK_FORMAT_R32_UINT);
}

void render_lights_update(render_lights *l, gpu *g, const scene *sc, const render_geometry *geo)
{
    uint32_t before = l->num_lights;
    GnLight *lights = local_lights(l, sc);
    if (l->num_lights <= before) {
        gpu_buffer_upload(g, &l->lights, lights, sizeof(GnLight) * l->num_lights, 0);
    } else { /* (more of the stand-ins for emissive meshes than before: a new buffer) */
        gpu_buffer_destroy(g, &l->lights);
        gpu_buffer_create_storage(g, &l->lights, lights, sizeof(GnLight) * l->num_lights);
        l->replaced++;
    }
    free(lights);
    free_emitters(l);
    build_emitters(l, sc, geo); /* (the same room: the same triangles and lights) */
    upload_emitter_instances(l, g, geo);
    l->env_source = NULL; /* the environment's weight follows the scene's bounds */
}

void render_lights_destroy(render_lights *l, gpu *g)
{
    if (g) {
        gpu_buffer_destroy(g, &l->lights);
        gpu_buffer_destroy(g, &l->emitters);
        gpu_buffer_destroy(g, &l->env);
    }
    free_emitters(l);
    memset(l, 0, sizeof *l);
}
