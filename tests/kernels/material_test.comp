#version 450
// material_test.comp: the kernels' material code run on buffers, one query per invocation, so
// the unit tests can check it against the host and the glTF specification:
// - push.pass_flags 0: material i through material_at (glsl/lib/scene.glsl, generated from
//   glsl/lib/material.h's table) and written back through std430 as the kernels see it;
// - MATERIAL_TEST_EVAL: material_eval (glsl/lib/material.glsl) of the material and uv of
//   query i (the scene's textures bound as the renderer binds them), on the frame normal +z,
//   tangent +x, vertex colour 1.
#extension GL_GOOGLE_include_directive : require

#include "scene.glsl"

layout(local_size_x = 64) in;

#define MATERIAL_TEST_EVAL 1u

// query i: uv (TEXCOORD_0 xy, TEXCOORD_1 zw) and material
struct MaterialQuery {
    vec4 uv;
    uint material; uint pad0; uint pad1; uint pad2;
};
// result i: the material (the textured one for an evaluation) and the film's thickness
struct MaterialResult {
    GnMaterial m;
    vec4 film; // x: Shading.film_thickness
};
layout(std430, binding = GN_BIND_AOV) readonly buffer QueryBlock { MaterialQuery queries[]; };
layout(std430, binding = GN_BIND_ACCUM) writeonly buffer OutBlock { MaterialResult results[]; };
layout(push_constant) uniform PushBlock { GnPush push; }; // sample_index: the count; pass_flags

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.sample_index)
        return;
    if (push.pass_flags != MATERIAL_TEST_EVAL) {
        results[i].m = material_at(i);
        results[i].film = vec4(0.0);
        return;
    }
    MaterialQuery q = queries[i];
    MaterialHit h;
    h.uv = q.uv;
    h.color = vec4(1.0);
    h.n = vec3(0.0, 0.0, 1.0);
    h.tangent = vec4(1.0, 0.0, 0.0, 1.0);
    Shading s = material_eval(material_at(q.material), h);
    results[i].m = s.m;
    results[i].film = vec4(s.film_thickness, 0.0, 0.0, 0.0);
}
