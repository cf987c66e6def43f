// wrap.glsl: texture coordinate wrapping (glTF sampler wrapS/wrapT: repeat, clamp to edge,
// mirrored repeat) of integer texel indices, for scene.glsl's texture lookups; included
// alone by wrap_test.comp so the unit tests check it against integer arithmetic.
#ifndef GONIO_WRAP_GLSL
#define GONIO_WRAP_GLSL

// i modulo n in [0, n) for 0 < n and |i| < 2^24 (beyond, still in [0, n)). x86 has no
// vector integer division, so llvmpipe runs `%` one lane at a time (what that cost
// textured scenes: docs/performance.md). In that range floor(float(i) / float(n)) is exact: a quotient
// that is not an integer is at least 1/n from one, more than its rounding error, |i/n|
// 2^-24. The selects and the clamp keep larger |i| in range.
int mod_floor(int i, int n)
{
    int m = i - n * int(floor(float(i) / float(n)));
    m = m < 0 ? m + n : m;
    return clamp(m >= n ? m - n : m, 0, n - 1);
}

int tex_wrap(int i, int n, uint mode)
{
    if (mode == GN_WRAP_CLAMP)
        return clamp(i, 0, n - 1);
    if (mode == GN_WRAP_MIRROR) {
        int m = mod_floor(i, 2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return mod_floor(i, n);
}

#endif
