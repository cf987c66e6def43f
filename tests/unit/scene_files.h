/* scene_files.h: what the scene loader's tests (test_scene.c, test_skin.c) share to write the
 * glTF files they load: a buffer as base64 text for a data: URI, and scene_load with its
 * messages (stderr) captured in load_log, to be printed only where a check fails. */
#ifndef GONIO_TEST_SCENE_FILES_H
#define GONIO_TEST_SCENE_FILES_H

#include <stdio.h>
#include <unistd.h>

#include "scene.h"
#include "util.h"

/* `n` bytes as base64 (A-Z a-z 0-9 + /, padded with '='), NUL-terminated; the caller frees it. */
static inline char *base64(const void *data, size_t n)
{
    static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const unsigned char *p = data;
    char *out = util_malloc(4 * ((n + 2) / 3) + 1), *o = out;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)p[i] << 16 | (i + 1 < n ? (unsigned)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        *o++ = tab[v >> 18 & 63];
        *o++ = tab[v >> 12 & 63];
        *o++ = i + 1 < n ? tab[v >> 6 & 63] : '=';
        *o++ = i + 2 < n ? tab[v & 63] : '=';
    }
    *o = 0;
    return out;
}

static char load_log[16384];

/* scene_load with its messages captured in load_log. */
static inline bool load(scene *s, const char *path)
{
    FILE *tmp = tmpfile();
    int saved = dup(2);
    fflush(stderr);
    dup2(fileno(tmp), 2);
    bool ok = scene_load(s, path);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rewind(tmp);
    size_t n = fread(load_log, 1, sizeof load_log - 1, tmp);
    load_log[n] = 0;
    fclose(tmp);
    return ok;
}

#endif
