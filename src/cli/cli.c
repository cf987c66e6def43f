/* cli.c: option helpers shared by the subcommands. */
#include <assert.h>
#include <float.h>
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "image.h"
#include "render.h"
#include "scene.h"
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

/* The option of c whose names include `name` (exactly), or -1. */
static int find_option(const cli_command *c, const char *name, size_t len)
{
    for (int k = 0; k < c->num_options; k++) {
        const char *n = c->options[k].names;
        if (c->options[k].kind == CLI_TEXT)
            continue;
        while (n && *n) {
            size_t l = strcspn(n, ",");
            if (l == len && !strncmp(n, name, len))
                return k;
            n += l;
            n += strspn(n, ", ");
        }
    }
    return -1;
}

static int bad_value(const cli_command *c, const char *opt, const char *val, const char *expect)
{
    return cli_usage_error(c->name, "%s '%s': expected %s", opt, val, expect);
}

/* A number outside an option's range: the message gives the range ("(0, 1e+06]": more
 * than 0; "[0, 1e+09]": 0 to 1e9, both included). */
static int out_of_range(const cli_command *c, const cli_option *o, const char *opt, const char *val)
{
    const bool open_low = o->kind == CLI_FLOAT || o->kind == CLI_DOUBLE ? o->min == FLT_MIN : false;
    return cli_usage_error(c->name, "%s '%s': out of range: must be in %s%.10g, %.10g]", opt, val,
                           open_low ? "(" : "[", open_low ? 0.0 : o->min, o->max);
}

/* Stores val in option o's destination; -1 ok, else 2 after a usage error. */
static int take_value(const cli_command *c, const cli_option *o, const char *opt, const char *val)
{
    long v;
    float f;
    switch (o->kind) {
    case CLI_STRING:
        *(const char **)o->dest = val;
        return -1;
    case CLI_INT:
    case CLI_U32:
        if (!util_parse_int(val, (long)o->min, (long)o->max, &v))
            return util_parse_int(val, LONG_MIN, LONG_MAX, &v) ? out_of_range(c, o, opt, val)
                                                                : bad_value(c, opt, val, o->expect);
        if (o->kind == CLI_INT)
            *(int *)o->dest = (int)v;
        else
            *(uint32_t *)o->dest = (uint32_t)v;
        return -1;
    case CLI_FLOAT:
    case CLI_DOUBLE:
        if (!util_parse_float(val, &f))
            return bad_value(c, opt, val, o->expect);
        if (!(f >= o->min && f <= o->max))
            return out_of_range(c, o, opt, val);
        if (o->kind == CLI_FLOAT)
            *(float *)o->dest = f;
        else
            *(double *)o->dest = f;
        return -1;
    case CLI_CALL:
        if (o->call(c->name, opt, val, o->dest))
            return -1;
        return o->expect ? bad_value(c, opt, val, o->expect) : 2;
    default:
        return -1;
    }
}

int cli_parse(const cli_command *c, int argc, char **argv, cli_args *out)
{
    bool options = true;
    assert(c->num_options <= CLI_MAX_OPTIONS);
    memset(out, 0, sizeof *out);
    out->arg = argv + 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *eq = a[0] == '-' && a[1] == '-' ? strchr(a, '=') : NULL;
        size_t len = eq ? (size_t)(eq - a) : strlen(a);
        if (!options || a[0] != '-' || !a[1]) {
            if (out->num_args == c->max_args)
                return cli_usage_error(c->name, "unexpected argument '%s'", a);
            argv[1 + out->num_args++] = (char *)a; /* never past i: the options read so far */
            continue;
        }
        if (!strcmp(a, "--")) {
            options = false;
            continue;
        }
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            cli_help(c, stdout);
            return 0;
        }
        int k = find_option(c, a, len);
        if (k < 0 && eq && len == 6 && !strncmp(a, "--help", 6))
            return cli_usage_error(c->name, "--help takes no value");
        if (k < 0)
            return cli_usage_error(c->name, "unknown option '%.*s'%s", (int)len, a, c->unknown_hint ? c->unknown_hint : "");
        const cli_option *o = &c->options[k];
        char opt[64];
        snprintf(opt, sizeof opt, "%.*s", (int)len, a);
        out->given[k] = true;
        if (o->kind == CLI_FLAG) {
            if (eq)
                return cli_usage_error(c->name, "%s takes no value", opt);
            *(bool *)o->dest = true;
            continue;
        }
        const char *val = eq ? eq + 1 : i + 1 < argc ? argv[++i] : NULL;
        if (!val)
            return cli_usage_error(c->name, "%s needs a value", opt);
        int rc = take_value(c, o, opt, val);
        if (rc >= 0)
            return rc;
    }
    if (out->num_args < c->min_args)
        return cli_usage_error(c->name, "%s", c->missing ? c->missing : "missing arguments");
    return -1;
}

bool cli_given(const cli_command *c, const cli_args *a, const char *name)
{
    int k = find_option(c, name, strlen(name));
    assert(k >= 0); /* a name the table does not have is a bug */
    return k >= 0 && a->given[k];
}

bool cli_take_size(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    int *wh = dest;
    return util_parse_size(value, &wh[0], &wh[1]);
}

bool cli_take_mode(const char *cmd, const char *opt, const char *value, void *dest)
{
    int m = render_mode_from_name(value);
    if (m < 0) {
        cli_usage_error(cmd, "%s '%s': expected one of %s", opt, value, render_mode_list());
        return false;
    }
    *(uint32_t *)dest = (uint32_t)m;
    return true;
}

bool cli_take_tonemap(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    return image_tonemap_from_name(value, dest);
}

bool cli_take_variant(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)dest;
    if (!*value) {
        cli_usage_error(cmd, "%s '': a variant's name (gonio info lists them)", opt);
        return false;
    }
    scene_select_variant(value);
    return true;
}

bool cli_take_exr_compression(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    return image_exr_compression_from_name(value, dest);
}

/* The help column: option names and value, padded to it, then the text. */
#define HELP_COLUMN 22

void cli_help(const cli_command *c, FILE *f)
{
    fprintf(f, "usage: gonio %s%s%s\n", c->name, c->synopsis ? " " : "", c->synopsis ? c->synopsis : "");
    if (c->intro)
        fprintf(f, "\n%s", c->intro);
    if (c->num_options)
        fputc('\n', f);
    for (int k = 0; k < c->num_options; k++) {
        const cli_option *o = &c->options[k];
        if (o->kind == CLI_TEXT) {
            fputs(o->help, f);
            continue;
        }
        int w = fprintf(f, "  %s%s%s", o->names, o->value ? " " : "", o->value ? o->value : "");
        for (const char *line = o->help; *line;) {
            size_t l = strcspn(line, "\n");
            fprintf(f, "%*s%.*s\n", w + 2 <= HELP_COLUMN ? HELP_COLUMN - w : 2, "", (int)l, line);
            line += l + (line[l] == '\n');
            w = 0;
        }
    }
    if (c->epilog)
        fprintf(f, "\n%s", c->epilog);
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
