/* cli.h: the subcommands of the gonio program; each takes argv with argv[0] = its name and
 * returns the process exit code: 0 ok, 1 bad input or failed work, 2 bad usage. */
#ifndef GONIO_CLI_H
#define GONIO_CLI_H

#include <stdbool.h>
#include <stdio.h>

#include "gpu.h"
#include "render_default_light.h"

int cmd_render(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_devices(int argc, char **argv);
int cmd_bench(int argc, char **argv);
int cmd_diff(int argc, char **argv);
int cmd_scene(int argc, char **argv);
int cmd_brdf(int argc, char **argv);
int cmd_teapot(int argc, char **argv);
int cmd_merge(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_preview(int argc, char **argv);
int cmd_denoise(int argc, char **argv);
int cmd_batch(int argc, char **argv);
/* How `gonio batch` runs a line: the program's dispatcher (argv[0] = the command's name),
 * which main sets. */
typedef int cli_command_fn(int argc, char **argv);
extern cli_command_fn *cli_dispatch;

/* One of `gonio scene`'s scenes ("cornell", "teapot") loaded as from its glTF (written to a
 * temporary directory and removed), so a default scene needs no file in the working
 * directory. */
bool cli_load_builtin_scene(struct scene *out, const char *name);

/* ---- options ----------------------------------------------------------------------------
 * Every command declares its options once, as a table of cli_option; cli_parse reads argv
 * against it (--opt value and --opt=value, -h/--help, "--" ending the options), cli_help
 * prints the --help text from it (which the man page reads), and bash completion asks the
 * program for the names and values in it (cli_complete, completion/gonio), so what --help
 * lists and completion offers is exactly what the command accepts. */
typedef enum cli_kind {
    CLI_FLAG,   /* bool *dest = true; takes no value */
    CLI_STRING, /* const char **dest = the value */
    CLI_INT,    /* int *dest: an integer in [min, max] */
    CLI_U32,    /* uint32_t *dest: an integer in [min, max] */
    CLI_FLOAT,  /* float *dest: a finite number in [min, max] */
    CLI_DOUBLE, /* double *dest: as CLI_FLOAT (read at float precision) */
    CLI_CALL,   /* call(cmd, option, value, dest): false = usage error (printed by cli_parse
                 * with `expect` when set, else by call) */
    CLI_TEXT,   /* no option: `help` is printed as it is, in the options' place */
} cli_kind;

typedef struct cli_option {
    const char *names; /* "--spp", or aliases "-o, --output" */
    const char *value; /* the value's name in --help ("N", "FILE"); NULL for flags */
    const char *help;  /* beside the names; further lines ('\n') under the first */
    cli_kind kind;
    void *dest;
    double min, max;    /* CLI_INT, CLI_U32, CLI_FLOAT, CLI_DOUBLE */
    const char *expect; /* what a bad value should have been: "WxH, e.g. 640x480"; NULL for a
                         * number: its range ("an integer in [1, 16777216]") */
    bool (*call)(const char *cmd, const char *opt, const char *value, void *dest);
    /* What completion offers for the value, separated by spaces or ", ": words, *.EXT (the
     * files with that extension, and folders), / (folders); NULL: nothing to guess. */
    const char *complete;
} cli_option;

#define CLI_MAX_OPTIONS 64

typedef struct cli_command {
    const char *name;     /* "render" */
    const char *synopsis; /* the usage line after "usage: gonio NAME " */
    const char *intro;    /* paragraphs between the usage line and the options; or NULL */
    const cli_option *options;
    int num_options;
    const char *epilog; /* paragraphs after the options; or NULL */
    int min_args, max_args; /* positional arguments; max_args -1: any number */
    const char *missing;    /* the usage error when fewer than min_args: "no scene given" */
    const char *unknown_hint; /* appended to "unknown option": where the options are listed */
    const char *complete_args; /* what completion offers for a positional argument (as
                                * cli_option.complete) */
} cli_command;
/* A destination of the type its kind writes, or a compile error (the table's void * would
 * take any pointer): CLI_AS(float, &x). The typed kinds' tables and the shared option
 * macros use it; a CLI_CALL's destination is its parser's to check. */
#define CLI_AS(type, p) _Generic((p), type *: (p))
#define CLI_OPTIONS(table) .options = (table), .num_options = (int)(sizeof(table) / sizeof *(table))

/* What cli_parse found: the positional arguments (in argv, which it reorders as GNU getopt
 * does: arg = argv + 1) and which options were given. */
typedef struct cli_args {
    char **arg;
    int num_args;
    bool given[CLI_MAX_OPTIONS];
} cli_args;

/* Parses argv[1..argc) (argv[0] the command's name). Returns -1 to go on, or the exit code
 * the command should return: 0 after --help, 2 after a usage error (printed). After
 * cli_complete, it prints the completions instead and returns 0. */
int cli_parse(const cli_command *c, int argc, char **argv, cli_args *out);
/* Whether option `name` (any of its aliases) was on the command line. */
bool cli_given(const cli_command *c, const cli_args *a, const char *name);
void cli_help(const cli_command *c, FILE *f);
/* One entry of a list in --help's layout, as the options are listed: "  NAME", then each line
 * of help ('\n' between them) from the help column on. */
void cli_help_item(FILE *f, const char *name, const char *help);

/* Completion (gonio __complete WORD..., which completion/gonio runs): from now on cli_parse
 * takes argv as the words before `word`, the one being completed, and prints what may stand
 * there, one a line: the option names when word starts with '-', the values of the option
 * before it, else the command's complete_args (see cli_option.complete). */
void cli_complete(const char *word);
/* Prints the items of a cli_option.complete list, one a line. */
void cli_complete_print(const char *list);

/* ---- the options several commands take, each defined once (options.c) -------------------
 * A command's table lists them with these macros: the names, the value, its range and parser
 * and what completion offers are fixed here; `help` (where a macro takes it) is the
 * command's own wording of what the option does there and its default. */

/* Samples per pixel: the sums count them exactly in float (sum.N, merge) up to 2^24. */
#define CLI_SPP_MAX (1 << 24)
#define CLI_OPT_SPP(dest, help)                                                                   \
    {"--spp", "N", help, CLI_INT, CLI_AS(int, dest), 1, CLI_SPP_MAX, NULL, NULL, NULL}
/* The image size, WxH, each 1..UTIL_SIZE_MAX (dest: int[2]). */
#define CLI_OPT_SIZE(dest, help)                                                                  \
    {"--size", "WxH", help, CLI_CALL, CLI_AS(int, dest), 0, 0,                                    \
     "WxH, e.g. 640x480 (each 1.." UTIL_STRING(UTIL_SIZE_MAX) ")", cli_take_size, NULL}
#define CLI_OPT_SEED(dest, help)                                                                  \
    {"--seed", "S", help, CLI_U32, CLI_AS(uint32_t, dest), 0, 4294967295.0, NULL, NULL, NULL}
/* The glTF scene of the file (its scenes[] index). */
#define CLI_OPT_SCENE(dest, help)                                                                 \
    {"--scene", "N", help, CLI_INT, CLI_AS(int, dest), 0, 1 << 20, NULL, NULL, NULL}
/* Path length: up to 2^16 bounces each has random dimensions of its own (the alpha tests'
 * DIM_ALPHA + DIM_ALPHA_RAY * 2 depth in glsl/lib/bvh.glsl stays within 32 bits), and a path
 * that long has been ended by Russian roulette long before (0: unbounded). */
#define CLI_MAX_DEPTH_MAX (1 << 16)
#define CLI_OPT_MAX_DEPTH(dest, help)                                                             \
    {"--max-depth", "N", help, CLI_INT, CLI_AS(int, dest), 0, CLI_MAX_DEPTH_MAX, NULL, NULL, NULL}
#define CLI_OPT_MODE(dest)                                                                        \
    {"--mode", "M", render_mode_help(), CLI_CALL, CLI_AS(uint32_t, dest), 0, 0, NULL, cli_take_mode, \
     render_mode_list()}
/* The path tracer's sampler (GN_SAMPLERS; dest: uint32_t). */
#define CLI_OPT_SAMPLER(dest)                                                                     \
    {"--sampler", "S", render_sampler_help(), CLI_CALL, CLI_AS(uint32_t, dest), 0, 0, NULL,        \
     cli_take_sampler, render_sampler_list()}
#define CLI_OPT_VARIANT(help)                                                                     \
    {"--variant", "NAME", help, CLI_CALL, NULL, 0, 0, NULL, cli_take_variant, NULL}
#define CLI_OPT_NO_SHADOWS(dest)                                                                  \
    {"--no-shadows", NULL, "local modes: no shadow rays", CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL, NULL}
#define CLI_OPT_EXPOSURE(dest, help)                                                              \
    {"--exposure", "E", help, CLI_FLOAT, CLI_AS(float, dest), -1e6, 1e6, NULL, NULL, NULL}
#define CLI_OPT_TONEMAP(dest, help)                                                               \
    {"--tonemap", "T", help, CLI_CALL, CLI_AS(image_tonemap, dest), 0, 0, NULL, cli_take_tonemap, \
     image_tonemap_list()}
/* Intel Open Image Denoise on the result (src/core/denoise.h). */
#define CLI_OPT_DENOISE(dest, help)                                                       \
    {"--denoise", NULL, help, CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL, NULL}
#define CLI_OPT_PNG(dest, help)                                                                   \
    {"--png", "FILE", help, CLI_STRING, CLI_AS(const char *, dest), 0, 0, NULL, NULL, "*.png"}
#define CLI_OPT_DEVICE(dest)                                                                      \
    {"--device", "N", "Vulkan device index (see gonio devices)", CLI_INT, CLI_AS(int, dest), 0, 64, \
     "an index (see gonio devices)", NULL, NULL}
#define CLI_OPT_VALIDATE(dest)                                                                    \
    {"--validate", NULL, "enable the Vulkan validation layer; any message is an error",           \
     CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL, NULL}
#define CLI_OPT_QUIET(dest, what)                                                                 \
    {"-q, --quiet", NULL, what, CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL, NULL}
#define CLI_OPT_ALLOW_OUTSIDE_FILES(dest)                                                         \
    {"--allow-outside-files", NULL,                                                               \
     "let the scene read files outside its folder (default: only\nregular files under it)",       \
     CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL, NULL}
/* --strict (render, compare, info; batch: every line): every warning about the file or the
 * command line, and a light gonio adds to a dark view, is an error, and nothing is written. */
#define CLI_OPT_STRICT(dest)                                                                      \
    {"--strict", NULL, "warnings are errors: a skipped primitive, an ignored extension or\n"      \
                       "option, a clamped value, a light added to a dark view exits 1\n"         \
                       "and writes nothing",                                                      \
     CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL, NULL}
/* EXR output (render, merge). */
#define CLI_OPT_EXR_HALF(dest)                                                                    \
    {"--half", NULL, "EXR: 16-bit half channels (default 32-bit float)", CLI_FLAG, CLI_AS(bool, dest), \
     0, 0, NULL, NULL, NULL}
#define CLI_OPT_EXR_COMPRESSION(dest)                                                             \
    {"--compression", "C", "EXR: none, rle, zips, zip (default), piz, pxr24, b44, b44a",          \
     CLI_CALL, CLI_AS(int, dest), 0, 0, NULL, cli_take_exr_compression, image_exr_compression_list()}

/* The CLI_CALL parsers of the options above; a bad value gets a usage error naming what the
 * value may be. */
bool cli_take_size(const char *cmd, const char *opt, const char *value, void *dest); /* WxH: int[2] */
bool cli_take_mode(const char *cmd, const char *opt, const char *value, void *dest); /* uint32_t GN_MODE_* */
bool cli_take_sampler(const char *cmd, const char *opt, const char *value, void *dest); /* uint32_t GN_SAMPLER_* */
bool cli_take_tonemap(const char *cmd, const char *opt, const char *value, void *dest); /* image_tonemap */
bool cli_take_variant(const char *cmd, const char *opt, const char *value, void *dest); /* no dest: scene_select_variant */
bool cli_take_exr_compression(const char *cmd, const char *opt, const char *value, void *dest); /* int */
/* The BRDF models' names (gonio brdf --list), ", "-separated. */
const char *cli_brdf_models(void);

/* ---- the view: camera and environment (options.c) --------------------------------------- */

/* The camera options of render, preview and compare: a camera_option (camera.h). */
#define CAMERA_OPTIONS(cam)                                                                       \
    {"--camera", "C",                                                                             \
     "N: the scene's N-th camera (0 = the first in the default scene's\n"                         \
     "node order, the default); frame: frame the bounds from a raised\n"                          \
     "three-quarter view (the default without a camera); FILE.exr: the\n"                         \
     "view recorded by gonio render or preview",                                                  \
     CLI_CALL, CLI_AS(camera_option, cam), 0, 0, NULL, cli_take_camera, "frame *.exr"},           \
    {"--look-at", "E,T[,U]",                                                                      \
     "place a camera: eye EX,EY,EZ, target TX,TY,TZ, up UX,UY,UZ\n"                               \
     "(default 0,1,0), world coordinates",                                                        \
     CLI_CALL, CLI_AS(camera_option, cam), 0, 0, NULL, cli_take_camera, NULL},                    \
    {"--fov", "DEGREES", "vertical field of view (default: the camera's own, else 45)",           \
     CLI_CALL, CLI_AS(camera_option, cam), 0, 0, NULL, cli_take_camera, NULL}
/* The camera options' parser (dest: the camera_option). */
bool cli_take_camera(const char *cmd, const char *opt, const char *val, void *dest);

/* The environment options' value: what the user asked of the light (src/render/render_default_light.h). */
typedef render_light_request env_option;

/* The environment options of render and preview: an env_option. CLI_OPT_ENV alone: --env
 * (bench: help its own wording). */
#define CLI_OPT_ENV(env, help)                                                                    \
    {"--env", "R,G,B | V", help, CLI_CALL, CLI_AS(env_option, env), 0, 0, NULL, cli_take_env,     \
     "studio *.exr *.hdr"}
#define ENV_OPTIONS(env)                                                                          \
    CLI_OPT_ENV(env, "constant environment radiance; 0: black (default: the scene's own\n"        \
                     "lights, or gonio's studio environment when it has none)"),                  \
    {NULL, NULL,                                                                                  \
     "  --env FILE          a lat-long HDR environment map, OpenEXR (.exr) or Radiance (.hdr),\n" \
     "                      +Y up; importance sampled by the path tracer, its mean radiance is\n" \
     "                      the local modes' ambient light\n"                                     \
     "  --env studio        gonio's studio environment besides the scene's own lights (as model\n" \
     "                      viewers light a scene that has only punctual lights)\n",              \
     CLI_TEXT, NULL, 0, 0, NULL, NULL, NULL},                                                     \
    {"--env-rotate", "DEG", "turn the environment about +Y (right-handed, default 0)",            \
     CLI_CALL, CLI_AS(env_option, env), 0, 0, NULL, cli_take_env, NULL},                          \
    {"--env-intensity", "X", "scale the environment's radiance (default 1)",                      \
     CLI_CALL, CLI_AS(env_option, env), 0, 0, NULL, cli_take_env, NULL}
/* The environment options' parser (dest: the env_option). */
bool cli_take_env(const char *cmd, const char *opt, const char *val, void *dest);

/* "gonio CMD: MESSAGE" and the hint to use --help; returns 2. */
int cli_usage_error(const char *cmd, const char *fmt, ...);
/* The image outputs of render and denoise, by name: -o (OUT.exr, or OUT.png: the format its
 * name says) and --png (OUT.png), either NULL, not both. Returns -1 to go on, with *exr_path
 * the -o name when it is an EXR and NULL otherwise, or 2 after a usage error naming the option. */
int cli_image_outputs(const char *cmd, const char *out_path, const char *png_path, const char **exr_path);
/* The Vulkan device for a command: --device, --validate (or GONIO_VALIDATE=1 in the
 * environment). While devices are shared (cli_gpu_share), the device the command before
 * handed back, when it has the same index and validation, with its compiled kernels. */
bool cli_gpu_create(gpu *g, int device_index, bool validate);
/* After work under validation: false (with an error) if any validation message was seen
 * since cli_gpu_create. While devices are shared, the device is kept for the next command
 * (and *g zeroed) instead of destroyed. */
bool cli_gpu_finish(gpu *g);
/* on: from now on cli_gpu_finish keeps the device for the next cli_gpu_create (gonio batch);
 * a device kept before is destroyed. off: the kept device is destroyed. False when that
 * destruction fails validation. */
bool cli_gpu_share(bool on);
/* --strict: cli_strict_begin(the command's --strict) turns it on (also when the batch running
 * the command has it: cli_strict_all) and returns the warnings so far; cli_strict_ok(that,
 * WHAT) is false, with an error naming WHAT, once more have come under --strict. A command
 * asks it before it writes anything. */
extern bool cli_strict_all;
int cli_strict_begin(bool strict);
bool cli_strict_ok(int since, const char *what);
/* The command line, space-joined, for output headers. */
void cli_set_command_line(int argc, char **argv);
const char *cli_command_line(void);

#endif
