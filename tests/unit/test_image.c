/* test_image.c: EXR/PNG input and output, sRGB conversion, image metrics, `gonio diff` and the
 * draw canvas. Reference files are written with OpenEXR's C API directly (half, uint, tiled),
 * reference numbers are computed by hand or with an independent formula. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "draw.h"
#include "image.h"
#include "test.h"
#include "util.h"

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <openexr.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- helpers --------------------------------------------------------------------------- */

static void make_dir(char *dir)
{
    strcpy(dir, "/tmp/gonio-image-XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        exit(1);
    }
}

static int dir_count(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    if (!d)
        return -1;
    while ((e = readdir(d)))
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

static void remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char path[512];
    if (!d)
        return;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (unlink(path) != 0)
            rmdir(path);
    }
    closedir(d);
    rmdir(dir);
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    CHECK(f && fwrite(data, 1, n, f) == n);
    if (f)
        fclose(f);
}

/* Redirects a stream (stdout or stderr) into a file until capture_end. */
typedef struct capture {
    FILE *stream;
    int saved_fd;
    char path[64];
} capture;

static void capture_begin(capture *c, FILE *stream)
{
    int fd;
    c->stream = stream;
    strcpy(c->path, "/tmp/gonio-capture-XXXXXX");
    fd = mkstemp(c->path);
    fflush(stream);
    c->saved_fd = dup(fileno(stream));
    dup2(fd, fileno(stream));
    close(fd);
}

static void capture_end(capture *c, char *buf, size_t cap)
{
    size_t n = 0;
    FILE *f;
    fflush(c->stream);
    dup2(c->saved_fd, fileno(c->stream));
    close(c->saved_fd);
    f = fopen(c->path, "rb");
    if (f) {
        n = fread(buf, 1, cap - 1, f);
        fclose(f);
    }
    buf[n] = 0;
    unlink(c->path);
}

/* Exact float -> half bits for values a half represents exactly (zero and normal halves). */
static uint16_t half_bits(float f)
{
    uint32_t u, e, sign;
    memcpy(&u, &f, sizeof u);
    sign = (u >> 16) & 0x8000u;
    e = (u >> 23) & 0xffu;
    if (e == 0)
        return (uint16_t)sign;
    CHECK(e >= 113 && e <= 142 && (u & 0x1fffu) == 0);
    return (uint16_t)(sign | ((e - 112) << 10) | ((u & 0x7fffffu) >> 13));
}

typedef struct raw_channel {
    const char *name;
    exr_pixel_type_t type;
    const void *data; /* w * h values of type: uint16_t half bits, float or uint32_t */
} raw_channel;

/* Writes an EXR with OpenEXR's C API directly, independently of image_write_exr: scanline or
 * tiled (tw x th, one level), any pixel types, the data window's top-left at (ox, oy), plus a
 * float attribute "exposure" = 1.5. */
static void write_raw_exr(const char *path, exr_storage_t storage, exr_compression_t comp, int ox, int oy, int w,
                          int h, int tw, int th, const raw_channel *ch, int n)
{
    const exr_attr_box2i_t dw = {.min = {.x = ox, .y = oy}, .max = {.x = ox + w - 1, .y = oy + h - 1}};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_context_t ctx;
    int part, lines = 1, nx = 1, ny;
    bool first = true;
    CHECK(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init) == 0);
    CHECK(exr_add_part(ctx, "raw", storage, &part) == 0);
    CHECK(exr_initialize_required_attr_simple(ctx, part, w, h, comp) == 0);
    CHECK(exr_set_data_window(ctx, part, &dw) == 0);
    if (storage == EXR_STORAGE_TILED)
        CHECK(exr_set_tile_descriptor(ctx, part, (uint32_t)tw, (uint32_t)th, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN) == 0);
    for (int c = 0; c < n; c++)
        CHECK(exr_add_channel(ctx, part, ch[c].name, ch[c].type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1) == 0);
    CHECK(exr_attr_set_float(ctx, part, "exposure", 1.5f) == 0);
    CHECK(exr_write_header(ctx) == 0);
    if (storage == EXR_STORAGE_TILED) {
        nx = (w + tw - 1) / tw;
        ny = (h + th - 1) / th;
    } else {
        CHECK(exr_get_scanlines_per_chunk(ctx, part, &lines) == 0);
        ny = (h + lines - 1) / lines;
    }
    for (int ty = 0; ty < ny; ty++) {
        for (int tx = 0; tx < nx; tx++) {
            exr_chunk_info_t ci;
            int x0 = storage == EXR_STORAGE_TILED ? tx * tw : 0;
            int y0 = storage == EXR_STORAGE_TILED ? ty * th : ty * lines;
            if (storage == EXR_STORAGE_TILED)
                CHECK(exr_write_tile_chunk_info(ctx, part, tx, ty, 0, 0, &ci) == 0);
            else
                CHECK(exr_write_scanline_chunk_info(ctx, part, oy + y0, &ci) == 0);
            CHECK((first ? exr_encoding_initialize(ctx, part, &ci, &enc) : exr_encoding_update(ctx, part, &ci, &enc)) == 0);
            for (int k = 0; k < enc.channel_count; k++) {
                exr_coding_channel_info_t *e = &enc.channels[k];
                int c = 0, size;
                while (strcmp(ch[c].name, e->channel_name) != 0)
                    c++;
                size = ch[c].type == EXR_PIXEL_HALF ? 2 : 4;
                e->encode_from_ptr = (const uint8_t *)ch[c].data + ((size_t)y0 * (size_t)w + (size_t)x0) * (size_t)size;
                e->user_pixel_stride = size;
                e->user_line_stride = size * w;
                e->user_bytes_per_element = (int16_t)size;
                e->user_data_type = (uint16_t)ch[c].type;
            }
            if (first)
                CHECK(exr_encoding_choose_default_routines(ctx, part, &enc) == 0);
            first = false;
            CHECK(exr_encoding_run(ctx, part, &enc) == 0);
        }
    }
    exr_encoding_destroy(ctx, &enc);
    CHECK(exr_finish(&ctx) == 0);
}

/* ---- EXR --------------------------------------------------------------------------------- */

TEST(image, exr_roundtrip)
{
    /* 19 rows: two ZIP chunks of 16 lines. Names given unsorted; EXR sorts them. */
    static const char *const names[5] = {"R", "G", "B", "normal.X", "A"};
    static const char *const sorted[5] = {"A", "B", "G", "R", "normal.X"};
    const int w = 5, h = 19;
    const image_attr attrs[3] = {
        {.name = "gonio:scene", .type = IMAGE_ATTR_STRING, .s = "scenes/cornell.gltf"},
        {.name = "gonio:spp", .type = IMAGE_ATTR_INT, .i = -64},
        {.name = "gonio:seconds", .type = IMAGE_ATTR_DOUBLE, .d = 0.1},
    };
    char dir[64], path[128], s[64];
    image img, back;
    double d;
    exr_context_t ctx;
    exr_compression_t comp;
    const exr_attr_chlist_t *chl;
    exr_attr_box2i_t dw;
    exr_storage_t storage;
    uint32_t seed = 12345;

    make_dir(dir);
    snprintf(path, sizeof path, "%s/round.exr", dir);
    image_create(&img, w, h, 5, names);
    for (int c = 0; c < 5; c++) {
        for (int i = 0; i < w * h; i++) {
            uint32_t bits;
            seed = seed * 1664525u + 1013904223u;
            bits = seed & 0xbfffffffu; /* any sign, mantissa, exponent below 128: finite */
            memcpy(&img.planes[c][i], &bits, sizeof bits);
        }
    }
    img.planes[0][0] = -0.0f;
    img.planes[1][1] = 1e-42f; /* denormal */
    CHECK(image_write_exr(&img, path, attrs, 3));
    CHECK(dir_count(dir) == 1);

    CHECK(image_read_exr(&back, path));
    CHECK(back.width == w && back.height == h && back.num_channels == 5);
    for (int c = 0; c < back.num_channels; c++)
        CHECKF(strcmp(back.names[c], sorted[c]) == 0, "channel %d is '%s'", c, back.names[c]);
    for (int c = 0; c < 5; c++) {
        int k = image_channel(&back, names[c]);
        CHECK(k >= 0);
        if (k >= 0)
            CHECKF(memcmp(back.planes[k], img.planes[c], sizeof(float) * (size_t)(w * h)) == 0, "channel %s", names[c]);
    }
    CHECK(image_channel(&back, "normal.Y") == -1);

    CHECK(image_exr_attr_string(path, "gonio:scene", s, sizeof s) && strcmp(s, "scenes/cornell.gltf") == 0);
    CHECK(image_exr_attr_string(path, "gonio:scene", s, 7) && strcmp(s, "scenes") == 0);
    CHECK(image_exr_attr_double(path, "gonio:spp", &d) && d == -64);
    CHECK(image_exr_attr_double(path, "gonio:seconds", &d) && d == 0.1); /* double, not float */
    CHECK(!image_exr_attr_double(path, "gonio:missing", &d));
    CHECK(!image_exr_attr_double(path, "gonio:scene", &d));
    CHECK(!image_exr_attr_string(path, "gonio:spp", s, sizeof s));

    /* What the file holds, read through the library rather than image_read_exr. */
    CHECK(exr_start_read(&ctx, path, NULL) == 0);
    CHECK(exr_get_storage(ctx, 0, &storage) == 0 && storage == EXR_STORAGE_SCANLINE);
    CHECK(exr_get_compression(ctx, 0, &comp) == 0 && comp == EXR_COMPRESSION_ZIP);
    CHECK(exr_get_data_window(ctx, 0, &dw) == 0 && dw.min.x == 0 && dw.min.y == 0 && dw.max.x == w - 1 &&
          dw.max.y == h - 1);
    CHECK(exr_get_channels(ctx, 0, &chl) == 0 && chl->num_channels == 5);
    for (int c = 0; c < chl->num_channels; c++)
        CHECK(chl->entries[c].pixel_type == EXR_PIXEL_FLOAT);
    exr_finish(&ctx);

    image_destroy(&back);
    image_destroy(&img);
    remove_dir(dir);
}

TEST(image, exr_half)
{
    /* Distinct values per channel and pixel, all exact in half precision; data windows not at
     * the origin are read relative to their top-left corner. */
    enum { W = 7, H = 5 };
    uint16_t r[W * H], g[W * H], b[W * H];
    raw_channel ch[3] = {{"R", EXR_PIXEL_HALF, r}, {"G", EXR_PIXEL_HALF, g}, {"B", EXR_PIXEL_HALF, b}};
    static const exr_compression_t comps[3] = {EXR_COMPRESSION_NONE, EXR_COMPRESSION_ZIP, EXR_COMPRESSION_PIZ};
    char dir[64], path[128];
    image img;
    double d;

    make_dir(dir);
    snprintf(path, sizeof path, "%s/half.exr", dir);
    for (int i = 0; i < W * H; i++) {
        r[i] = half_bits(0.5f + 0.25f * (float)i);
        g[i] = half_bits(-(1.0f + 0.25f * (float)i));
        b[i] = half_bits(100.0f + 0.25f * (float)i);
    }
    CHECK(r[0] == 0x3800 && g[0] == 0xbc00); /* 0.5 and -1 by the IEEE 754 half layout */
    for (int k = 0; k < 3; k++) {
        write_raw_exr(path, EXR_STORAGE_SCANLINE, comps[k], -3 * k, 10 * k, W, H, 0, 0, ch, 3);
        CHECK(image_read_exr(&img, path));
        CHECK(img.width == W && img.height == H && img.num_channels == 3);
        if (img.num_channels == 3) {
            int cr = image_channel(&img, "R"), cg = image_channel(&img, "G"), cb = image_channel(&img, "B");
            for (int i = 0; i < W * H; i++) {
                CHECKF(img.planes[cr][i] == 0.5f + 0.25f * (float)i, "R[%d] = %g (compression %d)", i,
                       img.planes[cr][i], comps[k]);
                CHECKF(img.planes[cg][i] == -(1.0f + 0.25f * (float)i), "G[%d] = %g", i, img.planes[cg][i]);
                CHECKF(img.planes[cb][i] == 100.0f + 0.25f * (float)i, "B[%d] = %g", i, img.planes[cb][i]);
            }
        }
        image_destroy(&img);
    }
    CHECK(image_exr_attr_double(path, "exposure", &d) && d == 1.5); /* a float attribute */
    remove_dir(dir);
}

TEST(image, exr_tiled)
{
    /* 7x5 in 3x2 tiles: partial tiles on the right and bottom; float, uint and half channels. */
    enum { W = 7, H = 5 };
    float y[W * H];
    uint32_t id[W * H];
    uint16_t z[W * H];
    raw_channel ch[3] = {{"Y", EXR_PIXEL_FLOAT, y}, {"id", EXR_PIXEL_UINT, id}, {"Z", EXR_PIXEL_HALF, z}};
    static const exr_compression_t comps[3] = {EXR_COMPRESSION_NONE, EXR_COMPRESSION_ZIP, EXR_COMPRESSION_RLE};
    char dir[64], path[128];
    image img;

    make_dir(dir);
    snprintf(path, sizeof path, "%s/tiled.exr", dir);
    for (int i = 0; i < W * H; i++) {
        y[i] = 0.5f * (float)i - 3.0f;
        id[i] = 1000u * (uint32_t)i + 7u;
        z[i] = half_bits(0.25f * (float)(i + 1));
    }
    for (int k = 0; k < 3; k++) {
        write_raw_exr(path, EXR_STORAGE_TILED, comps[k], 5 * k, -k, W, H, 3, 2, ch, 3);
        CHECK(image_read_exr(&img, path));
        CHECK(img.width == W && img.height == H && img.num_channels == 3);
        if (img.num_channels == 3) {
            int cy = image_channel(&img, "Y"), ci = image_channel(&img, "id"), cz = image_channel(&img, "Z");
            CHECK(cy >= 0 && ci >= 0 && cz >= 0);
            for (int i = 0; cy >= 0 && ci >= 0 && cz >= 0 && i < W * H; i++) {
                CHECKF(img.planes[cy][i] == 0.5f * (float)i - 3.0f, "Y[%d] = %g (compression %d)", i,
                       img.planes[cy][i], comps[k]);
                CHECKF(img.planes[ci][i] == (float)(1000 * i + 7), "id[%d] = %g", i, img.planes[ci][i]);
                CHECKF(img.planes[cz][i] == 0.25f * (float)(i + 1), "Z[%d] = %g", i, img.planes[cz][i]);
            }
        }
        image_destroy(&img);
    }
    remove_dir(dir);
}

/* A read that must fail: false, a zeroed image, and a message that names the file. */
static void check_read_fails(const char *path, const char *why)
{
    capture cap;
    char msg[2048];
    image img;
    bool ok;
    memset(&img, 0xab, sizeof img);
    capture_begin(&cap, stderr);
    ok = image_read_exr(&img, path);
    capture_end(&cap, msg, sizeof msg);
    CHECKF(!ok, "%s: read succeeded", why);
    CHECKF(strstr(msg, path) != NULL, "%s: message does not name the file: %s", why, msg);
    CHECKF(img.num_channels == 0 && img.planes[0] == NULL, "%s: image not zeroed", why);
    if (ok)
        image_destroy(&img);
}

TEST(image, exr_bad_files)
{
    static const char *const names[3] = {"R", "G", "B"};
    char dir[64], good[128], bad[128], msg[256];
    unsigned char *data, *copy;
    size_t size;
    image img;
    int survived = 0;
    uint32_t seed = 99;

    make_dir(dir);
    snprintf(good, sizeof good, "%s/good.exr", dir);
    snprintf(bad, sizeof bad, "%s/bad.exr", dir);
    image_create(&img, 4, 20, 3, names);
    for (int i = 0; i < 80; i++)
        img.planes[0][i] = img.planes[1][i] = img.planes[2][i] = (float)i * 0.37f;
    CHECK(image_write_exr(&img, good, NULL, 0));
    image_destroy(&img);

    check_read_fails("/nonexistent-dir/missing.exr", "missing file");
    write_bytes(bad, "", 0);
    check_read_fails(bad, "empty file");
    write_bytes(bad, "P3\n1 1\n255\n0 0 0\n", 17);
    check_read_fails(bad, "not an EXR");
    check_read_fails(dir, "a directory");

    data = util_read_file(good, &size);
    CHECK(data && size > 100);
    if (!data) {
        remove_dir(dir);
        return;
    }
    /* Every truncation fails cleanly. */
    for (size_t n = 0; n < size; n += 1 + (n > 40) * 6) {
        write_bytes(bad, data, n);
        snprintf(msg, sizeof msg, "truncated to %zu of %zu bytes", n, size);
        check_read_fails(bad, msg);
    }
    /* The magic number followed by garbage. */
    copy = util_malloc(size);
    for (size_t i = 4; i < size; i++)
        copy[i] = (unsigned char)(seed = seed * 1664525u + 1013904223u) >> 24;
    memcpy(copy, data, 4);
    write_bytes(bad, copy, size);
    check_read_fails(bad, "garbage after the magic number");
    /* Corrupted bytes anywhere: no crash or leak (ASan), and a failure names the file. */
    for (size_t i = 0; i < size; i += 3) {
        capture cap;
        bool ok;
        memcpy(copy, data, size);
        copy[i] ^= (unsigned char)(0x55 + i);
        write_bytes(bad, copy, size);
        capture_begin(&cap, stderr);
        ok = image_read_exr(&img, bad);
        capture_end(&cap, msg, sizeof msg);
        CHECKF(ok || strstr(msg, bad), "byte %zu: %s", i, msg);
        survived += ok;
        if (ok)
            image_destroy(&img);
    }
    CHECK(survived < (int)size / 3); /* most corruptions are detected */
    free(copy);
    free(data);
    remove_dir(dir);
}

/* Writing img to path (PNG or EXR) fails with a message naming path and leaves `files`
 * entries in dir (the temporary file gone). */
static bool write_fails(const image *img, const char *path, bool png, const char *dir, int files)
{
    char msg[1024];
    capture cap;
    capture_begin(&cap, stderr);
    bool ok = png ? image_write_png_from(img, path, 0, IMAGE_TONEMAP_CLAMP) : image_write_exr(img, path, NULL, 0);
    capture_end(&cap, msg, sizeof msg);
    return !ok && strstr(msg, path) && dir_count(dir) == files;
}

TEST(image, exr_write_fails)
{
    static const char *const names[1] = {"Y"};
    char dir[64], path[256], ro[128];
    image img;

    make_dir(dir);
    image_create(&img, 3, 3, 1, names);

    snprintf(path, sizeof path, "%s/missing/out.exr", dir);
    CHECK(write_fails(&img, path, false, dir, 0));

    /* The parent is a regular file: fails even for root. */
    snprintf(path, sizeof path, "%s/file", dir);
    write_bytes(path, "x", 1);
    snprintf(path, sizeof path, "%s/file/out.exr", dir);
    CHECK(write_fails(&img, path, false, dir, 1));

    /* The destination is a directory: the rename fails and the temporary file goes. */
    snprintf(path, sizeof path, "%s/isdir.exr", dir);
    CHECK(mkdir(path, 0755) == 0);
    CHECK(write_fails(&img, path, false, dir, 2));

    /* A read-only directory (root writes anyway, so only checked for other users). */
    snprintf(ro, sizeof ro, "%s/ro", dir);
    CHECK(mkdir(ro, 0555) == 0);
    if (geteuid() != 0) {
        snprintf(path, sizeof path, "%s/out.exr", ro);
        CHECK(write_fails(&img, path, false, ro, 0));
        snprintf(path, sizeof path, "%s/out.png", ro);
        CHECK(write_fails(&img, path, true, ro, 0));
    }

    snprintf(path, sizeof path, "%s/missing/out.png", dir);
    CHECK(write_fails(&img, path, true, dir, 3));

    image_destroy(&img);
    image_destroy(&img); /* destroy of a zeroed image is fine */
    remove_dir(ro);
    snprintf(path, sizeof path, "%s/isdir.exr", dir);
    rmdir(path);
    remove_dir(dir);
}

/* ---- sRGB and PNG ------------------------------------------------------------------------ */

static uint8_t to8(float v, float exposure, image_tonemap tm)
{
    uint8_t out[4];
    image_to_srgb8(&v, &v, &v, 1, 1, exposure, tm, out);
    CHECK(out[0] == out[1] && out[1] == out[2] && out[3] == 255);
    return out[0];
}

TEST(image, srgb)
{
    /* Reference bytes: round(255 * OETF(x)) with OETF(x) = 12.92 x (x <= 0.0031308), else
     * 1.055 x^(1/2.4) - 0.055, worked out separately. 0.002 is on the linear branch (the power
     * branch would give 6); 0.01 on the power branch (the linear one would give 33). */
    static const struct { float in; uint8_t out; } clamp[] = {
        {0.0f, 0}, {1.0f, 255}, {0.5f, 188}, {0.18f, 118}, {0.0031308f, 10}, {0.002f, 7}, {0.01f, 25},
        {7.0f, 255}, {-0.5f, 0}, {NAN, 0}, {-INFINITY, 0}, {INFINITY, 255},
    };
    for (size_t i = 0; i < sizeof clamp / sizeof clamp[0]; i++)
        CHECKF(to8(clamp[i].in, 0, IMAGE_TONEMAP_CLAMP) == clamp[i].out, "%g -> %d, want %d", clamp[i].in,
               to8(clamp[i].in, 0, IMAGE_TONEMAP_CLAMP), clamp[i].out);
    CHECK(to8(0.25f, 1, IMAGE_TONEMAP_CLAMP) == 188);  /* 2^1 * 0.25 = 0.5 */
    CHECK(to8(2.0f, -2, IMAGE_TONEMAP_CLAMP) == 188);  /* 2^-2 * 2 = 0.5 */
    CHECK(to8(1.0f, 0, IMAGE_TONEMAP_REINHARD) == 188); /* 1 / (1 + 1) = 0.5 */
    CHECK(to8(3.0f, 0, IMAGE_TONEMAP_REINHARD) == 225); /* 0.75 */
    CHECK(to8(INFINITY, 0, IMAGE_TONEMAP_REINHARD) == 255);
    CHECK(to8(1.0f, 0, IMAGE_TONEMAP_ACES) == 232);     /* 2.54 / 3.16 */
    CHECK(to8(0.18f, 0, IMAGE_TONEMAP_ACES) == 141);
    CHECK(to8(1e6f, 0, IMAGE_TONEMAP_ACES) == 255);
    CHECK(to8(NAN, 0, IMAGE_TONEMAP_ACES) == 0 && to8(-1, 0, IMAGE_TONEMAP_REINHARD) == 0);
    {
        float r[2] = {1, 0}, g[2] = {0, 0.5f}, b[2] = {0.5f, 1};
        uint8_t out[8];
        image_to_srgb8(r, g, b, 2, 1, 0, IMAGE_TONEMAP_CLAMP, out);
        CHECK(out[0] == 255 && out[1] == 0 && out[2] == 188 && out[3] == 255);
        CHECK(out[4] == 0 && out[5] == 188 && out[6] == 255 && out[7] == 255);
    }
}

TEST(image, png)
{
    static const char *const grey[1] = {"Y"};
    static const char *const rgba_names[4] = {"A", "B", "G", "R"};
    uint8_t px[3 * 2 * 4], *back = NULL;
    char dir[64], path[128], msg[1024];
    unsigned char *bytes;
    size_t size;
    int w = 0, h = 0;
    image img;
    capture cap;
    bool ok;

    make_dir(dir);
    snprintf(path, sizeof path, "%s/a.png", dir);
    for (int i = 0; i < (int)sizeof px; i++)
        px[i] = (uint8_t)(i * 37 + 11);
    CHECK(image_write_png(path, px, 3, 2));
    CHECK(dir_count(dir) == 1);
    bytes = util_read_file(path, &size);
    CHECK(bytes && size > 8 && memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0);
    free(bytes);
    CHECK(image_read_png(path, &back, &w, &h));
    CHECK(w == 3 && h == 2 && back && memcmp(back, px, sizeof px) == 0);
    free(back);

    /* One channel -> grey; R, G, B found by name whatever their order. */
    image_create(&img, 2, 1, 1, grey);
    img.planes[0][0] = 0.5f;
    img.planes[0][1] = 1.0f;
    CHECK(image_write_png_from(&img, path, 0, IMAGE_TONEMAP_CLAMP));
    image_destroy(&img);
    CHECK(image_read_png(path, &back, &w, &h));
    CHECK(w == 2 && h == 1 && back && back[0] == 188 && back[1] == 188 && back[2] == 188 && back[3] == 255 &&
          back[4] == 255 && back[7] == 255);
    free(back);
    image_create(&img, 1, 1, 4, rgba_names);
    img.planes[image_channel(&img, "R")][0] = 1.0f;
    img.planes[image_channel(&img, "G")][0] = 0.5f;
    img.planes[image_channel(&img, "B")][0] = 0.0f;
    img.planes[image_channel(&img, "A")][0] = 0.25f;
    CHECK(image_write_png_from(&img, path, 0, IMAGE_TONEMAP_CLAMP));
    image_destroy(&img);
    CHECK(image_read_png(path, &back, &w, &h));
    CHECK(back && back[0] == 255 && back[1] == 188 && back[2] == 0 && back[3] == 255);
    free(back);

    snprintf(path, sizeof path, "%s/missing.png", dir);
    capture_begin(&cap, stderr);
    ok = image_read_png(path, &back, &w, &h);
    capture_end(&cap, msg, sizeof msg);
    CHECK(!ok && back == NULL && strstr(msg, path));
    snprintf(path, sizeof path, "%s/text.png", dir);
    write_bytes(path, "not a png at all", 16);
    capture_begin(&cap, stderr);
    ok = image_read_png(path, &back, &w, &h);
    capture_end(&cap, msg, sizeof msg);
    CHECK(!ok && back == NULL && strstr(msg, path));
    remove_dir(dir);
}

/* ---- metrics ----------------------------------------------------------------------------- */

static void fill(image *img, const float *v)
{
    for (int c = 0; c < img->num_channels; c++)
        memcpy(img->planes[c], v + c * img->width * img->height, sizeof(float) * (size_t)(img->width * img->height));
}

static bool near(double a, double b) { return fabs(a - b) <= 1e-9 * fmax(1, fabs(b)); }

TEST(image, metrics)
{
    static const char *const y[1] = {"Y"}, *const z[1] = {"Z"}, *const rgb[3] = {"R", "G", "B"};
    static const char *const rgbaz[5] = {"A", "B", "G", "R", "Z"}, *const r_only[1] = {"R"};
    image a, b, c;
    image_metrics m;
    capture cap;
    char msg[512];
    bool ok;

    /* Single channels (different names: first channel of each). a - b = 0, 0, -1, 2. */
    image_create(&a, 2, 2, 1, y);
    image_create(&b, 2, 2, 1, z);
    fill(&a, (const float[]){1, 2, 3, 5});
    fill(&b, (const float[]){1, 2, 4, 3});
    CHECK(image_compare(&a, &b, &m));
    CHECK(near(m.rmse, sqrt(5.0 / 4)));                   /* (0 + 0 + 1 + 4) / 4 */
    CHECK(near(m.mae, 3.0 / 4));
    CHECK(near(m.max_err, 2));
    CHECK(near(m.rel_bias, (11.0 / 4 - 10.0 / 4) / (10.0 / 4))); /* 0.1 */
    CHECK(near(m.psnr, 20 * log10(4 / sqrt(1.25))));      /* peak max|b| = 4: 11.0721 dB */
    CHECK(m.nonfinite == 0);
    CHECK(image_compare(&b, &a, &m) && near(m.rel_bias, -1.0 / 11) && near(m.psnr, 20 * log10(5 / sqrt(1.25))));

    /* Identical: rmse 0, psnr infinite; all zero: rel_bias 0. */
    CHECK(image_compare(&a, &a, &m) && m.rmse == 0 && isinf(m.psnr) && m.psnr > 0 && m.rel_bias == 0);
    fill(&a, (const float[]){0, 0, 0, 0});
    fill(&b, (const float[]){0, 0, 0, 0});
    CHECK(image_compare(&a, &b, &m) && m.rel_bias == 0 && m.max_err == 0);
    /* b all zero: peak 1; mean(b) = 0 with mean(a) != 0: infinite relative bias. */
    fill(&a, (const float[]){0.1f, 0, 0, 0});
    CHECK(image_compare(&a, &b, &m) && near(m.psnr, 20 * log10(1 / (0.1f / 2.0))) && isinf(m.rel_bias));

    /* NaN in a, Inf in b: counted, and the other pairs still measured. */
    fill(&a, (const float[]){NAN, 2, 3, 1});
    fill(&b, (const float[]){1, INFINITY, 3, 3});
    CHECK(image_compare(&a, &b, &m) && m.nonfinite == 2);
    CHECK(near(m.rmse, sqrt(4.0 / 2)) && near(m.max_err, 2) && near(m.rel_bias, (4.0 - 6.0) / 6.0));
    image_destroy(&a);
    image_destroy(&b);

    /* RGB + extras: only R, G, B compared; channel order in the image does not matter. */
    image_create(&a, 1, 2, 3, rgb);
    image_create(&b, 1, 2, 5, rgbaz);
    fill(&a, (const float[]){1, 1, 2, 2, 3, 3});          /* R G B */
    fill(&b, (const float[]){9, 9, 3, 3, 2, 2, 1, 1, 9, 9}); /* A B G R Z */
    CHECK(image_compare(&a, &b, &m) && m.rmse == 0 && m.max_err == 0);
    b.planes[4][0] = 5; /* Z is not compared */
    b.planes[3][1] = 2; /* R[1]: 1 vs 2 */
    CHECK(image_compare(&a, &b, &m) && near(m.rmse, sqrt(1.0 / 6)) && near(m.max_err, 1));
    CHECK(image_compare_channels(&a, &b, (const char *const[]){"G"}, 1, &m) && m.rmse == 0);
    CHECK(image_compare_channels(&a, &b, (const char *const[]){"R", "B"}, 2, &m) && near(m.mae, 1.0 / 4));

    capture_begin(&cap, stderr);
    ok = image_compare_channels(&a, &b, (const char *const[]){"Z"}, 1, &m);
    capture_end(&cap, msg, sizeof msg);
    CHECK(!ok && strstr(msg, "'Z'"));
    image_create(&c, 2, 1, 1, r_only);
    capture_begin(&cap, stderr);
    ok = image_compare(&a, &c, &m);
    capture_end(&cap, msg, sizeof msg);
    CHECK(!ok && strstr(msg, "1x2") && strstr(msg, "2x1"));
    image_destroy(&c);
    image_create(&c, 1, 2, 1, z); /* RGB against no RGB: nothing to compare */
    capture_begin(&cap, stderr);
    ok = image_compare(&a, &c, &m);
    capture_end(&cap, msg, sizeof msg);
    CHECK(!ok && msg[0]);
    image_destroy(&c);
    image_destroy(&a);
    image_destroy(&b);
}

/* ---- gonio diff -------------------------------------------------------------------------- */

/* Runs cmd_diff with up to 10 arguments; its stdout and stderr go to out and err. */
static int run_diff(char *out, char *err, size_t cap, const char *const *args)
{
    char *argv[12] = {"diff"};
    int argc = 1, rc;
    capture co, ce;
    while (args[argc - 1])
        argv[argc] = (char *)args[argc - 1], argc++;
    capture_begin(&co, stdout);
    capture_begin(&ce, stderr);
    rc = cmd_diff(argc, argv);
    capture_end(&ce, err, cap);
    capture_end(&co, out, cap);
    return rc;
}

static double metric(const char *out, const char *name)
{
    char key[32];
    const char *p;
    snprintf(key, sizeof key, "%s ", name);
    for (p = out; p; p = strchr(p, '\n'), p = p ? p + 1 : NULL)
        if (strncmp(p, key, strlen(key)) == 0)
            return strtod(p + strlen(key), NULL);
    return NAN;
}

TEST(image, diff_cli)
{
    static const char *const rgb[4] = {"R", "G", "B", "normal.X"};
    char dir[64], a[128], b[128], small[128], nan[128], out[4096], err[4096];
    image img;

    make_dir(dir);
    snprintf(a, sizeof a, "%s/a.exr", dir);
    snprintf(b, sizeof b, "%s/b.exr", dir);
    snprintf(small, sizeof small, "%s/small.exr", dir);
    snprintf(nan, sizeof nan, "%s/nan.exr", dir);
    /* b: R = G = B = 1 over 2x2; a: one R value 3 -> 12 values, one off by 2. */
    image_create(&img, 2, 2, 4, rgb);
    for (int c = 0; c < 3; c++)
        for (int i = 0; i < 4; i++)
            img.planes[c][i] = 1;
    CHECK(image_write_exr(&img, b, NULL, 0));
    img.planes[0][3] = 3;
    img.planes[3][0] = 100; /* normal.X differs but is not compared by default */
    CHECK(image_write_exr(&img, a, NULL, 0));
    img.planes[0][2] = NAN;
    CHECK(image_write_exr(&img, nan, NULL, 0));
    image_destroy(&img);
    image_create(&img, 1, 2, 3, rgb);
    CHECK(image_write_exr(&img, small, NULL, 0));
    image_destroy(&img);

    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, NULL}) == 0);
    CHECKF(near(metric(out, "rmse"), sqrt(4.0 / 12)) || fabs(metric(out, "rmse") - sqrt(4.0 / 12)) < 1e-6, "%s", out);
    CHECK(fabs(metric(out, "mae") - 2.0 / 12) < 1e-6);
    CHECK(fabs(metric(out, "rel_bias") - 2.0 / 12) < 1e-6); /* (14/12 - 1) / 1 */
    CHECK(fabs(metric(out, "max_err") - 2) < 1e-6);
    CHECK(fabs(metric(out, "psnr") - 20 * log10(1 / sqrt(1.0 / 3))) < 0.006 && strstr(out, " dB\n"));
    CHECK(err[0] == 0);

    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--max-rmse", "0.6", "--max-error", "2", NULL}) == 0);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){"--max-rmse", "0.5", a, b, NULL}) == 1);
    CHECK(strstr(err, "gonio: diff: rmse 0.57735 > 0.5") != NULL);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--max-rel-bias", "0.1", "--quiet", NULL}) == 1);
    CHECK(out[0] == 0 && strstr(err, "rel_bias"));
    CHECK(run_diff(out, err, sizeof out, (const char *[]){b, a, "--max-rel-bias", "0.15", NULL}) == 0); /* |-1/7| */
    CHECK(run_diff(out, err, sizeof out, (const char *[]){b, a, "--max-rel-bias", "0.14", NULL}) == 1);
    CHECK(fabs(metric(out, "rel_bias") + 1.0 / 7) < 1e-6);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--max-error", "1.5", NULL}) == 1);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--channels", "G,B", "--max-error", "0", NULL}) == 0);
    CHECK(metric(out, "rmse") == 0);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--channels", "normal.X", NULL}) == 0);
    CHECK(metric(out, "max_err") == 100);

    /* Bad inputs: exit 1 and a message naming the file. */
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, "/nonexistent.exr", NULL}) == 1 && strstr(err, "/nonexistent.exr"));
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, small, NULL}) == 1);
    CHECK(strstr(err, a) && strstr(err, small) && strstr(err, "2x2") && strstr(err, "1x2"));
    CHECK(run_diff(out, err, sizeof out, (const char *[]){nan, b, NULL}) == 1 && strstr(err, nan) && strstr(err, "NaN"));
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--channels", "Z", NULL}) == 1 && strstr(err, "'Z'"));

    /* Bad usage: exit 2 with the usage line. */
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--frobnicate", NULL}) == 2 && strstr(err, "gonio diff --help"));
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--max-rmse", NULL}) == 2);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--max-rmse", "abc", NULL}) == 2);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--max-rmse", "-1", NULL}) == 2);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, "--channels", "R,,B", NULL}) == 2);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, NULL}) == 2);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){a, b, b, NULL}) == 2);
    CHECK(run_diff(out, err, sizeof out, (const char *[]){"--help", NULL}) == 0 && strstr(out, "usage:") && !err[0]);
    remove_dir(dir);
}

/* ---- draw -------------------------------------------------------------------------------- */

static const uint8_t *px_at(const draw_canvas *c, int x, int y) { return c->rgba + 4 * (y * c->width + x); }

TEST(image, draw_text)
{
    /* Starts and ends with 'H', whose outer columns are ink on every row: the box is tight. */
    static const char *const texts[3] = {"H", "Hgj{|}~ 0.5, (x) @#$ H", "H\x01\xff" "H"};
    draw_canvas c = {0};
    CHECK(draw_text_width("", 3) == 0 && draw_text_width("a", 1) == 5 && draw_text_width("ab", 2) == 22);
    for (int t = 0; t < 3; t++) {
        for (int scale = 1; scale <= 3; scale++) {
            int x0 = 7, y0 = 5, w = draw_text_width(texts[t], scale), hgt = DRAW_GLYPH_H * scale;
            int outside = 0, minx = 1 << 30, maxx = -1, miny = 1 << 30, maxy = -1;
            draw_create(&c, 400, 40);
            draw_clear(&c, 0x000000ff);
            draw_text(&c, x0, y0, scale, 0xffffffff, texts[t]);
            for (int y = 0; y < c.height; y++) {
                for (int x = 0; x < c.width; x++) {
                    if (px_at(&c, x, y)[0] == 0)
                        continue;
                    outside += x < x0 || x >= x0 + w || y < y0 || y >= y0 + hgt;
                    minx = x < minx ? x : minx;
                    maxx = x > maxx ? x : maxx;
                    miny = y < miny ? y : miny;
                    maxy = y > maxy ? y : maxy;
                }
            }
            CHECKF(outside == 0, "'%s' x%d: %d pixels outside", texts[t], scale, outside);
            CHECKF(minx == x0 && maxx == x0 + w - 1 && miny == y0 && maxy == y0 + hgt - 1,
                   "'%s' x%d: ink %d..%d x %d..%d", texts[t], scale, minx, maxx, miny, maxy);
            draw_destroy(&c);
        }
    }
    /* Every printable character has ink except space; unprintable ones draw '?'. */
    draw_create(&c, 8, 8);
    for (int ch = 32; ch <= 127; ch++) {
        char s[2] = {(char)ch, 0};
        int ink = 0;
        draw_clear(&c, 0);
        draw_text(&c, 1, 0, 1, 0xffffffff, s);
        for (int i = 0; i < 64; i++)
            ink += c.rgba[4 * i + 3] != 0;
        CHECKF((ch == ' ') == (ink == 0), "char %d has %d ink pixels", ch, ink);
    }
    draw_destroy(&c);
    draw_destroy(&c);
}

TEST(image, draw_shapes)
{
    draw_canvas c;
    char dir[64], path[128];
    uint8_t block[4 * 4 * 4], *back = NULL;
    int w, h, partial = 0;

    draw_create(&c, 40, 40);
    CHECK(px_at(&c, 3, 3)[3] == 0); /* transparent black to start */
    draw_clear(&c, 0x000000ff);
    /* Horizontal line along the centres of row 10, from x = 5 to 35. */
    draw_line(&c, 5, 10.5f, 35, 10.5f, 1, 0xffffffff);
    CHECK(px_at(&c, 20, 10)[0] == 255 && px_at(&c, 20, 9)[0] == 0 && px_at(&c, 20, 11)[0] == 0);
    CHECK(px_at(&c, 3, 10)[0] == 0 && px_at(&c, 37, 10)[0] == 0);
    /* Thick line: 5 wide covers rows 8..12. */
    draw_clear(&c, 0x000000ff);
    draw_line(&c, 5, 20.5f, 35, 20.5f, 5, 0x00ff00ff);
    CHECK(px_at(&c, 20, 18)[1] == 255 && px_at(&c, 20, 22)[1] == 255 && px_at(&c, 20, 24)[1] == 0);
    /* Diagonal: on it full ink, off it none, edges partial. */
    draw_clear(&c, 0x000000ff);
    draw_line(&c, 0, 0, 40, 40, 1.5f, 0xffffffff);
    CHECK(px_at(&c, 15, 15)[0] == 255 && px_at(&c, 15, 18)[0] == 0 && px_at(&c, 18, 15)[0] == 0);
    for (int i = 0; i < 40 * 40; i++)
        partial += c.rgba[4 * i] > 0 && c.rgba[4 * i] < 255;
    CHECK(partial > 20);
    /* Circle of radius 10 centred on pixel (20, 20)'s centre. */
    draw_clear(&c, 0x000000ff);
    draw_circle(&c, 20.5f, 20.5f, 10, 1, 0xff0000ff);
    CHECK(px_at(&c, 30, 20)[0] == 255 && px_at(&c, 10, 20)[0] == 255 && px_at(&c, 20, 30)[0] == 255);
    CHECK(px_at(&c, 20, 20)[0] == 0 && px_at(&c, 25, 20)[0] == 0 && px_at(&c, 33, 20)[0] == 0);
    /* Rectangles, clipped. */
    draw_clear(&c, 0x000000ff);
    draw_fill_rect(&c, -5, -5, 10, 10, 0x0000ffff);
    CHECK(px_at(&c, 0, 0)[2] == 255 && px_at(&c, 4, 4)[2] == 255 && px_at(&c, 5, 5)[2] == 0 && px_at(&c, 5, 0)[2] == 0);
    draw_rect(&c, 10, 10, 5, 4, 0xffffffff);
    CHECK(px_at(&c, 10, 10)[0] == 255 && px_at(&c, 14, 13)[0] == 255 && px_at(&c, 12, 13)[0] == 255);
    CHECK(px_at(&c, 12, 11)[0] == 0 && px_at(&c, 15, 10)[0] == 0 && px_at(&c, 10, 14)[0] == 0);
    /* Half-transparent white over black: 128; over transparent: colour kept, alpha 128. */
    draw_pixel(&c, 30, 30, 0xffffff80);
    CHECK(px_at(&c, 30, 30)[0] == 128 && px_at(&c, 30, 30)[3] == 255);
    draw_clear(&c, 0);
    draw_pixel(&c, 30, 30, 0xffffff80);
    CHECK(px_at(&c, 30, 30)[0] == 255 && px_at(&c, 30, 30)[3] == 128);
    /* Off-canvas and degenerate shapes draw nothing and do not crash. */
    draw_clear(&c, 0);
    draw_pixel(&c, -1, 5, 0xffffffff);
    draw_pixel(&c, 40, 5, 0xffffffff);
    draw_line(&c, -1e30f, 5, 1e30f, 5, 1, 0xffffff00);
    draw_line(&c, NAN, 5, 10, 5, 1, 0xffffffff);
    draw_line(&c, 100, 100, 200, 300, 3, 0xffffffff);
    draw_circle(&c, -100, -100, 5, 1, 0xffffffff);
    draw_fill_rect(&c, 2147483600, 2147483600, 100, 100, 0xffffffff);
    draw_rect(&c, 5, 5, 0, 3, 0xffffffff);
    draw_text(&c, -1000, 1000, 2, 0xffffffff, "off canvas");
    for (int i = 0; i < 40 * 40; i++)
        CHECK(c.rgba[4 * i + 3] == 0);
    /* A point-like line is a dot. */
    draw_line(&c, 5.5f, 5.5f, 5.5f, 5.5f, 1, 0xffffffff);
    CHECK(px_at(&c, 5, 5)[3] == 255 && px_at(&c, 6, 5)[3] == 0);

    /* Blit, clipped at the top-left and bottom-right. */
    for (int i = 0; i < 16; i++) {
        block[4 * i + 0] = (uint8_t)i;
        block[4 * i + 1] = 1;
        block[4 * i + 2] = 2;
        block[4 * i + 3] = 255;
    }
    draw_clear(&c, 0);
    draw_blit(&c, -2, -1, block, 4, 4);
    CHECK(px_at(&c, 0, 0)[0] == 6 && px_at(&c, 1, 2)[0] == 15 && px_at(&c, 2, 0)[3] == 0 && px_at(&c, 0, 3)[3] == 0);
    draw_blit(&c, 38, 39, block, 4, 4);
    CHECK(px_at(&c, 38, 39)[0] == 0 && px_at(&c, 39, 39)[0] == 1);
    draw_blit(&c, 100, -100, block, 4, 4);

    make_dir(dir);
    snprintf(path, sizeof path, "%s/canvas.png", dir);
    CHECK(draw_write_png(&c, path));
    CHECK(image_read_png(path, &back, &w, &h));
    CHECK(w == 40 && h == 40 && back && memcmp(back, c.rgba, 40 * 40 * 4) == 0);
    free(back);
    remove_dir(dir);
    draw_destroy(&c);
}

TEST(image, draw_colormap)
{
    double prev = -1;
    /* matplotlib viridis: entries 0, 128 and 255 of its 256-colour table. */
    CHECK(draw_colormap(0) == 0x440154ff);
    CHECK(draw_colormap(0.5f) == 0x21918cff);
    CHECK(draw_colormap(1) == 0xfde725ff);
    CHECK(draw_colormap(-3) == 0x440154ff && draw_colormap(NAN) == 0x440154ff && draw_colormap(7) == 0xfde725ff);
    /* Viridis is designed with monotonically increasing lightness: check Rec. 709 luma. */
    for (int i = 0; i <= 200; i++) {
        uint32_t col = draw_colormap((float)i / 200);
        double luma = 0.2126 * (col >> 24) + 0.7152 * (col >> 16 & 0xff) + 0.0722 * (col >> 8 & 0xff);
        CHECKF(luma >= prev, "t = %g", i / 200.0);
        CHECK((col & 0xff) == 0xff);
        prev = luma;
    }
}
