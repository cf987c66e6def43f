#version 450
// trace_test.comp: traces a buffer of rays through bvh.glsl, one ray per invocation, so the
// unit tests can compare the GPU walk with the C traversal and with brute force, over one
// tree or (INSTANCES) two levels. A walk that spends its budget is saved and resumed by the
// next dispatch (GN_PASS_RESUME), which gives exact answers even where one invocation could
// not finish on llvmpipe.
#extension GL_GOOGLE_include_directive : require

#include "bvh.glsl"

layout(local_size_x = 64) in;

// ray i: rays[2i] = (origin, tmin), rays[2i+1] = (direction, tmax)
layout(std430, binding = GN_BIND_ACCUM) readonly buffer RayBlock { vec4 rays[]; };
// result i: (t, u, v, uintBitsToFloat(tri)), (steps, unfinished, uintBitsToFloat(inst), 0)
layout(std430, binding = GN_BIND_AOV) buffer HitBlock { vec4 hits[]; };
// saved walks of unfinished rays
layout(std430, binding = GN_BIND_VCOLOR) buffer WalkBlock { Walk walks[]; };
layout(std430, binding = GN_BIND_STATUS) buffer StatusBlock { uint status[]; };
layout(push_constant) uniform PushBlock { GnPush push; }; // sample_index: ray count; pass_flags

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.sample_index)
        return;
    vec4 a = rays[2u * i], b = rays[2u * i + 1u];
    if ((push.pass_flags & GN_PASS_RESUME) == 0u) {
        walk_start(b.w);
    } else {
        if (hits[2u * i + 1u].y == 0.0)
            return; // finished earlier
        walk = walks[i];
    }
    bvh_walk(ray_pre(a.xyz, b.xyz), a.w, (push.pass_flags & GN_PASS_ANY_HIT) != 0u, frame.traversal_budget);
    Walk w = walk;
    hits[2u * i] = vec4(w.hit.t, w.hit.u, w.hit.v, uintBitsToFloat(w.hit.tri));
    hits[2u * i + 1u] = vec4(float(w.hit.steps), w.hit.truncated ? 1.0 : 0.0, uintBitsToFloat(w.hit.inst), 0.0);
    if (w.hit.truncated) {
        walks[i] = w;
        atomicAdd(status[0], 1u);
    }
}
