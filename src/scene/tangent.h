/* tangent.h: per-vertex tangents of an indexed triangle mesh by the MikkTSpace method
 * (Mikkelsen 2008, "Simulation of wrinkled surfaces revisited"), which glTF 2.0 names for
 * meshes with a normal texture and no TANGENT. */
#ifndef GONIO_TANGENT_H
#define GONIO_TANGENT_H

#include <stddef.h>
#include <stdint.h>

/* nv vertices (pos: 3 floats each, nrm: 3, unit length; uv: 2, glTF's convention, v down)
 * and nt triangles (idx: 3 each, < nv). A vertex whose triangles disagree on handedness, or
 * that joins fans of triangles not connected through its edges, is split: the function
 * returns the new vertex count n >= (vertices used), sets *remap (n entries: the input
 * vertex each output vertex copies) and *tangents (4 floats each: xyz unit, orthogonal to
 * the vertex's normal, w = +-1 with bitangent = cross(normal, xyz) * w pointing toward
 * decreasing v, "up" in the image), and rewrites idx to the new vertices. Both arrays are
 * the caller's to free. */
size_t tangent_generate(size_t nv, const float *pos, const float *nrm, const float *uv, size_t nt,
                        uint32_t *idx, uint32_t **remap, float **tangents);

#endif
