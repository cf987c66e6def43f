/* bvh_internal.h: what the BVH's build (bvh.c), its top level (bvh_top.c) and its C traversal
 * (bvh_traverse.c) share;
 * only src/accel includes it. */
#ifndef GONIO_BVH_INTERNAL_H
#define GONIO_BVH_INTERNAL_H

/* GnBvhNode levels at most; also the host walk's stack, which never overflows. */
#define BVH_MAX_DEPTH 64

/* a < b ? a : b and a > b ? a : b (no NaN handling: the boxes and rays have none). */
static inline float minf(float a, float b) { return a < b ? a : b; }
static inline float maxf(float a, float b) { return a > b ? a : b; }

/* The top tree over n instance boxes (lo xyz, hi xyz each): bvh.c's binned SAH with leaves of
 * one instance, at most max_depth levels where the count allows (bvh_top.c). */
void bvh_build_instance_tree(bvh *out, const float (*boxes)[6], uint32_t n, uint32_t max_depth);

#endif
