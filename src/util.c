/* util.c: error reporting, timing, checked allocation, strict parsing, safe file output. */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static bool quiet_flag;
static int warnings;

static void vreport(const char *prefix, const char *fmt, va_list ap)
{
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

void util_tmp_path(char *out, size_t cap, const char *final_path)
{
    const char *slash = strrchr(final_path, '/');
    int dirlen = slash ? (int)(slash - final_path + 1) : 0;
    snprintf(out, cap, "%.*s.%s.tmp-%ld", dirlen, final_path, slash ? slash + 1 : final_path,
             (long)getpid());
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
    if (ok && rename(tmp_path, final_path) != 0) {
        util_error("%s: cannot write: %s", final_path, strerror(errno));
        ok = false;
    }
    if (!ok)
        unlink(tmp_path);
    return ok;
}
