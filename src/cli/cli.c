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

/* The usage errors said so far (cli_usage_error). */
static int usage_errors;

static char command_line[4096];

bool cli_strict_all;

int cli_strict_begin(bool strict)
{
    util_set_strict(strict || cli_strict_all);
    return util_warning_count();
}

bool cli_strict_ok(int since, const char *what)
{
    int n = util_warning_count() - since;
    if (!util_strict() || n <= 0)
        return true;
    util_error("%s: %d warning%s, which --strict makes errors: nothing written", what, n, n == 1 ? "" : "s");
    return false;
}

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

/* What a bad value of o should have been: its expect, else for a number its range, for a
 * list of words "one of" them; NULL when the parser says it itself. */
static const char *expectation(const cli_option *o, char *buf, size_t cap)
{
    if (o->expect)
        return o->expect;
    switch (o->kind) {
    case CLI_INT:
    case CLI_U32:
        snprintf(buf, cap, "an integer in [%.10g, %.10g]", o->min, o->max);
        return buf;
    case CLI_FLOAT:
    case CLI_DOUBLE:
        snprintf(buf, cap, "a number in %s%.10g, %.10g]", o->min == FLT_MIN ? "(" : "[",
                 o->min == FLT_MIN ? 0.0 : o->min, o->max);
        return buf;
    case CLI_CALL:
        if (!o->complete || strchr(o->complete, '*') || strchr(o->complete, '/'))
            return NULL;
        snprintf(buf, cap, "one of %s", o->complete);
        return buf;
    default:
        return NULL;
    }
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
    char buf[256];
    const char *expect = expectation(o, buf, sizeof buf);
    switch (o->kind) {
    case CLI_STRING:
        *(const char **)o->dest = val;
        return -1;
    case CLI_INT:
    case CLI_U32:
        if (!util_parse_int(val, (long)o->min, (long)o->max, &v))
            return util_parse_int(val, LONG_MIN, LONG_MAX, &v) ? out_of_range(c, o, opt, val)
                                                                : bad_value(c, opt, val, expect);
        if (o->kind == CLI_INT)
            *(int *)o->dest = (int)v;
        else
            *(uint32_t *)o->dest = (uint32_t)v;
        return -1;
    case CLI_FLOAT:
    case CLI_DOUBLE:
        if (!util_parse_float(val, &f))
            return bad_value(c, opt, val, expect);
        if (!(f >= o->min && f <= o->max))
            return out_of_range(c, o, opt, val);
        if (o->kind == CLI_FLOAT)
            *(float *)o->dest = f;
        else
            *(double *)o->dest = f;
        return -1;
    case CLI_CALL: {
        /* (a parser that said what is wrong itself is not followed by a second message) */
        const int said = usage_errors;
        if (o->call(c->name, opt, val, o->dest))
            return -1;
        return expect && usage_errors == said ? bad_value(c, opt, val, expect) : 2;
    }
    default:
        return -1;
    }
}

/* ---- completion ------------------------------------------------------------------------- */

static const char *complete_word; /* the word being completed; NULL: parse */

void cli_complete(const char *word) { complete_word = word; }

void cli_complete_print(const char *list)
{
    while (list && *list) {
        size_t n = strcspn(list, ", ");
        if (n)
            printf("%.*s\n", (int)n, list);
        list += n;
        list += strspn(list, ", ");
    }
}

/* cli_parse under cli_complete: argv holds the words before complete_word. */
static int complete(const cli_command *c, int argc, char **argv)
{
    const cli_option *value_of = NULL; /* the option whose value complete_word is */
    bool options = true;
    int positional = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        value_of = NULL;
        if (!options || a[0] != '-' || !a[1]) {
            positional++;
        } else if (!strcmp(a, "--")) {
            options = false;
        } else if (!strchr(a, '=')) {
            int k = find_option(c, a, strlen(a));
            if (k >= 0 && c->options[k].kind != CLI_FLAG) {
                if (i + 1 < argc)
                    i++; /* its value */
                else
                    value_of = &c->options[k];
            }
        }
    }
    if (value_of)
        cli_complete_print(value_of->complete);
    else if (options && complete_word[0] == '-') {
        for (int k = 0; k < c->num_options; k++)
            if (c->options[k].kind != CLI_TEXT)
                cli_complete_print(c->options[k].names);
        cli_complete_print("--help");
    } else if (c->max_args < 0 || positional < c->max_args || positional == 0) {
        /* (positional 0: also the first argument a command reads before its options, such
         * as brdf's model, which its max_args does not count until it is there) */
        cli_complete_print(c->complete_args);
    }
    return 0;
}

/* ---- parsing ---------------------------------------------------------------------------- */

int cli_parse(const cli_command *c, int argc, char **argv, cli_args *out)
{
    bool options = true;
    assert(c->num_options <= CLI_MAX_OPTIONS);
    memset(out, 0, sizeof *out);
    out->arg = argv + 1;
    if (complete_word)
        return complete(c, argc, argv);
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
        char name[256];
        snprintf(name, sizeof name, "%s%s%s", o->names, o->value ? " " : "", o->value ? o->value : "");
        cli_help_item(f, name, o->help);
    }
    if (c->epilog)
        fprintf(f, "\n%s", c->epilog);
}

void cli_help_item(FILE *f, const char *name, const char *help)
{
    int w = fprintf(f, "  %s", name);
    for (const char *line = help; *line;) {
        size_t l = strcspn(line, "\n");
        fprintf(f, "%*s%.*s\n", w + 2 <= HELP_COLUMN ? HELP_COLUMN - w : 2, "", (int)l, line);
        line += l + (line[l] == '\n');
        w = 0;
    }
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    usage_errors++;
    fprintf(stderr, "gonio %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see gonio %s --help)\n", cmd);
    return 2;
}

int cli_image_outputs(const char *cmd, const char *out_path, const char *png_path, const char **exr_path)
{
    *exr_path = NULL;
    if (!out_path && !png_path)
        return cli_usage_error(cmd, "no output given (-o OUT.exr and/or --png OUT.png)");
    if (out_path && image_format_of(out_path) == IMAGE_FORMAT_UNKNOWN)
        return cli_usage_error(cmd, "-o '%s': expected a .exr (OpenEXR) or .png name", out_path);
    if (png_path && image_format_of(png_path) != IMAGE_FORMAT_PNG)
        return cli_usage_error(cmd, "--png '%s': expected a .png name", png_path);
    if (out_path && image_format_of(out_path) == IMAGE_FORMAT_EXR)
        *exr_path = out_path;
    return -1;
}

/* gonio batch's device, kept between commands (cli_gpu_share). */
static struct {
    bool on, kept;
    gpu g;
    int device_index;
    char driver_env[4096]; /* driver_environment() when it was made */
} shared;
static int messages_before; /* validation messages when the command's device was made or lent */

/* The environment the Vulkan loader and the drivers read when a device is made (VK_ICD_FILENAMES,
 * VK_LOADER_*, Mesa's MESA_* and lavapipe's LP_*, ...), as one string: a batch line that sets
 * any of them gets a device of its own, as `gonio LINE` would, not the one kept. */
static void driver_environment(char *out, size_t cap)
{
    extern char **environ;
    static const char *const prefixes[] = {"VK_", "MESA_", "LP_", "GALLIUM_", "RADV_", "ANV_", "NV_", "__GL", "DRI_PRIME"};
    static unsigned long overflows;
    size_t len = 0;
    out[0] = 0;
    for (char **e = environ; e && *e; e++)
        for (size_t k = 0; k < sizeof prefixes / sizeof *prefixes; k++)
            if (!strncmp(*e, prefixes[k], strlen(prefixes[k]))) {
                if (len + strlen(*e) + 2 >= cap) { /* too long to compare: never the same as another */
                    snprintf(out, cap, "(%lu: too long)", ++overflows);
                    return;
                }
                len += (size_t)snprintf(out + len, cap - len, "%s\n", *e);
                break;
            }
}

bool cli_gpu_create(gpu *g, int device_index, bool validate)
{
    const char *env = getenv("GONIO_VALIDATE");
    gpu_desc d = {.device_index = device_index};
    char driver_env[sizeof shared.driver_env];
    d.validate = validate || (env && strcmp(env, "1") == 0);
    driver_environment(driver_env, sizeof driver_env);
    if (shared.kept && shared.device_index == device_index && shared.g.validate == d.validate &&
        !strcmp(shared.driver_env, driver_env)) {
        *g = shared.g;
        shared.kept = false;
        messages_before = gpu_validation_message_count();
        return true;
    }
    if (shared.kept && !cli_gpu_share(true)) /* another device, validation or driver setting: made anew */
        return false;
    messages_before = gpu_validation_message_count();
    shared.device_index = device_index;
    memcpy(shared.driver_env, driver_env, sizeof driver_env);
    return gpu_create(g, &d);
}

bool cli_gpu_finish(gpu *g)
{
    bool validate = g->validate;
    if (shared.on && g->device && !shared.kept) {
        shared.g = *g;
        shared.kept = true;
        memset(g, 0, sizeof *g);
    } else {
        gpu_destroy(g);
    }
    int seen = gpu_validation_message_count() - messages_before;
    if (validate && seen > 0) {
        util_error("%d Vulkan validation message(s) (see above)", seen);
        return false;
    }
    return true;
}

bool cli_gpu_share(bool on)
{
    shared.on = on;
    if (!shared.kept)
        return true;
    /* The kept device destroyed (on: to make another): what validation says of its
     * destruction (objects left behind) is an error here. */
    gpu g = shared.g;
    bool keep = shared.on;
    shared.kept = false;
    shared.on = false;
    messages_before = gpu_validation_message_count();
    bool ok = cli_gpu_finish(&g);
    shared.on = keep;
    return ok;
}
