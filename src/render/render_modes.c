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

int render_mode_from_name(const char *name)
{
    for (int i = 0; i < (int)GN_MODE_COUNT; i++)
        if (strcmp(name, render_modes[i].name) == 0)
            return i;
    return -1;
}

const char *render_mode_name(uint32_t mode) { return mode < GN_MODE_COUNT ? render_modes[mode].name : "?"; }

/* "a, b, c" of n names, or lines "name  help" with the names `width` wide (help non-NULL),
 * into buf. */
static const char *names_text(char *buf, size_t size, const char *const *names, const char *const *help, uint32_t n,
                              int width)
{
    if (!buf[0])
        for (uint32_t i = 0; i < n; i++) {
            size_t at = strlen(buf);
            if (help)
                snprintf(buf + at, size - at, "%s%-*s %s", i ? "\n" : "", width, names[i], help[i]);
            else
                snprintf(buf + at, size - at, "%s%s", i ? ", " : "", names[i]);
        }
    return buf;
}

#define MODE_NAME(id, value, kernel, flags, name, help) [value] = name,
#define MODE_HELP(id, value, kernel, flags, name, help) [value] = help,
static const char *const mode_names[] = {GN_MODES(MODE_NAME)}, *const mode_help[] = {GN_MODES(MODE_HELP)};

const char *render_mode_list(void)
{
    static char list[256];
    return names_text(list, sizeof list, mode_names, NULL, GN_MODE_COUNT, 0);
}

const char *render_mode_help(void)
{
    static char help[2048];
    return names_text(help, sizeof help, mode_names, mode_help, GN_MODE_COUNT, 8);
}

#define SAMPLER_NAME(id, value, name, help) [value] = name,
#define SAMPLER_HELP(id, value, name, help) [value] = help,
static const char *const sampler_names[] = {GN_SAMPLERS(SAMPLER_NAME)},
                         *const sampler_help[] = {GN_SAMPLERS(SAMPLER_HELP)};

int render_sampler_from_name(const char *name)
{
    for (int i = 0; i < (int)GN_SAMPLER_COUNT; i++)
        if (strcmp(name, sampler_names[i]) == 0)
            return i;
    return -1;
}

const char *render_sampler_name(uint32_t sampler) { return sampler < GN_SAMPLER_COUNT ? sampler_names[sampler] : "?"; }

const char *render_sampler_list(void)
{
    static char list[256];
    return names_text(list, sizeof list, sampler_names, NULL, GN_SAMPLER_COUNT, 0);
}

const char *render_sampler_help(void)
{
    static char help[1024];
    return names_text(help, sizeof help, sampler_names, sampler_help, GN_SAMPLER_COUNT, 11);
}
