/* cmd_batch.c: `gonio batch`, many commands in one process. Each line of the file is a gonio
 * command line, run as the program would run it, one after the other; the Vulkan device is
 * made once and lent to every command (cli_gpu_share), so each kernel variant is compiled
 * once for the whole batch instead of once a process (on lavapipe, most of a small render's
 * time). */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "scene.h"
#include "util.h"

cli_command_fn *cli_dispatch;

#define BATCH_MAX_WORDS 256

/* Splits line into words in place: blanks separate them, '...' and "..." quote (no escapes).
 * Returns the number of words, -1 on an unterminated quote or too many words. */
static int split_words(char *line, char **words)
{
    int n = 0;
    char *r = line, *w = line;
    for (;;) {
        while (*r == ' ' || *r == '\t')
            r++;
        if (!*r || *r == '#')
            return n;
        if (n == BATCH_MAX_WORDS)
            return -1;
        words[n++] = w;
        while (*r && *r != ' ' && *r != '\t') {
            if (*r == '\'' || *r == '"') {
                char q = *r++;
                while (*r && *r != q)
                    *w++ = *r++;
                if (*r != q)
                    return -1;
                r++;
            } else {
                *w++ = *r++;
            }
        }
        bool end = !*r;
        *w++ = 0;
        if (end)
            return n;
        r++;
    }
}

/* NAME=value: an environment assignment before the command, as a shell takes it. */
static bool is_assignment(const char *word)
{
    const char *eq = strchr(word, '=');
    if (!eq || eq == word)
        return false;
    for (const char *p = word; p < eq; p++)
        if (!(*p == '_' || (*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (p > word && *p >= '0' && *p <= '9')))
            return false;
    return true;
}

/* Points stdout and stderr at path (saved: the originals, for restore_output). */
static bool redirect_output(const char *path, int saved[2])
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        util_error("%s: cannot write: %s", path, strerror(errno));
        return false;
    }
    fflush(stdout);
    fflush(stderr);
    saved[0] = dup(1);
    saved[1] = dup(2);
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
    return true;
}

static void restore_output(const int saved[2])
{
    fflush(stdout);
    fflush(stderr);
    dup2(saved[0], 1);
    dup2(saved[1], 2);
    close(saved[0]);
    close(saved[1]);
}

/* One line's command, with its assignments set around it; its exit status. */
static int run_line(char **words, int n)
{
    int first = 0;
    while (first < n && is_assignment(words[first]))
        first++;
    /* What the dynamic loader reads when a program starts cannot take effect in this one: such
     * a line is refused rather than run without it. (The Vulkan loader's and the drivers'
     * variables do take effect: such a line gets a device of its own, cli_gpu_create.) */
    for (int k = 0; k < first; k++)
        if (!strncmp(words[k], "LD_", 3)) {
            util_error("batch: %.*s is read by the dynamic loader when a program starts, so it cannot take effect "
                       "on a batch line: run that line as a gonio of its own", (int)(strchr(words[k], '=') - words[k]),
                       words[k]);
            return 2;
        }
    char *old[BATCH_MAX_WORDS] = {0};
    bool had[BATCH_MAX_WORDS] = {0};
    for (int k = 0; k < first; k++) {
        char *eq = strchr(words[k], '=');
        *eq = 0;
        const char *was = getenv(words[k]);
        had[k] = was != NULL;
        old[k] = was ? strdup(was) : NULL;
        setenv(words[k], eq + 1, 1);
    }
    int rc;
    if (first == n) {
        util_error("batch: a line with assignments and no command");
        rc = 2;
    } else if (!strcmp(words[first], "batch") || !strcmp(words[first], "preview")) {
        util_error("batch: '%s' cannot run in a batch", words[first]);
        rc = 2;
    } else {
        char *line[BATCH_MAX_WORDS + 1] = {"gonio"}; /* the headers' command line */
        memcpy(line + 1, words + first, sizeof *words * (size_t)(n - first));
        cli_set_command_line(n - first + 1, line);
        /* What a process starts with, whatever the line before set: the settings that
         * options put in globals, and the signals' default actions. */
        util_set_quiet(false);
        scene_allow_outside_files(false);
        scene_select_variant(NULL);
        scene_animation_time(-1);
        scene_instance_animated(false);
        rc = cli_dispatch(n - first, words + first);
        signal(SIGINT, SIG_DFL); /* (render catches them while it works) */
        signal(SIGTERM, SIG_DFL);
    }
    for (int k = first - 1; k >= 0; k--) {
        if (had[k])
            setenv(words[k], old[k], 1);
        else
            unsetenv(words[k]);
        free(old[k]);
    }
    return rc;
}

/* Writes text to DIR/N.EXT (a line's status or time), saying so when it cannot. */
static bool write_line_file(const char *dir, int number, const char *ext, const char *text)
{
    char name[4096];
    snprintf(name, sizeof name, "%s/%d.%s", dir, number, ext);
    FILE *f = fopen(name, "w");
    bool ok = f && fputs(text, f) >= 0;
    if (f && fclose(f) != 0)
        ok = false;
    if (!ok)
        util_error("%s: cannot write", name);
    return ok;
}

int cmd_batch(int argc, char **argv)
{
    const char *logs = NULL;
    bool strict = false;
    const cli_option options[] = {
        {"--logs", "DIR", "each line's output (stdout and stderr) in DIR/N.log, its exit status in\n"
                          "DIR/N.status and its wall time in seconds in DIR/N.time, N its line\n"
                          "number; else the output goes to the batch's own",
         CLI_STRING, CLI_AS(const char *, &logs), 0, 0, NULL, NULL, "/"},
        {"--strict", NULL, "every render, compare and info line as with --strict: its warnings\n"
                           "are errors and it writes nothing (the batch goes on)",
         CLI_FLAG, CLI_AS(bool, &strict), 0, 0, NULL, NULL, NULL},
    };
    const cli_command cmd = {
        .name = "batch",
        .synopsis = "FILE|- [--logs DIR] [--strict]",
        .intro = "Runs the gonio command lines of FILE (- for standard input) one after the other in\n"
                 "this process, as `gonio LINE` would run each: one Vulkan device serves them all, so\n"
                 "each kernel is compiled once for the batch rather than once a command (most of a\n"
                 "small render's time on a CPU). A line is words split at blanks, '...' and \"...\"\n"
                 "quoting; a # starts a comment; NAME=value words before the command set that\n"
                 "environment variable for that line only (VK_*, MESA_*, LP_*: the line gets a\n"
                 "device of its own; LD_*, read when a program starts, refuse the line). Every\n"
                 "line runs, whatever the ones before it gave; preview and batch cannot be lines.",
        CLI_OPTIONS(options),
        .epilog = "Exit status: 0 when every line gave 0; else 1, after a line on stderr for each\n"
                  "line that did not (2 for a usage error of the batch itself). A line stopped by\n"
                  "a signal (128 + N) ends the batch with its status.\n",
        .min_args = 1,
        .max_args = 1,
        .missing = "no batch file given",
        .complete_args = "*.txt",
    };
    cli_args args;
    int rc = cli_parse(&cmd, argc, argv, &args);
    if (rc >= 0)
        return rc;
    const char *path = args.arg[0];
    FILE *f = strcmp(path, "-") ? fopen(path, "r") : stdin;
    if (!f) {
        util_error("%s: cannot read: %s", path, strerror(errno));
        return 1;
    }
    char *line = NULL, *words[BATCH_MAX_WORDS];
    size_t cap = 0;
    int number = 0, failed = 0, stopped = 0;
    cli_gpu_share(true);
    cli_strict_all = strict;
    while (!stopped && getline(&line, &cap, f) >= 0) {
        number++;
        line[strcspn(line, "\r\n")] = 0;
        int n = split_words(line, words);
        if (n == 0)
            continue;
        int saved[2], status;
        char name[4096];
        bool logged = false;
        double t0 = util_now();
        if (logs) {
            snprintf(name, sizeof name, "%s/%d.log", logs, number);
            if (!redirect_output(name, saved)) {
                failed++;
                continue;
            }
            logged = true;
        }
        if (n < 0) {
            util_error("%s:%d: an unterminated quote, or more than %d words", path, number, BATCH_MAX_WORDS);
            status = 2;
        } else {
            status = run_line(words, n);
            util_set_strict(false); /* (a line's --strict is its own) */
        }
        if (logged)
            restore_output(saved);
        if (logs) {
            char text[64];
            snprintf(text, sizeof text, "%d\n", status);
            failed += !write_line_file(logs, number, "status", text);
            snprintf(text, sizeof text, "%.3f\n", util_now() - t0);
            failed += !write_line_file(logs, number, "time", text);
        }
        if (status != 0) {
            failed++;
            util_warn("batch: %s:%d gave exit status %d", path, number, status);
        }
        if (status > 128)
            stopped = status;
    }
    free(line);
    cli_strict_all = false;
    if (f != stdin)
        fclose(f);
    if (!cli_gpu_share(false))
        failed++;
    return stopped ? stopped : failed ? 1 : 0;
}
