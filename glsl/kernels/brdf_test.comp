#version 450
// brdf_test.comp: runs brdf.glsl, the same file the renderer includes, on a buffer of
// queries (one per invocation) so the unit tests and `gonio brdf` measure the shader code
// itself: eval and pdf at given directions, sample with given random numbers, and the
// Fresnel functions (BrdfQuery/BrdfResult in brdf_models.h).
// Specialised, as the renderer's kernels are, on the GN_FEAT_* that a batch's queries need
// (src/render/brdf.c: brdf_query_features): llvmpipe runs both sides of a branch, so the code
// of every model a query does not use would cost it as much time as its own (20 times a
// Lambert's). FEATURES = GN_FEAT_ALL (GONIO_ALL_FEATURES) is the unspecialised kernel.
#extension GL_GOOGLE_include_directive : require

#define GN_HAS(f) ((FEATURES & (f)) != 0u)
#include "shared.h"
layout(constant_id = 1) const uint FEATURES = GN_FEAT_ALL;

#include "brdf.glsl"

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
        r.f = vec3(brdf_fresnel_dielectric(q.wo.z, q.params.x),
                   brdf_fresnel_schlick(q.wo.z, vec3(q.params.y), q.params.z).x,
                   brdf_sheen_table(q.wo.z, q.params.w));
        r.s_f = brdf_fresnel_conductor(q.wo.z, q.color, q.extra.xyz);
        results[i] = r;
        return;
    }
    // (the models' and glTF's parts gated as path.comp's material_bsdf gates them)
    Bsdf b;
    if (GN_HAS(GN_FEAT_MODELS) && (!GN_HAS(GN_FEAT_GLTF) || q.model != BRDF_GLTF)) {
        b = bsdf_from_model(q.model, q.color, q.params);
    } else {
        b = bsdf_gltf(q.color, q.params.x, q.params.y, q.params.z, q.extra.xyz, q.params.w, q.extra.w);
        if (GN_HAS(GN_FEAT_LAYERS)) {
            b = bsdf_gltf_film(b, q.color, q.params.x, q.params.z, q.extra.xyz, q.params.w, q.extra.w, q.irid.xyz, q.dt);
            b = bsdf_layers(b, q.layer.x, q.layer.y, vec3(sin(q.layer.w), 0.0, cos(q.layer.w)), q.sheen.rgb, q.layer.z);
        }
        // the tangent is +x: the anisotropy's direction is the rotation's
        b = bsdf_anisotropy(b, q.aniso.x, vec2(cos(q.aniso.y), sin(q.aniso.y)));
    }
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
