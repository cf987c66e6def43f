/* brdf_models.h: the BRDF model ids, their parameter slots and the records of the BRDF test
 * kernel, shared by C (src/render/brdf.c, the tests) and GLSL (brdf.glsl, brdf_test.comp). The
 * models and their equations are docs/brdf.md's.
 *
 * A model is a colour plus four scalars: GnMaterial.brdf (the id) with base_color.rgb as the
 * colour and brdf_params as the scalars; bsdf_from_model() in brdf.glsl reads them. The
 * glTF model (id 0) has more parameters and is built by bsdf_gltf() from GnMaterial. */
#ifndef GONIO_BRDF_MODELS_H
#define GONIO_BRDF_MODELS_H

#include "shared.h"

/* ---- model ids (GnMaterial.brdf) ------------------------------------------------------ */
#define BRDF_GLTF 0u             /* glTF metallic-roughness (+ specular, transmission, ior, clearcoat, sheen) */
#define BRDF_LAMBERT 1u          /* colour = albedo */
#define BRDF_MIRROR 2u           /* colour = reflectance; the ideal mirror's delta BRDF */
#define BRDF_PHONG 3u            /* colour = diffuse; specular, exponent */
#define BRDF_BLINN_PHONG 4u      /* colour = diffuse; specular, exponent */
#define BRDF_TORRANCE_SPARROW 5u /* colour = diffuse; specular, exponent e of Blinn's D, ior */
#define BRDF_BECKMANN 6u         /* colour = diffuse; specular, alpha, ior */
#define BRDF_GGX 7u              /* colour = diffuse; specular, alpha, ior */
#define BRDF_CONDUCTOR 8u        /* colour = eta (real part of the index, RGB); k.rgb, alpha */
#define BRDF_DIELECTRIC 9u       /* colour = transmission tint; ior, alpha */
#define BRDF_MODEL_COUNT 10u

/* ---- slots of the four scalars (indices into brdf_params) ------------------------------ */
/* phong, blinn-phong, torrance-sparrow, beckmann, ggx: a Lambert layer (the colour) plus one
 * specular lobe; max(diffuse) + specular <= 1 keeps the sum energy conserving. */
#define BRDF_P_SPECULAR 0 /* lobe weight ks */
#define BRDF_P_SHAPE 1    /* Phong/Blinn exponent, or microfacet alpha (Beckmann, GGX) */
#define BRDF_P_IOR 2      /* index of the dielectric below the lobe (Fresnel) */
/* conductor */
#define BRDF_P_K 0        /* k.r, k.g, k.b in slots 0, 1, 2 */
#define BRDF_P_ALPHA 3    /* GGX alpha; 0 = polished (delta) */
/* dielectric */
#define BRDF_P_DIELECTRIC_IOR 0
#define BRDF_P_DIELECTRIC_ALPHA 1 /* GGX alpha; 0 = smooth glass (delta) */

/* The sheen's albedo table (brdf.glsl) in the BRDF kernels (brdf_test.comp, brdf_sphere.comp):
 * an R32UI texel buffer of SHEEN_N x SHEEN_N float bits. */
#define BRDF_BIND_SHEEN 2

/* ---- BsdfSample.flags ----------------------------------------------------------------- */
#define BRDF_FLAG_REFLECTION 1u
#define BRDF_FLAG_TRANSMISSION 2u
#define BRDF_FLAG_DELTA 4u /* a Dirac lobe: eval and pdf are 0 there; weight holds its value */

/* ---- the test kernel (brdf_test.comp): one query per invocation ------------------------- */
#define BRDF_OP_EVAL 1u    /* f and pdf at (wo, wi) */
#define BRDF_OP_SAMPLE 2u  /* sample(wo, u), then f and pdf at the sampled direction */
#define BRDF_OP_FRESNEL 4u /* Fresnel functions at cos = wo.z (see BrdfResult) */
#define BRDF_OP_NDF 8u     /* the base's GGX: D at the half vector wi, G1(wo) (see BrdfResult) */

/* A material and the directions to query it with. model BRDF_GLTF: color = base colour,
 * params = (metallic, roughness, specular, ior), extra = (specular colour, transmission),
 * layer = (clearcoat, clearcoat roughness, sheen roughness, the coat normal's tilt from +z
 * toward +x in radians: a test-only stand-in for a clearcoat normal map), sheen.rgb = sheen
 * colour (bsdf_layers); aniso, irid and dt as their comments say.
 * Otherwise color and params are those of bsdf_from_model and extra is unused.
 * BRDF_OP_FRESNEL: params.x = eta (dielectric), color = eta and extra.xyz = k (conductor),
 * params.y = F0 and params.z = F90 (Schlick), params.w = sheen roughness (the sheen's table). */
GN_STRUCT(BrdfQuery) {
    vec3 color; uint model;
    vec4 params;
    vec4 extra;
    vec3 wo; uint op;   /* wo: toward the viewer, local frame (normal = +z) */
    vec3 wi; float pad0; /* wi: toward the light */
    vec3 u; float pad1;  /* the sample's random numbers in [0, 1) */
    vec4 layer;
    vec4 sheen;
    vec4 aniso; /* KHR_materials_anisotropy: strength, rotation (radians), 0, 0 */
    vec4 irid;  /* KHR_materials_iridescence: factor, film ior, film thickness (nm), 0 */
    vec4 dt;    /* KHR_materials_diffuse_transmission: colour.rgb, factor */
} GN_END(BrdfQuery); /* 176 bytes */

/* BRDF_OP_EVAL: f, pdf. BRDF_OP_SAMPLE: s_* (s_f, s_pdf_eval: eval and pdf at s_wi).
 * BRDF_OP_FRESNEL: f = (dielectric, Schlick, the sheen's albedo E from its table), s_f =
 * conductor (RGB). BRDF_OP_NDF (model BRDF_GLTF, roughness > 0): f = (D(wi), G1(wo), 0). */
GN_STRUCT(BrdfResult) {
    vec3 f; float pdf;
    vec3 s_wi; float s_pdf;
    vec3 s_weight; uint s_flags;
    vec3 s_f; float s_pdf_eval;
} GN_END(BrdfResult); /* 64 bytes */

/* brdf_sphere.comp: a unit sphere at the origin, seen from +z by a pinhole camera, lit by a
 * directional light and a constant environment (the material-ball view of `gonio brdf`).
 * Material fields as in BrdfQuery. */
GN_STRUCT(BrdfSphere) {
    vec3 color; uint model;
    vec4 params;
    vec4 extra;
    vec3 light_dir; uint width;        /* unit, toward the light */
    vec3 light_irradiance; uint height; /* W/m^2 on a surface facing the light */
    vec3 env; uint max_depth;          /* environment radiance; path length limit */
    vec4 layer;
    vec4 sheen;
    vec4 aniso; /* as BrdfQuery's */
    vec4 irid;
    vec4 dt;
} GN_END(BrdfSphere); /* 176 bytes */

#ifndef VULKAN
GN_STATIC_ASSERT(sizeof(BrdfSphere) == 176, "BrdfSphere layout");
GN_STATIC_ASSERT(sizeof(BrdfQuery) == 176, "BrdfQuery layout");
GN_STATIC_ASSERT(offsetof(BrdfQuery, wo) == 48, "BrdfQuery layout");
GN_STATIC_ASSERT(sizeof(BrdfResult) == 64, "BrdfResult layout");
#endif

#endif /* GONIO_BRDF_MODELS_H */
