#version 450
// display.comp: the accumulated radiance sums -> 8-bit sRGB texels for the preview window:
// divide by spp, scale by 2^exposure, tonemap (clamp, Reinhard, or the ACES fit of Narkowicz
// 2015), sRGB OETF of IEC 61966-2-1, round. The same steps as image_to_srgb8 (src/core/image.c),
// so a screenshot matches `gonio render --png` of the same samples.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;

layout(std430, binding = GN_DISPLAY_BIND_ACCUM) readonly buffer AccumBlock { vec4 accum[]; };
layout(std430, binding = GN_DISPLAY_BIND_OUT) writeonly buffer OutBlock { uint texels[]; };
layout(push_constant) uniform PushBlock { GnDisplayPush push; };

uint srgb8(float value)
{
    float x = value * push.scale;
    if (!(x > 0.0)) // also NaN
        return 0u;
    // image.c computes in double; in float, 1e18 keeps the ACES fit's x*x finite and every
    // tonemap still maps it to 1.
    x = min(x, 1e18);
    if (push.tonemap == GN_TONEMAP_REINHARD)
        x = x / (1.0 + x);
    else if (push.tonemap == GN_TONEMAP_ACES)
        x = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    x = min(x, 1.0);
    x = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
    return uint(x * 255.0 + 0.5);
}

void main()
{
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= push.width || px.y >= push.height)
        return;
    uint i = px.y * push.width + px.x;
    vec3 c = accum[i].rgb * push.inv_spp;
    uvec3 t = uvec3(srgb8(c.r), srgb8(c.g), srgb8(c.b));
    if ((push.flags & GN_DISPLAY_BGRA) != 0u)
        t = t.bgr;
    texels[i] = t.r | (t.g << 8) | (t.b << 16) | (255u << 24);
}
