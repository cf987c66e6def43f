#version 450
// material_test.comp: the kernels' material reader (material_at of glsl/lib/scene.glsl, which
// glsl/lib/material.h's table generates) run on a buffer of materials, one per invocation,
// each written back through std430 as the kernels see it, so the unit tests can compare every
// field with what the host wrote.
#extension GL_GOOGLE_include_directive : require

#include "scene.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = GN_BIND_ACCUM) writeonly buffer OutBlock { GnMaterial materials_out[]; };
layout(push_constant) uniform PushBlock { GnPush push; }; // sample_index: the material count

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.sample_index)
        return;
    materials_out[i] = material_at(i);
}
