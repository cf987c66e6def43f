/* teapot.h: the Utah teapot (Martin Newell, 1975) as a smooth indexed triangle mesh,
 * tessellated from its 32 bicubic Bezier patches (rim, body, handle, spout, lid, bottom).
 *
 * Frame: glTF's, Y up, spout along +X, handle along -X; scaled by 1/3.15 so the teapot is
 * exactly 1 tall, standing on y = 0 with the body's axis on the Y axis. (glutSolidTeapot(s)
 * instead scales the data by s/2: 1.575 s tall, centred near the origin.) Extents in the
 * original units: x in [-3, 3.434] (handle to spout tip), height [0, 3.15], depth +-2. */
#ifndef GONIO_TEAPOT_H
#define GONIO_TEAPOT_H

#include "meshgen.h"

/* The procedural meshes' arrays (meshgen.h): normals unit length and outward, triangles
 * counter-clockwise seen from outside. */
typedef meshgen_mesh teapot_mesh;

/* Evaluates every patch on an (level+1) x (level+1) grid of (u, v), two triangles per grid
 * cell, with normals from the patch derivatives; vertices that coincide across patch seams
 * are merged and their normals averaged, so shading is smooth across seams. The lid top and
 * the bottom centre are poles where 4 patches each collapse one edge to a point; the
 * triangles that degenerate there are dropped, so the mesh has exactly
 * 64 level^2 - 8 level triangles. The mesh is not closed (neither is the real teapot's
 * model): the lid rests inside the rim leaving a thin gap, and the spout and handle are
 * open tubes pushed into the body. At level 1 the spout tip's two patches, whose corners
 * are collinear, give 4 zero-area triangles. Precondition: 1 <= level <= 1024. */
void teapot_tessellate(teapot_mesh *out, int level);

/* Frees the arrays; accepts a zeroed struct (meshgen_destroy). */
void teapot_destroy(teapot_mesh *m);

#endif
