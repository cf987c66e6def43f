#version 450
// local.comp: one sample per pixel per dispatch of the non-path-traced modes: the Phong
// reflection model of OpenGL 1.x (glsl/lib/phong.glsl) evaluated once per triangle (flat),
// per vertex and interpolated (Gouraud) or per pixel (Phong shading), and the debug images
// normal, albedo, depth and BVH cost. The mode is a specialization constant, so each mode
// compiles to its own lean kernel.
#extension GL_GOOGLE_include_directive : require

// Specialised on GN_FEAT_ALPHA only (src/render/render.c: kernel_features): the rest is always on.
#define GN_HAS(f) (((FEATURES & (f).x) | (FEATURES_HI & (f).y)) != 0u)
#include "shared.h"
layout(constant_id = GN_SPEC_FEATURES) const uint FEATURES = 0xffffffffu;    // GN_FEAT_* bits 0-31
layout(constant_id = GN_SPEC_FEATURES_HI) const uint FEATURES_HI = 0xffffffffu; // ... 32-63

#include "phong.glsl"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;
layout(constant_id = 0) const uint MODE = GN_MODE_PHONG;

layout(std430, binding = GN_BIND_ACCUM) buffer AccumBlock { vec4 accum[]; };
layout(std430, binding = GN_BIND_AOV) buffer AovBlock { vec4 aov[]; };
layout(std430, binding = GN_BIND_VCOLOR) readonly buffer VColorBlock { vec4 vcolor[]; };
layout(std430, binding = GN_BIND_STATUS) buffer StatusBlock { uint status[]; };
layout(push_constant) uniform PushBlock { GnPush push; };

// Gouraud shading (Gouraud 1971): the colours glsl/kernels/vertex.comp computed at the corners,
// interpolated with the hit's barycentrics. Each vertex has a colour per side (vcolor[2i]
// lit with its normal, vcolor[2i+1] with the opposite one); the side is the one per-pixel
// shading would light, where the interpolated normal faces the viewer (see surface_at).
vec3 gouraud_color(Hit h, vec3 d)
{
    GnPrim pr = prim_at(h.tri);
    GnVertex a = vertex_at(pr.i0), b = vertex_at(pr.i1), c = vertex_at(pr.i2);
    float w = 1.0 - h.u - h.v;
    vec3 ng = cross(b.position - a.position, c.position - a.position);
    vec3 n = w * a.normal + h.u * b.normal + h.v * c.normal;
    uint side = dot(n, ng) * dot(ng, d) > 0.0 ? 1u : 0u; // n and the viewer on opposite sides
    return w * vcolor[2u * pr.i0 + side].rgb + h.u * vcolor[2u * pr.i1 + side].rgb +
           h.v * vcolor[2u * pr.i2 + side].rgb;
}

// Flat shading: the face normal, lit once at the centroid and seen from there, so the
// whole triangle has one colour.
vec3 flat_color(Hit h, vec3 d)
{
    GnPrim pr = prim_at(h.tri);
    vec3 center = (vertex_at(pr.i0).position + vertex_at(pr.i1).position +
                  vertex_at(pr.i2).position) / 3.0;
    Surface s = surface_at(h.tri, 0.0, 1.0 / 3.0, 1.0 / 3.0, center, d);
    return phong_shade(center, s.ng, s.ng, s.uv, s.vcolor, s.material,
                       camera_view(center));
}

void main()
{
    uvec2 px = tile_pixel();
    if (px.x >= frame.crop_width || px.y >= frame.crop_height)
        return;
    uint slot = px.y * frame.crop_width + px.x; // in the region's buffers (GnFrame)
    px += uvec2(frame.crop_x, frame.crop_y);    // in the whole image
    uint pixel = px.y * frame.width + px.x;
    vec2 jitter = push.sample_index == 0u ? vec2(0.5) : rand2(pixel, push.sample_index, 0u);
    vec3 o, d;
    float tnear;
    camera_ray(vec2(px) + jitter, o, d, tnear);
    rng_pixel = pixel;
    rng_sample = push.sample_index;
    Hit h = trace_visible(o, d, tnear, 1e30, false, frame.traversal_budget, DIM_ALPHA);

    vec3 color = vec3(0.0);
    vec3 normal = vec3(0.0), albedo = vec3(0.0);
    float depth = 0.0;
    if (h.tri != GN_INVALID) {
        Surface s = surface_at(h.tri, h.t, h.u, h.v, o, d);
        normal = s.sh.n;
        albedo = s.sh.m.base_color.rgb;
        depth = h.t * dot(d, frame.camera.forward);
        if (MODE == GN_MODE_NORMAL) color = normal;
        else if (MODE == GN_MODE_ALBEDO) color = albedo;
        else if (MODE == GN_MODE_DEPTH) color = vec3(depth);
        else if (MODE == GN_MODE_PHONG) color = phong_shade(s.p, s.sh.n, s.ng, s.uv, s.vcolor, s.material, -d);
        else if (MODE == GN_MODE_GOURAUD) color = gouraud_color(h, d);
        else if (MODE == GN_MODE_FLAT) color = flat_color(h, d);
    } else {
        color = (mode_flags(MODE) & GN_MODEF_LIT) != 0u ? frame.env_color : vec3(0.0);
    }
    if (MODE == GN_MODE_COST) color = vec3(float(h.steps));
    accum[slot] += vec4(color, h.tri != GN_INVALID ? 1.0 : 0.0); // w: coverage
    if (h.truncated)
        atomicAdd(status[0], 1u);
    if ((frame.flags & GN_FRAME_AOV) != 0u) {
        aov[3u * slot + 0u] += vec4(normal, 0.0);
        aov[3u * slot + 1u] += vec4(albedo, 0.0);
        aov[3u * slot + 2u] += vec4(depth, 0.0, 0.0, 0.0);
    }
}
