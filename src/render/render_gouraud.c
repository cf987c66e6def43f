/* render_gouraud.c: Gouraud's vertex pass (glsl/kernels/vertex.comp): a colour per vertex
 * and side, lit once per frame, which --mode gouraud's pixels interpolate. */
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"
#include "util.h"

#include "vertex.h" /* spv_vertex: glsl/kernels/vertex.comp */

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

/* Gouraud colours, two sides per vertex; the material of each vertex rides in the bits of
 * the first one's w for glsl/kernels/vertex.comp (a vertex belongs to one glTF primitive).
 * With instances each has its own copy of its mesh's vertices (gouraud_vertices). */
void vertex_colors_create(renderer *r)
{
    gpu *g = r->g;
    const scene *sc = r->sc;
    vec4 *vcolor;
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
}

/* Gouraud's vertex pass: lights every vertex for the frame just uploaded, one dispatch per
 * side (glsl/kernels/vertex.comp), in rows of work groups when one row would have more than
 * maxComputeWorkGroupCount[0]. False (with an error) when the device cannot hold them. */
bool light_vertices(renderer *r)
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
    if (r->vertex_pass.pipeline) {
        renderer_rebind(r, &r->vertex_pass, &r->vertex_bound);
    } else {
        gpu_binding b[GN_BIND_COUNT];
        const uint32_t instances = r->geo.two_levels;
        const VkSpecializationMapEntry entry = {GN_SPEC_INSTANCES, 0, sizeof instances};
        const VkSpecializationInfo spec = {1, &entry, sizeof instances, &instances};
        gpu_pipeline_desc pd = {
            .name = "vertex", .code = spv_vertex, .code_size = sizeof spv_vertex,
            .local_size = {64, 1, 1}, .push_size = sizeof(GnPush), .specialization = &spec,
            .bindings = b, .num_bindings = renderer_bindings(r, b)};
        gpu_pipeline_create(r->g, &r->vertex_pass, &pd);
        r->vertex_bound = r->buffers_replaced;
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
