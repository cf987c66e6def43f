/* main.c: the gonio command-line program: dispatches to the subcommands of cli.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "image_decode.h"
#include "util.h"

static const struct {
    const char *name;
    int (*fn)(int, char **);
    const char *summary;
} commands[] = {
    {"render", cmd_render, "render a glTF scene to EXR (and PNG)"},
    {"preview", cmd_preview, "show the render converging in a window, interactive camera"},
    {"info", cmd_info, "print a scene's contents and BVH statistics"},
    {"devices", cmd_devices, "list the Vulkan devices"},
    {"compare", cmd_compare, "flat vs Gouraud vs per-pixel Phong vs path traced, side by side"},
    {"merge", cmd_merge, "combine renders of one scene with different seeds, exactly"},
    {"denoise", cmd_denoise, "denoise an EXR render (Intel Open Image Denoise)"},
    {"diff", cmd_diff, "compare two EXR images (RMSE, PSNR, bias); exit 1 above thresholds"},
    {"bench", cmd_bench, "measure BVH build, ray throughput and path tracing (--paths)"},
    {"brdf", cmd_brdf, "virtual goniophotometer: BRDF lobe plots, albedo, material balls"},
    {"scene", cmd_scene, "write a built-in scene (cornell, teapot) as glTF"},
    {"teapot", cmd_teapot, "write the Utah teapot at a tessellation level as glTF"},
    {"batch", cmd_batch, "run many gonio command lines in one process, on one device"},
};

static void usage(FILE *f);

/* argv[0] the command's name: its exit status (also gonio batch's way to run a line). */
static int dispatch(int argc, char **argv)
{
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(argv[0], commands[i].name))
            return commands[i].fn(argc, argv);
    fprintf(stderr, "gonio: unknown command '%s'\n\n", argv[0]);
    usage(stderr);
    return 2;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: gonio COMMAND [OPTIONS]   (gonio COMMAND --help for details)\n\n"
               "A physically based renderer: GLSL compute shaders on Vulkan ray-trace\n"
               "triangle BVHs and shade with physically based BRDFs.\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        fprintf(f, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\n  --version   print the version\n"
               "\nOptions take their value as --opt value or --opt=value.\n");
}

/* gonio __complete WORD... (completion/gonio; not in --help): what may stand in place of
 * the last word after the others, one candidate a line (cli_complete). */
static int complete(int n, char **words)
{
    if (n <= 1) { /* the command itself */
        for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
            printf("%s\n", commands[i].name);
        printf("--help\n--version\n");
        return 0;
    }
    cli_complete(words[n - 1]);
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(words[0], commands[i].name))
            return commands[i].fn(n - 1, words);
    return 0;
}

int main(int argc, char **argv)
{
    cli_set_command_line(argc, argv);
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "__complete"))
        return complete(argc - 2, argv + 2);
    if (!strcmp(argv[1], "--version")) {
        printf("gonio %s\nimage decoders: %s\n", GONIO_VERSION, image_decode_versions());
        return 0;
    }
    cli_dispatch = dispatch;
    return dispatch(argc - 1, argv + 1);
}
