/* render_modes.c: the registry of render modes (glsl/lib/shared.h: GN_MODES) and of the
 * kernels they run (render_modes.h). */
#include "render_modes.h"

#include <stdio.h>
#include <string.h>

#include "local.h" /* spv_local: glsl/kernels/local.comp compiled by the build */
#include "path.h"  /* spv_path: glsl/kernels/path.comp */

#define MODE_ENTRY(id, value, kernel, flags, name, help) [value] = {name, help, kernel, flags},
const render_mode_info render_modes[GN_MODE_COUNT] = {GN_MODES(MODE_ENTRY)};
#undef MODE_ENTRY

static const render_kernel kernels[] = {
    [GN_KERNEL_PATH] = {"path", spv_path, sizeof spv_path, GN_FEAT_ALL, true},
    [GN_KERNEL_LOCAL] = {"local", spv_local, sizeof spv_local, GN_FEAT_ALPHA | GN_FEAT_CULL | GN_FEAT_TEX_TRANSFORM | GN_FEAT_UV1,
                         false},
};

const render_kernel *render_mode_kernel(uint32_t mode) { return &kernels[render_modes[mode].kernel]; }

/* A list of names (the modes', the samplers'), with their help and the texts made of them. */
typedef struct name_table {
    const char *const *names, *const *help;
    uint32_t count;
    int width;        /* the names' column in the help */
    char list[256];   /* "a, b, c" */
    char text[2048];  /* lines "name  help" */
} name_table;

static int table_index(const name_table *t, const char *name)
{
    for (uint32_t i = 0; i < t->count; i++)
        if (strcmp(name, t->names[i]) == 0)
            return (int)i;
    return -1;
}

static const char *table_list(name_table *t)
{
    if (!t->list[0])
        for (uint32_t i = 0; i < t->count; i++)
            snprintf(t->list + strlen(t->list), sizeof t->list - strlen(t->list), "%s%s", i ? ", " : "", t->names[i]);
    return t->list;
}

static const char *table_help(name_table *t)
{
    if (!t->text[0])
        for (uint32_t i = 0; i < t->count; i++)
            snprintf(t->text + strlen(t->text), sizeof t->text - strlen(t->text), "%s%-*s %s", i ? "\n" : "",
                     t->width, t->names[i], t->help[i]);
    return t->text;
}

#define MODE_NAME(id, value, kernel, flags, name, help) [value] = name,
#define MODE_HELP(id, value, kernel, flags, name, help) [value] = help,
static const char *const mode_names[] = {GN_MODES(MODE_NAME)}, *const mode_help[] = {GN_MODES(MODE_HELP)};
static name_table modes = {mode_names, mode_help, GN_MODE_COUNT, 8, "", ""};

#define SAMPLER_NAME(id, value, name, help) [value] = name,
#define SAMPLER_HELP(id, value, name, help) [value] = help,
static const char *const sampler_names[] = {GN_SAMPLERS(SAMPLER_NAME)},
                         *const sampler_help[] = {GN_SAMPLERS(SAMPLER_HELP)};
static name_table samplers = {sampler_names, sampler_help, GN_SAMPLER_COUNT, 11, "", ""};

int render_mode_from_name(const char *name) { return table_index(&modes, name); }
const char *render_mode_name(uint32_t mode) { return mode < GN_MODE_COUNT ? render_modes[mode].name : "?"; }
const char *render_mode_list(void) { return table_list(&modes); }
const char *render_mode_help(void) { return table_help(&modes); }

int render_sampler_from_name(const char *name) { return table_index(&samplers, name); }
const char *render_sampler_name(uint32_t sampler) { return sampler < GN_SAMPLER_COUNT ? sampler_names[sampler] : "?"; }
const char *render_sampler_list(void) { return table_list(&samplers); }
const char *render_sampler_help(void) { return table_help(&samplers); }
