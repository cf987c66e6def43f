/* render_gouraud.c: Gouraud's vertex pass (glsl/kernels/vertex.comp): a colour per vertex
 * and side, lit once per frame, which --mode gouraud's pixels interpolate. */
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"
#include "util.h"

#include "vertex.h" /* spv_vertex: glsl/kernels/vertex.comp */

/* Gouraud colours, two sides per vertex; the material of each vertex rides in the bits of
 * the first one's w for glsl/kernels/vertex.comp (a vertex belongs to one glTF primitive). */
void vertex_colors_create(renderer *r)
{
    gpu *g = r->g;
    const scene *sc = r->sc;
    vec4 *vcolor;
    r->vcolor_bytes = 2 * sizeof *vcolor * (VkDeviceSize)sc->num_vertices;
    if (r->vcolor_bytes <= gpu_storage_limit(g, NULL)) {
        vcolor = util_calloc(2 * (size_t)sc->num_vertices, sizeof *vcolor);
        for (uint32_t t = 0; t < sc->num_triangles; t++)
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
    const uint32_t groups = (r->sc->num_vertices + 63) / 64;
    const uint32_t groups_x = groups < max_x ? groups : max_x;
    const uint32_t groups_y = groups_x ? (groups + groups_x - 1) / groups_x : 0;
    const char *limit;
    VkDeviceSize bytes = gpu_storage_limit(r->g, &limit);
    if (r->vcolor_bytes > bytes) {
        util_error("%s: --mode gouraud: the %u vertices' colours need %llu bytes, more than one "
                   "storage buffer may hold on this device (%s: %llu)", r->sc->path,
                   r->sc->num_vertices, (unsigned long long)r->vcolor_bytes, limit,
                   (unsigned long long)bytes);
        return false;
    }
    if (groups_y > max_y) {
        util_error("%s: --mode gouraud: the %u vertices need %u work groups, more than this device "
                   "dispatches (maxComputeWorkGroupCount %u x %u)", r->sc->path, r->sc->num_vertices,
                   groups, max_x, max_y);
        return false;
    }
    if (!r->vertex_pass.pipeline) {
        gpu_binding b[GN_BIND_COUNT];
        gpu_pipeline_desc pd = {
            .name = "vertex", .code = spv_vertex, .code_size = sizeof spv_vertex,
            .local_size = {64, 1, 1}, .push_size = sizeof(GnPush),
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
