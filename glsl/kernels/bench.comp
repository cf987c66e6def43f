#version 450
// bench.comp: ray throughput for `gonio bench`. MODE 0 traces one camera ray per pixel
// and writes the diffuse bounce ray leaving each hit (cosine-distributed about the
// geometric normal); MODE 1 traces a buffer of such rays. Timing the two dispatches apart
// gives coherent (primary) and incoherent (diffuse) rates of the same traversal code.
#extension GL_GOOGLE_include_directive : require

#include "bvh.glsl"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;
layout(constant_id = 0) const uint MODE = 0u;

layout(std430, binding = GN_BIND_ACCUM) buffer HitBlock { vec4 hit_out[]; };
// bounce ray i: rays[2i] = (origin, tmin), rays[2i+1] = (direction, tmax < 0: none)
layout(std430, binding = GN_BIND_AOV) buffer RayBlock { vec4 rays[]; };
layout(push_constant) uniform PushBlock { GnPush push; };

void main()
{
    uvec2 px = tile_pixel();
    if (px.x >= frame.width || px.y >= frame.height)
        return;
    uint pixel = px.y * frame.width + px.x;
    if (MODE == 0u) {
        vec3 o, d;
        float tnear;
        camera_ray(vec2(px) + rand2(pixel, push.sample_index, 0u), o, d, tnear);
        Hit h = bvh_trace(o, d, tnear, 1e30, false);
        hit_out[pixel] = vec4(h.t, float(h.steps), 0.0, uintBitsToFloat(h.tri));
        if (h.tri == GN_INVALID) {
            rays[2u * pixel + 1u] = vec4(0.0, 0.0, 1.0, -1.0);
            return;
        }
        vec3 c0, c1, c2;
        tri_corners(h.tri, h.inst, c0, c1, c2);
        vec3 n = normalize(cross(c1 - c0, c2 - c0));
        if (dot(n, d) > 0.0) n = -n;
        vec2 u = rand2(pixel, push.sample_index, 1u);
        // cosine-weighted direction about n (Malley's method on a concentric-free disk)
        float r = sqrt(u.x), phi = 2.0 * PI * u.y;
        vec3 a = abs(n.x) > 0.5 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
        vec3 tx = normalize(cross(a, n)), ty = cross(n, tx);
        vec3 wi = r * cos(phi) * tx + r * sin(phi) * ty + sqrt(max(0.0, 1.0 - u.x)) * n;
        vec3 p = o + h.t * d;
        float eps = 1e-4 * max(1.0, max(abs(p.x), max(abs(p.y), abs(p.z))));
        rays[2u * pixel] = vec4(p + n * eps, 0.0);
        rays[2u * pixel + 1u] = vec4(wi, 1e30);
    } else {
        vec4 a = rays[2u * pixel], b = rays[2u * pixel + 1u];
        if (b.w < 0.0)
            return;
        Hit h = bvh_trace(a.xyz, b.xyz, a.w, b.w, false);
        hit_out[pixel] = vec4(h.t, float(h.steps), 1.0, uintBitsToFloat(h.tri));
    }
}
