#version 450
// sampler_test.comp: sampler_get4 of sampling.glsl, the function the path kernel draws its
// numbers from, on a buffer of queries (pixel, sample index, dimension, seed) for the
// sampler `kind`, so the unit tests can check the points' properties on the host.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sampling.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer QueryBlock { uvec4 queries[]; };
layout(std430, binding = 1) writeonly buffer ResultBlock { vec4 results[]; };
layout(push_constant) uniform PushBlock { uint count; uint kind; } push;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count)
        return;
    uvec4 q = queries[i];
    results[i] = sampler_get4(push.kind, q.x, q.y, q.z, q.w);
}
