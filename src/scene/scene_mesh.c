/* scene_mesh.c: a scene made from one procedural triangle mesh (tests, benchmarks). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene.h"
#include "scene_mesh.h"
#include "util.h"

void scene_from_mesh(scene *out, const char *name, uint32_t num_vertices, const float *positions,
                     const float *normals, uint32_t num_triangles, const uint32_t *indices)
{
    memset(out, 0, sizeof *out);
    snprintf(out->path, sizeof out->path, "%s", name);
    out->num_vertices = num_vertices;
    out->vertices = util_calloc(num_vertices, sizeof *out->vertices);
    for (uint32_t i = 0; i < num_vertices; i++) {
        GnVertex *v = &out->vertices[i];
        v->position = (vec3){positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
        v->color = (vec4){1, 1, 1, 1};
        if (normals)
            v->normal = (vec3){normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
    }
    out->num_triangles = num_triangles;
    out->indices = util_malloc(sizeof *out->indices * 3 * (size_t)num_triangles);
    memcpy(out->indices, indices, sizeof *out->indices * 3 * (size_t)num_triangles);
    out->tri_material = util_calloc(num_triangles, sizeof *out->tri_material);
    out->num_meshes = out->num_gltf_meshes = out->num_nodes = 1;
    out->num_materials = 1;
    out->materials = util_calloc(1, sizeof *out->materials);
    out->material_extras = util_calloc(1, sizeof *out->material_extras);
    out->material_names = util_calloc(1, sizeof *out->material_names);
    snprintf(out->material_names[0], sizeof out->material_names[0], "default");
    scene_material_default(&out->materials[0]);
    scene_compute_bounds(out);
}
