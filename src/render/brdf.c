/* brdf.c: the table of BRDF models (docs/brdf.md, glsl/lib/brdf_*.glsl) with their parameters,
 * and strict `--PARAM VALUE` and `--brdf` parsing. */
#include "brdf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"
#include "util.h"

#define P(slot) (BRDF_SLOT_PARAMS + (slot))
#define COLOR(name, slot, d0, d1, d2, lo, hi) {name, slot, 3, {d0, d1, d2}, lo, hi}
#define SCALAR(name, slot, d, lo, hi) {name, slot, 1, {d, 0, 0}, lo, hi}
#define UNPAREN(...) __VA_ARGS__
/* The table of glsl/lib/brdf_models.h; the parameter count is that of its list. */
#define MODEL(id, name, summary, lobe, fresnel, layout, lobe_feats, feats, params)                  \
    {name, id, summary, (int)(sizeof((brdf_param[]){UNPAREN params}) / sizeof(brdf_param)),       \
     {UNPAREN params}, (lobe_feats) | (feats)},

const brdf_model brdf_models[] = {BRDF_MODELS(MODEL)};
/* Each model's parameters fit brdf_model.params, in every build: beyond BRDF_MAX_PARAMS an
 * initializer's excess elements would only be a warning, and a build without -Werror (make
 * fuzz's) would drop them silently. */
#define MODEL_FITS(id, name, summary, lobe, fresnel, layout, lobe_feats, feats, params)               \
    _Static_assert(sizeof((brdf_param[]){UNPAREN params}) / sizeof(brdf_param) <= BRDF_MAX_PARAMS, \
                   "BRDF model " name ": more parameters than BRDF_MAX_PARAMS (src/render/brdf.h)");
BRDF_MODELS(MODEL_FITS)
const int brdf_num_models = (int)(sizeof brdf_models / sizeof *brdf_models);

const float brdf_sheen_table[BRDF_SHEEN_TABLE_SIZE] = {SHEEN_ALBEDO_VALUES};

const brdf_model *brdf_model_find(const char *name)
{
    char list[512] = "";
    for (int i = 0; i < brdf_num_models; i++)
        if (strcmp(brdf_models[i].name, name) == 0)
            return &brdf_models[i];
    for (int i = 0; i < brdf_num_models; i++)
        strcat(strcat(list, i ? ", " : ""), brdf_models[i].name);
    util_error("unknown BRDF model '%s'; the models are: %s", name, list);
    return NULL;
}

void brdf_setting_init(brdf_setting *s, const brdf_model *m)
{
    memset(s, 0, sizeof *s);
    s->model = m;
    scene_material_default(&s->m);
    s->m.brdf = m->id;
    for (int i = 0; i < m->num_params; i++)
        memcpy(&s->v[m->params[i].slot], m->params[i].def, sizeof(float) * (size_t)m->params[i].count);
}

const brdf_param *brdf_param_find(const brdf_model *m, const char *name)
{
    for (int i = 0; i < m->num_params; i++)
        if (strcmp(m->params[i].name, name) == 0)
            return &m->params[i];
    return NULL;
}

/* "--a X, --b R,G,B" (options of gonio brdf) or "a=X, b=R,G,B" (a --brdf spec) */
static void param_list(const brdf_model *m, bool spec, char *out, size_t cap)
{
    size_t len = 0;
    out[0] = 0;
    for (int i = 0; i < m->num_params && len < cap; i++)
        len += (size_t)snprintf(out + len, cap - len, "%s%s%s%s", i ? ", " : "", spec ? "" : "--",
                                m->params[i].name, m->params[i].count == 3 ? (spec ? "=R,G,B" : " R,G,B")
                                                                           : (spec ? "=X" : " X"));
}

/* "X" or "R,G,B" -> the number of values (at most 3), 0 when malformed. */
static int parse_values(const char *text, float v[3])
{
    int n = 0;
    for (const char *c = text;; c++) {
        size_t len = strcspn(c, ",");
        char num[64];
        if (n == 3 || len >= sizeof num)
            return 0;
        memcpy(num, c, len);
        num[len] = 0;
        if (!util_parse_float(num, &v[n++]))
            return 0;
        c += len;
        if (!*c)
            return n;
    }
}

/* Errors name the parameter as the user wrote it: "--alpha" (an option of gonio brdf) or
 * "parameter alpha" (a PARAM=VALUE of a --brdf spec). */
static bool setting_set(brdf_setting *s, const char *name, const char *value, bool spec)
{
    const brdf_param *p = brdf_param_find(s->model, name);
    const char *pre = spec ? "parameter " : "--";
    float v[3];
    int n;
    if (!p) {
        char list[512];
        param_list(s->model, spec, list, sizeof list);
        util_error("BRDF model %s has no %s%s; it accepts %s", s->model->name, pre, name, list);
        return false;
    }
    n = parse_values(value, v);
    if (n == 1 && p->count == 3) {
        v[1] = v[2] = v[0];
        n = 3;
    }
    if (n != p->count) {
        util_error("BRDF model %s: %s%s needs %s, not '%s'", s->model->name, pre, name,
                   p->count == 3 ? "a colour R,G,B or one number" : "one number", value);
        return false;
    }
    for (int i = 0; i < n; i++) {
        if (!(v[i] >= p->min && v[i] <= p->max)) {
            util_error("BRDF model %s: %s%s%s%s is out of range [%g, %g]", s->model->name, pre, name,
                       spec ? "=" : " ", value, p->min, p->max);
            return false;
        }
    }
    memcpy(&s->v[p->slot], v, sizeof(float) * (size_t)n);
    return true;
}

bool brdf_setting_set(brdf_setting *s, const char *name, const char *value)
{
    return setting_set(s, name, value, false);
}

/* The spec's text up to the first ':' is the model name. */
const brdf_model *brdf_spec_model(const char *spec)
{
    char name[64];
    size_t len = strcspn(spec, ":");
    if (len == 0 || len >= sizeof name) {
        util_error("--brdf '%s': expected MODEL[:PARAM=VALUE...]", spec);
        return NULL;
    }
    memcpy(name, spec, len);
    name[len] = 0;
    return brdf_model_find(name);
}

bool brdf_spec_apply(brdf_setting *s, const char *spec)
{
    const char *c = spec + strcspn(spec, ":");
    /* Every ':' starts one PARAM=VALUE: "ggx:" and "ggx:::" are mistakes, not defaults. */
    while (*c == ':') {
        char kv[128], *eq;
        size_t len = strcspn(++c, ":");
        if (len >= sizeof kv) {
            util_error("--brdf '%s': a PARAM=VALUE is too long", spec);
            return false;
        }
        memcpy(kv, c, len);
        kv[len] = 0;
        c += len;
        if (!(eq = strchr(kv, '=')) || eq == kv) {
            util_error("--brdf '%s': expected MODEL[:PARAM=VALUE...], not '%s'", spec, kv);
            return false;
        }
        *eq = 0;
        if (!setting_set(s, kv, eq + 1, true))
            return false;
    }
    return true;
}

bool brdf_spec_check(const char *spec)
{
    const brdf_model *m = brdf_spec_model(spec);
    brdf_setting st;
    if (!m)
        return false;
    brdf_setting_init(&st, m);
    return brdf_spec_apply(&st, spec);
}

bool brdf_setting_two_sided(const brdf_setting *s)
{
    return s->model->id == BRDF_DIELECTRIC ||
           (s->model->id == BRDF_GLTF && (s->m.transmission > 0 || s->m.diffuse_transmission > 0));
}

void brdf_setting_to_query(const brdf_setting *s, BrdfQuery *q)
{
    q->material = s->m;
    q->material.brdf = s->model->id;
    q->coat_tilt = s->coat_tilt;
}

static void format_setting(char *out, size_t cap, const brdf_setting *s, bool changed_only)
{
    const brdf_model *m = s->model;
    size_t len = (size_t)snprintf(out, cap, "%s", m->name);
    for (int i = 0; i < m->num_params && len < cap; i++) {
        const float *v = &s->v[m->params[i].slot];
        if (changed_only && !memcmp(v, m->params[i].def, sizeof(float) * (size_t)m->params[i].count))
            continue;
        if (m->params[i].count == 3 && (v[0] != v[1] || v[1] != v[2]))
            len += (size_t)snprintf(out + len, cap - len, " %s=%g,%g,%g", m->params[i].name, v[0], v[1], v[2]);
        else
            len += (size_t)snprintf(out + len, cap - len, " %s=%g", m->params[i].name, v[0]);
    }
}

void brdf_format_setting(char *out, size_t cap, const brdf_setting *s) { format_setting(out, cap, s, false); }

void brdf_format_title(char *out, size_t cap, const brdf_setting *s)
{
    bool changed_only = s->model->num_params > BRDF_TITLE_PARAMS;
    format_setting(out, cap, s, changed_only);
    if (changed_only && strlen(out) + 1 < cap)
        snprintf(out + strlen(out), cap - strlen(out), " (the rest at their defaults)");
}
