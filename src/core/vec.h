/* vec.h: the small vector helpers the host's geometry uses, defined once: 3-vectors as
 * float[3] (the precision of what the GPU gets) and double[3] (sums, areas), 3x3 cofactors
 * (inverses and the normals' transform), luminance and clamping. C and C++. Header-only: each is a few operations, in the order written here, so a caller
 * gets the same bits as from code written out in place. */
#ifndef GONIO_VEC_H
#define GONIO_VEC_H

#include <math.h>
#include <stdbool.h>

#include "shared.h"

static inline float vec_dot(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline void vec_sub(const float a[3], const float b[3], float out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = a[k] - b[k];
}

static inline void vec_cross(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* v / |v|; false (v unchanged) when |v| is 0 or not finite. */
static inline bool vec_normalize(float v[3])
{
    float l = sqrtf(vec_dot(v, v));
    if (!(l > 0) || !isfinite(l))
        return false;
    for (int k = 0; k < 3; k++)
        v[k] /= l;
    return true;
}

static inline double vec_dot_d(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline double vec_length_d(const double v[3]) { return sqrt(vec_dot_d(v, v)); }

static inline void vec_cross_d(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* A float[3] as the vec3 of glsl/lib/shared.h. */
static inline vec3 vec3_of(const float p[3]) { return (vec3){p[0], p[1], p[2]}; }

/* Rec. 709 luminance of linear RGB: rgb[0..2], or a vec3's &v.x. */
static inline double vec_luminance(const float *rgb) { return GN_LUMA_R * rgb[0] + GN_LUMA_G * rgb[1] + GN_LUMA_B * rgb[2]; }

/* The cofactor matrix of the 3x3 matrix a: cof[r][k] the signed minor of a[r][k], so that
 * det(a) a^-1 = cof^T and cof = det(a) a^-T, the transform normals take (defined for a
 * singular a too). Returns det(a). */
static inline double vec_cofactors3(double a[3][3], double cof[3][3])
{
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            cof[r][k] = a[r1][k1] * a[r2][k2] - a[r1][k2] * a[r2][k1];
        }
    return a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
}

static inline float vec_clamp01(float x) { return x < 0 ? 0 : x > 1 ? 1 : x; }

#endif
