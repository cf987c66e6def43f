/* material.h: the one declaration of a material. Every field of GnMaterial is one row of
 * GN_MATERIAL below, with its GPU type and place and, for what a glTF file sets, where it
 * comes from; everything else is expanded from the table:
 * - GnMaterial itself, in C, C++ and GLSL (glsl/lib/shared.h), with a static assert per row
 *   that the field sits at its word (std430 and C agree, or the build fails);
 * - the kernels' reader, material_at (glsl/lib/scene.glsl), and the textures applied to the
 *   factors at a hit (glsl/lib/material.glsl: material_eval);
 * - the loader's reading and checking of every parameter and texture slot, and the defaults
 *   (src/scene/gltf_material.cpp, scene_material_default);
 * - the glTF model's `--brdf gltf:PARAM=VALUE` and `gonio brdf --PARAM` parameters
 *   (src/render/brdf.c) and the overrides that set them (src/render/render_material.c).
 * Included by shared.h at GnMaterial's place; valid C, C++ and GLSL (the strings and ranges
 * are tokens the GLSL expansions drop).
 *
 * The rows, in GPU order (word = the field's offset in 4-byte words; a vec3 or vec4 starts a
 * 16-byte texel, a vec3 is followed by a scalar, as everywhere in shared.h):
 *   PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf)
 *     a factor of the file: `ext` the extension's name ("" for glTF 2.0 itself), `json` the
 *     property's path in the material (core) or the extension object, `def` its default,
 *     [lo, hi] its range and `rule` what a value outside it gets (GN_MAT_RULE_*: clamped
 *     with a warning, or ignored with one); `feat`: the path kernel's feature that the glTF
 *     model's construction needs where the factor is above 0 (its textures only scale it
 *     down; src/render/render_material.c: material_features), GN_FEAT_NONE for none;
 *     `brdf`: BRDF(name, default, lo, hi), its
 *     parameter of the glTF BRDF model (the default that of the material ball of `gonio
 *     brdf`, the range the one the command line accepts), or NO_BRDF. A wrong JSON type is
 *     an error naming the JSON path, for every row alike.
 *   TEX(name, word, ext, json, space, gate, uses)
 *     a texture slot (an index into GnTexture[], GN_INVALID when absent): `json` its
 *     textureInfo (index, texCoord, KHR_texture_transform), `space` SRGB or LINEAR, `gate`
 *     the kernel feature besides GN_FEAT_TEXTURES under which it is read, and `uses` the
 *     factors it scales: USES1(field, channels), USES2(field, channels, field, channels)
 *     (material_eval multiplies them in), or SPECIAL (read by code of its own: normal maps,
 *     the anisotropy direction, the film's thickness, occlusion in the local modes).
 *   FIELD(name, type, word)
 *     set by the loader's own rules or by the renderer (flags, the BRDF override, the Phong
 *     parameters, the medium flag) or padding.
 * Adding a material extension: docs/architecture.md, "Adding a glTF material extension". */
#ifndef GONIO_MATERIAL_H
#define GONIO_MATERIAL_H

#define GN_MATERIAL(PARAM, TEX, FIELD) \
    /* linear RGBA */ \
    PARAM(base_color, vec4, 0, "", "pbrMetallicRoughness.baseColorFactor", \
        1, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("base-color", 0.8f, 0, 1)) \
    /* x KHR_materials_emissive_strength */ \
    PARAM(emissive, vec3, 4, "", "emissiveFactor", 0, 0, 1, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    PARAM(metallic, float, 7, "", "pbrMetallicRoughness.metallicFactor", \
        1, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("metallic", 0, 0, 1)) \
    PARAM(specular_color, vec3, 8, "KHR_materials_specular", "specularColorFactor", \
        1, 0, GN_INF, CHECK, GN_FEAT_NONE, BRDF("specular-color", 1, 0, 100)) \
    PARAM(roughness, float, 11, "", "pbrMetallicRoughness.roughnessFactor", \
        1, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("roughness", 0.5f, 0, 1)) \
    PARAM(specular, float, 12, "KHR_materials_specular", "specularFactor", \
        1, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("specular", 1, 0, 1)) \
    PARAM(ior, float, 13, "KHR_materials_ior", "ior", 1.5f, 1, GN_INF, IOR, GN_FEAT_NONE, BRDF("ior", 1.5f, 1, 4)) \
    PARAM(transmission, float, 14, "KHR_materials_transmission", "transmissionFactor", \
        0, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("transmission", 0, 0, 1)) \
    PARAM(normal_scale, float, 15, "", "normalTexture.scale", 1, -GN_INF, GN_INF, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    PARAM(occlusion_strength, float, 16, "", "occlusionTexture.strength", 1, 0, 1, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    PARAM(alpha_cutoff, float, 17, "", "alphaCutoff", 0.5f, 0, GN_INF, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    /* GN_MAT_*: doubleSided, alphaMode, KHR_materials_unlit */ \
    FIELD(flags, uint, 18) \
    /* the BRDF model (brdf_models.h): 0 = glTF */ \
    FIELD(brdf, uint, 19) \
    TEX(tex_base, 20, "", "pbrMetallicRoughness.baseColorTexture", SRGB, GN_FEAT_TEXTURES, USES1(base_color, rgba)) \
    TEX(tex_mr, 21, "", "pbrMetallicRoughness.metallicRoughnessTexture", \
        LINEAR, GN_FEAT_TEXTURES, USES2(roughness, g, metallic, b)) \
    TEX(tex_normal, 22, "", "normalTexture", LINEAR, GN_FEAT_NORMAL_MAP, SPECIAL) \
    TEX(tex_emissive, 23, "", "emissiveTexture", SRGB, GN_FEAT_TEXTURES, USES1(emissive, rgb)) \
    /* R: phong.glsl */ \
    TEX(tex_occlusion, 24, "", "occlusionTexture", LINEAR, GN_FEAT_TEXTURES, SPECIAL) \
    TEX(tex_specular, 25, "KHR_materials_specular", "specularTexture", LINEAR, GN_FEAT_TEXTURES, USES1(specular, a)) \
    TEX(tex_specular_color, 26, "KHR_materials_specular", "specularColorTexture", \
        SRGB, GN_FEAT_TEXTURES, USES1(specular_color, rgb)) \
    TEX(tex_transmission, 27, "KHR_materials_transmission", "transmissionTexture", \
        LINEAR, GN_FEAT_TEXTURES, USES1(transmission, r)) \
    /* the override model's four scalars */ \
    FIELD(brdf_params, vec4, 28) \
    /* the classic (OpenGL 1.x) Phong parameters of the local modes (scene_phong_from_pbr, extras.gonio.phong) */ \
    FIELD(phong_ambient, vec3, 32) \
    FIELD(phong_shininess, float, 35) \
    FIELD(phong_diffuse, vec3, 36) \
    FIELD(phong_pad0, float, 39) \
    FIELD(phong_specular, vec3, 40) \
    FIELD(phong_pad1, float, 43) \
    FIELD(phong_emission, vec3, 44) \
    FIELD(phong_pad2, float, 47) \
    /* KHR_materials_volume: sigma_a = -ln(attenuation_color) / attenuation_distance (+inf: none); the medium's \
     * flag (volume) is thicknessFactor > 0; the thickness itself is the rasterizers' stand-in for the geometry the \
     * path tracer follows (docs/path-tracing.md) */ \
    PARAM(attenuation_color, vec3, 48, "KHR_materials_volume", "attenuationColor", \
        1, 0, 1, CHECK, GN_FEAT_NONE, NO_BRDF) \
    PARAM(attenuation_distance, float, 51, "KHR_materials_volume", "attenuationDistance", \
        GN_INF, 0, GN_INF, POSITIVE, GN_FEAT_NONE, NO_BRDF) \
    PARAM(thickness, float, 52, "KHR_materials_volume", "thicknessFactor", \
        0, 0, GN_INF, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    /* 20 / Abbe */ \
    PARAM(dispersion, float, 53, "KHR_materials_dispersion", "dispersion", \
        0, 0, GN_INF, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    FIELD(volume, uint, 54) \
    /* (gate none: the path kernel never reads the thickness) */ \
    TEX(tex_thickness, 55, "KHR_materials_volume", "thicknessTexture", LINEAR, GN_FEAT_NONE, USES1(thickness, g)) \
    PARAM(clearcoat, float, 56, "KHR_materials_clearcoat", "clearcoatFactor", \
        0, 0, 1, CLAMP, GN_FEAT_LAYERS, BRDF("clearcoat", 0, 0, 1)) \
    PARAM(clearcoat_roughness, float, 57, "KHR_materials_clearcoat", "clearcoatRoughnessFactor", \
        0, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("clearcoat-roughness", 0, 0, 1)) \
    TEX(tex_clearcoat, 58, "KHR_materials_clearcoat", "clearcoatTexture", \
        LINEAR, GN_FEAT_LAYERS, USES1(clearcoat, r)) \
    TEX(tex_clearcoat_roughness, 59, "KHR_materials_clearcoat", "clearcoatRoughnessTexture", \
        LINEAR, GN_FEAT_LAYERS, USES1(clearcoat_roughness, g)) \
    /* the coat's own normal map (GN_INVALID: the mesh's normal, never normalTexture's) */ \
    TEX(tex_clearcoat_normal, 60, "KHR_materials_clearcoat", "clearcoatNormalTexture", \
        LINEAR, GN_FEAT_LAYERS, SPECIAL) \
    PARAM(clearcoat_normal_scale, float, 61, "KHR_materials_clearcoat", "clearcoatNormalTexture.scale", \
        1, -GN_INF, GN_INF, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    TEX(tex_sheen_color, 62, "KHR_materials_sheen", "sheenColorTexture", \
        SRGB, GN_FEAT_LAYERS, USES1(sheen_color, rgb)) \
    TEX(tex_sheen_roughness, 63, "KHR_materials_sheen", "sheenRoughnessTexture", \
        LINEAR, GN_FEAT_LAYERS, USES1(sheen_roughness, a)) \
    PARAM(sheen_color, vec3, 64, "KHR_materials_sheen", "sheenColorFactor", \
        0, 0, 1, CLAMP, GN_FEAT_LAYERS, BRDF("sheen-color", 0, 0, 1)) \
    PARAM(sheen_roughness, float, 67, "KHR_materials_sheen", "sheenRoughnessFactor", \
        0, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("sheen-roughness", 0, 0, 1)) \
    /* KHR_materials_anisotropy: the rotation in radians from the tangent toward the bitangent, any angle reduced \
     * to [-pi, pi]; the texture's RG the direction, B the strength */ \
    PARAM(anisotropy_strength, float, 68, "KHR_materials_anisotropy", "anisotropyStrength", \
        0, 0, 1, CLAMP, GN_FEAT_ANISO, BRDF("anisotropy", 0, 0, 1)) \
    PARAM(anisotropy_rotation, float, 69, "KHR_materials_anisotropy", "anisotropyRotation", \
        0, -GN_INF, GN_INF, ANGLE, GN_FEAT_NONE, BRDF("anisotropy-rotation", 0, -6.2832f, 6.2832f)) \
    TEX(tex_anisotropy, 70, "KHR_materials_anisotropy", "anisotropyTexture", LINEAR, GN_FEAT_ANISO, SPECIAL) \
    FIELD(anisotropy_pad0, float, 71) \
    /* KHR_materials_iridescence: the film's thickness is mix(min, max, texture G), max without one (thicknesses up \
     * to 1 mm and indices up to 100 keep its phase finite) */ \
    PARAM(iridescence, float, 72, "KHR_materials_iridescence", "iridescenceFactor", \
        0, 0, 1, CLAMP, GN_FEAT_LAYERS, BRDF("iridescence", 0, 0, 1)) \
    PARAM(iridescence_ior, float, 73, "KHR_materials_iridescence", "iridescenceIor", \
        1.3f, 1, 100, CLAMP, GN_FEAT_NONE, BRDF("iridescence-ior", 1.3f, 1, 4)) \
    PARAM(iridescence_thickness_min, float, 74, "KHR_materials_iridescence", "iridescenceThicknessMinimum", \
        100, 0, 1e6f, CLAMP, GN_FEAT_NONE, NO_BRDF) \
    PARAM(iridescence_thickness_max, float, 75, "KHR_materials_iridescence", "iridescenceThicknessMaximum", \
        400, 0, 1e6f, CLAMP, GN_FEAT_NONE, BRDF("iridescence-thickness", 400, 0, 2000)) \
    TEX(tex_iridescence, 76, "KHR_materials_iridescence", "iridescenceTexture", \
        LINEAR, GN_FEAT_LAYERS, USES1(iridescence, r)) \
    TEX(tex_iridescence_thickness, 77, "KHR_materials_iridescence", "iridescenceThicknessTexture", \
        LINEAR, GN_FEAT_LAYERS, SPECIAL) \
    PARAM(diffuse_transmission, float, 78, "KHR_materials_diffuse_transmission", "diffuseTransmissionFactor", \
        0, 0, 1, CLAMP, GN_FEAT_LAYERS, BRDF("diffuse-transmission", 0, 0, 1)) \
    TEX(tex_diffuse_transmission, 79, "KHR_materials_diffuse_transmission", "diffuseTransmissionTexture", \
        LINEAR, GN_FEAT_LAYERS, USES1(diffuse_transmission, a)) \
    PARAM(diffuse_transmission_color, vec3, 80, "KHR_materials_diffuse_transmission", "diffuseTransmissionColorFactor", \
        1, 0, 1, CLAMP, GN_FEAT_NONE, BRDF("diffuse-transmission-color", 1, 0, 1)) \
    TEX(tex_diffuse_transmission_color, 83, "KHR_materials_diffuse_transmission", "diffuseTransmissionColorTexture", \
        SRGB, GN_FEAT_LAYERS, USES1(diffuse_transmission_color, rgb))

#define GN_MATERIAL_WORDS 84u  /* the size of GnMaterial in 4-byte words */
#define GN_MATERIAL_TEXELS 21u /* ... in the RGBA32UI texels material_at reads */

/* GN_MAT_RULE_<rule>: what a factor outside its range gets (the loader's messages) */
#define GN_MAT_RULE_CLAMP 0    /* "NAME V is out of range [LO, HI] (clamped)", per component */
#define GN_MAT_RULE_CHECK 1    /* "NAME must be N numbers in [LO, HI] (ignored)": the default kept */
#define GN_MAT_RULE_POSITIVE 2 /* "NAME V must be positive (ignored)" (lo excluded) */
#define GN_MAT_RULE_IOR 3      /* CLAMP, but 0 is kept: KHR_materials_ior's F0 = 1, a mirror */
#define GN_MAT_RULE_ANGLE 4    /* any finite number, reduced to [-pi, pi] (non-finite: the default) */

/* the components of a row's type */
#define GN_MAT_COUNT_float 1
#define GN_MAT_COUNT_uint 1
#define GN_MAT_COUNT_vec3 3
#define GN_MAT_COUNT_vec4 4

/* The table's expansions that make the struct (shared.h) */
#define GN_MAT_DECL_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) type name;
#define GN_MAT_DECL_TEX(name, word, ext, json, space, gate, uses) uint name;
#define GN_MAT_DECL_FIELD(name, type, word) type name;
/* ... and nothing (for a kind a consumer does not expand) */
#define GN_MAT_NO_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf)
#define GN_MAT_NO_TEX(name, word, ext, json, space, gate, uses)
#define GN_MAT_NO_FIELD(name, type, word)

#ifdef VULKAN
/* ---- GLSL: a GnMaterial from its texels (RGBA32UI: the words as they are) -------------- */
#define GN_MAT_LOAD_uint(b, k, w) texelFetch(b, int((k) + uint(w) / 4u))[uint(w) % 4u]
#define GN_MAT_LOAD_float(b, k, w) uintBitsToFloat(GN_MAT_LOAD_uint(b, k, w))
#define GN_MAT_LOAD_vec3(b, k, w) uintBitsToFloat(texelFetch(b, int((k) + uint(w) / 4u)).xyz)
#define GN_MAT_LOAD_vec4(b, k, w) uintBitsToFloat(texelFetch(b, int((k) + uint(w) / 4u)))
/* m.name = its word of the material whose first texel is k in material_texels: every field
 * assigned, those a kernel never reads compiled away with their fetches (glsl/lib/scene.glsl:
 * material_at). */
#define GN_MAT_READ_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) \
    m.name = GN_MAT_LOAD_##type(material_texels, k, word);
#define GN_MAT_READ_TEX(name, word, ext, json, space, gate, uses) m.name = GN_MAT_LOAD_uint(material_texels, k, word);
#define GN_MAT_READ_FIELD(name, type, word) m.name = GN_MAT_LOAD_##type(material_texels, k, word);
#else
/* ---- C and C++ ---------------------------------------------------------------------------- */
#include <math.h>
#define GN_INF INFINITY
#define GN_MAT_WORD(name) (offsetof(GnMaterial, name) / 4) /* (shared.h includes stddef.h) */
#endif

#endif /* GONIO_MATERIAL_H */
