/* lobes.h: which lobes a material builds, decided once: the predicates of the construction
 * (glsl/lib/brdf_material.glsl, brdf_bsdf.glsl) that the host's feature selection
 * (src/render/render_material.c: material_features) evaluates too, over the values a
 * material's textures can reach, to choose the code the path kernel compiles. Valid C and GLSL
 * (the common subset: scalars, the fields of shared.h's structs, float literals with f), so
 * that the two cannot disagree. */
#ifndef GONIO_LOBES_H
#define GONIO_LOBES_H

#include "brdf_models.h"

#ifdef VULKAN
#define LOBES_FN
float lobes_clamp01(float x) { return clamp(x, 0.0, 1.0); }
#else
#include <stdbool.h>
#define LOBES_FN static inline
LOBES_FN float lobes_clamp01(float x) { return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x; }
#endif

/* A GGX or Beckmann lobe of this alpha is the mirror (a Dirac lobe): a narrower one is under a
 * tenth of a degree wide, which float directions cannot resolve (BRDF_ALPHA_MIN). */
LOBES_FN bool lobes_smooth(float alpha) { return alpha < BRDF_ALPHA_MIN; }

/* glTF's GGX alpha: roughness^2, the roughness clamped to [0, 1]. */
LOBES_FN float lobes_gltf_alpha(float roughness)
{
    float r = lobes_clamp01(roughness);
    return r * r;
}

/* The weight bsdf_gltf gives its dielectric (glass): (1 - metallic) transmission. */
LOBES_FN float lobes_gltf_glass(float metallic, float transmission)
{
    return (1.0f - lobes_clamp01(metallic)) * lobes_clamp01(transmission);
}

/* Can bsdf_gltf's specular lobe weigh anything: a dielectric's F0 (specular > 0) or a metal?
 * (Where not, bsdf_gltf builds it with weight 0, and the host leaves its code out.) */
LOBES_FN bool lobes_gltf_lobe(float specular, float metallic) { return specular != 0.0f || metallic > 0.0f; }

/* bsdf_layers' coat (KHR_materials_clearcoat) or sheen (KHR_materials_sheen), of these
 * weights (clamped or not: the same answer). The host turns GN_FEAT_LAYERS on by the same rule,
 * a factor above 0, from the material table's feat column. */
LOBES_FN bool lobes_layers(float coat, float sheen_r, float sheen_g, float sheen_b)
{
    return coat > 0.0f || sheen_r > 0.0f || sheen_g > 0.0f || sheen_b > 0.0f;
}

/* bsdf_anisotropy's stretch (KHR_materials_anisotropy) of this strength (the host: the table's
 * feat column, GN_FEAT_ANISO). */
LOBES_FN bool lobes_anisotropic(float strength) { return strength > 0.0f; }

#endif /* GONIO_LOBES_H */
