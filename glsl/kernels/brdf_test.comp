#version 450
// brdf_test.comp: runs brdf_material.glsl, the same files the renderer includes, on a buffer of
// queries (one per invocation) so the unit tests and `gonio brdf` measure the shader code
// itself: eval and pdf at given directions, sample with given random numbers, and the
// Fresnel functions (BrdfQuery/BrdfResult in brdf_models.h).
// Specialised, as the renderer's kernels are, on the GN_FEAT_* that a batch's queries need
// (src/render/brdf.c: brdf_query_features): llvmpipe runs both sides of a branch, so the code
// of every model a query does not use would cost it as much time as its own (20 times a
// Lambert's). Every bit set (GONIO_ALL_FEATURES) is the unspecialised kernel.
#extension GL_GOOGLE_include_directive : require

#define GN_HAS(f) (((FEATURES & (f).x) | (FEATURES_HI & (f).y)) != 0u)
#include "shared.h"
layout(constant_id = GN_SPEC_FEATURES) const uint FEATURES = 0xffffffffu;    // GN_FEAT_* bits 0-31
layout(constant_id = GN_SPEC_FEATURES_HI) const uint FEATURES_HI = 0xffffffffu; // ... 32-63

// The queries' materials have no textures (every slot GN_INVALID): no lookup is ever made.
#define MATERIAL_TEXTURE(index, uv, srgb) vec4(1.0)
#include "brdf_material.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer QueryBlock { BrdfQuery queries[]; };
layout(std430, binding = 1) writeonly buffer ResultBlock { BrdfResult results[]; };
layout(push_constant) uniform PushBlock { uint count; } push;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count)
        return;
    BrdfQuery q = queries[i];
    BrdfResult r;
    r.f = vec3(0.0);
    r.pdf = 0.0;
    r.s_wi = vec3(0.0);
    r.s_pdf = 0.0;
    r.s_weight = vec3(0.0);
    r.s_flags = 0u;
    r.s_f = vec3(0.0);
    r.s_pdf_eval = 0.0;
    if ((q.op & BRDF_OP_FRESNEL) != 0u) {
        r.f = vec3(brdf_fresnel_dielectric(q.wo.z, q.args.x), brdf_fresnel_schlick(q.wo.z, vec3(q.args.y), q.args.z).x,
                   brdf_sheen_table(q.wo.z, q.args.w));
        r.s_f = brdf_fresnel_conductor(q.wo.z, q.material.base_color.rgb, q.material.brdf_params.xyz);
        results[i] = r;
        return;
    }
    // The material on the shading frame itself: normal +z, tangent +x (the anisotropy's
    // direction is its rotation), and the coat's normal tilted toward +x by coat_tilt.
    MaterialHit h;
    h.uv = vec4(0.0);
    h.color = vec4(1.0);
    h.n = vec3(0.0, 0.0, 1.0);
    h.tangent = vec4(1.0, 0.0, 0.0, 1.0);
    Shading sh = material_eval(q.material, h);
    Bsdf b = bsdf_orient(bsdf_material(sh), sh, vec3(sin(q.coat_tilt), 0.0, cos(q.coat_tilt)), sh.aniso_t.xy);
    if ((q.op & BRDF_OP_NDF) != 0u) {
        r.f = vec3(brdf_base_d(b, q.wi), brdf_base_g1(b, q.wo), 0.0);
        results[i] = r;
        return;
    }
    if ((q.op & BRDF_OP_EVAL) != 0u)
        bsdf_eval_pdf(b, q.wo, q.wi, r.f, r.pdf);
    if ((q.op & BRDF_OP_SAMPLE) != 0u) {
        BsdfSample s = bsdf_sample(b, q.wo, q.u);
        r.s_wi = s.wi;
        r.s_pdf = s.pdf;
        r.s_weight = s.weight;
        r.s_flags = s.flags;
        bsdf_eval_pdf(b, q.wo, s.wi, r.s_f, r.s_pdf_eval);
    }
    results[i] = r;
}
