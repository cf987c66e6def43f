/* fuzz_common.h: what both libFuzzer targets share. The loaders take a path (one code path
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

/* The path of the input file for this process: DIR/NAME in a folder made once. */
static const char *fuzz_input_path(const char *name)
{
    static char path[256];
    if (!path[0]) {
        char dir[128];
        snprintf(dir, sizeof dir, "%s/gonio-fuzz-XXXXXX", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
        if (!mkdtemp(dir)) {
            perror("gonio fuzz: mkdtemp");
            abort();
        }
        snprintf(path, sizeof path, "%s/%s", dir, name);
    }
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
