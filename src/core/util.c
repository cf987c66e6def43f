/* util.c: error reporting, timing, checked allocation, strict parsing, safe file output. */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <assert.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static bool quiet_flag, silent_flag, strict_flag;
static int warnings;

/* One character of s at *p, escaped when it is a control character, into out (room for 7
 * bytes); advances *p past what it used. */
static int escape_one(const unsigned char **p, char *out)
{
    const unsigned char c = **p;
    if (c < 0x20 || c == 0x7f) {
        (*p)++;
        return sprintf(out, "\\x%02x", c);
    }
    if (c == 0xc2 && (*p)[1] >= 0x80 && (*p)[1] <= 0x9f) { /* U+0080..U+009F, the C1 controls */
        int n = sprintf(out, "\\u%04x", (*p)[1]);
        *p += 2;
        return n;
    }
    out[0] = (char)c;
    (*p)++;
    return 1;
}

void util_fputs_safe(const char *s, FILE *f)
{
    char e[8];
    for (const unsigned char *p = (const unsigned char *)s; *p;)
        fwrite(e, 1, (size_t)escape_one(&p, e), f);
}

const char *util_escape(const char *s, char *buf, size_t cap)
{
    size_t len = 0;
    char e[8];
    for (const unsigned char *p = (const unsigned char *)s; *p;) {
        int n = escape_one(&p, e);
        if (len + (size_t)n >= cap)
            break;
        memcpy(buf + len, e, (size_t)n);
        len += (size_t)n;
    }
    buf[len] = 0;
    return buf;
}

/* A message is one line: text from files and the command line (names, URIs, values) goes
 * through util_fputs_safe, so a name cannot move the cursor, recolour the terminal or
 * forge a line of its own. */
static void vreport(const char *prefix, const char *fmt, va_list ap)
{
    char buf[1024], *text = buf;
    va_list again;
    int n;
    if (silent_flag)
        return;
    va_copy(again, ap);
    n = vsnprintf(buf, sizeof buf, fmt, ap);
    if (n >= (int)sizeof buf) {
        text = util_malloc((size_t)n + 1);
        vsnprintf(text, (size_t)n + 1, fmt, again);
    }
    va_end(again);
    fprintf(stderr, "gonio: %s", prefix);
    util_fputs_safe(n >= 0 ? text : fmt, stderr);
    fputc('\n', stderr);
    if (text != buf)
        free(text);
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
    vreport(strict_flag ? "error: " : "warning: ", fmt, ap);
    va_end(ap);
}

void util_fallback(const char *fmt, ...)
{
    va_list ap;
    if (quiet_flag && !strict_flag)
        return;
    warnings += strict_flag;
    va_start(ap, fmt);
    vreport(strict_flag ? "error: " : "", fmt, ap);
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
void util_set_strict(bool strict) { strict_flag = strict; }
bool util_strict(void) { return strict_flag; }
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
    if (!util_parse_int(buf, 1, UTIL_SIZE_MAX, &lw) || !util_parse_int(x + 1, 1, UTIL_SIZE_MAX, &lh))
        return false;
    *w = (int)lw;
    *h = (int)lh;
    return true;
}

const char *util_join(char *buf, size_t cap, const char *const *names, int n)
{
    size_t len = 0;
    buf[0] = 0;
    for (int i = 0; i < n && len < cap; i++)
        len += (size_t)snprintf(buf + len, cap - len, "%s%s", i ? ", " : "", names[i]);
    return buf;
}

/* O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer, forever. It is
 * cleared once the file is known to be regular (where it means nothing anyway). */
int util_open_read(const char *path)
{
    struct stat st;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        util_error("%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        util_error("%s: %s; gonio reads only regular files", path,
                   S_ISDIR(st.st_mode) ? "is a directory" : S_ISFIFO(st.st_mode) ? "is a FIFO (named pipe)"
                   : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "is a device"
                   : S_ISSOCK(st.st_mode) ? "is a socket" : "is not a regular file");
        close(fd);
        return -1;
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    return fd;
}

FILE *util_fopen_read(const char *path)
{
    int fd = util_open_read(path);
    FILE *f = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (fd >= 0 && !f) {
        util_error("%s: cannot open: %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

void *util_read_file(const char *path, size_t *size)
{
    FILE *f = util_fopen_read(path);
    char *data;
    long len;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        util_error("%s: cannot read: %s", path, strerror(errno));
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
static char pending_tmp[PATH_MAX];
static volatile sig_atomic_t pending;
/* The temporary name: "DIR/.NAME.tmp-PID-XXXXXX", XXXXXX random: nobody can have made it
 * in advance, and it is created exclusively all the same. */
#define TMP_PREFIX "."
#define TMP_INFIX ".tmp-"
#define TMP_RANDOM 6
#define TMP_EXTRA (sizeof TMP_PREFIX + sizeof TMP_INFIX + 10 + 1 + TMP_RANDOM)

bool util_has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

void util_remove_pending_tmp(void)
{
    if (pending)
        unlink(pending_tmp);
}

/* Removes "DIR/.NAME.tmp-PID-XXXXXX" files left by a gonio that was killed (SIGKILL, power
 * loss) while writing NAME: only regular files of this user, and only of processes that
 * no longer exist. */
static void remove_stale_tmp(const char *dir, const char *name)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    size_t len = strlen(name);
    if (!d)
        return;
    while ((e = readdir(d))) {
        const char *n = e->d_name, *pid_text = n + 1 + len + strlen(TMP_INFIX), *dash;
        char path[PATH_MAX], pid_buf[16];
        struct stat st;
        long pid;
        if (n[0] != '.' || strncmp(n + 1, name, len) || strncmp(n + 1 + len, TMP_INFIX, strlen(TMP_INFIX)) ||
            !(dash = strchr(pid_text, '-')) || dash - pid_text >= (long)sizeof pid_buf ||
            strlen(dash + 1) != TMP_RANDOM)
            continue;
        snprintf(pid_buf, sizeof pid_buf, "%.*s", (int)(dash - pid_text), pid_text);
        if (!util_parse_int(pid_buf, 1, LONG_MAX, &pid) || pid == (long)getpid())
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        if (snprintf(path, sizeof path, "%s/%s", dir, n) < (int)sizeof path && lstat(path, &st) == 0 &&
            S_ISREG(st.st_mode) && st.st_uid == geteuid() && unlink(path) == 0)
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

/* Six characters of [0-9a-z] from the kernel's random numbers (or the clock, where they
 * are unavailable: the name only has to be hard to guess; exclusivity is O_EXCL's). */
static void random_suffix(char out[TMP_RANDOM + 1])
{
    static const char digits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    unsigned char bytes[TMP_RANDOM];
    if (getrandom(bytes, sizeof bytes, GRND_NONBLOCK) != (ssize_t)sizeof bytes) {
        uint64_t x = (uint64_t)(util_now() * 1e9) ^ (uint64_t)getpid() << 32;
        for (int i = 0; i < TMP_RANDOM; i++, x = x * 6364136223846793005ull + 1442695040888963407ull)
            bytes[i] = (unsigned char)(x >> 56);
    }
    for (int i = 0; i < TMP_RANDOM; i++)
        out[i] = digits[bytes[i] % 36];
    out[TMP_RANDOM] = 0;
}

bool util_out_open(util_out *o, const char *path)
{
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path + 1) : 0;
    memset(o, 0, sizeof *o);
    o->path = path;
    o->fd = -1;
    for (int attempt = 0; attempt < 16 && o->fd < 0; attempt++) {
        char r[TMP_RANDOM + 1];
        random_suffix(r);
        if (snprintf(o->tmp, sizeof o->tmp, "%.*s" TMP_PREFIX "%s" TMP_INFIX "%ld-%s", dirlen, path,
                     slash ? slash + 1 : path, (long)getpid(), r) >= (int)sizeof o->tmp) {
            util_error("%s: cannot write: the path is too long", path);
            return false;
        }
        /* O_EXCL: a new file or nothing; a link (even one to nowhere) at the name fails. The
         * mode is the umask's, as a shell's > gives a new file. */
        o->fd = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY, 0666);
        if (o->fd < 0 && errno != EEXIST) {
            util_error("%s: cannot write: %s", path, strerror(errno));
            return false;
        }
    }
    struct stat st;
    if (o->fd < 0 || fstat(o->fd, &st) != 0) {
        util_error("%s: cannot create a temporary file beside it", path);
        if (o->fd >= 0)
            close(o->fd);
        return false;
    }
    o->dev = (uint64_t)st.st_dev;
    o->ino = (uint64_t)st.st_ino;
    pending = 0;
    snprintf(pending_tmp, sizeof pending_tmp, "%s", o->tmp);
    pending = 1;
    return true;
}

FILE *util_out_file(util_out *o)
{
    assert(o->fd >= 0 && !o->file);
    if (!(o->file = fdopen(o->fd, "wb")))
        util_error("%s: cannot write: %s", o->path, strerror(errno));
    return o->file;
}

/* The temporary file is still the one util_out_open created (nobody renamed another file
 * to its name since). */
static bool still_ours(const util_out *o)
{
    struct stat st;
    return lstat(o->tmp, &st) == 0 && S_ISREG(st.st_mode) && (uint64_t)st.st_dev == o->dev &&
           (uint64_t)st.st_ino == o->ino;
}

bool util_out_commit(util_out *o, bool ok)
{
    struct stat st;
    bool exists;
    int fd = o->file ? fileno(o->file) : o->fd;
    if (ok && o->file && (fflush(o->file) != 0 || ferror(o->file))) {
        util_error("%s: cannot write: %s", o->path, strerror(errno));
        ok = false;
    }
    /* Checked again here: the path may have changed since util_check_output, and not every
     * writer's caller checks. */
    if (ok && !replaceable(o->path, &st, &exists))
        ok = false;
    /* A replaced file keeps its permissions (and its owner, where we may give it), set
     * through the descriptor: no name is followed. */
    if (ok && exists) {
        if (fchmod(fd, st.st_mode & 07777) != 0) {
            util_error("%s: cannot write: %s", o->path, strerror(errno));
            ok = false;
        } else if ((st.st_uid != geteuid() || st.st_gid != getegid()) && fchown(fd, st.st_uid, st.st_gid) != 0) {
            /* Not ours to give away: the new file is the writer's, as with any rename. */
        }
    }
    if (o->file ? fclose(o->file) != 0 : close(o->fd) != 0) {
        if (ok)
            util_error("%s: cannot write: %s", o->path, strerror(errno));
        ok = false;
    }
    o->file = NULL;
    o->fd = -1;
    if (ok && !still_ours(o)) {
        util_error("%s: its temporary file %s was replaced by another process; nothing written", o->path, o->tmp);
        pending = 0;
        return false;
    }
    if (ok && rename(o->tmp, o->path) != 0) {
        util_error("%s: cannot write: %s", o->path, strerror(errno));
        ok = false;
    }
    if (!ok && still_ours(o))
        unlink(o->tmp);
    pending = 0;
    return ok;
}
