/* cli.h: the subcommands of the gonio program; each takes argv with argv[0] = its name and
 * returns the process exit code: 0 ok, 1 bad input or failed work, 2 bad usage. */
#ifndef GONIO_CLI_H
#define GONIO_CLI_H

#include <stdbool.h>

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

/* One of `gonio scene`'s scenes ("cornell", "teapot") loaded as from its glTF (written to a
 * temporary directory and removed), so a default scene needs no file in the working
 * directory. */
bool cli_load_builtin_scene(struct scene *out, const char *name);

/* Shared option handling. cli_value returns argv[i + 1] (advancing *i) or reports a usage
 * error naming the option; cli_usage_error prints "gonio CMD: MESSAGE" and the hint to use
 * --help. */
const char *cli_value(int argc, char **argv, int *i);
/* cli_value for an option the command's usage text lists with a value (see cli.c); any
 * other option is reported as unknown, so a mistyped one never takes the next argument. */
const char *cli_option_value(int argc, char **argv, int *i, const char *usage);
bool cli_usage_lists_value(const char *usage, const char *opt);
/* argv with every "--name=value" (after the command name) split into "--name" "value", so
 * each command's parser sees one form. Returns the new argc and sets *out (allocated, kept
 * until exit), or -1 after a usage error (a flag given a value). */
int cli_split_equals(int argc, char **argv, char ***out);
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
