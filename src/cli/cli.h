/* cli.h: the subcommands of the gonio program; each takes argv with argv[0] = its name and
 * returns the process exit code: 0 ok, 1 bad input or failed work, 2 bad usage. */
#ifndef GONIO_CLI_H
#define GONIO_CLI_H

#include <stdbool.h>
#include <stdio.h>

#include "gpu.h"

struct scene;

#define GONIO_VERSION "0.1.0"

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

/* One of `gonio scene`'s scenes ("cornell", "teapot") loaded as from its glTF (written to a
 * temporary directory and removed), so a default scene needs no file in the working
 * directory. */
bool cli_load_builtin_scene(struct scene *out, const char *name);

/* ---- options ----------------------------------------------------------------------------
 * Every command declares its options once, as a table of cli_option; cli_parse reads argv
 * against it (--opt value and --opt=value, -h/--help, "--" ending the options) and cli_help
 * prints the --help text from it, so what --help lists is exactly what the command accepts
 * (completion/gonio and the man page read that text). */
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
    const char *expect; /* what a bad value should have been: "an integer 1..16777216" */
    bool (*call)(const char *cmd, const char *opt, const char *value, void *dest);
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
 * the command should return: 0 after --help, 2 after a usage error (printed). */
int cli_parse(const cli_command *c, int argc, char **argv, cli_args *out);
/* Whether option `name` (any of its aliases) was on the command line. */
bool cli_given(const cli_command *c, const cli_args *a, const char *name);
void cli_help(const cli_command *c, FILE *f);

/* Options every command that uses a device has, defined once. */
#define CLI_OPT_DEVICE(dest)                                                                  \
    {"--device", "N", "Vulkan device index (see gonio devices)", CLI_INT, CLI_AS(int, dest), 0, 64, \
     "an index (see gonio devices)", NULL}
#define CLI_OPT_VALIDATE(dest)                                                                \
    {"--validate", NULL, "enable the Vulkan validation layer; any message is an error",     \
     CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL}
#define CLI_OPT_QUIET(dest, what)                                                             \
    {"-q, --quiet", NULL, what, CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL}
#define CLI_OPT_ALLOW_OUTSIDE_FILES(dest)                                                     \
    {"--allow-outside-files", NULL,                                                           \
     "let the scene read files outside its folder (default: only\nregular files under it)",  \
     CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL}

/* CLI_CALL parsers of values several commands take. */
bool cli_take_size(const char *cmd, const char *opt, const char *value, void *dest); /* WxH: int[2] */
bool cli_take_mode(const char *cmd, const char *opt, const char *value, void *dest); /* uint32_t GN_MODE_* */
bool cli_take_tonemap(const char *cmd, const char *opt, const char *value, void *dest); /* image_tonemap */
bool cli_take_variant(const char *cmd, const char *opt, const char *value, void *dest); /* no dest: scene_select_variant */

/* EXR output options (render, merge). */
bool cli_take_exr_compression(const char *cmd, const char *opt, const char *value, void *dest);
#define CLI_OPT_EXR_HALF(dest)                                                                \
    {"--half", NULL, "EXR: 16-bit half channels (default 32-bit float)", CLI_FLAG, CLI_AS(bool, dest), 0, 0, NULL, NULL}
#define CLI_OPT_EXR_COMPRESSION(dest)                                                         \
    {"--compression", "C", "EXR: none, rle, zips, zip (default), piz, pxr24, b44, b44a",      \
     CLI_CALL, CLI_AS(int, dest), 0, 0, "none, rle, zips, zip, piz, pxr24, b44 or b44a",       \
     cli_take_exr_compression}

/* "gonio CMD: MESSAGE" and the hint to use --help; returns 2. */
int cli_usage_error(const char *cmd, const char *fmt, ...);
/* The Vulkan device for a command: --device, --validate (or GONIO_VALIDATE=1 in the
 * environment). */
bool cli_gpu_create(gpu *g, int device_index, bool validate);
/* After work under validation: false (with an error) if any validation message was seen. */
bool cli_gpu_finish(gpu *g);
/* The command line, space-joined, for output headers. */
void cli_set_command_line(int argc, char **argv);
const char *cli_command_line(void);

#endif
