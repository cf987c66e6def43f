/* render_material.c: the renderer's view of a material: the GN_FEAT_* it can need in the path
 * kernel, and the --brdf / extras.gonio overrides that replace its model. */
#include "render_material.h"

#include <stdio.h>
#include <string.h>

#include "brdf.h"
#include "lobes.h"
#include "util.h"
#include "vec.h"

static bool any_positive(const float *v, int n)
{
    for (int k = 0; k < n; k++)
        if (v[k] > 0)
            return true;
    return false;
}

/* The GN_FEAT_* that material m can need in the path kernel: the parts of the Bsdf that
 * bsdf_gltf or bsdf_from_model (glsl/lib/brdf_material.glsl) can build from it with a nonzero
 * weight, decided by the construction's own predicates (glsl/lib/lobes.h) over every value
 * its textures can reach (a texture scales its factor by [0, 1]); its textures, emission and
 * unlit flag. */
GnFeatures material_features(const GnMaterial *m)
{
    GnFeatures f = GN_FEAT_NONE, gates = GN_FEAT_NONE;
    /* each texture slot's gate (glsl/lib/material.h): the feature it is read under */
#define TEX_GATE(name, word, ext, json, space, gate, uses) \
    if (m->name != GN_INVALID)                              \
        gates |= (gate);
    GN_MATERIAL(GN_MAT_NO_PARAM, TEX_GATE, GN_MAT_NO_FIELD)
#undef TEX_GATE
    if (m->flags & GN_MAT_UNLIT)
        f |= GN_FEAT_UNLIT;
    if (m->flags & (GN_MAT_MASK | GN_MAT_BLEND))
        f |= GN_FEAT_ALPHA;
    if (!(m->flags & GN_MAT_DOUBLE_SIDED))
        f |= GN_FEAT_CULL;
    if (vec_luminance(&m->emissive.x) > 0)
        f |= GN_FEAT_EMISSIVE;
    if (m->brdf == BRDF_GLTF) {
        /* bsdf_gltf: a GGX lobe (the mirror where lobes_smooth) with Schlick's F of weight
         * wd f0 + m base and F90 wd specular + m; the diffuse coupled to that layer when
         * specular > 0; glass of weight lobes_gltf_glass. */
        bool mr = m->tex_mr != GN_INVALID;
        float metal_hi = lobes_clamp01(m->metallic), metal_lo = mr ? 0 : metal_hi;
        float rough_hi = lobes_clamp01(m->roughness), rough_lo = mr ? 0 : rough_hi;
        /* KHR_materials_pbrSpecularGlossiness: roughness 1 - glossiness x the texture's A */
        if ((m->flags & GN_MAT_SPEC_GLOSS) && m->tex_spec_gloss != GN_INVALID)
            rough_hi = 1;
        float t = lobes_clamp01(m->transmission); /* (its texture: down to 0, where the glass is none) */
        bool smooth = lobes_smooth(lobes_gltf_alpha(rough_lo)), rough = !lobes_smooth(lobes_gltf_alpha(rough_hi));
        bool glass = lobes_gltf_glass(metal_lo, t) > 0;
        f |= GN_FEAT_GLTF;
        if (lobes_gltf_lobe(m->specular, metal_hi)) {
            f |= GN_FEAT_FRESNEL_SCHLICK | (smooth ? GN_FEAT_MIRROR : 0u) | (rough ? GN_FEAT_GGX : 0u);
            if (m->specular != 0)
                f |= GN_FEAT_COUPLED;
        }
        if (glass)
            f |= (smooth ? GN_FEAT_SMOOTH_GLASS : 0u) | (rough ? GN_FEAT_ROUGH_GLASS : 0u);
        /* KHR_materials_volume acts only where the surface transmits (glass or a diffuse
         * transmission), _dispersion only where it refracts */
        if (metal_lo < 1 && ((t > 0 && (m->volume || m->dispersion > 0)) || (m->diffuse_transmission > 0 && m->volume)))
            f |= GN_FEAT_VOLUME;
        /* the parts a factor above 0 switches on (the table's feat column: bsdf_layers' coat
         * and sheen, bsdf_gltf_film's film and diffuse transmission, bsdf_anisotropy); their
         * textures only scale the factors down */
#define PARAM_FEAT(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) \
    if (any_positive((const float *)&m->name, GN_MAT_COUNT_##type))            \
        f |= (feat);
        GN_MATERIAL(PARAM_FEAT, GN_MAT_NO_TEX, GN_MAT_NO_FIELD)
#undef PARAM_FEAT
        /* bsdf_anisotropy: the lobe and the glass stay GGX where roughness 0 would make them
         * Dirac */
        if (f & GN_FEAT_ANISO) {
            if (lobes_gltf_lobe(m->specular, metal_hi))
                f |= GN_FEAT_GGX;
            if (glass)
                f |= GN_FEAT_ROUGH_GLASS;
        }
    } else {
        /* an override model: its row of the table (glsl/lib/brdf_models.h); an id unknown to it
         * keeps every feature */
        GnFeatures mf = GN_FEAT_ALL;
        for (int i = 0; i < brdf_num_models; i++)
            if (brdf_models[i].id == m->brdf)
                mf = brdf_models[i].features;
        f |= mf | GN_FEAT_MODELS;
    }
    /* the textures, where the kernel reads them: under their gate's code (always for the maps
     * of the core and of KHR_materials_specular and _transmission; the layers' and the
     * anisotropy's where the material has them) */
    if (gates & (GN_FEAT_TEXTURES | GN_FEAT_NORMAL_MAP | (f & (GN_FEAT_LAYERS | GN_FEAT_ANISO))))
        f |= GN_FEAT_TEXTURES | (gates & GN_FEAT_NORMAL_MAP);
    return f;
}

/* A setting's values and a material are both a GnMaterial's words (brdf_setting.v); a
 * parameter is its words there (src/render/brdf.c: the glTF model's are the material table's
 * BRDF columns, glsl/lib/material.h). */
static void copy_params(float *dst, const float *src, const brdf_model *model)
{
    for (int i = 0; i < model->num_params; i++)
        memcpy(dst + model->params[i].slot, src + model->params[i].slot,
               sizeof(float) * (size_t)model->params[i].count);
}

/* Sets m's model from a setting: its colour and four scalars, and every parameter (the glTF
 * model's are the material's own fields). */
static void apply_setting(GnMaterial *m, const brdf_setting *st)
{
    memcpy(&m->base_color.x, &st->m.base_color.x, 3 * sizeof(float));
    m->brdf_params = st->m.brdf_params;
    m->brdf = st->model->id;
    copy_params((float *)m, st->v, st->model);
    /* a specular-glossiness material's roughness is 1 - glossiness at a point (material_eval) */
    if (m->flags & GN_MAT_SPEC_GLOSS)
        m->glossiness = 1 - m->roughness;
}

/* A setting of `model` that starts from m: its colour is the material's base colour (but a
 * conductor's, its complex index, keeps the model's default); glTF starts from every field. */
static void setting_from_material(brdf_setting *st, const brdf_model *model, const GnMaterial *m)
{
    brdf_setting_init(st, model);
    if (model->id != BRDF_CONDUCTOR)
        memcpy(&st->m.base_color.x, &m->base_color.x, 3 * sizeof(float));
    if (model->id == BRDF_GLTF)
        copy_params(st->v, (const float *)m, model);
}

bool render_material_overrides(scene *sc, const char *brdf)
{
    const brdf_model *global = NULL;
    if (brdf && !(global = brdf_spec_model(brdf)))
        return false;
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        GnMaterial *m = &sc->materials[i];
        const scene_material_extras *x = &sc->material_extras[i];
        brdf_setting st;
        if (global) {
            setting_from_material(&st, global, m);
            if (!brdf_spec_apply(&st, brdf))
                return false;
        } else if (x->brdf[0]) {
            const brdf_model *model = brdf_model_find(x->brdf);
            if (!model) {
                util_error("%s: material '%s': extras.gonio.brdf names no BRDF model", sc->path,
                           sc->material_names[i]);
                return false;
            }
            setting_from_material(&st, model, m);
            for (int k = 0; k < x->num_params; k++) {
                char value[32];
                snprintf(value, sizeof value, "%.9g", x->param_values[k]);
                if (!brdf_setting_set(&st, x->param_names[k], value)) {
                    util_error("%s: material '%s': bad extras.gonio parameter '%s'", sc->path,
                               sc->material_names[i], x->param_names[k]);
                    return false;
                }
            }
        } else {
            continue;
        }
        apply_setting(m, &st);
    }
    return true;
}
