/* scene_mesh.h: a scene from plain mesh arrays, for tests and benchmarks. */
#ifndef GONIO_SCENE_MESH_H
#define GONIO_SCENE_MESH_H

#include <stdint.h>

#include "scene.h"

/* One mesh with the glTF default material; normals may be NULL (the shaders then fall back
 * to the geometric normal). Arrays are copied. */
void scene_from_mesh(scene *out, const char *name, uint32_t num_vertices, const float *positions,
                     const float *normals, uint32_t num_triangles, const uint32_t *indices);

#endif
