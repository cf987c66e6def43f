#version 450
// wrap_test.comp: tex_wrap of wrap.glsl, the file the renderer's texture lookups include, on
// a buffer of queries (i, n, mode) so the unit tests can check it against integer
// arithmetic.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "wrap.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer QueryBlock { ivec4 queries[]; };
layout(std430, binding = 1) writeonly buffer ResultBlock { int results[]; };
layout(push_constant) uniform PushBlock { uint count; } push;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count)
        return;
    ivec4 q = queries[i];
    results[i] = tex_wrap(q.x, q.y, uint(q.z));
}
