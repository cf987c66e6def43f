// brdf_material.glsl: a Bsdf (brdf_bsdf.glsl) built from a material at a point (a Shading of
// material.glsl): the models of brdf_models.h's table from a colour and four scalars, and glTF
// metallic-roughness with its extensions' layers, film, transmission and anisotropy. The path
// kernel and the BRDF kernels build every Bsdf with the same two calls:
//   Bsdf b = bsdf_material(material_eval(m, hit));   // in the shading frame, coat normal +z
//   b = bsdf_orient(b, s, coat_n, aniso_dir);        // the directions, once the frame is known
// (the frame can depend on b: a transmitting surface is shaded from the side it faces).
#ifndef BRDF_MATERIAL_GLSL
#define BRDF_MATERIAL_GLSL

#include "brdf_bsdf.glsl"
#include "material.glsl"

// ---- construction ---------------------------------------------------------------------------


Bsdf brdf_empty()
{
    Bsdf b;
    b.diffuse = vec3(0.0);
    b.lobe = BRDF_LOBE_NONE;
    b.specular = vec3(0.0);
    b.fresnel = BRDF_FRESNEL_NONE;
    b.eta = vec3(1.0);
    b.shape = 0.0;
    b.k = vec3(0.0);
    b.ior = 1.5;
    b.tint = vec3(1.0);
    b.dielectric = 0.0;
    b.couple_f0 = vec3(0.0);
    b.couple_f90 = 0.0;
    b.f90 = 1.0;
    b.coat = 0.0;
    b.coat_n = vec3(0.0, 0.0, 1.0);
    b.coat_alpha = 0.0;
    b.sheen = vec3(0.0);
    b.sheen_r = 0.0;
    b.aniso_dir = vec2(1.0, 0.0);
    b.aniso_at = 0.0;
    b.irid = 0.0;
    b.irid_ior = 1.0;
    b.irid_d = 0.0;
    b.irid_wd = 0.0;
    b.irid_f0 = vec3(0.0);
    b.irid_wm = 0.0;
    b.irid_base = vec3(0.0);
    b.irid_avg = vec3(0.0);
    b.dt = vec3(0.0);
    return b;
}

// A model of brdf_models.h's table but glTF from a colour and four scalars, placed as its
// row's layout says; a microfacet lobe too narrow for float directions is the mirror.
Bsdf bsdf_from_model(uint model, vec3 color, vec4 params)
{
    Bsdf b = brdf_empty();
    uint place = BRDF_LAYOUT_GLTF;
// (the parameters are named apart from Bsdf's fields, which they would replace)
#define BRDF_X_ROW(id, name_, summary_, lobe_, fresnel_, layout_, lobe_feats_, feats_, params_) \
    if (model == id) {                                                                          \
        b.lobe = lobe_;                                                                         \
        b.fresnel = fresnel_;                                                                   \
        place = layout_;                                                                        \
    }
    BRDF_MODELS(BRDF_X_ROW)
#undef BRDF_X_ROW
    if (place == BRDF_LAYOUT_DIFFUSE) {
        b.diffuse = color;
    } else if (place == BRDF_LAYOUT_LOBE) {
        b.specular = color;
    } else if (place == BRDF_LAYOUT_LAYERED) {
        b.diffuse = color;
        b.specular = vec3(params[BRDF_P_SPECULAR]);
        b.shape = params[BRDF_P_SHAPE];
        b.ior = params[BRDF_P_IOR];
    } else if (place == BRDF_LAYOUT_CONDUCTOR) {
        b.specular = vec3(1.0);
        b.eta = color;
        b.k = params.xyz;
        b.shape = params[BRDF_P_ALPHA];
    } else if (place == BRDF_LAYOUT_DIELECTRIC) {
        b.dielectric = 1.0;
        b.tint = color;
        b.ior = params[BRDF_P_DIELECTRIC_IOR];
        b.shape = params[BRDF_P_DIELECTRIC_ALPHA];
    } else {
        b.lobe = BRDF_LOBE_NONE; // glTF has its own constructor; an unknown id is black
        b.fresnel = BRDF_FRESNEL_NONE;
    }
    if ((b.lobe == BRDF_LOBE_BECKMANN || b.lobe == BRDF_LOBE_GGX) && lobes_smooth(b.shape))
        b.lobe = BRDF_LOBE_MIRROR;
    return b;
}

// glTF 2.0 metallic-roughness with KHR_materials_specular, _transmission and _ior, as a sum
// weighted (1-m)(1-t) dielectric-over-diffuse + m metal + (1-m) t rough glass:
// - one GGX lobe (alpha = roughness^2) with Schlick's F whose F0, F90 mix the dielectric's
//   (F0 = min(((ior-1)/(ior+1))^2 specular_color, 1) specular, F90 = specular) and the
//   metal's (F0 = base colour, F90 = 1); Schlick is linear in F0, F90, so the mix is exact;
// - the diffuse base colour coupled to the dielectric's Fresnel (brdf_diffuse), not the
//   spec's fresnel_mix (1 - F(v.h)), which is not energy conserving: 1.3 at 80 degrees for
//   a white base (docs/brdf.md);
// - transmission as the rough (or smooth) dielectric of index ior, tinted by base colour.
Bsdf bsdf_gltf(vec3 base_color, float metallic, float roughness, float specular,
               vec3 specular_color, float ior, float transmission)
{
    Bsdf b = brdf_empty();
    float m = clamp(metallic, 0.0, 1.0), t = clamp(transmission, 0.0, 1.0);
    float alpha = lobes_gltf_alpha(roughness);
    vec3 f0 = min(vec3(brdf_schlick_f0(ior)) * specular_color, vec3(1.0)) * specular;
    float wd = (1.0 - m) * (1.0 - t);
    b.diffuse = wd * base_color;
    b.couple_f0 = f0;
    b.couple_f90 = specular;
    b.lobe = lobes_smooth(alpha) ? BRDF_LOBE_MIRROR : BRDF_LOBE_GGX;
    b.shape = alpha;
    b.fresnel = BRDF_FRESNEL_SCHLICK;
    b.specular = wd * f0 + m * base_color;
    b.f90 = wd * specular + m;
    b.dielectric = lobes_gltf_glass(metallic, transmission);
    b.tint = base_color;
    b.ior = max(ior, 1.01); // at 1 the rough BTDF collapses to a Dirac along -wo
    return b;
}

// KHR_materials_anisotropy on a glTF base (bsdf_gltf): strength s in [0, 1] along dir (local
// xy, any length; none: the tangent) stretches the GGX of the specular, metal and
// transmission lobes to alpha_t = mix(alpha, 1, s^2) along dir, alpha_b = alpha across it.
// alpha_b is kept >= BRDF_ALPHA_MIN (a mirror across, rough along is still a GGX lobe); s = 0,
// or a lobe still too narrow along dir, leaves b exactly as it is.
Bsdf bsdf_anisotropy(Bsdf b, float strength, vec2 dir)
{
    float s = clamp(strength, 0.0, 1.0), at = mix(b.shape, 1.0, s * s);
    if (!GN_HAS(GN_FEAT_ANISO) || !lobes_anisotropic(s) || lobes_smooth(at))
        return b;
    if (b.lobe == BRDF_LOBE_MIRROR)
        b.lobe = BRDF_LOBE_GGX;
    b.shape = max(b.shape, BRDF_ALPHA_MIN);
    b.aniso_at = at;
    b.aniso_dir = dot(dir, dir) > 1e-20 ? normalize(dir) : vec2(1.0, 0.0);
    return b;
}

// KHR_materials_iridescence and _diffuse_transmission on b = bsdf_gltf(...) of the same
// parameters: irid = (factor, the film's ior, its thickness in nm), dt = (colour, factor).
// - the film: the lobe's F = mix(F, F_film, factor), F_film of the dielectric's F0 and of the
//   metal's (the base colour) weighted as bsdf_gltf weights the two (brdf_irid_lobe); the
//   diffuse is coupled to that F (brdf_coupled), so its albedo stays kd (1 - F(wo));
// - the diffuse transmission: the diffuse weight kd = (1-m)(1-t) base colour becomes
//   (1 - factor) kd reflected and kt = factor (1-m)(1-t) colour transmitted (brdf_dt_eval_pdf).
// Factors of 0 leave b exactly as it is.
Bsdf bsdf_gltf_film(Bsdf b, vec3 base_color, float metallic, float specular, vec3 specular_color,
                    float ior, float transmission, vec3 irid, vec4 dt)
{
    float m = clamp(metallic, 0.0, 1.0), t = clamp(transmission, 0.0, 1.0);
    float wd = (1.0 - m) * (1.0 - t), k = clamp(dt.w, 0.0, 1.0);
    b.irid = clamp(irid.x, 0.0, 1.0);
    b.irid_ior = max(irid.y, 1.0);
    b.irid_d = max(irid.z, 0.0);
    b.irid_wd = wd * specular;
    b.irid_f0 = min(vec3(brdf_schlick_f0(ior)) * specular_color, vec3(1.0));
    b.irid_wm = m;
    b.irid_base = base_color;
    if (b.irid > 0.0) // (once here: it depends on the material only)
        b.irid_avg = brdf_irid_mean(b);
    if (k > 0.0) {
        b.dt = k * wd * clamp(dt.rgb, vec3(0.0), vec3(1.0));
        b.diffuse *= 1.0 - k;
    }
    return b;
}

// The layers on a base Bsdf: coat weight c, roughness cr, normal cn (local frame); sheen
// colour sc, roughness sr. c = 0 and sc = 0 leave b exactly as it is.
Bsdf bsdf_layers(Bsdf b, float c, float cr, vec3 cn, vec3 sc, float sr)
{
    b.coat = clamp(c, 0.0, 1.0);
    float a = clamp(cr, 0.0, 1.0);
    b.coat_alpha = a * a;
    b.coat_n = cn;
    b.sheen = clamp(sc, vec3(0.0), vec3(1.0));
    b.sheen_r = clamp(sr, 0.0, 1.0);
    return b;
}

// The Bsdf of the material at a point: its BRDF-model override (bsdf_from_model; the model's
// colour is the textured base colour, but a conductor's, its index, never a texture's), or
// glTF's (bsdf_gltf) with the layers (bsdf_layers, the coat's normal +z until bsdf_orient) and
// the film and diffuse transmission (bsdf_gltf_film) of a kernel with GN_FEAT_LAYERS.
Bsdf bsdf_material(Shading s)
{
    GnMaterial m = s.m;
    if (GN_HAS(GN_FEAT_MODELS) && (!GN_HAS(GN_FEAT_GLTF) || m.brdf != BRDF_GLTF))
        return bsdf_from_model(m.brdf, s.model_color, m.brdf_params);
    vec3 base = m.base_color.rgb;
    Bsdf b = bsdf_gltf(base, m.metallic, m.roughness, m.specular, m.specular_color, m.ior, m.transmission);
    if (GN_HAS(GN_FEAT_LAYERS))
        b = bsdf_layers(b, m.clearcoat, m.clearcoat_roughness, vec3(0.0, 0.0, 1.0), m.sheen_color, m.sheen_roughness);
    if (GN_HAS(GN_FEAT_LAYERS)) // iridescence, diffuse transmission
        b = bsdf_gltf_film(b, base, m.metallic, m.specular, m.specular_color, m.ior, m.transmission,
                           vec3(m.iridescence, m.iridescence_ior, s.film_thickness),
                           vec4(m.diffuse_transmission_color, m.diffuse_transmission));
    return b;
}

// b = bsdf_material(s) on its shading frame: the coat's normal coat_n and the anisotropy's
// direction aniso_dir (any length), both in that frame.
Bsdf bsdf_orient(Bsdf b, Shading s, vec3 coat_n, vec2 aniso_dir)
{
    if (GN_HAS(GN_FEAT_LAYERS))
        b.coat_n = coat_n;
    if (GN_HAS(GN_FEAT_ANISO) && lobes_anisotropic(s.m.anisotropy_strength) && s.m.brdf == BRDF_GLTF)
        b = bsdf_anisotropy(b, s.m.anisotropy_strength, aniso_dir);
    return b;
}

#endif
