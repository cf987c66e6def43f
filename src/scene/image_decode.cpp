/* image_decode.cpp: WebP through libwebp and KTX2 through Basis Universal's transcoder
 * (image_decode.h). Every field of the file that sizes something is checked here, with a
 * message naming it, before the libraries see the bytes: libwebp checks its own, but Basis
 * Universal's transcoder reports only true or false, and trusts some sums of 64-bit offsets.
 * No C++ exception escapes into C. */
#include "image_decode.h"

#include <gonio_basisu.h> /* written by deps/basisu.sh: GONIO_BASISU and the versions */
#include <webp/decode.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <vector>

#if GONIO_BASISU
#include <basisu_transcoder.h>
#endif

extern "C" {
#include "util.h"
}

namespace {

image_decode_status bad(char *why, size_t n, const char *fmt, ...) UTIL_PRINTF(3, 4);
image_decode_status bad(char *why, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
    return IMAGE_BAD;
}

/* The declared size against the budget, before any allocation. */
bool over_budget(uint32_t w, uint32_t h, uint64_t max_texels) { return uint64_t(w) * uint64_t(h) > max_texels; }

const char *webp_status(VP8StatusCode s)
{
    switch (s) {
    case VP8_STATUS_OUT_OF_MEMORY: return "out of memory";
    case VP8_STATUS_INVALID_PARAM: return "invalid parameter";
    case VP8_STATUS_BITSTREAM_ERROR: return "corrupt bitstream";
    case VP8_STATUS_UNSUPPORTED_FEATURE: return "a feature libwebp does not decode";
    case VP8_STATUS_SUSPENDED: return "suspended";
    case VP8_STATUS_USER_ABORT: return "aborted";
    case VP8_STATUS_NOT_ENOUGH_DATA: return "truncated";
    default: return "unknown error";
    }
}

image_decode_status decode_webp(const uint8_t *bytes, size_t size, uint64_t max_texels, uint8_t **rgba8,
                                uint32_t *width, uint32_t *height, char *why, size_t n)
{
    WebPBitstreamFeatures f;
    VP8StatusCode s = WebPGetFeatures(bytes, size, &f);
    if (s != VP8_STATUS_OK)
        return bad(why, n, "WebP: %s (libwebp reads no image size)", webp_status(s));
    if (f.width < 1 || f.height < 1)
        return bad(why, n, "WebP: image size %dx%d", f.width, f.height);
    *width = uint32_t(f.width);
    *height = uint32_t(f.height);
    if (over_budget(*width, *height, max_texels))
        return IMAGE_TOO_LARGE;
    if (f.has_animation)
        return bad(why, n, "WebP: an animation (EXT_texture_webp textures are still images)");
    size_t stride = size_t(*width) * 4, bytes_out = stride * *height;
    uint8_t *out = static_cast<uint8_t *>(util_malloc(bytes_out));
    if (!WebPDecodeRGBAInto(bytes, size, out, bytes_out, int(stride))) {
        free(out);
        return bad(why, n, "WebP: libwebp cannot decode the %ux%u image (corrupt or truncated data)", *width, *height);
    }
    *rgba8 = out;
    return IMAGE_DECODED;
}

/* ---- KTX2 ------------------------------------------------------------------------------ */

const uint8_t KTX2_ID[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
const size_t KTX2_HEADER = 80, KTX2_LEVEL = 24; /* the header, one level index entry */

uint32_t le32(const uint8_t *p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }
uint64_t le64(const uint8_t *p) { return uint64_t(le32(p)) | uint64_t(le32(p + 4)) << 32; }

/* offset + length lies within size, without overflow. */
bool within(uint64_t offset, uint64_t length, size_t size) { return offset <= size && length <= size - offset; }

#if GONIO_BASISU
std::once_flag basisu_once;

/* A key's value as KTX2 stores it (bytes, usually NUL-terminated), as a short C string. */
bool key_value(const basist::ktx2_transcoder &t, const char *key, char *out, size_t n)
{
    const basisu::uint8_vec *v = t.find_key(key);
    if (!v)
        return false;
    size_t len = 0;
    while (len < v->size() && len + 1 < n && (*v)[len])
        len++;
    memcpy(out, v->data(), len);
    out[len] = 0;
    for (size_t i = 0; i < len; i++)
        if (out[i] < 0x20 || out[i] > 0x7e)
            out[i] = '?';
    return true;
}
#endif

image_decode_status decode_ktx2(const uint8_t *b, size_t size, uint64_t max_texels, uint8_t **rgba8, uint32_t *width,
                                uint32_t *height, char *why, size_t n)
{
    if (size < KTX2_HEADER)
        return bad(why, n, "KTX2: truncated (%zu bytes; the header alone is %zu)", size, KTX2_HEADER);
    uint32_t vk_format = le32(b + 12), type_size = le32(b + 16), w = le32(b + 20), h = le32(b + 24),
             depth = le32(b + 28), layers = le32(b + 32), faces = le32(b + 36), levels = le32(b + 40),
             scheme = le32(b + 44), dfd_off = le32(b + 48), dfd_len = le32(b + 52), kvd_off = le32(b + 56),
             kvd_len = le32(b + 60);
    uint64_t sgd_off = le64(b + 64), sgd_len = le64(b + 72);
    if (w < 1 || h < 1)
        return bad(why, n, "KTX2: image size %ux%u (a 2D texture has both)", w, h);
    *width = w;
    *height = h;
    if (over_budget(w, h, max_texels))
        return IMAGE_TOO_LARGE;
    if (vk_format != 0)
        return bad(why, n, "KTX2: vkFormat %u, not Basis Universal data (KHR_texture_basisu's images have "
                   "VK_FORMAT_UNDEFINED, 0, with ETC1S or UASTC)", vk_format);
    if (type_size != 1)
        return bad(why, n, "KTX2: typeSize %u (must be 1 with VK_FORMAT_UNDEFINED)", type_size);
    if (depth != 0 || layers > 1 || faces != 1)
        return bad(why, n, "KTX2: a %s, not the 2D texture KHR_texture_basisu requires",
                   depth ? "3D texture" : faces != 1 ? "cube map or bad faceCount" : "texture array");
    unsigned max_levels = 1;
    for (uint32_t m = w > h ? w : h; m > 1; m >>= 1)
        max_levels++;
    if (levels < 1 || levels > max_levels)
        return bad(why, n, "KTX2: levelCount %u (a %ux%u Basis Universal image has 1 to %u levels)", levels, w, h,
                   max_levels);
    if (!within(KTX2_HEADER, uint64_t(levels) * KTX2_LEVEL, size))
        return bad(why, n, "KTX2: truncated (%zu bytes; the level index ends at byte %llu)", size,
                   (unsigned long long)(KTX2_HEADER + uint64_t(levels) * KTX2_LEVEL));
    /* Every range the file gives, in 64 bits: the transcoder adds some in 32 (a key/value
     * length of 2^32 - 14 wrapped around and it copied 128 KiB past the end of the file). */
    for (uint32_t l = 0; l < levels; l++) {
        uint64_t off = le64(b + KTX2_HEADER + KTX2_LEVEL * l), len = le64(b + KTX2_HEADER + KTX2_LEVEL * l + 8);
        if (!within(off, len, size) || len == 0)
            return bad(why, n, "KTX2: level %u's %llu bytes at byte %llu do not lie within the file's %zu bytes", l,
                       (unsigned long long)len, (unsigned long long)off, size);
    }
    uint64_t off0 = le64(b + KTX2_HEADER), len0 = le64(b + KTX2_HEADER + 8), raw0 = le64(b + KTX2_HEADER + 16);
    if (kvd_len && !within(kvd_off, kvd_len, size))
        return bad(why, n, "KTX2: the key/value data (%u bytes at byte %u) does not lie within the file's %zu bytes",
                   kvd_len, kvd_off, size);
    if (dfd_len < 16 || !within(dfd_off, dfd_len, size))
        return bad(why, n, "KTX2: the data format descriptor (%u bytes at byte %u) does not lie within the "
                   "file's %zu bytes", dfd_len, dfd_off, size);
    uint32_t model = b[dfd_off + 12]; /* after the total size and the block's two header words */
    uint64_t blocks = uint64_t((w + 3) / 4) * uint64_t((h + 3) / 4);
    if (scheme == 1) {
        if (model != 163)
            return bad(why, n, "KTX2: BasisLZ supercompression with colour model %u (must be ETC1S, 163)", model);
        if (!within(sgd_off, sgd_len, size) || sgd_len == 0)
            return bad(why, n, "KTX2: the BasisLZ global data (%llu bytes at byte %llu) does not lie within the "
                       "file's %zu bytes", (unsigned long long)sgd_len, (unsigned long long)sgd_off, size);
    } else if (scheme == 0 || scheme == 2) {
        if (model != 166)
            return bad(why, n, "KTX2: colour model %u with supercompression %u (must be UASTC, 166; ETC1S comes "
                       "with BasisLZ)", model, scheme);
        /* KTX2 aligns a level of 16-byte blocks to 16 bytes; the transcoder reads them in place. */
        if (scheme == 0 && off0 % 16)
            return bad(why, n, "KTX2: level 0 starts at byte %llu, not a multiple of 16 as KTX2 aligns UASTC blocks",
                       (unsigned long long)off0);
        /* Zstandard inflates level 0 to raw0 bytes: exactly the blocks, 16 bytes each. */
        uint64_t data = scheme == 2 ? raw0 : len0;
        if (data != blocks * 16)
            return bad(why, n, "KTX2: level 0 holds %llu bytes of UASTC blocks%s, a %ux%u image has %llu",
                       (unsigned long long)data, scheme == 2 ? " once inflated" : "", w, h,
                       (unsigned long long)(blocks * 16));
    } else {
        return bad(why, n, "KTX2: supercompression scheme %u (Basis Universal's are BasisLZ, 1, for ETC1S, and "
                   "none, 0, or Zstandard, 2, for UASTC)", scheme);
    }
    if (size > UINT32_MAX)
        return bad(why, n, "KTX2: %zu bytes, more than Basis Universal reads", size);
#if GONIO_BASISU
    /* The transcoder reads UASTC blocks as structs: the file goes where new aligns it when
     * the bytes are not (an image in a GLB's buffer view may start at any byte). */
    std::vector<uint8_t> copy;
    if (reinterpret_cast<uintptr_t>(b) % 16) {
        copy.assign(b, b + size);
        b = copy.data();
    }
    std::call_once(basisu_once, basist::basisu_transcoder_init);
    basist::ktx2_transcoder t;
    if (!t.init(b, uint32_t(size)))
        return bad(why, n, "KTX2: Basis Universal rejects the header, level index, data format descriptor or "
                   "key/value data (corrupt or not ETC1S/UASTC)");
    char v[32];
    if (key_value(t, "KTXorientation", v, sizeof v) && strcmp(v, "rd") != 0)
        return bad(why, n, "KTX2: KTXorientation '%s' (KHR_texture_basisu allows only 'rd', rows down from the "
                   "top left)", v);
    if (key_value(t, "KTXswizzle", v, sizeof v) && strcmp(v, "rgba") != 0)
        return bad(why, n, "KTX2: KTXswizzle '%s' (KHR_texture_basisu allows only 'rgba')", v);
    if (!t.start_transcoding())
        return bad(why, n, "KTX2: Basis Universal cannot read the %s", t.is_etc1s() ? "BasisLZ global data (corrupt)"
                                                                               : "level data (corrupt)");
    size_t texels = size_t(w) * h;
    uint8_t *out = static_cast<uint8_t *>(util_malloc(texels * 4));
    if (!t.transcode_image_level(0, 0, 0, out, uint32_t(texels), basist::transcoder_texture_format::cTFRGBA32, 0, w,
                                 h, -1, -1, nullptr)) {
        free(out);
        return bad(why, n, "KTX2: Basis Universal cannot transcode level 0 of the %ux%u %s image (corrupt%s)", w, h,
                   t.is_etc1s() ? "ETC1S" : "UASTC",
                   scheme == 2 ? " or truncated, or its Zstandard data does not inflate" : " or truncated data");
    }
    /* Red-green textures: Basis Universal keeps green in the alpha slice (ETC1S's RRR + GGG,
     * UASTC's RRRG); glTF samples it from green. */
    bool rg = t.is_etc1s() ? t.get_dfd_total_samples() == 2 && t.get_dfd_channel_id0() == basist::KTX2_DF_CHANNEL_ETC1S_RRR &&
                                 t.get_dfd_channel_id1() == basist::KTX2_DF_CHANNEL_ETC1S_GGG
                           : t.get_dfd_channel_id0() == basist::KTX2_DF_CHANNEL_UASTC_RRRG;
    if (rg)
        for (size_t i = 0; i < texels; i++) {
            out[4 * i + 1] = out[4 * i + 3];
            out[4 * i + 2] = 0;
            out[4 * i + 3] = 255;
        }
    *rgba8 = out;
    return IMAGE_DECODED;
#else
    (void)rgba8;
    return bad(why, n, "KTX2: this gonio was built without Basis Universal (%s)", GONIO_BASISU_MISSING);
#endif
}

} // namespace

extern "C" texture_format texture_format_of(const uint8_t *b, size_t size)
{
    static const uint8_t png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (size >= 8 && memcmp(b, png, 8) == 0)
        return TEXTURE_FORMAT_PNG;
    if (size >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF)
        return TEXTURE_FORMAT_JPEG;
    if (size >= 12 && memcmp(b, "RIFF", 4) == 0 && memcmp(b + 8, "WEBP", 4) == 0)
        return TEXTURE_FORMAT_WEBP;
    if (size >= sizeof KTX2_ID && memcmp(b, KTX2_ID, sizeof KTX2_ID) == 0)
        return TEXTURE_FORMAT_KTX2;
    return TEXTURE_FORMAT_UNKNOWN;
}

extern "C" const char *texture_format_name(texture_format f)
{
    switch (f) {
    case TEXTURE_FORMAT_PNG: return "PNG";
    case TEXTURE_FORMAT_JPEG: return "JPEG";
    case TEXTURE_FORMAT_WEBP: return "WebP";
    case TEXTURE_FORMAT_KTX2: return "KTX2";
    default: return "unknown";
    }
}

extern "C" image_decode_status image_decode(const uint8_t *bytes, size_t size, const char *mime_type,
                                            uint64_t max_texels, uint8_t **rgba8, uint32_t *width, uint32_t *height,
                                            char *why, size_t why_size)
{
    *rgba8 = nullptr;
    *width = *height = 0;
    if (why_size)
        why[0] = 0;
    try {
        switch (texture_format_of(bytes, size)) {
        case TEXTURE_FORMAT_WEBP: return decode_webp(bytes, size, max_texels, rgba8, width, height, why, why_size);
        case TEXTURE_FORMAT_KTX2: return decode_ktx2(bytes, size, max_texels, rgba8, width, height, why, why_size);
        case TEXTURE_FORMAT_PNG:
        case TEXTURE_FORMAT_JPEG:
            return bad(why, why_size, "%s is decoded by the glTF loader's stb path, not here",
                       texture_format_name(texture_format_of(bytes, size)));
        default:
            if (mime_type && mime_type[0])
                return bad(why, why_size, "not a PNG, JPEG, WebP or KTX2 image (its mimeType says %.40s, its bytes "
                           "are none of these)", mime_type);
            return bad(why, why_size, "not a PNG, JPEG, WebP or KTX2 image");
        }
    } catch (const std::bad_alloc &) {
        free(*rgba8);
        *rgba8 = nullptr;
        return bad(why, why_size, "out of memory while decoding");
    } catch (...) {
        free(*rgba8);
        *rgba8 = nullptr;
        return bad(why, why_size, "the decoder failed");
    }
}

extern "C" bool image_decode_has_ktx2(void) { return GONIO_BASISU != 0; }

extern "C" const char *image_decode_ktx2_missing(void)
{
#if GONIO_BASISU
    return "";
#else
    return GONIO_BASISU_MISSING;
#endif
}

extern "C" const char *image_decode_versions(void)
{
    static char line[256];
    int v = WebPGetDecoderVersion();
#if GONIO_BASISU
    snprintf(line, sizeof line, "stb_image (PNG, JPEG), libwebp %d.%d.%d (WebP), Basis Universal %s (KTX2; crate %s)",
             v >> 16 & 255, v >> 8 & 255, v & 255, GONIO_BASISU_VERSION, GONIO_BASISU_CRATE);
#else
    snprintf(line, sizeof line, "stb_image (PNG, JPEG), libwebp %d.%d.%d (WebP), no Basis Universal for KTX2 (%s)",
             v >> 16 & 255, v >> 8 & 255, v & 255, GONIO_BASISU_MISSING);
#endif
    return line;
}
