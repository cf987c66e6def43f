/* brdf.h: the BRDF model table (names, parameters, defaults and ranges of the models in
 * glsl/lib/brdf_models.h) with strict parsing of `--PARAM VALUE` settings and `--brdf`
 * specs. The kernel that evaluates them for tests and gonio brdf: brdf_runner.h. */
#ifndef GONIO_BRDF_H
#define GONIO_BRDF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "brdf_models.h"
#include "sheen_albedo.h"

/* Where a setting's values go: the words of a GnMaterial (glsl/lib/material.h), the colour
 * of a model in base_color.rgb, its four scalars in brdf_params, the glTF model's parameters
 * in their own fields. */
#define BRDF_SLOT_COLOR ((int)GN_MAT_WORD(base_color))
#define BRDF_SLOT_PARAMS ((int)GN_MAT_WORD(brdf_params))
/* The parameters a model may have: the glTF model's are every BRDF column of the material
 * table (glsl/lib/material.h); a model with more fails the build (brdf.c). */
#define BRDF_MAX_PARAMS 18

typedef struct brdf_param {
    const char *name; /* option name without the leading "--" */
    int slot;         /* its first word in brdf_setting.v (GnMaterial's words) */
    int count;        /* 1: a scalar; 3: a colour ("R,G,B" or one value for all three) */
    float def[3];
    float min, max;   /* accepted range of every component */
} brdf_param;

typedef struct brdf_model {
    const char *name; /* lower case, e.g. "torrance-sparrow" */
    uint32_t id;      /* BRDF_* of brdf_models.h */
    const char *summary;
    int num_params;
    brdf_param params[BRDF_MAX_PARAMS];
    GnFeatures features; /* GN_FEAT_* its Bsdf can need (the table's lobe_feats | feats) */
} brdf_model;

/* A model and its parameters' values: a material (glTF's every field, a model's colour and
 * four scalars), untextured, the rest at glTF's defaults (scene_material_default). */
typedef struct brdf_setting {
    const brdf_model *model;
    union {
        GnMaterial m;
        float v[GN_MATERIAL_WORDS]; /* the same, by word (brdf_param.slot) */
    };
    float coat_tilt; /* the coat normal's tilt (BrdfQuery.coat_tilt): no parameter, tests only */
} brdf_setting;

/* The sheen's directional albedo (glsl/lib/sheen_albedo.h), SHEEN_N x SHEEN_N floats, which every
 * kernel that builds a sheen reads from a texel buffer (brdf_scatter.glsl: brdf_sheen_table). */
extern const float brdf_sheen_table[];
#define BRDF_SHEEN_TABLE_SIZE (SHEEN_N * SHEEN_N)

extern const brdf_model brdf_models[];
extern const int brdf_num_models;

/* The model of that name; NULL with an error listing the accepted names otherwise. */
const brdf_model *brdf_model_find(const char *name);
/* A setting of m with every parameter at its default. */
void brdf_setting_init(brdf_setting *s, const brdf_model *m);
/* Sets parameter `name` (without "--") from text; false with an error naming the model and
 * listing its parameters (unknown name), or giving the accepted form and range (bad value). */
bool brdf_setting_set(brdf_setting *s, const char *name, const char *value);
/* A `--brdf MODEL[:PARAM=VALUE...]` spec (gonio render). brdf_spec_model: its model, NULL
 * with an error otherwise; brdf_spec_apply: sets its parameters on s (of that model), false
 * with an error naming the spec or "parameter NAME" (an empty PARAM=VALUE is an error);
 * brdf_spec_check: both, on a default setting, for checking a command line before work. */
const brdf_model *brdf_spec_model(const char *spec);
bool brdf_spec_apply(brdf_setting *s, const char *spec);
bool brdf_spec_check(const char *spec);
/* The first parameter named `name`, or NULL. */
const brdf_param *brdf_param_find(const brdf_model *m, const char *name);
/* Does the setting transmit (a dielectric interface: light below the surface matters)? */
bool brdf_setting_two_sided(const brdf_setting *s);
/* Fills the material (its model in .brdf) and the coat's tilt of a test-kernel query. */
void brdf_setting_to_query(const brdf_setting *s, BrdfQuery *q);
/* "name param=value ..." (colours as one value when grey, else R,G,B): the `gonio brdf
 * --list` line of a default setting. */
void brdf_format_setting(char *out, size_t cap, const brdf_setting *s);
/* The same for a plot's title: a model of more than BRDF_TITLE_PARAMS parameters (glTF's)
 * lists only those that differ from their defaults, so that the title stays a few lines. */
#define BRDF_TITLE_PARAMS 8
void brdf_format_title(char *out, size_t cap, const brdf_setting *s);

#endif
