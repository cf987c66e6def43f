/* image.c: planar float images; OpenEXR through its C API (openexr.h), PNG through libpng's
 * simplified API, the sRGB OETF of IEC 61966-2-1, Reinhard and ACES (Narkowicz 2015) tonemaps,
 * and the error metrics behind `gonio diff`. */
#include "image.h"
#include "util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* Corrupt headers may claim any size; refuse what no render of ours would produce rather than
 * let util_malloc stop the program. */
#define IMAGE_MAX_DIM 65536
#define IMAGE_MAX_PIXELS (1LL << 28)

void image_create(image *img, int width, int height, int num_channels, const char *const *names)
{
    assert(width > 0 && height > 0 && (long long)width * height <= IMAGE_MAX_PIXELS);
    assert(num_channels > 0 && num_channels <= IMAGE_MAX_CHANNELS);
    memset(img, 0, sizeof *img);
    img->width = width;
    img->height = height;
    img->num_channels = num_channels;
    for (int c = 0; c < num_channels; c++) {
        assert(strlen(names[c]) < sizeof img->names[c]);
        strcpy(img->names[c], names[c]);
        img->planes[c] = util_calloc((size_t)width * (size_t)height, sizeof(float));
    }
}

void image_destroy(image *img)
{
    for (int c = 0; c < IMAGE_MAX_CHANNELS; c++)
        free(img->planes[c]);
    memset(img, 0, sizeof *img);
}

bool image_inside_frame(const image *img)
{
    return !img->full_width || (img->x0 >= 0 && img->y0 >= 0 && img->width <= img->full_width - img->x0 &&
                                img->height <= img->full_height - img->y0);
}

int image_channel(const image *img, const char *name)
{
    for (int c = 0; c < img->num_channels; c++)
        if (strcmp(img->names[c], name) == 0)
            return c;
    return -1;
}

void image_remove_channel(image *img, int c)
{
    assert(c >= 0 && c < img->num_channels);
    free(img->planes[c]);
    for (int k = c; k + 1 < img->num_channels; k++) {
        memcpy(img->names[k], img->names[k + 1], sizeof img->names[k]);
        img->planes[k] = img->planes[k + 1];
    }
    img->num_channels--;
    img->planes[img->num_channels] = NULL;
    img->names[img->num_channels][0] = 0;
}

/* ---- OpenEXR ------------------------------------------------------------------------- */

/* OpenEXR reports details (which chunk, which attribute) only through this callback; the
 * first message of an operation is the cause, later ones are consequences. */
static _Thread_local char exr_message[256];

static void exr_capture(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    if (!exr_message[0])
        snprintf(exr_message, sizeof exr_message, "%s", msg ? msg : exr_get_default_error_message(code));
}

static exr_context_initializer_t exr_init(void)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_capture;
    exr_message[0] = 0;
    return init;
}

/* OpenEXR reads and writes through gonio's own descriptors: an input is opened by
 * util_open_read (regular files only, never blocking on a FIFO), an output is
 * util_out_open's exclusive temporary file. */
static int64_t exr_pread(exr_const_context_t ctxt, void *user, void *buf, uint64_t size, uint64_t offset,
                         exr_stream_error_func_ptr_t error_cb)
{
    int fd = *(int *)user;
    uint64_t done = 0;
    while (done < size) {
        ssize_t n = pread(fd, (char *)buf + done, size - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            return error_cb(ctxt, EXR_ERR_READ_IO, "read failed: %s", strerror(errno)), -1;
        if (n == 0)
            break;
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static int64_t exr_fsize(exr_const_context_t ctxt, void *user)
{
    struct stat st;
    (void)ctxt;
    return fstat(*(int *)user, &st) == 0 ? (int64_t)st.st_size : -1;
}

static int64_t exr_pwrite(exr_const_context_t ctxt, void *user, const void *buf, uint64_t size, uint64_t offset,
                          exr_stream_error_func_ptr_t error_cb)
{
    int fd = *(int *)user;
    uint64_t done = 0;
    while (done < size) {
        ssize_t n = pwrite(fd, (const char *)buf + done, size - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return error_cb(ctxt, EXR_ERR_WRITE_IO, "write failed: %s", n < 0 ? strerror(errno) : "no space"), -1;
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static void exr_report(const char *path, const char *what, exr_result_t rv)
{
    util_error("%s: %s: %s", path, what, exr_message[0] ? exr_message : exr_get_default_error_message(rv));
}

image_format image_format_of(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return IMAGE_FORMAT_UNKNOWN;
    if (!strcasecmp(dot, ".exr"))
        return IMAGE_FORMAT_EXR;
    if (!strcasecmp(dot, ".png"))
        return IMAGE_FORMAT_PNG;
    return IMAGE_FORMAT_UNKNOWN;
}

/* Indexed by exr_compression_t. OpenEXR 3.1's C API reads DWAA/DWAB but cannot write them
 * ("not yet implemented in C"), so they are not offered. */
static const char *const exr_compression_names[] = {"none", "rle",  "zips", "zip",  "piz",
                                                    "pxr24", "b44", "b44a", "dwaa", "dwab"};
#define EXR_WRITABLE_COMPRESSIONS (EXR_COMPRESSION_B44A + 1)

bool image_exr_compression_from_name(const char *name, int *out)
{
    for (int i = 0; i < EXR_WRITABLE_COMPRESSIONS; i++)
        if (!strcasecmp(name, exr_compression_names[i])) {
            *out = i;
            return true;
        }
    return false;
}

const char *image_exr_compression_list(void)
{
    static char list[128];
    return list[0] ? list : util_join(list, sizeof list, exr_compression_names, EXR_WRITABLE_COMPRESSIONS);
}

/* B44 packs HALF channels only; the rest of a chunk is stored as is, channel by channel, so
 * a chunk of float channels comes out exactly as large as the data. OpenEXR's rule (its C++
 * library follows it) is that a chunk that does not shrink is stored uncompressed, and a
 * reader takes a chunk of the uncompressed size to be uncompressed. The C API of OpenEXR 3.1
 * (3.2 fixes it) breaks the rule both ways: it writes the B44 form whatever its size and
 * decodes a full-size B44 chunk as B44. These two shims apply the rule. */
static _Thread_local exr_result_t (*exr_b44_compress)(exr_encode_pipeline_t *);

static exr_result_t exr_b44_compress_or_store(exr_encode_pipeline_t *enc)
{
    exr_result_t rv = exr_b44_compress(enc);
    /* The compressed buffer holds at least the packed size (the library allocates 110%). */
    if (!rv && enc->compressed_bytes >= enc->packed_bytes) {
        memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
        enc->compressed_bytes = enc->packed_bytes;
    }
    return rv;
}

static bool exr_is_b44(exr_compression_t c) { return c == EXR_COMPRESSION_B44 || c == EXR_COMPRESSION_B44A; }

bool image_write_exr(const image *img, const char *path, const image_attr *attrs, int num_attrs)
{
    return image_write_exr_with(img, path, attrs, num_attrs, NULL);
}

bool image_write_exr_with(const image *img, const char *path, const image_attr *attrs, int num_attrs,
                          const image_exr_options *opt)
{
    const image_exr_options o = opt ? *opt : IMAGE_EXR_DEFAULTS;
    exr_context_initializer_t init = exr_init();
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_context_t ctx = NULL;
    bool encoding = false;
    int part = 0, lines = 0;
    util_out out;
    exr_result_t rv;

    if (!util_out_open(&out, path))
        return false;
    init.user_data = &out.fd;
    init.write_fn = exr_pwrite;
    rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (!rv)
        rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    if (!rv && img->full_width > 0) {
        exr_attr_box2i_t display, data;
        exr_attr_v2f_t center;
        memset(&center, 0, sizeof center);
        display.min.x = display.min.y = 0;
        display.max.x = img->full_width - 1;
        display.max.y = img->full_height - 1;
        data.min.x = img->x0;
        data.min.y = img->y0;
        data.max.x = img->x0 + img->width - 1;
        data.max.y = img->y0 + img->height - 1;
        rv = exr_initialize_required_attr(ctx, part, &display, &data, 1, &center, 1,
                                          EXR_LINEORDER_INCREASING_Y, (exr_compression_t)o.compression);
    } else if (!rv) {
        rv = exr_initialize_required_attr_simple(ctx, part, img->width, img->height,
                                                 (exr_compression_t)o.compression);
    }
    /* The library converts the float planes to half as it encodes. */
    for (int c = 0; !rv && c < img->num_channels; c++) {
        bool exact = o.exact_prefix && !strncmp(img->names[c], o.exact_prefix, strlen(o.exact_prefix));
        rv = exr_add_channel(ctx, part, img->names[c], o.half && !exact ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    }
    for (int i = 0; !rv && i < num_attrs; i++) {
        switch (attrs[i].type) {
        case IMAGE_ATTR_STRING: rv = exr_attr_set_string(ctx, part, attrs[i].name, attrs[i].s); break;
        case IMAGE_ATTR_INT: rv = exr_attr_set_int(ctx, part, attrs[i].name, attrs[i].i); break;
        case IMAGE_ATTR_DOUBLE: rv = exr_attr_set_double(ctx, part, attrs[i].name, attrs[i].d); break;
        case IMAGE_ATTR_M44F: {
            exr_attr_m44f_t m;
            memcpy(m.m, attrs[i].m, sizeof m.m);
            rv = exr_attr_set_m44f(ctx, part, attrs[i].name, &m);
            break;
        }
        }
    }
    if (!rv)
        rv = exr_write_header(ctx);
    if (!rv)
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    for (int y = 0; !rv && y < img->height; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctx, part, img->y0 + y, &ci);
        if (!rv)
            rv = encoding ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (rv)
            break;
        encoding = true;
        /* The library keeps channels sorted by name, so match them by name. */
        for (int k = 0; k < enc.channel_count; k++) {
            exr_coding_channel_info_t *ch = &enc.channels[k];
            int c = image_channel(img, ch->channel_name);
            assert(c >= 0);
            ch->encode_from_ptr = (const uint8_t *)(img->planes[c] + (size_t)y * (size_t)img->width);
            ch->user_pixel_stride = (int32_t)sizeof(float);
            ch->user_line_stride = (int32_t)sizeof(float) * img->width;
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
        }
        rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (!rv && exr_is_b44((exr_compression_t)o.compression) && enc.compress_fn) {
            exr_b44_compress = enc.compress_fn;
            enc.compress_fn = exr_b44_compress_or_store;
        }
        if (!rv)
            rv = exr_encoding_run(ctx, part, &enc);
    }
    if (encoding)
        exr_encoding_destroy(ctx, &enc);
    if (ctx) {
        exr_result_t frv = exr_finish(&ctx);
        if (!rv)
            rv = frv;
    }
    if (rv)
        exr_report(path, "cannot write EXR", rv);
    return util_out_commit(&out, rv == EXR_ERR_SUCCESS);
}

static void exr_close_input(exr_const_context_t ctxt, void *user, int failed)
{
    (void)ctxt, (void)failed;
    close(*(int *)user);
    free(user);
}

static bool exr_open(exr_context_t *ctx, const char *path)
{
    exr_context_initializer_t init = exr_init();
    exr_result_t rv;
    int *fd = util_malloc(sizeof *fd);
    *ctx = NULL;
    if ((*fd = util_open_read(path)) < 0) {
        free(fd);
        return false;
    }
    init.user_data = fd;
    init.read_fn = exr_pread;
    init.size_fn = exr_fsize;
    init.destroy_fn = exr_close_input;
    rv = exr_start_read(ctx, path, &init);
    if (rv) {
        exr_report(path, "cannot read EXR", rv);
        *ctx = NULL;
        return false;
    }
    return true;
}

/* Decodes one chunk (a scanline block or a tile) whose top-left pixel is (x0, y0) of the data
 * window, straight into the image planes. Always planar: OpenEXR 3.1.5 swaps channels when
 * decoding half data into an interleaved float buffer. */
static exr_result_t exr_decode_chunk(exr_context_t ctx, exr_decode_pipeline_t *dec, bool *decoding,
                                     const exr_chunk_info_t *ci, exr_compression_t compression,
                                     image *img, int x0, int y0)
{
    exr_result_t rv;
    if (x0 < 0 || y0 < 0 || ci->width < 0 || ci->height < 0 || ci->width > img->width - x0 ||
        ci->height > img->height - y0) {
        snprintf(exr_message, sizeof exr_message, "chunk %d lies outside the data window", ci->idx);
        return EXR_ERR_CORRUPT_CHUNK;
    }
    rv = *decoding ? exr_decoding_update(ctx, 0, ci, dec) : exr_decoding_initialize(ctx, 0, ci, dec);
    if (rv)
        return rv;
    *decoding = true;
    for (int k = 0; k < dec->channel_count; k++) {
        exr_coding_channel_info_t *ch = &dec->channels[k];
        float *plane = img->planes[image_channel(img, ch->channel_name)];
        ch->decode_to_ptr = (uint8_t *)(plane + (size_t)y0 * (size_t)img->width + (size_t)x0);
        ch->user_pixel_stride = (int32_t)sizeof(float);
        ch->user_line_stride = (int32_t)sizeof(float) * img->width;
        ch->user_bytes_per_element = (int16_t)sizeof(float);
        ch->user_data_type = EXR_PIXEL_FLOAT;
    }
    rv = exr_decoding_choose_default_routines(ctx, 0, dec);
    /* A B44 chunk of the uncompressed size is stored uncompressed (see exr_b44_compress); the
     * library has already placed it in the unpacked buffer. */
    if (!rv && exr_is_b44(compression) && ci->packed_size == ci->unpacked_size)
        dec->decompress_fn = NULL;
    return rv ? rv : exr_decoding_run(ctx, 0, dec);
}

/* Reads the header of part 0 and allocates img; false with an error on anything we cannot
 * represent. */
static bool exr_prepare(exr_context_t ctx, const char *path, image *img, exr_attr_box2i_t *dw, exr_storage_t *storage)
{
    const exr_attr_chlist_t *chl = NULL;
    const char *names[IMAGE_MAX_CHANNELS];
    long long w, h;

    if (exr_get_storage(ctx, 0, storage) || exr_get_data_window(ctx, 0, dw) || exr_get_channels(ctx, 0, &chl)) {
        exr_report(path, "cannot read EXR", EXR_ERR_FILE_BAD_HEADER);
        return false;
    }
    if (*storage != EXR_STORAGE_SCANLINE && *storage != EXR_STORAGE_TILED) {
        util_error("%s: deep EXR images are not supported", path);
        return false;
    }
    w = (long long)dw->max.x - dw->min.x + 1;
    h = (long long)dw->max.y - dw->min.y + 1;
    if (w < 1 || h < 1 || w > IMAGE_MAX_DIM || h > IMAGE_MAX_DIM || w * h > IMAGE_MAX_PIXELS) {
        util_error("%s: unsupported EXR data window %lldx%lld", path, w, h);
        return false;
    }
    if (chl->num_channels < 1 || chl->num_channels > IMAGE_MAX_CHANNELS) {
        util_error("%s: EXR has %d channels (1 to %d supported)", path, chl->num_channels, IMAGE_MAX_CHANNELS);
        return false;
    }
    for (int c = 0; c < chl->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        if (e->name.length >= (int32_t)sizeof img->names[0]) {
            util_error("%s: EXR channel name '%s' is too long", path, e->name.str);
            return false;
        }
        if (e->x_sampling != 1 || e->y_sampling != 1) {
            util_error("%s: EXR channel '%s' is subsampled (not supported)", path, e->name.str);
            return false;
        }
        if (e->pixel_type != EXR_PIXEL_UINT && e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT) {
            util_error("%s: EXR channel '%s' has an unknown pixel type %d", path, e->name.str, (int)e->pixel_type);
            return false;
        }
        names[c] = e->name.str;
    }
    image_create(img, (int)w, (int)h, chl->num_channels, names);
    for (int c = 0; c < chl->num_channels; c++)
        img->stored[c] = chl->entries[c].pixel_type == EXR_PIXEL_UINT   ? IMAGE_STORED_UINT
                         : chl->entries[c].pixel_type == EXR_PIXEL_HALF ? IMAGE_STORED_HALF
                                                                         : IMAGE_STORED_FLOAT;
    {
        exr_attr_box2i_t disp;
        if (!exr_get_display_window(ctx, 0, &disp) &&
            (disp.min.x != dw->min.x || disp.min.y != dw->min.y || disp.max.x != dw->max.x ||
             disp.max.y != dw->max.y)) {
            long long fw = (long long)disp.max.x - disp.min.x + 1, fh = (long long)disp.max.y - disp.min.y + 1;
            long long x0 = (long long)dw->min.x - disp.min.x, y0 = (long long)dw->min.y - disp.min.y;
            if (fw < 1 || fh < 1 || fw > IMAGE_MAX_DIM || fh > IMAGE_MAX_DIM || llabs(x0) > IMAGE_MAX_DIM ||
                llabs(y0) > IMAGE_MAX_DIM) {
                util_error("%s: unsupported EXR display window %lldx%lld (data window at %lld,%lld of it)", path,
                           fw, fh, x0, y0);
                image_destroy(img);
                return false;
            }
            img->full_width = (int)fw;
            img->full_height = (int)fh;
            img->x0 = (int)x0;
            img->y0 = (int)y0;
        }
    }
    return true;
}

bool image_read_exr(image *img, const char *path)
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    exr_context_t ctx;
    exr_attr_box2i_t dw;
    exr_storage_t storage;
    exr_compression_t compression;
    bool decoding = false;
    exr_result_t rv = EXR_ERR_SUCCESS;

    memset(img, 0, sizeof *img);
    if (!exr_open(&ctx, path))
        return false;
    if (!exr_prepare(ctx, path, img, &dw, &storage) || exr_get_compression(ctx, 0, &compression)) {
        exr_finish(&ctx);
        image_destroy(img);
        return false;
    }
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
        for (int64_t y = dw.min.y; !rv && y <= dw.max.y; y += lines) {
            exr_chunk_info_t ci;
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci);
            if (!rv)
                rv = exr_decode_chunk(ctx, &dec, &decoding, &ci, compression, img, 0, ci.start_y - dw.min.y);
        }
    } else {
        /* Level 0 of a tiled (or mip/rip-mapped) file is the full-resolution image. */
        uint32_t tw = 0, th = 0;
        rv = exr_get_tile_descriptor(ctx, 0, &tw, &th, NULL, NULL);
        if (!rv && (tw == 0 || th == 0))
            rv = EXR_ERR_INVALID_ATTR;
        for (int ty = 0; !rv && (int64_t)ty * th < img->height; ty++) {
            for (int tx = 0; !rv && (int64_t)tx * tw < img->width; tx++) {
                exr_chunk_info_t ci;
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci);
                if (!rv)
                    rv = exr_decode_chunk(ctx, &dec, &decoding, &ci, compression, img, tx * (int)tw, ty * (int)th);
            }
        }
    }
    if (decoding)
        exr_decoding_destroy(ctx, &dec);
    exr_finish(&ctx);
    if (rv) {
        exr_report(path, "cannot read EXR", rv);
        image_destroy(img);
        return false;
    }
    return true;
}

/* Opens path and finds attribute name in part 0; false without a message when it is absent. */
static bool exr_find_attr(const char *path, const char *name, exr_context_t *ctx, const exr_attribute_t **attr)
{
    if (!exr_open(ctx, path))
        return false;
    if (exr_get_attribute_by_name(*ctx, 0, name, attr) != EXR_ERR_SUCCESS) {
        exr_finish(ctx);
        return false;
    }
    return true;
}

bool image_exr_attr_double(const char *path, const char *name, double *out)
{
    exr_context_t ctx;
    const exr_attribute_t *a;
    bool ok = true;
    if (!exr_find_attr(path, name, &ctx, &a))
        return false;
    switch (a->type) {
    case EXR_ATTR_INT: *out = a->i; break;
    case EXR_ATTR_FLOAT: *out = a->f; break;
    case EXR_ATTR_DOUBLE: *out = a->d; break;
    default: ok = false; break;
    }
    exr_finish(&ctx);
    return ok;
}

bool image_exr_attr_string(const char *path, const char *name, char *out, int cap)
{
    exr_context_t ctx;
    const exr_attribute_t *a;
    bool ok;
    assert(cap > 0);
    if (!exr_find_attr(path, name, &ctx, &a))
        return false;
    ok = a->type == EXR_ATTR_STRING;
    if (ok)
        snprintf(out, (size_t)cap, "%.*s", a->string->length, a->string->str ? a->string->str : "");
    exr_finish(&ctx);
    return ok;
}

bool image_exr_size(const char *path, int *width, int *height)
{
    exr_context_t ctx;
    const exr_attribute_t *a;
    bool ok;
    if (!exr_find_attr(path, "dataWindow", &ctx, &a))
        return false;
    ok = a->type == EXR_ATTR_BOX2I;
    if (ok) {
        *width = a->box2i->max.x - a->box2i->min.x + 1;
        *height = a->box2i->max.y - a->box2i->min.y + 1;
        ok = *width > 0 && *height > 0;
    }
    exr_finish(&ctx);
    return ok;
}

/* The attributes OpenEXR requires of every file, which the writer sets itself. */
static bool exr_required_attr(const char *name)
{
    static const char *const names[] = {"channels", "compression", "dataWindow", "displayWindow", "lineOrder",
                                        "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "tiles",
                                        "type", "name", "version", "chunkCount"};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++)
        if (!strcmp(name, names[k]))
            return true;
    return false;
}

bool image_exr_attrs(const char *path, image_attr_list *out)
{
    exr_context_t ctx;
    int32_t n = 0;
    memset(out, 0, sizeof *out);
    if (!exr_open(&ctx, path))
        return false;
    if (exr_get_attribute_count(ctx, 0, &n) != EXR_ERR_SUCCESS || n < 0)
        n = 0;
    out->attrs = util_calloc((size_t)n + 1, sizeof *out->attrs);
    for (int32_t k = 0; k < n; k++) {
        const exr_attribute_t *a;
        image_attr *d = &out->attrs[out->count];
        if (exr_get_attribute_by_index(ctx, 0, EXR_ATTR_LIST_FILE_ORDER, k, &a) != EXR_ERR_SUCCESS ||
            exr_required_attr(a->name))
            continue;
        switch (a->type) {
        case EXR_ATTR_STRING: {
            char *s = util_malloc((size_t)a->string->length + 1);
            memcpy(s, a->string->str ? a->string->str : "", (size_t)a->string->length);
            s[a->string->length] = 0;
            *d = (image_attr){NULL, IMAGE_ATTR_STRING, s, 0, 0, NULL};
            break;
        }
        case EXR_ATTR_INT: *d = (image_attr){NULL, IMAGE_ATTR_INT, NULL, a->i, 0, NULL}; break;
        case EXR_ATTR_FLOAT: *d = (image_attr){NULL, IMAGE_ATTR_DOUBLE, NULL, 0, a->f, NULL}; break;
        case EXR_ATTR_DOUBLE: *d = (image_attr){NULL, IMAGE_ATTR_DOUBLE, NULL, 0, a->d, NULL}; break;
        case EXR_ATTR_M44F: {
            float *m = util_malloc(sizeof a->m44f->m);
            memcpy(m, a->m44f->m, sizeof a->m44f->m);
            *d = (image_attr){NULL, IMAGE_ATTR_M44F, NULL, 0, 0, m};
            break;
        }
        default: continue; /* types the writer does not write */
        }
        d->name = strcpy(util_malloc(strlen(a->name) + 1), a->name);
        out->count++;
    }
    exr_finish(&ctx);
    return true;
}

void image_attr_list_destroy(image_attr_list *l)
{
    for (int k = 0; k < l->count; k++) {
        free((char *)l->attrs[k].name);
        free((char *)l->attrs[k].s);
        free((float *)l->attrs[k].m);
    }
    free(l->attrs);
    memset(l, 0, sizeof *l);
}

/* ---- 8-bit output and PNG ------------------------------------------------------------ */

static uint8_t srgb8(float value, float scale, image_tonemap tm)
{
    /* Double precision keeps x*x finite in the ACES fit for huge inputs; !(x > 0) also
     * catches NaN. */
    double x = (double)value * scale;
    if (!(x > 0))
        return 0;
    x = fmin(x, 1e30);
    switch (tm) {
    case IMAGE_TONEMAP_CLAMP: break;
    case IMAGE_TONEMAP_REINHARD: x = x / (1 + x); break;
    case IMAGE_TONEMAP_ACES: x = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14); break;
    }
    x = fmin(x, 1);
    x = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055;
    return (uint8_t)(x * 255 + 0.5);
}

void image_to_srgb8(const float *r, const float *g, const float *b, int width, int height,
                    float exposure, image_tonemap tm, uint8_t *rgba8)
{
    float scale = exp2f(exposure);
    size_t n = (size_t)width * (size_t)height;
    for (size_t i = 0; i < n; i++) {
        rgba8[4 * i + 0] = srgb8(r[i], scale, tm);
        rgba8[4 * i + 1] = srgb8(g[i], scale, tm);
        rgba8[4 * i + 2] = srgb8(b[i], scale, tm);
        rgba8[4 * i + 3] = 255;
    }
}

bool image_write_png(const char *path, const uint8_t *rgba8, int width, int height)
{
    png_image pi;
    util_out out;
    FILE *f;
    bool ok;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    pi.width = (png_uint_32)width;
    pi.height = (png_uint_32)height;
    pi.format = PNG_FORMAT_RGBA;
    if (!util_out_open(&out, path))
        return false;
    if (!(f = util_out_file(&out)))
        return util_out_commit(&out, false);
    ok = png_image_write_to_stdio(&pi, f, 0, rgba8, 0, NULL) != 0;
    if (!ok)
        util_error("%s: cannot write PNG: %s", path, pi.message);
    png_image_free(&pi);
    return util_out_commit(&out, ok);
}

bool image_write_png_from(const image *img, const char *path, float exposure, image_tonemap tm)
{
    int r = image_channel(img, "R"), g = image_channel(img, "G"), b = image_channel(img, "B");
    uint8_t *rgba8 = util_malloc((size_t)img->width * (size_t)img->height * 4);
    bool ok;
    if (r < 0 || g < 0 || b < 0)
        r = g = b = 0;
    image_to_srgb8(img->planes[r], img->planes[g], img->planes[b], img->width, img->height, exposure, tm, rgba8);
    ok = image_write_png(path, rgba8, img->width, img->height);
    free(rgba8);
    return ok;
}

bool image_read_png(const char *path, uint8_t **rgba8, int *width, int *height)
{
    png_image pi;
    FILE *f;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    *rgba8 = NULL;
    if (!(f = util_fopen_read(path)))
        return false;
    if (!png_image_begin_read_from_stdio(&pi, f)) {
        util_error("%s: cannot read PNG: %s", path, pi.message);
        png_image_free(&pi);
        fclose(f);
        return false;
    }
    if ((long long)pi.width * pi.height > IMAGE_MAX_PIXELS) {
        util_error("%s: PNG too large (%ux%u)", path, (unsigned)pi.width, (unsigned)pi.height);
        png_image_free(&pi);
        fclose(f);
        return false;
    }
    pi.format = PNG_FORMAT_RGBA;
    *rgba8 = util_malloc(PNG_IMAGE_SIZE(pi));
    if (!png_image_finish_read(&pi, NULL, *rgba8, 0, NULL)) {
        util_error("%s: cannot read PNG: %s", path, pi.message);
        png_image_free(&pi);
        fclose(f);
        free(*rgba8);
        *rgba8 = NULL;
        return false;
    }
    fclose(f);
    *width = (int)pi.width;
    *height = (int)pi.height;
    return true;
}

/* ---- Metrics ------------------------------------------------------------------------- */

/* Pairs where either value is NaN or Inf are counted in nonfinite and left out of every other
 * metric, so one bad pixel is reported instead of turning all metrics into NaN. */
static void compare_planes(const image *a, const image *b, const int *ca, const int *cb, int n, image_metrics *m)
{
    size_t count = (size_t)a->width * (size_t)a->height, used = 0;
    double sum_sq = 0, sum_abs = 0, sum_a = 0, sum_b = 0, max_err = 0, peak = 0;
    memset(m, 0, sizeof *m);
    for (int k = 0; k < n; k++) {
        const float *pa = a->planes[ca[k]], *pb = b->planes[cb[k]];
        for (size_t i = 0; i < count; i++) {
            double va = pa[i], vb = pb[i], d = va - vb;
            if (!isfinite(va) || !isfinite(vb)) {
                m->nonfinite += !isfinite(va) + !isfinite(vb);
                continue;
            }
            used++;
            sum_sq += d * d;
            sum_abs += fabs(d);
            sum_a += va;
            sum_b += vb;
            max_err = fmax(max_err, fabs(d));
            peak = fmax(peak, fabs(vb));
        }
    }
    if (used == 0)
        return;
    m->rmse = sqrt(sum_sq / (double)used);
    m->mae = sum_abs / (double)used;
    m->max_err = max_err;
    m->psnr = m->rmse > 0 ? 20 * log10((peak > 0 ? peak : 1) / m->rmse) : INFINITY;
    /* The sums share one count, so the ratio of sums is the ratio of means. */
    m->rel_bias = sum_a == 0 && sum_b == 0 ? 0 : (sum_a - sum_b) / fabs(sum_b);
}

static bool compare_sizes(const image *a, const image *b)
{
    if (a->width != b->width || a->height != b->height) {
        util_error("image sizes differ: %dx%d vs %dx%d", a->width, a->height, b->width, b->height);
        return false;
    }
    return true;
}

bool image_compare(const image *a, const image *b, image_metrics *m)
{
    static const char *const rgb[3] = {"R", "G", "B"};
    int ca[3], cb[3], n = 0;
    bool a_rgb = false, b_rgb = false;
    if (!compare_sizes(a, b))
        return false;
    for (int k = 0; k < 3; k++) {
        ca[n] = image_channel(a, rgb[k]);
        cb[n] = image_channel(b, rgb[k]);
        a_rgb |= ca[n] >= 0;
        b_rgb |= cb[n] >= 0;
        n += ca[n] >= 0 && cb[n] >= 0;
    }
    if (n == 0 && !a_rgb && !b_rgb) {
        ca[0] = cb[0] = 0;
        n = 1;
    }
    if (n == 0) {
        util_error("images have no R, G or B channel in common (first has %s..., second has %s...)",
                   a->names[0], b->names[0]);
        return false;
    }
    compare_planes(a, b, ca, cb, n, m);
    return true;
}

bool image_compare_channels(const image *a, const image *b, const char *const *names, int n, image_metrics *m)
{
    int ca[IMAGE_MAX_CHANNELS], cb[IMAGE_MAX_CHANNELS];
    assert(n > 0 && n <= IMAGE_MAX_CHANNELS);
    if (!compare_sizes(a, b))
        return false;
    for (int k = 0; k < n; k++) {
        ca[k] = image_channel(a, names[k]);
        cb[k] = image_channel(b, names[k]);
        if (ca[k] < 0 || cb[k] < 0) {
            util_error("channel '%s' missing from the %s image", names[k], ca[k] < 0 ? "first" : "second");
            return false;
        }
    }
    compare_planes(a, b, ca, cb, n, m);
    return true;
}

static const char *const tonemap_names[] = {"clamp", "aces", "reinhard"};

bool image_tonemap_from_name(const char *name, image_tonemap *out)
{
    for (int i = 0; i < 3; i++)
        if (!strcmp(name, tonemap_names[i])) {
            *out = (image_tonemap)i;
            return true;
        }
    return false;
}

const char *image_tonemap_name(image_tonemap tm) { return tonemap_names[tm]; }

const char *image_tonemap_list(void)
{
    static char list[64];
    return list[0] ? list : util_join(list, sizeof list, tonemap_names, 3);
}
