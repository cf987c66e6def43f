// material.glsl: a material at a point, its textures applied (as nvpro's evaluateMaterial):
// material_eval turns a GnMaterial and what the hit knows (uv, vertex colour, normal, tangent)
// into a Shading, from which brdf_material.glsl's bsdf_material builds the Bsdf; the path
// kernel and the BRDF kernels call the same pair. The factors a texture scales are the table's
// (glsl/lib/material.h: TEX rows with USES), the rest is the extensions' own rules below.
//
// The includer defines MATERIAL_TEXTURE(index, uv, srgb), the lookup of a GnTexture at the
// hit's uv (vec4: TEXCOORD_0 in xy, TEXCOORD_1 in zw) that returns linear RGBA
// (glsl/lib/scene.glsl: texture_sample); the BRDF kernels, whose materials have no textures,
// define it as a constant.
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL

#include "brdf_models.h" // (BRDF_CONDUCTOR)

#ifndef MATERIAL_TEXTURE
#error "material.glsl: define MATERIAL_TEXTURE(index, uv, srgb) before including it"
#endif

// What material_eval needs of a hit, in the frame its results are wanted in (world space in
// the renderer, the shading frame in the BRDF kernels).
struct MaterialHit {
    vec4 uv;      // TEXCOORD_0 (xy) and TEXCOORD_1 (zw)
    vec4 color;   // the vertex colour (1 without COLOR_0)
    vec3 n;       // the interpolated normal (unit)
    vec4 tangent; // xyz the interpolated tangent (0: none), w the bitangent's sign
};

// The material at a point.
struct Shading {
    GnMaterial m;        // the factors with their textures multiplied in (the base colour also
                         // by the vertex colour); the rest as the material has it
    vec3 model_color;    // the colour of a BRDF-model override: the base colour, but a
                         // conductor's own (its complex index, never a texture's)
    float film_thickness; // KHR_materials_iridescence: the film's thickness (nm)
    vec3 n;              // the shading normal, normal-mapped
    vec3 coat_n;         // KHR_materials_clearcoat: the coat's normal (the mesh's, or its own
                         // normal map's: never normalTexture's)
    vec3 aniso_t;        // KHR_materials_anisotropy: the direction (the tangent frame's,
                         // rotated; 0 where the mesh has no tangents), when the strength is > 0
};

// The factors a texture scales, from the table: USES1(field, channels) and USES2(...).
#define MATERIAL_USES_USES1(f, c) s.m.f *= t.c;
#define MATERIAL_USES_USES2(f1, c1, f2, c2) s.m.f1 *= t.c1; s.m.f2 *= t.c2;
#define MATERIAL_USES_SPECIAL
#define MATERIAL_SRGB_SRGB true
#define MATERIAL_SRGB_LINEAR false
#define MATERIAL_APPLY_TEX(name, word, ext, json, space, gate, uses) \
    if (GN_HAS(GN_FEAT_TEXTURES) && GN_HAS(gate) && m.name != GN_INVALID) { \
        vec4 t = MATERIAL_TEXTURE(m.name, h.uv, MATERIAL_SRGB_##space); \
        MATERIAL_USES_##uses \
    }

// A normal map's normal: texture `tex` (tangent space, [0, 1] -> [-1, 1], X and Y times
// `scale`, as glTF's normalTexture) on the frame of unit normal n and tangent tg (w: the
// bitangent's sign, bitangent = cross(n, tangent) w, toward -v); n where the frame or the
// result degenerates. The tangents are the mesh's TANGENT or the loader's MikkTSpace ones,
// which glTF asks for (src/scene/tangent.c).
vec3 material_normal_map(uint tex, float scale, vec4 uv, vec3 n, vec4 tg)
{
    vec3 tangent = tg.xyz - n * dot(n, tg.xyz);
    if (dot(tangent, tangent) > 1e-20) {
        tangent = normalize(tangent);
        vec3 bitangent = (tg.w < 0.0 ? -1.0 : 1.0) * cross(n, tangent);
        vec3 tn = MATERIAL_TEXTURE(tex, uv, false).xyz * 2.0 - 1.0;
        tn.xy *= scale; // glTF: the scale applies to X and Y of the sampled normal
        vec3 nm = tn.x * tangent + tn.y * bitangent + tn.z * n;
        if (dot(nm, nm) > 1e-20)
            return normalize(nm);
    }
    return n;
}

Shading material_eval(GnMaterial m, MaterialHit h)
{
    Shading s;
    s.m = m;
    GN_MATERIAL(GN_MAT_NO_PARAM, MATERIAL_APPLY_TEX, GN_MAT_NO_FIELD)
    s.m.base_color *= h.color;
    s.model_color = m.brdf == BRDF_CONDUCTOR ? m.base_color.rgb : s.m.base_color.rgb;
    s.n = h.n;
    s.coat_n = h.n;
    s.film_thickness = m.iridescence_thickness_max;
    if (GN_HAS(GN_FEAT_LAYERS)) {
        if (GN_HAS(GN_FEAT_TEXTURES) && s.m.clearcoat > 0.0 && m.tex_clearcoat_normal != GN_INVALID)
            s.coat_n = material_normal_map(m.tex_clearcoat_normal, m.clearcoat_normal_scale, h.uv, h.n, h.tangent);
        // KHR_materials_iridescence: thickness mix(min, max, texture G)
        if (GN_HAS(GN_FEAT_TEXTURES) && s.m.iridescence > 0.0 && m.tex_iridescence_thickness != GN_INVALID)
            s.film_thickness = mix(m.iridescence_thickness_min, m.iridescence_thickness_max,
                                   MATERIAL_TEXTURE(m.tex_iridescence_thickness, h.uv, false).g);
    }
    s.aniso_t = vec3(0.0);
    if (GN_HAS(GN_FEAT_ANISO) && m.anisotropy_strength > 0.0) {
        // The extension's direction: (1, 0) or the texture's RG in [-1, 1], rotated by the
        // rotation from the tangent toward the bitangent; its B scales the strength.
        vec2 dir = vec2(1.0, 0.0);
        if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_anisotropy != GN_INVALID) {
            vec3 ta = MATERIAL_TEXTURE(m.tex_anisotropy, h.uv, false).rgb;
            dir = ta.rg * 2.0 - 1.0;
            s.m.anisotropy_strength *= ta.b;
        }
        float cr = cos(m.anisotropy_rotation), sr = sin(m.anisotropy_rotation);
        dir = vec2(cr * dir.x - sr * dir.y, sr * dir.x + cr * dir.y);
        vec3 tangent = h.tangent.xyz - h.n * dot(h.n, h.tangent.xyz);
        if (dot(tangent, tangent) > 1e-20) {
            tangent = normalize(tangent);
            vec3 bitangent = (h.tangent.w < 0.0 ? -1.0 : 1.0) * cross(h.n, tangent);
            s.aniso_t = dir.x * tangent + dir.y * bitangent;
        }
    }
    if (GN_HAS(GN_FEAT_NORMAL_MAP) && m.tex_normal != GN_INVALID)
        s.n = material_normal_map(m.tex_normal, m.normal_scale, h.uv, h.n, h.tangent);
    return s;
}

#endif
