/* scene.c: the loader-independent parts of a scene: freeing, bounds, triangle validation, a
 * framing camera, and the glTF metallic-roughness -> OpenGL Phong mapping (Beckmann/Blinn-Phong
 * exponent correspondence of Walter et al. 2007, "Microfacet models for refraction"). */
#include "scene.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"
#include "vec.h"

void scene_destroy(scene *s)
{
    for (uint32_t i = 0; i < s->num_images; i++)
        free(s->images[i].rgba8);
    free(s->vertices);
    free(s->indices);
    free(s->tri_material);
    free(s->materials);
    free(s->material_extras);
    free(s->material_names);
    free(s->variant_names);
    free(s->extensions);
    free(s->lights);
    free(s->images);
    free(s->textures);
    free(s->cameras);
    image_destroy(&s->environment);
    scene_free_instances(s);
    memset(s, 0, sizeof *s);
}

void scene_compute_bounds(scene *s)
{
    for (int k = 0; k < 3; k++) {
        s->bounds_min[k] = FLT_MAX;
        s->bounds_max[k] = -FLT_MAX;
    }
    for (uint32_t i = 0; i < 3 * s->num_triangles; i++) {
        const vec3 *p = &s->vertices[s->indices[i]].position;
        const float c[3] = {p->x, p->y, p->z};
        for (int k = 0; k < 3; k++) {
            s->bounds_min[k] = fminf(s->bounds_min[k], c[k]);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], c[k]);
        }
    }
    scene_bound_instances(s);
}

void scene_triangle_cross(const scene *s, uint32_t t, double out[3])
{
    const float *p[3];
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++)
        p[k] = &s->vertices[s->indices[3 * t + k]].position.x;
    for (int k = 0; k < 3; k++) {
        e1[k] = p[1][k] - p[0][k];
        e2[k] = p[2][k] - p[0][k];
    }
    vec_cross_d(e1, e2, out);
}

static bool position_ok(const vec3 *p)
{
    return isfinite(p->x) && isfinite(p->y) && isfinite(p->z) && fabsf(p->x) <= 1e15f &&
           fabsf(p->y) <= 1e15f && fabsf(p->z) <= 1e15f;
}

uint32_t scene_drop_invalid_triangles_of(GnVertex *vertices, uint32_t num_vertices, uint32_t *indices,
                                         uint32_t *tri_material, uint32_t *num_triangles)
{
    uint32_t kept = 0;
    for (uint32_t t = 0; t < *num_triangles; t++) {
        const uint32_t *tri = &indices[3 * t];
        if (!position_ok(&vertices[tri[0]].position) || !position_ok(&vertices[tri[1]].position) ||
            !position_ok(&vertices[tri[2]].position))
            continue;
        memmove(&indices[3 * kept], tri, 3 * sizeof *tri);
        tri_material[kept++] = tri_material[t];
    }
    for (uint32_t v = 0; v < num_vertices; v++)
        if (!position_ok(&vertices[v].position))
            memset(&vertices[v], 0, sizeof vertices[v]);
    uint32_t dropped = *num_triangles - kept;
    *num_triangles = kept;
    return dropped;
}

uint32_t scene_drop_invalid_triangles(scene *s)
{
    return scene_drop_invalid_triangles_of(s->vertices, s->num_vertices, s->indices, s->tri_material,
                                           &s->num_triangles) +
           scene_drop_invalid_instanced(s);
}

void scene_default_camera(const scene *s, float aspect, scene_camera *out)
{
    scene_frame_camera(s, aspect, (float)(M_PI / 4), out);
}

void scene_frame_camera(const scene *s, float aspect, float yfov, scene_camera *out)
{
    assert(aspect > 0 && isfinite(aspect) && yfov > 0 && yfov < (float)M_PI);
    const float tan_v = tanf(0.5f * yfov), tan_h = tan_v * aspect;
    float c[3] = {0, 0, 0}, half[3] = {0.5f, 0.5f, 0.5f};
    if (s->bounds_min[0] <= s->bounds_max[0]) {
        float cmax = 0;
        for (int k = 0; k < 3; k++) {
            c[k] = 0.5f * (s->bounds_min[k] + s->bounds_max[k]);
            half[k] = 0.5f * (s->bounds_max[k] - s->bounds_min[k]);
            cmax = fmaxf(cmax, fabsf(c[k]));
        }
        /* A point (or a box below float resolution at its position) still needs a box the
         * camera can stand outside of. */
        float floor = 1e-5f * fmaxf(1.0f, cmax);
        for (int k = 0; k < 3; k++)
            half[k] = fmaxf(half[k], floor);
    }
    /* A raised three-quarter view, as model viewers open a file: glTF models face +Z with +Y
     * up, so the camera stands in front (+Z), turned toward +X and raised, looking toward the
     * centre with a level horizon. Straight down an axis, a box looks like a flat square. */
    const float az = (float)(SCENE_FRAME_AZIMUTH * M_PI / 180), el = (float)(SCENE_FRAME_ELEVATION * M_PI / 180);
    const float dir[3] = {sinf(az) * cosf(el), sinf(el), cosf(az) * cosf(el)};
    const float right[3] = {cosf(az), 0, -sinf(az)};                                   /* forward x (0, 1, 0) */
    const float up[3] = {-sinf(el) * sinf(az), cosf(el), -sinf(el) * cosf(az)}; /* right x forward */
    /* The nearest distance along dir from which every corner of the bounding box projects
     * inside the frame, less SCENE_FRAME_MARGIN: the box, not its bounding sphere, so that a
     * model fills the frame (a cube's sphere leaves it at 58 % of the width). A corner at
     * depth z toward the camera and offset x across it fits when |x - shift| <= tan * (dist -
     * z). Perspective makes the near corners' side of the picture larger, so the camera also
     * moves across (shift, keeping its direction) until the picture is centred: a few rounds
     * of centring, then the distance at which every corner fits with the final shift. */
    const float fit = 1 - SCENE_FRAME_MARGIN;
    float px[8], py[8], pz[8], zmin = INFINITY, zmax = -INFINITY;
    for (int i = 0; i < 8; i++) {
        float p[3] = {i & 1 ? half[0] : -half[0], i & 2 ? half[1] : -half[1], i & 4 ? half[2] : -half[2]};
        px[i] = py[i] = pz[i] = 0;
        for (int k = 0; k < 3; k++) {
            px[i] += p[k] * right[k];
            py[i] += p[k] * up[k];
            pz[i] += p[k] * dir[k];
        }
        zmin = fminf(zmin, pz[i]);
        zmax = fmaxf(zmax, pz[i]);
    }
    float dist = 0, sx = 0, sy = 0;
    for (int round = 0; round < 8; round++) {
        dist = 0;
        for (int i = 0; i < 8; i++)
            dist = fmaxf(dist, fmaxf(fabsf(px[i] - sx) / (fit * tan_h), fabsf(py[i] - sy) / (fit * tan_v)) + pz[i]);
        /* Every corner in front of the camera, with room for a near plane. */
        dist = fmaxf(dist, 1.01f * zmax + 1e-6f * (zmax - zmin));
        if (round == 7)
            break;
        float lox = INFINITY, hix = -INFINITY, loy = INFINITY, hiy = -INFINITY;
        for (int i = 0; i < 8; i++) {
            float d = dist - pz[i];
            lox = fminf(lox, (px[i] - sx) / d), hix = fmaxf(hix, (px[i] - sx) / d);
            loy = fminf(loy, (py[i] - sy) / d), hiy = fmaxf(hiy, (py[i] - sy) / d);
        }
        sx += 0.5f * (lox + hix) * dist;
        sy += 0.5f * (loy + hiy) * dist;
    }
    memset(out, 0, sizeof *out);
    strcpy(out->name, "framing");
    for (int k = 0; k < 3; k++) {
        out->position[k] = c[k] + sx * right[k] + sy * up[k] + dist * dir[k];
        out->forward[k] = -dir[k];
        out->right[k] = right[k];
        out->up[k] = up[k];
    }
    out->yfov = yfov;
    out->aspect = aspect;
    out->znear = 0.5f * (dist - zmax);
    out->zfar = 2.0f * (dist - zmin);
}

/* The table's defaults: a factor's own, each component; a texture slot's none. */
static void set_default(float *v, int n, float def)
{
    for (int k = 0; k < n; k++)
        v[k] = def;
}
#define DEFAULT_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) \
    set_default((float *)&m->name, GN_MAT_COUNT_##type, (float)(def));
#define DEFAULT_TEX(name, word, ext, json, space, gate, uses) m->name = GN_INVALID;

void scene_material_default(GnMaterial *m)
{
    memset(m, 0, sizeof *m);
    GN_MATERIAL(DEFAULT_PARAM, DEFAULT_TEX, GN_MAT_NO_FIELD)
    scene_phong_from_pbr(m);
}

static float mixf(float a, float b, float t) { return a + (b - a) * t; }

void scene_phong_from_pbr(GnMaterial *m)
{
    const float base[3] = {m->base_color.x, m->base_color.y, m->base_color.z};
    const float tint[3] = {m->specular_color.x, m->specular_color.y, m->specular_color.z};
    float diffuse[3], specular[3];
    /* the dielectric's F0 factor: 0.04 at glTF's ior 1.5, 1 at KHR_materials_ior's 0 (as
     * KHR_materials_pbrSpecularGlossiness is read); the specular-glossiness diffuse colour
     * is times 1 - max(F0) (GN_MAT_SPEC_GLOSS) */
    float r = (m->ior - 1) / (m->ior + 1), f0 = r * r, kd = 1;
    if (m->flags & GN_MAT_SPEC_GLOSS)
        kd = 1 - fmaxf(tint[0], fmaxf(tint[1], tint[2]));
    for (int k = 0; k < 3; k++) {
        diffuse[k] = kd * base[k] * (1 - m->metallic) * (1 - m->transmission);
        specular[k] = mixf(fminf(f0 * tint[k], 1) * m->specular, base[k], m->metallic);
    }
    m->phong_diffuse = (vec3){diffuse[0], diffuse[1], diffuse[2]};
    m->phong_ambient = m->phong_diffuse;
    m->phong_specular = (vec3){specular[0], specular[1], specular[2]};
    m->phong_emission = m->emissive;
    float alpha = m->roughness * m->roughness;
    float a2 = alpha * alpha;
    float n = a2 > 0 ? 2 / a2 - 2 : 10000;
    m->phong_shininess = fminf(fmaxf(n, 1), 10000);
}
