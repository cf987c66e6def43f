/* test_util.c: writing outputs and reading inputs safely (src/core/util.h), against another
 * process that plays with the output folder between gonio's steps. */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "test.h"
#include "util.h"

static char *scratch(char *dir)
{
    strcpy(dir, "/tmp/gonio-util-XXXXXX");
    return mkdtemp(dir);
}

static char *file_text(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(buf, 1, cap - 1, f) : 0;
    buf[n] = 0;
    if (f)
        fclose(f);
    return buf;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    fputs(text, f);
    fclose(f);
}

/* The ordinary case: the temporary file is new, beside the output, renamed onto it. */
TEST(util, out_writes_and_renames)
{
    char dir[64], path[128], buf[64];
    util_out o;
    struct stat st;
    if (!scratch(dir)) {
        CHECK(false);
        return;
    }
    snprintf(path, sizeof path, "%s/a.txt", dir);
    CHECK(util_out_open(&o, path));
    CHECK(!strncmp(o.tmp, dir, strlen(dir)) && strstr(o.tmp, "/.a.txt.tmp-") != NULL);
    CHECK(lstat(o.tmp, &st) == 0 && S_ISREG(st.st_mode) && st.st_size == 0);
    CHECK(write(o.fd, "hello", 5) == 5);
    CHECK(util_out_commit(&o, true));
    CHECK(!strcmp(file_text(path, buf, sizeof buf), "hello"));
    CHECK(lstat(o.tmp, &st) != 0);
    /* A failed write leaves neither the output nor the temporary file. */
    snprintf(path, sizeof path, "%s/b.txt", dir);
    CHECK(util_out_open(&o, path));
    CHECK(!util_out_commit(&o, false));
    CHECK(lstat(path, &st) != 0 && lstat(o.tmp, &st) != 0);
    snprintf(path, sizeof path, "%s/a.txt", dir);
    unlink(path);
    rmdir(dir);
}

/* Another process renames a link to a victim onto the temporary name after gonio made it:
 * gonio must not rename the link onto the output, nor change the victim's mode. */
TEST(util, out_refuses_a_swapped_temporary_file)
{
    char dir[64], path[128], victim[128], link[160], buf[64];
    util_out o;
    struct stat st;
    if (!scratch(dir)) {
        CHECK(false);
        return;
    }
    snprintf(path, sizeof path, "%s/out.exr", dir);
    snprintf(victim, sizeof victim, "%s/victim", dir);
    snprintf(link, sizeof link, "%s/link", dir);
    write_text(victim, "precious");
    chmod(victim, 0600);
    write_text(path, "old");
    chmod(path, 0644);
    CHECK(util_out_open(&o, path));
    CHECK(write(o.fd, "new", 3) == 3);
    CHECK(symlink(victim, link) == 0);
    CHECK(rename(link, o.tmp) == 0); /* the swap */
    util_set_silent(true);
    CHECK(!util_out_commit(&o, true));
    util_set_silent(false);
    CHECK(!strcmp(file_text(victim, buf, sizeof buf), "precious"));
    CHECK(stat(victim, &st) == 0 && (st.st_mode & 07777) == 0600);
    CHECK(lstat(path, &st) == 0 && S_ISREG(st.st_mode) && !strcmp(file_text(path, buf, sizeof buf), "old"));
    unlink(o.tmp);
    unlink(path);
    unlink(victim);
    rmdir(dir);
}

/* A replaced output keeps its mode; a new one gets the umask's, as the shell's > gives. */
TEST(util, out_modes)
{
    char dir[64], path[128];
    util_out o;
    struct stat st;
    mode_t old = umask(027);
    if (!scratch(dir)) {
        CHECK(false);
        umask(old);
        return;
    }
    snprintf(path, sizeof path, "%s/new", dir);
    CHECK(util_out_open(&o, path) && util_out_commit(&o, true));
    CHECK(stat(path, &st) == 0 && (st.st_mode & 07777) == 0640);
    chmod(path, 0604);
    CHECK(util_out_open(&o, path) && util_out_commit(&o, true));
    CHECK(stat(path, &st) == 0 && (st.st_mode & 07777) == 0604);
    umask(old);
    unlink(path);
    rmdir(dir);
}

/* A FIFO is refused at once, not waited on (an alarm turns a hang into a failure). */
TEST(util, read_refuses_a_fifo)
{
    char dir[64], path[128];
    size_t size;
    if (!scratch(dir)) {
        CHECK(false);
        return;
    }
    snprintf(path, sizeof path, "%s/fifo", dir);
    CHECK(mkfifo(path, 0600) == 0);
    alarm(10);
    util_set_silent(true);
    CHECK(util_read_file(path, &size) == NULL);
    CHECK(util_open_read(path) < 0);
    CHECK(util_open_read(dir) < 0);
    util_set_silent(false);
    alarm(0);
    unlink(path);
    rmdir(dir);
}

TEST(util, escape)
{
    char buf[64];
    CHECK(!strcmp(util_escape("a\x1b[2Jb\n", buf, sizeof buf), "a\\x1b[2Jb\\x0a"));
    CHECK(!strcmp(util_escape("\xc2\x9b" "1m \xc3\xa9", buf, sizeof buf), "\\u009b1m \xc3\xa9")); /* C1 CSI; e-acute kept */
    CHECK(!strcmp(util_escape("\x7f", buf, 4), "")); /* "\x7f" does not fit in 4 bytes: cut */
}
