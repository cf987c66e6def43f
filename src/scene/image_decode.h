/* image_decode.h: the image formats of glTF's texture extensions, encoded bytes in, RGBA8 out:
 * WebP (EXT_texture_webp) through libwebp, KTX2 with Basis Universal supercompression
 * (KHR_texture_basisu: ETC1S with BasisLZ, UASTC with or without Zstandard) through Basis
 * Universal's transcoder. PNG and JPEG, glTF's core formats, are recognised here but decoded
 * by the glTF loader's own stb path (tinygltf's). A narrow C interface: the loader's only use
 * is image_decode after texture_format_of. */
#ifndef GONIO_IMAGE_DECODE_H
#define GONIO_IMAGE_DECODE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum texture_format {
    TEXTURE_FORMAT_UNKNOWN = 0,
    TEXTURE_FORMAT_PNG,
    TEXTURE_FORMAT_JPEG,
    TEXTURE_FORMAT_WEBP,
    TEXTURE_FORMAT_KTX2,
    TEXTURE_FORMAT_COUNT
} texture_format;

/* The format the bytes' signature says (not the file name or the glTF mimeType). */
texture_format texture_format_of(const uint8_t *bytes, size_t size);
/* "PNG", "JPEG", "WebP", "KTX2", or "unknown". */
const char *texture_format_name(texture_format f);

typedef enum image_decode_status {
    IMAGE_DECODED = 0,   /* *rgba8 holds width * height * 4 bytes (free() them) */
    IMAGE_BAD,           /* why says what is wrong with the bytes, or what is missing */
    IMAGE_TOO_LARGE,     /* width x height, as the file declares it, is over max_texels */
} image_decode_status;

/* Decodes a WebP or KTX2 image into RGBA8, rows top to bottom (as glTF's texture coordinates
 * have them: v = 0 is the top row), alpha 255 where the image has none. The declared size is
 * checked against max_texels before anything is allocated, and every size and offset the file
 * gives against its bytes, so memory stays bounded by the file and the budget. mime_type (the
 * glTF image's, or NULL) only sharpens the message when the bytes are not what it says.
 * KTX2: level 0 of a 2D texture (KHR_texture_basisu allows no other); KTX2's rows run down
 * from the top-left ("rd", the only KTXorientation the extension allows), so none are
 * flipped. A red-green texture (ETC1S's RRR+GGG slices, UASTC's RRRG) has its green moved
 * from where Basis Universal keeps it (alpha) to green. */
image_decode_status image_decode(const uint8_t *bytes, size_t size, const char *mime_type, uint64_t max_texels,
                                 uint8_t **rgba8, uint32_t *width, uint32_t *height, char *why, size_t why_size);

/* Whether this build reads KTX2 (Basis Universal was fetched and built in); when not,
 * image_decode_ktx2_missing says why. */
bool image_decode_has_ktx2(void);
const char *image_decode_ktx2_missing(void);
/* The image decoders and their versions, one line: "stb_image (PNG, JPEG), libwebp 1.2.4
 * (WebP), Basis Universal 1.16 (KTX2; crate ...)", or why Basis Universal is missing. */
const char *image_decode_versions(void);

#ifdef __cplusplus
}
#endif

#endif
