// sampling.glsl: warps of uniform random numbers to directions (Shirley & Chiu 1997's
// concentric disk, Malley's cosine hemisphere), an orthonormal basis from a normal (Duff et
// al. 2017, "Building an orthonormal basis, revisited"), and counter-based random numbers
// from the PCG hash (Jarzynski & Olano 2020, "Hash functions for GPU rendering"), so a
// sample depends only on (pixel, sample index, dimension) and renders are reproducible.
#ifndef SAMPLING_GLSL
#define SAMPLING_GLSL

#include "shared.h"

// [0,1)^2 -> unit disk, area preserving and with low distortion (stratification survives).
vec2 sampling_concentric_disk(vec2 u)
{
    vec2 o = 2.0 * u - 1.0;
    if (o.x == 0.0 && o.y == 0.0)
        return vec2(0.0);
    float r, phi;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        phi = 0.25 * GN_PI * (o.y / o.x);
    } else {
        r = o.y;
        phi = 0.5 * GN_PI - 0.25 * GN_PI * (o.x / o.y);
    }
    return r * vec2(cos(phi), sin(phi));
}

// Cosine-weighted direction about +z: pdf = z / pi.
vec3 sampling_cosine_hemisphere(vec2 u)
{
    vec2 d = sampling_concentric_disk(u);
    return vec3(d, sqrt(max(0.0, 1.0 - dot(d, d))));
}

// Uniform direction on the unit sphere: pdf = 1 / (4 pi).
vec3 sampling_uniform_sphere(vec2 u)
{
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * GN_PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// Tangent t and bitangent b with (t, b, n) right-handed and orthonormal, for unit n; no
// branch on a threshold, so it is continuous except at n.z = 0 and exact near the poles.
void sampling_basis(vec3 n, out vec3 t, out vec3 b)
{
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// The PCG-based 4D hash: every output bit depends on every input bit.
uvec4 rng_pcg4d(uvec4 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    return v;
}

// Four uniform numbers in [0, 1) for (pixel, sample index, dimension, seed): the top 24 bits
// of each hash word, so 1.0 itself is never returned.
vec4 rng_uniform4(uint pixel, uint sample_index, uint dimension, uint seed)
{
    uvec4 h = rng_pcg4d(uvec4(pixel, sample_index, dimension, seed));
    return vec4(h >> 8u) * (1.0 / 16777216.0);
}

#endif
