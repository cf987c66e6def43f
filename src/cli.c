/* cli.c: option helpers shared by the subcommands. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "util.h"

static char command_line[4096];

void cli_set_command_line(int argc, char **argv)
{
    size_t len = 0;
    command_line[0] = 0;
    for (int i = 0; i < argc && len + 2 < sizeof command_line; i++)
        len += (size_t)snprintf(command_line + len, sizeof command_line - len, "%s%s",
                                i ? " " : "", argv[i]);
}

const char *cli_command_line(void) { return command_line; }

const char *cli_value(int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        cli_usage_error(argv[0], "%s needs a value", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "gonio %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see gonio %s --help)\n", cmd);
    return 2;
}

bool cli_gpu_create(gpu *g, int device_index, bool validate)
{
    const char *env = getenv("GONIO_VALIDATE");
    gpu_desc d = {.device_index = device_index};
    d.validate = validate || (env && strcmp(env, "1") == 0);
    return gpu_create(g, &d);
}

bool cli_gpu_finish(gpu *g)
{
    bool validate = g->validate;
    gpu_destroy(g);
    if (validate && gpu_validation_message_count() > 0) {
        util_error("%d Vulkan validation message(s) (see above)", gpu_validation_message_count());
        return false;
    }
    return true;
}

