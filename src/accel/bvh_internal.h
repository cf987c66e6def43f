/* bvh_internal.h: what the BVH's build (bvh.c) and its C traversal (bvh_traverse.c) share;
 * only src/accel includes it. */
#ifndef GONIO_BVH_INTERNAL_H
#define GONIO_BVH_INTERNAL_H

/* GnBvhNode levels at most; also the host walk's stack, which never overflows. */
#define BVH_MAX_DEPTH 64

/* a < b ? a : b and a > b ? a : b (no NaN handling: the boxes and rays have none). */
static inline float minf(float a, float b) { return a < b ? a : b; }
static inline float maxf(float a, float b) { return a > b ? a : b; }

#endif
