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

/* Does the usage text list `opt` as an option that takes a value? An option line starts
 * (after indentation) with the option's names, ", " between aliases, and then one space and
 * its value's name ("  --spp N   ...", "  -o, --output FILE   ..."); a flag's names are
 * followed by two or more spaces or the line's end. The usage text is thus the one list of a
 * command's options: what --help shows is what the command accepts. */
bool cli_usage_lists_value(const char *usage, const char *opt)
{
    size_t len = strlen(opt);
    for (const char *line = usage; *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : "") {
        const char *p = line;
        bool named = false;
        while (*p == ' ')
            p++;
        while (*p == '-') {
            const char *name = p;
            while (*p && *p != ' ' && *p != ',' && *p != '\n')
                p++;
            named |= (size_t)(p - name) == len && !strncmp(name, opt, len);
            if (p[0] != ',' || p[1] != ' ' || p[2] != '-')
                break;
            p += 2;
        }
        if (named)
            return p[0] == ' ' && p[1] && p[1] != ' ' && p[1] != '\n';
    }
    return false;
}

const char *cli_option_value(int argc, char **argv, int *i, const char *usage)
{
    if (!cli_usage_lists_value(usage, argv[*i])) {
        cli_usage_error(argv[0], "unknown option '%s'", argv[*i]);
        return NULL;
    }
    return cli_value(argc, argv, i);
}

/* Options that never take a value, in every command: "--quiet=yes" is an error, not
 * "--quiet" followed by an argument "yes". */
static const char *const flags[] = {"--help", "--quiet", "--validate", "--no-shadows", "--paths",
                                    "--albedo", "--sphere", "--list", "--version"};

int cli_split_equals(int argc, char **argv, char ***out)
{
    int n = 0;
    char **v = util_calloc((size_t)argc * 2 + 1, sizeof *v);
    for (int i = 0; i < argc; i++) {
        char *a = argv[i], *eq = strchr(a, '=');
        if (i >= 2 && a[0] == '-' && a[1] == '-' && a[2] && eq && eq > a + 2) {
            size_t len = (size_t)(eq - a);
            for (size_t k = 0; k < sizeof flags / sizeof *flags; k++)
                if (strlen(flags[k]) == len && !strncmp(a, flags[k], len)) {
                    free(v);
                    cli_usage_error(argv[1], "%.*s takes no value", (int)len, a);
                    return -1;
                }
            v[n] = util_malloc(len + 1);
            memcpy(v[n], a, len);
            v[n++][len] = 0;
            v[n++] = eq + 1;
        } else {
            v[n++] = a;
        }
    }
    *out = v;
    return n;
}

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

