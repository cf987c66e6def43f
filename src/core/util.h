/* util.h: error reporting, timing and small parsing helpers shared by every module.
 *
 * Three kinds of failure, three treatments: a Vulkan/driver failure stops in GPU_CHECK
 * (src/core/gpu.h) with the call, file, line and VkResult name; bad user input is reported with
 * util_error (naming the file and the problem) and returned as `false` up to main, which
 * exits 1; a programmer's mistake is an assert. */
#ifndef GONIO_UTIL_H
#define GONIO_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* The program's version (gonio --version, the gonio:version of what it writes). */
#define GONIO_VERSION "0.1.0"

#if defined(__GNUC__)
#define UTIL_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define UTIL_PRINTF(a, b)
#endif

/* "gonio: error: ..." on stderr. Messages about a file start with the file's path. */
void util_error(const char *fmt, ...) UTIL_PRINTF(1, 2);
/* "gonio: warning: ..." on stderr. */
void util_warn(const char *fmt, ...) UTIL_PRINTF(1, 2);
/* Informational line on stderr, silenced by util_set_quiet(true). */
void util_info(const char *fmt, ...) UTIL_PRINTF(1, 2);
void util_set_quiet(bool quiet);
/* Writes s with its control characters escaped (\xNN; the C1 controls U+0080..U+009F as
 * \uNNNN): for text from files or the command line printed to a terminal. Every message of
 * util_error, util_warn and util_info goes through it. */
void util_fputs_safe(const char *s, FILE *f);
/* The same into buf (cap bytes, cut short where it does not fit); returns buf. */
const char *util_escape(const char *s, char *buf, size_t cap);
/* No errors or warnings either (warnings still counted): for the fuzz targets only, where
 * printing them is most of the time spent. */
void util_set_silent(bool silent);
bool util_quiet(void);
/* Number of warnings printed so far (tests and the CLI summary use it). */
int util_warning_count(void);
/* --strict: a warning (and a util_fallback) is printed as an error, and still counted, so
 * that the command refuses to write anything once it sees the count grow (cli_strict_ok). */
void util_set_strict(bool strict);
bool util_strict(void);
/* A fallback the program chose for the file (a light added where its own leaves the view
 * dark): an informational line (util_info), which --strict makes an error as it does warnings. */
void util_fallback(const char *fmt, ...) UTIL_PRINTF(1, 2);

/* Monotonic seconds. */
double util_now(void);

/* malloc/calloc/realloc that stop the program with a message when memory runs out. */
void *util_malloc(size_t size);
void *util_calloc(size_t count, size_t size);
void *util_realloc(void *ptr, size_t size);

/* Strict number parsing: the whole string must be a decimal number in range, as typed: no
 * leading space, no '+', no hexadecimal; false otherwise. */
bool util_parse_int(const char *s, long min, long max, long *out);
bool util_parse_float(const char *s, float *out);
/* "R,G,B" or one value V (= V,V,V), each finite and >= 0: a colour or a radiance. */
bool util_parse_rgb(const char *s, float out[3]);
/* "WxH" -> width, height (each 1..UTIL_SIZE_MAX). */
#define UTIL_SIZE_MAX 16384
bool util_parse_size(const char *s, int *w, int *h);
/* names[0..n) joined by ", " into buf (cut short at cap); returns buf. */
const char *util_join(char *buf, size_t cap, const char *const *names, int n);
/* A macro's value as a string literal: UTIL_STRING(UTIL_SIZE_MAX) is "16384". */
#define UTIL_STRING(x) UTIL_STRING_(x)
#define UTIL_STRING_(x) #x

/* Inputs: only regular files are read. A FIFO, a device, a directory or a socket is refused
 * with an error naming the path, without blocking (a FIFO with no writer would otherwise
 * wait forever). util_open_read gives a descriptor (-1 on failure), util_fopen_read a
 * stream, util_read_file the whole file (NULL on failure); each reports its error. */
int util_open_read(const char *path);
FILE *util_fopen_read(const char *path);
void *util_read_file(const char *path, size_t *size);

/* Writing an output file safely. util_out_open creates a new temporary file
 * "DIR/.NAME.tmp-PID-XXXXXX" (XXXXXX random) beside the destination, exclusively (O_EXCL:
 * never through a link or a file someone made there); the writer writes through its
 * descriptor (o->fd) or util_out_file's stream; util_out_commit gives a replaced file's
 * mode and owner to the new one through the descriptor, and renames the temporary file into
 * place only if it is still the file gonio created (else nothing is written), or removes it
 * when ok is false. A failed or interrupted write therefore never leaves a half-written
 * output, and no name another process controls is ever written through.
 *
 * What an output path may be (every command checks with util_check_output before any work,
 * and util_out_commit checks again): a new name, or a regular file that may be written,
 * which is replaced and keeps its mode (and owner, where the writer may give it). Refused
 * with an error naming the path: an empty name, a path too long for its temporary name, a
 * missing or unwritable folder, a directory, a symbolic link, a device (/dev/null), FIFO or
 * socket, a read-only file (for root too). util_check_output also removes the temporary
 * files of this name that a killed gonio of this user left behind (their process no longer
 * exists). */
typedef struct util_out {
    char tmp[4096];    /* the temporary file */
    const char *path;  /* the destination */
    int fd;            /* open on tmp (util_out_file's stream owns it once made) */
    FILE *file;        /* util_out_file's stream, or NULL */
    uint64_t dev, ino; /* the temporary file's identity */
} util_out;
bool util_check_output(const char *path);
bool util_out_open(util_out *o, const char *path);
FILE *util_out_file(util_out *o);
bool util_out_commit(util_out *o, bool ok);
/* Whether s ends in suffix, ignoring case (file extensions). */
bool util_has_suffix(const char *s, const char *suffix);
/* Removes the temporary file of a write under way (async-signal-safe: for a handler that
 * ends the program at once). */
void util_remove_pending_tmp(void);

#endif
