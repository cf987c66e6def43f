/* util.c: error reporting, timing, checked allocation, strict parsing, safe file output. */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static bool quiet_flag, silent_flag;
static int warnings;

static void vreport(const char *prefix, const char *fmt, va_list ap)
{
    if (silent_flag)
        return;
    fprintf(stderr, "gonio: %s", prefix);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

void util_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport("error: ", fmt, ap);
    va_end(ap);
}

void util_warn(const char *fmt, ...)
{
    va_list ap;
    warnings++;
    va_start(ap, fmt);
    vreport("warning: ", fmt, ap);
    va_end(ap);
}

void util_info(const char *fmt, ...)
{
    va_list ap;
    if (quiet_flag)
        return;
    va_start(ap, fmt);
    vreport("", fmt, ap);
    va_end(ap);
}

void util_set_quiet(bool quiet) { quiet_flag = quiet; }
void util_set_silent(bool silent) { silent_flag = silent; }
bool util_quiet(void) { return quiet_flag; }
int util_warning_count(void) { return warnings; }

double util_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void *check_alloc(void *p, size_t size)
{
    if (!p && size) {
        fprintf(stderr, "gonio: error: out of memory (%zu bytes)\n", size);
        exit(1);
    }
    return p;
}

void *util_malloc(size_t size) { return check_alloc(malloc(size ? size : 1), size); }
void *util_calloc(size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size)
        return check_alloc(NULL, SIZE_MAX);
    return check_alloc(calloc(count ? count : 1, size ? size : 1), count * size);
}
void *util_realloc(void *ptr, size_t size) { return check_alloc(realloc(ptr, size ? size : 1), size); }

/* strtol and strtod skip leading white space and take a '+': neither is a number as a
 * user types it on a command line (" 16", "+16"). */
static bool plain_number_start(const char *s)
{
    return s && (*s == '-' || *s == '.' || (*s >= '0' && *s <= '9'));
}

bool util_parse_int(const char *s, long min, long max, long *out)
{
    char *end;
    long v;
    if (!plain_number_start(s))
        return false;
    errno = 0;
    v = strtol(s, &end, 10);
    if (errno || *end || v < min || v > max)
        return false;
    *out = v;
    return true;
}

bool util_parse_float(const char *s, float *out)
{
    char *end;
    double v;
    /* strtod also reads hexadecimal ("0x1p4"), not a number as a user writes one. */
    if (!plain_number_start(s) || strpbrk(s, "xX"))
        return false;
    errno = 0;
    v = strtod(s, &end);
    if (errno || *end || !isfinite(v) || fabs(v) > 3.0e38)
        return false;
    *out = (float)v;
    return true;
}

bool util_parse_rgb(const char *s, float out[3])
{
    char buf[128], *g, *b;
    if (!s || strlen(s) >= sizeof buf)
        return false;
    strcpy(buf, s);
    if (!(g = strchr(buf, ','))) {
        if (!util_parse_float(buf, &out[0]))
            return false;
        out[1] = out[2] = out[0];
    } else {
        *g++ = 0;
        if (!(b = strchr(g, ',')))
            return false;
        *b++ = 0;
        if (!util_parse_float(buf, &out[0]) || !util_parse_float(g, &out[1]) ||
            !util_parse_float(b, &out[2]))
            return false;
    }
    return out[0] >= 0 && out[1] >= 0 && out[2] >= 0;
}

bool util_parse_size(const char *s, int *w, int *h)
{
    char buf[64];
    char *x;
    long lw, lh;
    if (!s || strlen(s) >= sizeof buf)
        return false;
    strcpy(buf, s);
    x = strchr(buf, 'x');
    if (!x)
        return false;
    *x = 0;
    if (!util_parse_int(buf, 1, 16384, &lw) || !util_parse_int(x + 1, 1, 16384, &lh))
        return false;
    *w = (int)lw;
    *h = (int)lh;
    return true;
}

void *util_read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    char *data;
    long len;
    struct stat st;
    if (!f) {
        util_error("%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    /* A directory opens and seeks on Linux (ftell gives LONG_MAX): only regular files. */
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        util_error("%s: not a regular file", path);
        fclose(f);
        return NULL;
    }
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        util_error("%s: cannot read (not a regular file?)", path);
        fclose(f);
        return NULL;
    }
    data = util_malloc((size_t)len + 1);
    if (fread(data, 1, (size_t)len, f) != (size_t)len) {
        util_error("%s: read failed", path);
        free(data);
        fclose(f);
        return NULL;
    }
    data[len] = 0;
    fclose(f);
    if (size)
        *size = (size_t)len;
    return data;
}

/* The temporary file being written, if any, for util_remove_pending_tmp (a signal handler):
 * one at a time, since every writer commits before the next starts. The flag is cleared
 * while the name changes and after the rename, so the handler never reads a half-written
 * name and at worst unlinks a name that no longer exists. */
static char pending_tmp[4096];
static volatile sig_atomic_t pending;
/* The temporary name: "DIR/.NAME.tmp-PID". */
#define TMP_PREFIX "."
#define TMP_INFIX ".tmp-"
#define TMP_EXTRA (sizeof TMP_PREFIX + sizeof TMP_INFIX + 10)

bool util_has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

void util_tmp_path(char *out, size_t cap, const char *final_path)
{
    const char *slash = strrchr(final_path, '/');
    int dirlen = slash ? (int)(slash - final_path + 1) : 0;
    snprintf(out, cap, "%.*s" TMP_PREFIX "%s" TMP_INFIX "%ld", dirlen, final_path,
             slash ? slash + 1 : final_path, (long)getpid());
    pending = 0;
    snprintf(pending_tmp, sizeof pending_tmp, "%s", out);
    pending = 1;
}

void util_remove_pending_tmp(void)
{
    if (pending)
        unlink(pending_tmp);
}

/* Removes "DIR/.NAME.tmp-PID" files left by a gonio that was killed (SIGKILL, power loss)
 * while writing NAME: only regular files, and only of processes that no longer exist. */
static void remove_stale_tmp(const char *dir, const char *name)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    size_t len = strlen(name);
    if (!d)
        return;
    while ((e = readdir(d))) {
        const char *n = e->d_name, *pid_text = n + 1 + len + strlen(TMP_INFIX);
        char path[PATH_MAX];
        struct stat st;
        long pid;
        if (n[0] != '.' || strncmp(n + 1, name, len) || strncmp(n + 1 + len, TMP_INFIX, strlen(TMP_INFIX)) ||
            !util_parse_int(pid_text, 1, LONG_MAX, &pid) || pid == (long)getpid())
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        if (snprintf(path, sizeof path, "%s/%s", dir, n) < (int)sizeof path && lstat(path, &st) == 0 &&
            S_ISREG(st.st_mode) && unlink(path) == 0)
            util_info("%s: removed a stale temporary file of process %ld", path, pid);
    }
    closedir(d);
}

/* What may be replaced at an output path: nothing, or a regular file that may be written.
 * A symbolic link, a device, a FIFO or a directory is refused: renaming over it would
 * replace the link or the device node itself, not write through it. A read-only file is
 * refused even for root, as the shell's > would refuse it for anyone else. */
static bool replaceable(const char *path, struct stat *st, bool *exists)
{
    *exists = false;
    if (lstat(path, st) != 0) {
        if (errno == ENOENT)
            return true;
        util_error("%s: cannot write: %s", path, strerror(errno));
        return false;
    }
    *exists = true;
    if (S_ISLNK(st->st_mode))
        util_error("%s: is a symbolic link; gonio replaces only regular files (name the target instead)", path);
    else if (S_ISDIR(st->st_mode))
        util_error("%s: is a directory; expected a file name", path);
    else if (!S_ISREG(st->st_mode))
        util_error("%s: is not a regular file (a device, FIFO or socket); gonio writes only regular files", path);
    else if ((st->st_mode & 0222) == 0 || access(path, W_OK) != 0)
        util_error("%s: is read-only; gonio does not replace it", path);
    else
        return true;
    return false;
}

bool util_check_output(const char *path)
{
    char dir[PATH_MAX];
    const char *slash, *name;
    struct stat st;
    bool exists;
    if (!path || !*path) {
        util_error("'': an output needs a file name");
        return false;
    }
    if (strlen(path) + TMP_EXTRA >= PATH_MAX) {
        util_error("%.40s...: output path of %zu characters is too long (at most %zu)", path, strlen(path),
                   (size_t)PATH_MAX - TMP_EXTRA - 1);
        return false;
    }
    slash = strrchr(path, '/');
    name = slash ? slash + 1 : path;
    if (!*name || !strcmp(name, ".") || !strcmp(name, "..")) {
        util_error("%s: is a directory; expected a file name", path);
        return false;
    }
    if (strlen(name) + TMP_EXTRA > NAME_MAX) {
        util_error("%s: file name of %zu characters is too long (at most %zu)", path, strlen(name),
                   (size_t)NAME_MAX - TMP_EXTRA);
        return false;
    }
    if (slash)
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    else
        strcpy(dir, ".");
    if (!*dir)
        strcpy(dir, "/");
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        util_error("%s: folder '%s' does not exist", path, dir);
        return false;
    }
    if (access(dir, W_OK) != 0) {
        util_error("%s: cannot write into '%s': %s", path, dir, strerror(errno));
        return false;
    }
    if (!replaceable(path, &st, &exists))
        return false;
    remove_stale_tmp(dir, name);
    return true;
}

FILE *util_tmp_open(char *tmp, size_t cap, const char *final_path, const char *mode)
{
    FILE *f;
    util_tmp_path(tmp, cap, final_path);
    if (!(f = fopen(tmp, mode)))
        util_error("%s: cannot write: %s", final_path, strerror(errno));
    return f;
}

bool util_commit_file(const char *tmp_path, const char *final_path, bool ok)
{
    struct stat st;
    bool exists;
    /* Checked again here: the path may have changed since util_check_output, and not every
     * writer's caller checks. */
    if (ok && !replaceable(final_path, &st, &exists))
        ok = false;
    /* A replaced file keeps its permissions (and its owner, where we may give it). */
    if (ok && exists) {
        if (chmod(tmp_path, st.st_mode & 07777) != 0) {
            util_error("%s: cannot write: %s", final_path, strerror(errno));
            ok = false;
        } else if ((st.st_uid != geteuid() || st.st_gid != getegid()) && chown(tmp_path, st.st_uid, st.st_gid) != 0) {
            /* Not ours to give away: the new file is the writer's, as with any rename. */
        }
    }
    if (ok && rename(tmp_path, final_path) != 0) {
        util_error("%s: cannot write: %s", final_path, strerror(errno));
        ok = false;
    }
    if (!ok)
        unlink(tmp_path);
    pending = 0;
    return ok;
}
