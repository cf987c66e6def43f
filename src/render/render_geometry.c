/* render_geometry.c: the scene's trees and the GPU arrays the walk reads (render_geometry.h). */
#include "render_geometry.h"

#include <stdlib.h>
#include <string.h>

#include "util.h"

/* GnPrim of the tree's slots: each triangle's corners in the order the walk's test takes
 * them (a rotation: the winding stays), so that its barycentrics apply as they are; vertex
 * indices from vbase, materials as the scene has them. */
static void fill_prims(GnPrim *out, const bvh *b, const uint32_t *indices, const uint32_t *tri_material,
                       uint32_t vbase)
{
    for (uint32_t i = 0; i < b->num_slots; i++) {
        uint32_t t = b->tri_index[i], k = b->tri_rotation[i];
        if (t == GN_INVALID)
            continue;
        out[i] = (GnPrim){vbase + indices[3 * t + k], vbase + indices[3 * t + (k + 1) % 3],
                          vbase + indices[3 * t + (k + 2) % 3], tri_material[t]};
    }
}

static bool one_level(render_geometry *g, const scene *sc)
{
    if (!bvh_build(&g->world, &sc->vertices[0].position.x, sizeof(GnVertex) / sizeof(float), sc->indices,
                   sc->num_triangles)) {
        util_error("%s: no triangles to render", sc->path);
        return false;
    }
    if (g->world.num_tris > GN_BVH_FIRST) { /* leaves index their first triangle in 27 bits */
        util_error("%s: %u triangles, more than the %u a BVH leaf can index", sc->path, sc->num_triangles,
                   GN_BVH_FIRST);
        return false;
    }
    g->nodes = g->world.nodes;
    g->num_nodes = g->world.num_nodes;
    g->pairs = g->world.pairs;
    g->num_pairs = g->world.num_pairs;
    g->num_slots = g->world.num_slots;
    g->prims = util_calloc(g->num_slots, sizeof *g->prims);
    fill_prims(g->prims, &g->world, sc->indices, sc->tri_material, 0);
    g->vertices = sc->vertices;
    g->num_vertices = sc->num_vertices;
    g->depth = g->world.depth;
    g->build_seconds = g->world.build_seconds;
    return true;
}

/* The instances' transforms: the world mesh's identity, then the scene's. */
static float (*transforms(const render_geometry *g, const scene *sc))[12]
{
    float (*xf)[12] = util_calloc(g->first_instance + (size_t)sc->num_instances, sizeof *xf);
    if (g->first_instance)
        xf[0][0] = xf[0][5] = xf[0][10] = 1;
    for (uint32_t i = 0; i < sc->num_instances; i++)
        memcpy(xf[g->first_instance + i], sc->instances[i].to_world, sizeof xf[0]);
    return xf;
}

static bool two_levels(render_geometry *g, const scene *sc)
{
    g->two_levels = true;
    /* the meshes: the world's triangles (when there are any: every mesh may be instanced),
     * then the instanced ones; the instances: the world's by the identity, then the scene's */
    g->first_instance = sc->num_triangles ? 1 : 0;
    g->num_meshes = g->first_instance + sc->num_instanced_meshes;
    g->meshes = util_calloc(g->num_meshes, sizeof *g->meshes);
    g->vertex_base = util_calloc(g->num_meshes + 1, sizeof *g->vertex_base);
    g->mesh_vertices = util_calloc(g->num_meshes + 1, sizeof *g->mesh_vertices);
    uint64_t vertices = sc->num_vertices;
    if (g->first_instance)
        g->mesh_vertices[0] = sc->num_vertices;
    if (g->first_instance) {
        bvh_build(&g->meshes[0], &sc->vertices[0].position.x, sizeof(GnVertex) / sizeof(float), sc->indices,
                  sc->num_triangles);
        g->build_seconds = g->meshes[0].build_seconds;
    }
    for (uint32_t m = 0; m < sc->num_instanced_meshes; m++) {
        const scene_instanced_mesh *im = &sc->instanced_meshes[m];
        uint32_t k = g->first_instance + m;
        g->vertex_base[k] = (uint32_t)(vertices < UINT32_MAX ? vertices : UINT32_MAX);
        g->mesh_vertices[k] = im->num_vertices;
        vertices += im->num_vertices;
        if (!bvh_build(&g->meshes[k], &im->vertices[0].position.x, sizeof(GnVertex) / sizeof(float), im->indices,
                       im->num_triangles)) {
            util_error("%s: instanced mesh %u (glTF mesh %u) has no triangles", sc->path, m, im->gltf_mesh);
            return false;
        }
        g->build_seconds += g->meshes[k].build_seconds;
    }
    if (vertices > UINT32_MAX) {
        util_error("%s: %llu vertices, more than a vertex index holds", sc->path, (unsigned long long)vertices);
        return false;
    }
    uint32_t n = g->first_instance + sc->num_instances;
    uint32_t *mesh = util_calloc(n, sizeof *mesh), *custom = util_calloc(n, sizeof *custom);
    if (g->first_instance)
        custom[0] = GN_INVALID; /* (the world: no node) */
    for (uint32_t i = 0; i < sc->num_instances; i++) {
        mesh[g->first_instance + i] = g->first_instance + sc->instances[i].mesh;
        custom[g->first_instance + i] = sc->instances[i].node;
    }
    float (*xf)[12] = transforms(g, sc);
    bool ok = bvh_top_build(&g->top, g->meshes, g->num_meshes, (const float(*)[12])xf, mesh, custom, n, sc->path);
    free(xf);
    free(mesh);
    free(custom);
    if (!ok)
        return false;
    g->top_seconds = g->top.build_seconds;
    g->build_seconds += g->top_seconds;
    for (uint32_t i = 0; i < g->top.num_instances; i++) { /* each its copy of its mesh's vertices */
        GnInstance *in = &g->top.instances[i];
        in->vcolor_offset = (uint32_t)g->instance_vertices - g->vertex_base[in->mesh]; /* (uint arithmetic) */
        g->instance_vertices += g->mesh_vertices[in->mesh];
    }
    g->num_nodes = g->top.num_nodes;
    g->num_pairs = g->top.num_pairs;
    g->nodes = util_malloc(g->num_nodes * sizeof *g->nodes);
    g->pairs = util_malloc(g->num_pairs * sizeof *g->pairs);
    bvh_top_gpu_nodes(&g->top, g->nodes);
    bvh_top_gpu_pairs(&g->top, g->pairs);
    g->num_slots = 2 * g->num_pairs;
    g->prims = util_calloc(g->num_slots, sizeof *g->prims);
    if (g->first_instance)
        fill_prims(g->prims, &g->meshes[0], sc->indices, sc->tri_material, 0);
    for (uint32_t m = 0; m < sc->num_instanced_meshes; m++) {
        const scene_instanced_mesh *im = &sc->instanced_meshes[m];
        uint32_t k = g->first_instance + m;
        fill_prims(g->prims + 2 * g->top.pair_base[k], &g->meshes[k], im->indices, im->tri_material,
                   g->vertex_base[k]);
    }
    g->num_vertices = (uint32_t)vertices;
    g->vertices = util_malloc((size_t)vertices * sizeof *g->vertices);
    memcpy(g->vertices, sc->vertices, sc->num_vertices * sizeof *g->vertices);
    for (uint32_t m = 0; m < sc->num_instanced_meshes; m++)
        memcpy(g->vertices + g->vertex_base[g->first_instance + m], sc->instanced_meshes[m].vertices,
               sc->instanced_meshes[m].num_vertices * sizeof *g->vertices);
    g->depth = bvh_top_depth(&g->top);
    return true;
}

bool render_geometry_build(render_geometry *g, const scene *sc)
{
    memset(g, 0, sizeof *g);
    bool ok = sc->num_instances ? two_levels(g, sc) : one_level(g, sc);
    if (!ok)
        render_geometry_destroy(g);
    return ok;
}

bool render_geometry_update(render_geometry *g, const scene *sc)
{
    if (!g->two_levels)
        return true;
    float (*xf)[12] = transforms(g, sc);
    bool ok = bvh_top_update(&g->top, (const float(*)[12])xf, sc->path);
    free(xf);
    if (ok) {
        g->top_seconds = g->top.build_seconds;
        bvh_top_gpu_nodes(&g->top, g->nodes); /* (only the top tree's part changes) */
    }
    return ok;
}

void render_geometry_destroy(render_geometry *g)
{
    if (g->two_levels) {
        for (uint32_t m = 0; m < g->num_meshes; m++)
            bvh_destroy(&g->meshes[m]);
        bvh_top_destroy(&g->top);
        free(g->nodes);
        free(g->pairs);
        free(g->vertices);
    }
    bvh_destroy(&g->world);
    free(g->meshes);
    free(g->vertex_base);
    free(g->mesh_vertices);
    free(g->prims);
    memset(g, 0, sizeof *g);
}

uint32_t render_geometry_triangle(const render_geometry *g, uint32_t slot, uint32_t *mesh)
{
    *mesh = 0;
    if (!g->two_levels)
        return g->world.tri_index[slot];
    uint32_t m = g->num_meshes - 1; /* the last mesh starting at or before the slot */
    while (m > 0 && 2 * g->top.pair_base[m] > slot)
        m--;
    *mesh = m;
    return g->meshes[m].tri_index[slot - 2 * g->top.pair_base[m]];
}

render_geometry_bytes render_geometry_size(const render_geometry *g)
{
    return (render_geometry_bytes){(uint64_t)g->num_nodes * sizeof(GnBvhNode),
                                   (uint64_t)g->num_pairs * sizeof(GnTriPair),
                                   (uint64_t)g->num_slots * sizeof(GnPrim),
                                   (uint64_t)g->num_vertices * sizeof(GnVertex),
                                   g->two_levels ? (uint64_t)g->top.num_instances * sizeof(GnInstance) : 0};
}
