/* fuzz_common.h: what the libFuzzer targets share. The loaders take a path (one code path
 * for real loads and fuzzing), so each input is written to a file in a private folder,
 * on /dev/shm when there is one. */
#ifndef GONIO_FUZZ_COMMON_H
#define GONIO_FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util.h"

/* The path of file NAME in this process's folder, made once. Four names at a time (each
 * call's path stays valid for the next three calls). */
static const char *fuzz_input_path(const char *name)
{
    static char dir[128], paths[4][256];
    static int next;
    char *path = paths[next++ & 3];
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "%s/gonio-fuzz-XXXXXX", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
        if (!mkdtemp(dir)) {
            perror("gonio fuzz: mkdtemp");
            abort();
        }
    }
    snprintf(path, sizeof paths[0], "%s/%s", dir, name);
    return path;
}

static const char *fuzz_write_input(const char *name, const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
        perror("gonio fuzz: writing the input");
        abort();
    }
    return path;
}

#endif
