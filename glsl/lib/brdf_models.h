/* brdf_models.h: the table of BRDF models, their parameter slots and the records of the BRDF
 * test kernel, shared by C (src/render/brdf.c, src/render/render_material.c, the tests) and
 * GLSL (brdf_material.glsl, brdf_test.comp). docs/brdf.md has the models' equations.
 *
 * A model is a colour plus four scalars: GnMaterial.brdf (the id) with base_color.rgb as the
 * colour and brdf_params as the scalars; bsdf_from_model() in brdf_material.glsl reads them. The
 * glTF model (id 0) has more parameters and is built by bsdf_gltf() from GnMaterial. */
#ifndef GONIO_BRDF_MODELS_H
#define GONIO_BRDF_MODELS_H

#include "shared.h"

/* ---- the models: one table, expanded by C (src/render/brdf.c: names, parameters, --list;
 * src/render/render_material.c: material_features) and GLSL (brdf_material.glsl: bsdf_from_model). A row is
 *   X(id, name, summary, lobe, fresnel, layout, lobe_feats, feats, params)
 * - id: GnMaterial.brdf; unique (tests/unit/test_brdf.c checks), never reused. BRDF_GLTF is
 *   built by bsdf_gltf from GnMaterial's own fields, the rest by bsdf_from_model from a
 *   colour and the four scalars of brdf_params, placed as `layout` says;
 * - name, summary, params: C only (glslang tokenises the strings but never expands them):
 *   the `gonio brdf` / `--brdf` name, its --list line, and its parameters as
 *   COLOR/SCALAR(name, slot, default(s), min, max) of src/render/brdf.c, slots of src/render/brdf.h;
 * - lobe, fresnel: the Bsdf's specular lobe and its Fresnel factor (BRDF_LOBE_*,
 *   BRDF_FRESNEL_* of brdf_bsdf.glsl); a microfacet lobe (Beckmann, GGX) whose alpha is below
 *   BRDF_ALPHA_MIN becomes the mirror;
 * - lobe_feats: the GN_FEAT_* of the lobes the model can build (GN_FEAT_LOBES is their
 *   union); feats: its other GN_FEAT_* (Fresnel, glass). The path kernel is specialised on
 *   their union for a scene whose materials use the model (src/render/render_material.c: material_features;
 *   glTF's bits depend on the material's values and are worked out there).
 * Adding a model: a row here, its lobe in brdf_bsdf.glsl if it has a new one, its section in
 * docs/brdf.md (docs/architecture.md: Adding a BRDF model). */
#define BRDF_GLTF 0u /* the ids that code names; a new model needs none */
#define BRDF_LAMBERT 1u
#define BRDF_MIRROR 2u
#define BRDF_PHONG 3u
#define BRDF_BLINN_PHONG 4u
#define BRDF_TORRANCE_SPARROW 5u
#define BRDF_BECKMANN 6u
#define BRDF_GGX 7u
#define BRDF_CONDUCTOR 8u
#define BRDF_DIELECTRIC 9u

/* layout: where bsdf_from_model puts the colour and the four scalars (slots below) */
#define BRDF_LAYOUT_GLTF 0u       /* none: bsdf_gltf reads GnMaterial */
#define BRDF_LAYOUT_DIFFUSE 1u    /* colour = Lambert albedo */
#define BRDF_LAYOUT_LOBE 2u       /* colour = the lobe's weight */
#define BRDF_LAYOUT_LAYERED 3u    /* colour = Lambert albedo; specular, shape, ior */
#define BRDF_LAYOUT_CONDUCTOR 4u  /* colour = eta (real part of the index, RGB); k.rgb, alpha */
#define BRDF_LAYOUT_DIELECTRIC 5u /* colour = transmission tint; ior, alpha */

#define BRDF_GLTF_FEATS (GN_FEAT_MIRROR | GN_FEAT_GGX) /* bsdf_gltf: a GGX lobe, a mirror when smooth */
#define BRDF_SMOOTH_FEATS(lobe) (lobe | GN_FEAT_MIRROR) /* a microfacet lobe: a mirror below BRDF_ALPHA_MIN */
#define BRDF_LAYERED_PARAMS(shape, shape_def, shape_max) \
    COLOR("diffuse", BRDF_SLOT_COLOR, 0, 0, 0, 0, 1), SCALAR("specular", P(BRDF_P_SPECULAR), 1, 0, 1), \
        SCALAR(shape, P(BRDF_P_SHAPE), shape_def, 0, shape_max)

#define BRDF_MODELS(X) \
    X(BRDF_LAMBERT, "lambert", "Lambertian diffuse, f = albedo / pi", \
      BRDF_LOBE_NONE, BRDF_FRESNEL_NONE, BRDF_LAYOUT_DIFFUSE, 0u, 0u, \
      (COLOR("diffuse", BRDF_SLOT_COLOR, 0.8f, 0.8f, 0.8f, 0, 1))) \
    X(BRDF_MIRROR, "mirror", "perfect mirror, Lo = R Li(r(wo)) (a Dirac lobe)", \
      BRDF_LOBE_MIRROR, BRDF_FRESNEL_NONE, BRDF_LAYOUT_LOBE, GN_FEAT_MIRROR, 0u, \
      (COLOR("reflectance", BRDF_SLOT_COLOR, 1, 1, 1, 0, 1))) \
    X(BRDF_PHONG, "phong", "diffuse + normalised Phong, ks (n+2)/(2 pi) cos^n(r(wi), wo)", \
      BRDF_LOBE_PHONG, BRDF_FRESNEL_NONE, BRDF_LAYOUT_LAYERED, GN_FEAT_PHONG, 0u, \
      (BRDF_LAYERED_PARAMS("exponent", 32, 100000))) \
    X(BRDF_BLINN_PHONG, "blinn-phong", "diffuse + normalised Blinn-Phong, ks N(n) (n.h)^n", \
      BRDF_LOBE_BLINN, BRDF_FRESNEL_NONE, BRDF_LAYOUT_LAYERED, GN_FEAT_BLINN, 0u, \
      (BRDF_LAYERED_PARAMS("exponent", 32, 100000))) \
    X(BRDF_TORRANCE_SPARROW, "torrance-sparrow", "diffuse + Torrance-Sparrow: Blinn D, V-cavity G, dielectric Fresnel", \
      BRDF_LOBE_TS, BRDF_FRESNEL_DIELECTRIC, BRDF_LAYOUT_LAYERED, GN_FEAT_TS, GN_FEAT_FRESNEL_DIELECTRIC, \
      (BRDF_LAYERED_PARAMS("exponent", 100, 100000), SCALAR("ior", P(BRDF_P_IOR), 1.5f, 1, 4))) \
    X(BRDF_BECKMANN, "beckmann", "diffuse + Beckmann microfacet, Smith G, dielectric Fresnel", \
      BRDF_LOBE_BECKMANN, BRDF_FRESNEL_DIELECTRIC, BRDF_LAYOUT_LAYERED, BRDF_SMOOTH_FEATS(GN_FEAT_BECKMANN), \
      GN_FEAT_FRESNEL_DIELECTRIC, (BRDF_LAYERED_PARAMS("alpha", 0.2f, 1), SCALAR("ior", P(BRDF_P_IOR), 1.5f, 1, 4))) \
    X(BRDF_GGX, "ggx", "diffuse + GGX microfacet, Smith G, dielectric Fresnel", \
      BRDF_LOBE_GGX, BRDF_FRESNEL_DIELECTRIC, BRDF_LAYOUT_LAYERED, BRDF_SMOOTH_FEATS(GN_FEAT_GGX), \
      GN_FEAT_FRESNEL_DIELECTRIC, (BRDF_LAYERED_PARAMS("alpha", 0.2f, 1), SCALAR("ior", P(BRDF_P_IOR), 1.5f, 1, 4))) \
    X(BRDF_CONDUCTOR, "conductor", "GGX metal, complex index eta + i k (default: gold)", \
      BRDF_LOBE_GGX, BRDF_FRESNEL_CONDUCTOR, BRDF_LAYOUT_CONDUCTOR, BRDF_SMOOTH_FEATS(GN_FEAT_GGX), \
      GN_FEAT_FRESNEL_CONDUCTOR, \
      (COLOR("eta", BRDF_SLOT_COLOR, 0.143f, 0.374f, 1.442f, 0.01f, 10), \
       COLOR("k", P(BRDF_P_K), 3.983f, 2.385f, 1.603f, 0, 20), SCALAR("alpha", P(BRDF_P_ALPHA), 0.1f, 0, 1))) \
    X(BRDF_DIELECTRIC, "dielectric", "glass: Fresnel reflection + refraction, smooth or GGX", \
      BRDF_LOBE_NONE, BRDF_FRESNEL_NONE, BRDF_LAYOUT_DIELECTRIC, 0u, GN_FEAT_SMOOTH_GLASS | GN_FEAT_ROUGH_GLASS, \
      (COLOR("tint", BRDF_SLOT_COLOR, 1, 1, 1, 0, 1), SCALAR("ior", P(BRDF_P_DIELECTRIC_IOR), 1.5f, 1.01f, 4), \
       SCALAR("alpha", P(BRDF_P_DIELECTRIC_ALPHA), 0, 0, 1))) \
    X(BRDF_GLTF, "gltf", \
      "glTF metallic-roughness + KHR_materials_specular/transmission/ior/clearcoat/sheen/anisotropy/iridescence/diffuse_transmission", \
      BRDF_LOBE_GGX, BRDF_FRESNEL_SCHLICK, BRDF_LAYOUT_GLTF, BRDF_GLTF_FEATS, GN_FEAT_GLTF, (BRDF_GLTF_PARAMS))

/* The glTF model's parameters: the material table's (glsl/lib/material.h), each row with a
 * BRDF(name, default, lo, hi) column, in the table's order, at its field's word. C only:
 * glslang expands a macro's arguments even where they are not used. */
#ifdef VULKAN
#define BRDF_GLTF_PARAMS
#else
#define BRDF_GLTF_PARAMS GN_MATERIAL(BRDF_GLTF_PARAM, GN_MAT_NO_TEX, GN_MAT_NO_FIELD)
#define BRDF_GLTF_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) \
    BRDF_GLTF_PARAM_##type(GN_MAT_WORD(name), brdf)
/* (the BRDF(...) column arrives expanded, as its arguments: has, name, default, lo, hi) */
#define BRDF_GLTF_PARAM_float(slot, has, name, def, lo, hi) BRDF_GLTF_SCALAR_##has(slot, name, def, lo, hi)
#define BRDF_GLTF_PARAM_vec3(slot, has, name, def, lo, hi) BRDF_GLTF_COLOR_##has(slot, name, def, lo, hi)
/* (RGB: the alpha is no parameter) */
#define BRDF_GLTF_PARAM_vec4(slot, has, name, def, lo, hi) BRDF_GLTF_COLOR_##has(slot, name, def, lo, hi)
#define BRDF_GLTF_SCALAR_BRDF_YES(slot, name, def, lo, hi) SCALAR(name, slot, def, lo, hi),
#define BRDF_GLTF_COLOR_BRDF_YES(slot, name, def, lo, hi) COLOR(name, slot, def, def, def, lo, hi),
#define BRDF_GLTF_SCALAR_BRDF_NO(slot, name, def, lo, hi)
#define BRDF_GLTF_COLOR_BRDF_NO(slot, name, def, lo, hi)
#define BRDF(name, def, lo, hi) BRDF_YES, name, def, lo, hi
#define NO_BRDF BRDF_NO, 0, 0, 0, 0
#endif

/* Below this GGX/Beckmann alpha a lobe is treated as smooth (a Dirac lobe): a narrower lobe
 * is under a tenth of a degree wide, which float directions cannot resolve (brdf_material.glsl's
 * constructors; src/render/render_material.c: material_features, which must agree). */
#define BRDF_ALPHA_MIN 1e-3f

/* The union of every model's lobe features: may a kernel meet any specular lobe at all. */
#define BRDF_X_LOBE_FEATS(id, name, summary, lobe, fresnel, layout, lobe_feats, feats, params) | (lobe_feats)
#define GN_FEAT_LOBES (GN_FEAT_NONE BRDF_MODELS(BRDF_X_LOBE_FEATS))

/* ---- slots of the four scalars (indices into brdf_params) ------------------------------ */
/* BRDF_LAYOUT_LAYERED: a Lambert layer (the colour) plus one specular lobe;
 * max(diffuse) + specular <= 1 keeps the sum energy conserving. */
#define BRDF_P_SPECULAR 0 /* lobe weight ks */
#define BRDF_P_SHAPE 1    /* Phong/Blinn exponent, or microfacet alpha (Beckmann, GGX) */
#define BRDF_P_IOR 2      /* index of the dielectric below the lobe (Fresnel) */
/* BRDF_LAYOUT_CONDUCTOR */
#define BRDF_P_K 0        /* k.r, k.g, k.b in slots 0, 1, 2 */
#define BRDF_P_ALPHA 3    /* GGX alpha; 0 = polished (delta) */
/* BRDF_LAYOUT_DIELECTRIC */
#define BRDF_P_DIELECTRIC_IOR 0
#define BRDF_P_DIELECTRIC_ALPHA 1 /* GGX alpha; 0 = smooth glass (delta) */

/* The sheen's albedo table (brdf_scatter.glsl) in the BRDF kernels (brdf_test.comp, brdf_sphere.comp):
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

/* A material and the directions to query it with: the material as the renderer has it, less
 * its textures (every slot GN_INVALID), its model in .brdf (bsdf_material builds its Bsdf as
 * the path kernel does: glTF from its own fields, a model from base_color.rgb and
 * brdf_params), on the shading frame with the tangent +x and the coat's normal tilted by
 * coat_tilt radians from +z toward +x (a test-only stand-in for a clearcoat normal map).
 * BRDF_OP_FRESNEL: args.x = eta (dielectric), the material's base_color.rgb = eta and its
 * brdf_params.xyz = k (conductor), args.y = F0 and args.z = F90 (Schlick), args.w = the sheen's
 * roughness (its table). */
GN_STRUCT(BrdfQuery) {
    GnMaterial material;
    vec3 wo; uint op;       /* wo: toward the viewer, local frame (normal = +z) */
    vec3 wi; float coat_tilt; /* wi: toward the light */
    vec3 u; float pad0;     /* the sample's random numbers in [0, 1) */
    vec4 args;
} GN_END(BrdfQuery); /* a GnMaterial, then 64 bytes */

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
 * The material as BrdfQuery's, its tangent along the ball's parallels. */
GN_STRUCT(BrdfSphere) {
    GnMaterial material;
    vec3 light_dir; uint width;        /* unit, toward the light */
    vec3 light_irradiance; uint height; /* W/m^2 on a surface facing the light */
    vec3 env; uint max_depth;          /* environment radiance; path length limit */
} GN_END(BrdfSphere); /* a GnMaterial, then 48 bytes */

#ifndef VULKAN
GN_STATIC_ASSERT(sizeof(BrdfSphere) == 4 * GN_MATERIAL_WORDS + 48, "BrdfSphere layout");
GN_STATIC_ASSERT(sizeof(BrdfQuery) == 4 * GN_MATERIAL_WORDS + 64, "BrdfQuery layout");
GN_STATIC_ASSERT(offsetof(BrdfQuery, wo) == 4 * GN_MATERIAL_WORDS, "BrdfQuery layout");
GN_STATIC_ASSERT(sizeof(BrdfResult) == 64, "BrdfResult layout");
#endif

#endif /* GONIO_BRDF_MODELS_H */
