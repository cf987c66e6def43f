/* bvh_top.c: the top level of two: instances of meshes (GnInstance: transforms both ways, a
 * mirror flag, the mesh's root) and the tree over their world boxes (bvh.h: bvh_top), built
 * by bvh.c's binned SAH with leaves of one instance, and rebuilt alone for a new set of
 * transforms (an animated frame). */
#include "bvh.h"
#include "bvh_internal.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"
#include "vec.h"

uint32_t bvh_top_max_depth(uint32_t mesh_depth)
{
    /* entries: one a level of the top tree, the marker, one a level of the mesh's, within
     * the GN_WALK_STACK - 2 that a walk's stack holds besides its sentinel and spare */
    uint32_t room = GN_WALK_STACK - 2;
    return mesh_depth + 1 < room ? room - 1 - mesh_depth : 0;
}

/* The union of node 0's two boxes: the tree's root box (b is empty, inverted, in a root leaf). */
static void tree_box(const bvh *b, double lo[3], double hi[3])
{
    const GnBvhNode *r = &b->nodes[0];
    const float *a0 = &r->a_min.x, *a1 = &r->a_max.x, *b0 = &r->b_min.x, *b1 = &r->b_max.x;
    for (int k = 0; k < 3; k++) {
        lo[k] = a0[k] < b0[k] ? a0[k] : b0[k];
        hi[k] = a1[k] > b1[k] ? a1[k] : b1[k];
    }
}

/* Instance g's transforms from m (3x4, row-major, object to world): to_object is its inverse,
 * computed in double (cofactors over the determinant). False when m is not finite or not
 * invertible in float (a zero determinant, or an inverse beyond float's range). */
static bool instance_transforms(GnInstance *g, const float m[12])
{
    double a[3][3], c[3][3], det, t[3];
    for (int k = 0; k < 12; k++)
        if (!isfinite(m[k]))
            return false;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            a[r][k] = m[4 * r + k];
    det = vec_cofactors3(a, c);
    if (!(det != 0) || !isfinite(det))
        return false;
    for (int r = 0; r < 3; r++)
        t[r] = m[4 * r + 3];
    for (int r = 0; r < 3; r++) {
        float *w = &g->to_world[r].x, *o = &g->to_object[r].x;
        double inv[3];
        for (int k = 0; k < 3; k++) /* (A^-1)[r][k] = cofactor[k][r] / det */
            inv[k] = c[k][r] / det;
        for (int k = 0; k < 4; k++)
            w[k] = m[4 * r + k];
        for (int k = 0; k < 3; k++)
            o[k] = (float)inv[k];
        o[3] = (float)-(inv[0] * t[0] + inv[1] * t[1] + inv[2] * t[2]);
        for (int k = 0; k < 4; k++)
            if (!isfinite(o[k]))
                return false;
    }
    g->flags = det < 0 ? GN_INSTANCE_MIRROR : 0u;
    return true;
}

/* Instance g's world box: the eight corners of its mesh's root box, transformed in double and
 * widened by a millionth of their size and place, so that a ray whose object-space image (the
 * transform rounded to float: bvh_instance_ray) hits the mesh never misses the box. */
static void instance_box(const GnInstance *g, const bvh *mesh, float box[6])
{
    double lo[3], hi[3], wlo[3] = {INFINITY, INFINITY, INFINITY}, whi[3] = {-INFINITY, -INFINITY, -INFINITY};
    tree_box(mesh, lo, hi);
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        for (int r = 0; r < 3; r++) {
            const float *w = &g->to_world[r].x;
            double x = w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3];
            wlo[r] = x < wlo[r] ? x : wlo[r];
            whi[r] = x > whi[r] ? x : whi[r];
        }
    }
    for (int r = 0; r < 3; r++) {
        double margin = 1e-6 * (fabs(wlo[r]) + fabs(whi[r]) + (whi[r] - wlo[r])) + 1e-30;
        box[r] = (float)(wlo[r] - margin);
        box[3 + r] = (float)(whi[r] + margin);
        box[r] = (double)box[r] > wlo[r] - margin ? nextafterf(box[r], -INFINITY) : box[r];
        box[3 + r] = (double)box[3 + r] < whi[r] + margin ? nextafterf(box[3 + r], INFINITY) : box[3 + r];
    }
}

/* The instances' transforms and boxes from to_world, and the top tree over them. */
static bool top_tree(bvh_top *t, const float (*to_world)[12], const char *what)
{
    float (*boxes)[6] = util_malloc(t->num_instances * sizeof *boxes);
    for (uint32_t i = 0; i < t->num_instances; i++) {
        GnInstance *g = &t->instances[i];
        if (!instance_transforms(g, to_world[i])) {
            util_error("%s: instance %u: its transform is not finite or not invertible", what, i);
            free(boxes);
            return false;
        }
        instance_box(g, &t->meshes[g->mesh], boxes[i]);
    }
    bvh_destroy(&t->tree);
    bvh_build_instance_tree(&t->tree, (const float(*)[6])boxes, t->num_instances, bvh_top_max_depth(t->mesh_depth));
    free(boxes);
    if (bvh_top_depth(t) > GN_WALK_STACK - 2) {
        util_error("%s: the tree over %u instances has %u levels and the deepest mesh's %u: more than "
                   "the %d a walk's stack holds", what, t->num_instances, t->tree.depth, t->mesh_depth,
                   GN_WALK_STACK - 3);
        return false;
    }
    assert(t->tree.num_nodes == (t->num_instances > 1 ? t->num_instances - 1 : 1));
    return true;
}

bool bvh_top_build(bvh_top *out, const bvh *meshes, uint32_t num_meshes, const float (*to_world)[12],
                   const uint32_t *mesh, const uint32_t *custom, uint32_t num_instances, const char *what)
{
    uint64_t nodes = num_instances > 1 ? num_instances - 1 : 1, pairs = 0;
    memset(out, 0, sizeof *out);
    if (num_instances == 0 || num_instances >= GN_BVH_FIRST) {
        util_error("%s: %u instances: a scene with instances has 1 to %u", what, num_instances, GN_BVH_FIRST - 1);
        return false;
    }
    out->meshes = meshes;
    out->num_meshes = num_meshes;
    out->num_instances = num_instances;
    out->node_base = util_calloc(num_meshes + 1, sizeof *out->node_base);
    out->pair_base = util_calloc(num_meshes + 1, sizeof *out->pair_base);
    for (uint32_t m = 0; m < num_meshes; m++) {
        out->node_base[m] = (uint32_t)nodes;
        out->pair_base[m] = (uint32_t)pairs;
        nodes += meshes[m].num_nodes;
        pairs += meshes[m].num_pairs;
        out->mesh_depth = meshes[m].depth > out->mesh_depth ? meshes[m].depth : out->mesh_depth;
        /* a leaf keeps its first pair in 27 bits, an inner node's index stays below GN_BVH_LEAF */
        if (meshes[m].num_nodes == 0 || pairs > GN_BVH_FIRST || nodes >= GN_BVH_LEAF) {
            util_error("%s: mesh %u: %s", what, m, meshes[m].num_nodes == 0 ? "no triangles"
                       : "the meshes together have more triangles than a BVH leaf can index");
            bvh_top_destroy(out);
            return false;
        }
    }
    out->num_nodes = (uint32_t)nodes;
    out->num_pairs = (uint32_t)pairs;
    out->instances = util_calloc(num_instances, sizeof *out->instances);
    for (uint32_t i = 0; i < num_instances; i++) {
        GnInstance *g = &out->instances[i];
        if (mesh[i] >= num_meshes) {
            util_error("%s: instance %u: mesh %u of %u", what, i, mesh[i], num_meshes);
            bvh_top_destroy(out);
            return false;
        }
        g->mesh = mesh[i];
        g->root = out->node_base[mesh[i]];
        g->prim_base = 2 * out->pair_base[mesh[i]];
        g->custom = custom ? custom[i] : 0;
    }
    if (!top_tree(out, to_world, what)) {
        bvh_top_destroy(out);
        return false;
    }
    out->build_seconds = out->tree.build_seconds;
    return true;
}

bool bvh_top_update(bvh_top *t, const float (*to_world)[12], const char *what)
{
    double t0 = util_now();
    if (!top_tree(t, to_world, what))
        return false;
    t->build_seconds = util_now() - t0;
    return true;
}

void bvh_top_destroy(bvh_top *t)
{
    bvh_destroy(&t->tree);
    free(t->instances);
    free(t->node_base);
    free(t->pair_base);
    memset(t, 0, sizeof *t);
}

uint32_t bvh_top_depth(const bvh_top *t) { return t->tree.depth + 1 + t->mesh_depth; }

void bvh_top_gpu_nodes(const bvh_top *t, GnBvhNode *out)
{
    memcpy(out, t->tree.nodes, t->tree.num_nodes * sizeof *out);
    for (uint32_t m = 0; m < t->num_meshes; m++) {
        GnBvhNode *n = out + t->node_base[m];
        memcpy(n, t->meshes[m].nodes, t->meshes[m].num_nodes * sizeof *n);
        for (uint32_t i = 0; i < t->meshes[m].num_nodes; i++) {
            uint32_t *index[2] = {&n[i].a_index, &n[i].b_index}, count[2] = {n[i].a_count, n[i].b_count};
            for (int c = 0; c < 2; c++)
                if (*index[c] != GN_INVALID) /* a leaf's first pair, or an inner node */
                    *index[c] += count[c] > 0 ? t->pair_base[m] : t->node_base[m];
        }
    }
}

void bvh_top_gpu_pairs(const bvh_top *t, GnTriPair *out)
{
    for (uint32_t m = 0; m < t->num_meshes; m++)
        memcpy(out + t->pair_base[m], t->meshes[m].pairs, t->meshes[m].num_pairs * sizeof *out);
}
