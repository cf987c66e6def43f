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

const char *render_mode_list(void)
{
    static char list[256];
    if (!list[0])
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", render_modes[i].name);
    return list;
}

const char *render_mode_help(void)
{
    static char help[2048];
    if (!help[0])
        for (uint32_t i = 0; i < GN_MODE_COUNT; i++)
            snprintf(help + strlen(help), sizeof help - strlen(help), "%s%-8s %s", i ? "\n" : "",
                     render_modes[i].name, render_modes[i].help);
    return help;
}
