/* scene_instances.c: the instanced meshes and instances of a scene (scene.h): bounds, the
 * triangles they place, the invalid ones dropped, and whether two loads of a file differ
 * only in the instances' transforms (an animated frame). */
#include "scene.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

static void mesh_free(scene_instanced_mesh *im)
{
    free(im->vertices);
    free(im->indices);
    free(im->tri_material);
}

void scene_free_instances(scene *s)
{
    for (uint32_t m = 0; m < s->num_instanced_meshes; m++)
        mesh_free(&s->instanced_meshes[m]);
    free(s->instanced_meshes);
    free(s->instances);
    s->instanced_meshes = NULL;
    s->instances = NULL;
    s->num_instanced_meshes = s->num_instances = 0;
}

uint64_t scene_placed_triangles(const scene *s)
{
    uint64_t n = s->num_triangles;
    for (uint32_t i = 0; i < s->num_instances; i++)
        n += s->instanced_meshes[s->instances[i].mesh].num_triangles;
    return n;
}

static void mesh_bounds(scene_instanced_mesh *m)
{
    for (int k = 0; k < 3; k++) {
        m->bounds_min[k] = FLT_MAX;
        m->bounds_max[k] = -FLT_MAX;
    }
    for (uint32_t i = 0; i < 3 * m->num_triangles; i++) {
        const float *p = &m->vertices[m->indices[i]].position.x;
        for (int k = 0; k < 3; k++) {
            m->bounds_min[k] = fminf(m->bounds_min[k], p[k]);
            m->bounds_max[k] = fmaxf(m->bounds_max[k], p[k]);
        }
    }
}

void scene_instance_box(const scene *s, uint32_t i, float lo[3], float hi[3])
{
    const scene_instance *in = &s->instances[i];
    const scene_instanced_mesh *m = &s->instanced_meshes[in->mesh];
    double l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 8; c++) {
        const double p[3] = {c & 1 ? m->bounds_max[0] : m->bounds_min[0], c & 2 ? m->bounds_max[1] : m->bounds_min[1],
                             c & 4 ? m->bounds_max[2] : m->bounds_min[2]};
        for (int r = 0; r < 3; r++) {
            const float *t = in->to_world + 4 * r;
            double x = t[0] * p[0] + t[1] * p[1] + t[2] * p[2] + t[3];
            l[r] = fmin(l[r], x);
            h[r] = fmax(h[r], x);
        }
    }
    for (int k = 0; k < 3; k++) {
        lo[k] = (float)l[k];
        hi[k] = (float)h[k];
    }
}

void scene_bound_instances(scene *s)
{
    for (uint32_t m = 0; m < s->num_instanced_meshes; m++)
        mesh_bounds(&s->instanced_meshes[m]);
    for (uint32_t i = 0; i < s->num_instances; i++) {
        float lo[3], hi[3];
        scene_instance_box(s, i, lo, hi);
        for (int k = 0; k < 3; k++) {
            s->bounds_min[k] = fminf(s->bounds_min[k], lo[k]);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], hi[k]);
        }
    }
}

void scene_instance_triangle_cross(const scene *s, uint32_t i, uint32_t t, double out[3])
{
    const scene_instance *in = &s->instances[i];
    const scene_instanced_mesh *m = &s->instanced_meshes[in->mesh];
    double p[3][3], e1[3], e2[3];
    for (int c = 0; c < 3; c++) {
        const float *q = &m->vertices[m->indices[3 * t + c]].position.x;
        for (int r = 0; r < 3; r++) {
            const float *w = in->to_world + 4 * r;
            p[c][r] = (double)w[0] * q[0] + (double)w[1] * q[1] + (double)w[2] * q[2] + w[3];
        }
    }
    for (int k = 0; k < 3; k++) {
        e1[k] = p[1][k] - p[0][k];
        e2[k] = p[2][k] - p[0][k];
    }
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

uint32_t scene_drop_invalid_instanced(scene *s)
{
    uint32_t dropped = 0, meshes = 0, kept = 0;
    uint32_t *uses = util_calloc(s->num_instanced_meshes + 1, sizeof *uses);
    for (uint32_t m = 0; m < s->num_instanced_meshes; m++) {
        scene_instanced_mesh *im = &s->instanced_meshes[m];
        uint32_t before = im->num_triangles;
        scene_drop_invalid_triangles_of(im->vertices, im->num_vertices, im->indices, im->tri_material,
                                        &im->num_triangles);
        for (uint32_t i = 0; i < s->num_instances; i++)
            dropped += s->instances[i].mesh == m ? before - im->num_triangles : 0;
        mesh_bounds(im);
    }
    /* instances of emptied meshes, or whose world box overflows what rays can test */
    for (uint32_t i = 0; i < s->num_instances; i++) {
        const scene_instance *in = &s->instances[i];
        float lo[3], hi[3];
        bool ok = s->instanced_meshes[in->mesh].num_triangles > 0;
        if (ok) {
            scene_instance_box(s, i, lo, hi);
            for (int k = 0; k < 3; k++)
                ok = ok && isfinite(lo[k]) && isfinite(hi[k]) && fabsf(lo[k]) <= 1e15f && fabsf(hi[k]) <= 1e15f;
        }
        if (!ok) {
            dropped += s->instanced_meshes[in->mesh].num_triangles;
            continue;
        }
        s->instances[kept++] = *in;
        uses[in->mesh]++;
    }
    s->num_instances = kept;
    /* meshes no instance uses any more */
    uint32_t *to = util_calloc(s->num_instanced_meshes + 1, sizeof *to);
    for (uint32_t m = 0; m < s->num_instanced_meshes; m++) {
        scene_instanced_mesh *im = &s->instanced_meshes[m];
        if (uses[m] == 0) {
            mesh_free(im);
            continue;
        }
        to[m] = meshes;
        s->instanced_meshes[meshes++] = *im;
    }
    s->num_instanced_meshes = meshes;
    for (uint32_t i = 0; i < s->num_instances; i++)
        s->instances[i].mesh = to[s->instances[i].mesh];
    free(to);
    free(uses);
    return dropped;
}

static bool same_bytes(const void *a, const void *b, size_t n) { return n == 0 || !memcmp(a, b, n); }

bool scene_same_geometry(const scene *a, const scene *b)
{
    if (a->num_triangles != b->num_triangles || a->num_vertices != b->num_vertices ||
        a->num_instanced_meshes != b->num_instanced_meshes || a->num_instances != b->num_instances ||
        a->num_materials != b->num_materials ||
        !same_bytes(a->vertices, b->vertices, a->num_vertices * sizeof *a->vertices) ||
        !same_bytes(a->indices, b->indices, 3 * sizeof *a->indices * a->num_triangles) ||
        !same_bytes(a->tri_material, b->tri_material, sizeof *a->tri_material * a->num_triangles) ||
        !same_bytes(a->materials, b->materials, sizeof *a->materials * a->num_materials))
        return false;
    for (uint32_t m = 0; m < a->num_instanced_meshes; m++) {
        const scene_instanced_mesh *x = &a->instanced_meshes[m], *y = &b->instanced_meshes[m];
        if (x->num_vertices != y->num_vertices || x->num_triangles != y->num_triangles ||
            !same_bytes(x->vertices, y->vertices, x->num_vertices * sizeof *x->vertices) ||
            !same_bytes(x->indices, y->indices, 3 * sizeof *x->indices * x->num_triangles) ||
            !same_bytes(x->tri_material, y->tri_material, sizeof *x->tri_material * x->num_triangles))
            return false;
    }
    for (uint32_t i = 0; i < a->num_instances; i++)
        if (a->instances[i].mesh != b->instances[i].mesh || a->instances[i].node != b->instances[i].node)
            return false;
    return true;
}
