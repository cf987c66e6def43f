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

// ---- the samplers (GN_SAMPLER_*; docs/path-tracing.md: "Samplers") -----------------------
// A sampler's numbers are, like rng_uniform4's, a pure function of (pixel, sample index,
// dimension, seed): any sample of any pixel is computed on its own, so tiles, resumed and
// merged renders are exact whichever sampler made them.

// Laine & Karras's permutation of a 32-bit word: output bit k depends only on input bits
// 0..k and the seed (additions and products carry upwards only), so applied to a value's
// reversed bits it is a nested uniform (Owen) scramble: each digit flipped by a function of
// the digits above it (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
uint sampler_lk_permute(uint x, uint seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Sobol's second dimension of index i, its bits reversed (bit j: the digit of weight 2^-(j+1)).
// Its generator matrix is Pascal's triangle mod 2: digit j is the XOR of the index bits k
// with binomial(k, j) odd, that is (Lucas) of those k whose bits hold all of j's: a superset
// XOR over the five bits of a bit position, one shift-and-mask per bit, no loop. The first
// dimension is the index itself reversed (van der Corput), so the reversed pair is (i, this).
uint sampler_sobol1_reversed(uint i)
{
    i ^= (i >> 1u) & 0x55555555u;
    i ^= (i >> 2u) & 0x33333333u;
    i ^= (i >> 4u) & 0x0f0f0f0fu;
    i ^= (i >> 8u) & 0x00ff00ffu;
    i ^= (i >> 16u) & 0x0000ffffu;
    return i;
}

// Sample i of Sobol's first two dimensions with the index shuffled and each coordinate
// Owen-scrambled by the three words of h (Burley 2020): the first 2^m shuffled indices are
// one aligned block of 2^m Sobol points, so every aligned power-of-two block of a pixel's
// samples is a (0, m, 2)-net of the square (one point in every elementary box): the pixel's
// samples are a (0, 2)-sequence.
vec2 sampler_sobol2(uint i, uvec3 h)
{
    uint j = bitfieldReverse(sampler_lk_permute(bitfieldReverse(i), h.x));
    uint x = bitfieldReverse(sampler_lk_permute(j, h.y));
    uint y = bitfieldReverse(sampler_lk_permute(sampler_sobol1_reversed(j), h.z));
    return vec2(uvec2(x, y) >> 8u) * (1.0 / 16777216.0);
}

// Four numbers for (pixel, sample index, dimension, seed) from the sampler `kind`
// (GN_SAMPLER_*). The path kernel's layout (docs/path-tracing.md): .yz a 2D decision (film
// position, a point on a light, a direction), .x and .w two 1D ones (light or lobe choice,
// roulette or medium).
// With GN_SAMPLER_SOBOL .yz is one scrambled Sobol pair and (.x, .w) another, each pair's
// index shuffled by its own hash of (pixel, dimension, seed), so pairs, dimensions and
// pixels are decorrelated while each pair is stratified over a pixel's samples.
vec4 sampler_get4(uint kind, uint pixel, uint sample_index, uint dimension, uint seed)
{
    if (kind != GN_SAMPLER_SOBOL)
        return rng_uniform4(pixel, sample_index, dimension, seed);
    uvec4 h = rng_pcg4d(uvec4(pixel, dimension, seed, 0x5ab01u));
    uvec4 g = rng_pcg4d(uvec4(pixel, dimension, seed, 0x5ab02u));
    vec2 a = sampler_sobol2(sample_index, h.xyz), b = sampler_sobol2(sample_index, g.xyz);
    return vec4(b.x, a, b.y);
}

#endif
