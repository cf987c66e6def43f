/* render_lights.c: the lights of a render: emissive geometry as the local modes' lights,
 * the path tracer's light table (triangles, punctual lights, the environment) with its
 * selection weights, and the environment map with the CDFs that importance sample it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"
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
uint32_t emissive_lights(const scene *sc, GnLight *out, uint32_t cap)
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
            if (geo->meshes[m].tri_index[j] != GN_INVALID && vec_luminance(&mat->emissive.x) > 0 &&
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
uint64_t emitter_room(const renderer *r)
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

/* The path tracer's light table: each emissive triangle (BVH order) and punctual light with
 * a selection weight proportional to its power, flux / pi: L A per emitting side for a
 * triangle (so picking one and then a uniform point has area density lum(L) sides / total),
 * 4 I for a point light, 2 (1 - cos outer) I for a spot, E r^2 for a directional light.
 * renderer_begin adds the environment and normalises. */
void build_emitters(renderer *r, const GnPrim *prims)
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
        double c[3];
        vec_cross_d(e1, e2, c);
        double area = 0.5 * vec_length_d(c);
        double lum = vec_luminance(&m->emissive.x);
        if (lum <= 0 || !(area > 0) || (m->flags & GN_MAT_UNLIT))
            continue;
        r->emitter_table[n] = (GnEmitter){i, (float)area, 0, 0};
        r->emitter_weight[n++] = lum * area * (m->flags & GN_MAT_DOUBLE_SIDED ? 2 : 1);
    }
    r->num_area_emitters = n;
    for (uint32_t i = 0; i < sc->num_lights; i++) {
        const GnLight *l = &sc->lights[i];
        double w = vec_luminance(&l->color.x);
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
    if (r->env.buffer && r->env.size == words * 4) { /* (the same map again: an animation's next frame) */
        gpu_buffer_upload(r->g, &r->env, data, words * 4, 0);
    } else {
        gpu_buffer_destroy(r->g, &r->env);
        gpu_buffer_create_texels_as(r->g, &r->env, data, words * 4, VK_FORMAT_R32_UINT);
        renderer_buffers_replaced(r); /* the kernels' descriptor sets name the old buffer */
    }
    /* mean L over the sphere = sum(L sin dtheta dphi) / 4 pi, dtheta dphi = 2 pi^2 / n */
    r->env_weight = scene_radius2(r->sc) * 2 * M_PI * M_PI * total / (double)n;
    r->env_source = map;
    free(data);
    free(row);
    return true;
}

/* The path tracer's lights for s (render_internal.h): the table of build_emitters, then the
 * environment, with each one's selection pdf and CDF over the weights. */
bool path_lights(renderer *r, const render_settings *s, GnFrame *frame, double *env_weight)
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
        env = 4 * M_PI * scene_radius2(r->sc) * vec_luminance(s->env);
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
    *env_weight = env;
    return true;
}

/* The lights r uploads: the scene's punctual ones, or stand-ins for its emissive meshes in
 * the local modes (emissive_lights); sets r->num_lights. */
GnLight *scene_lights(renderer *r)
{
    const scene *sc = r->sc;
    GnLight *lights = util_calloc(sc->num_lights + 16, sizeof *lights);
    if (sc->num_lights)
        memcpy(lights, sc->lights, sizeof *lights * sc->num_lights);
    r->num_lights = sc->num_lights ? sc->num_lights : emissive_lights(sc, lights, 16);
    return lights;
}

/* With instances, the light table's entries' instances, after the table (GnFrame.emitter_instances). */
void upload_emitter_instances(renderer *r)
{
    if (!r->geo.two_levels)
        return;
    uvec4 *inst = util_calloc(r->emitter_cap, sizeof *inst);
    for (uint32_t i = 0; i < r->num_emitters; i++)
        inst[i].x = r->emitter_instance[i];
    gpu_buffer_upload(r->g, &r->emitters, inst, sizeof *inst * r->emitter_cap, sizeof(GnEmitter) * r->emitter_cap);
    free(inst);
}
