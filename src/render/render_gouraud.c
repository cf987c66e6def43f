/* render_gouraud.c: Gouraud's vertex pass (render_gouraud.h). */
#include "render_gouraud.h"

#include <stdlib.h>
#include <string.h>

#include "util.h"

#include "vertex.h" /* spv_vertex: glsl/kernels/vertex.comp */

/* The vertex pass's inputs with instances: [2j].w each copy's material (from its mesh's
 * triangles), [2j + 1].w its instance (glsl/kernels/vertex.comp). */
static void gouraud_materials(const render_geometry *geo, vec4 *vcolor)
{
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

/* Gouraud colours, two sides per vertex; the material of each vertex rides in the bits of
 * the first one's w for glsl/kernels/vertex.comp (a vertex belongs to one glTF primitive).
 * With instances each has its own copy of its mesh's vertices
 * (render_geometry.instance_vertices). */
void render_gouraud_create(render_gouraud *v, gpu *g, const scene *sc, const render_geometry *geo)
{
    vec4 *vcolor;
    uint64_t nv = geo->two_levels ? geo->instance_vertices : sc->num_vertices;
    memset(v, 0, sizeof *v);
    v->bytes = 2 * sizeof *vcolor * (VkDeviceSize)nv;
    v->count = (uint32_t)(nv < UINT32_MAX ? nv : UINT32_MAX);
    if (v->bytes <= gpu_storage_limit(g, NULL)) {
        vcolor = util_calloc(2 * (size_t)nv, sizeof *vcolor);
        if (geo->two_levels)
            gouraud_materials(geo, vcolor);
        for (uint32_t t = 0; t < sc->num_triangles && !geo->two_levels; t++)
            for (int k = 0; k < 3; k++)
                memcpy(&vcolor[2 * (size_t)sc->indices[3 * t + k]].w, &sc->tri_material[t], 4);
        gpu_buffer_create_storage(g, &v->vcolor, vcolor, v->bytes);
        free(vcolor);
    } else { /* too many vertices for Gouraud here (render_gouraud_light says so); the rest renders */
        gpu_buffer_create_storage(g, &v->vcolor, NULL, 16);
    }
}

void render_gouraud_destroy(render_gouraud *v, gpu *g)
{
    if (g) {
        gpu_buffer_destroy(g, &v->vcolor);
        gpu_pipeline_destroy(g, &v->pass);
    }
    memset(v, 0, sizeof *v);
}

/* One dispatch per side, in rows of work groups when one row would have more than
 * maxComputeWorkGroupCount[0]. */
bool render_gouraud_light(render_gouraud *v, gpu *g, const char *scene_path, bool instances, const gpu_binding *b,
                          uint32_t num_bindings, uint32_t generation)
{
    VkCommandBuffer cmd;
    const uint32_t max_x = gpu_max_groups(g, 0), max_y = gpu_max_groups(g, 1);
    const uint32_t groups = (v->count + 63) / 64;
    const uint32_t groups_x = groups < max_x ? groups : max_x;
    const uint32_t groups_y = groups_x ? (groups + groups_x - 1) / groups_x : 0;
    const char *limit;
    VkDeviceSize bytes = gpu_storage_limit(g, &limit);
    if (v->bytes > bytes) {
        util_error("%s: --mode gouraud: the %u vertices' colours need %llu bytes, more than one "
                   "storage buffer may hold on this device (%s: %llu)", scene_path,
                   v->count, (unsigned long long)v->bytes, limit, (unsigned long long)bytes);
        return false;
    }
    if (groups_y > max_y) {
        util_error("%s: --mode gouraud: the %u vertices need %u work groups, more than this device "
                   "dispatches (maxComputeWorkGroupCount %u x %u)", scene_path, v->count,
                   groups, max_x, max_y);
        return false;
    }
    if (v->pass.pipeline && v->bound != generation) {
        gpu_pipeline_bind(g, &v->pass, b, num_bindings);
    } else if (!v->pass.pipeline) {
        const uint32_t inst = instances;
        const VkSpecializationMapEntry entry = {GN_SPEC_INSTANCES, 0, sizeof inst};
        const VkSpecializationInfo spec = {1, &entry, sizeof inst, &inst};
        gpu_pipeline_desc pd = {
            .name = "vertex", .code = spv_vertex, .code_size = sizeof spv_vertex,
            .local_size = {64, 1, 1}, .push_size = sizeof(GnPush), .specialization = &spec,
            .bindings = b, .num_bindings = num_bindings};
        gpu_pipeline_create(g, &v->pass, &pd);
    }
    v->bound = generation;
    cmd = gpu_begin(g);
    for (uint32_t side = 0; side < 2; side++) {
        GnPush push = {0, side, 0, 0};
        gpu_dispatch(cmd, &v->pass, &push, 64 * groups_x, groups_y, 1);
        gpu_barrier(cmd);
    }
    gpu_submit_wait(g, cmd);
    return true;
}
