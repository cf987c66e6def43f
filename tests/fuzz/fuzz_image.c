/* fuzz_image.c: libFuzzer target over image_decode, the WebP and KTX2 decoders of glTF's
 * texture extensions (libwebp, Basis Universal's transcoder), with the input's first byte
 * choosing the format: the signature is written before the rest, so mutations go into the
 * headers and data rather than into signatures that fail at once. The texel budget is a
 * small one, so declared sizes past it are refused and those within it decoded. Any input
 * must give an image or a reason, never a crash, a sanitizer report, a leak or a hang. */
#include <stdlib.h>
#include <string.h>

#include "image_decode.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const uint8_t ktx2[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
    uint8_t *buf, *rgba = NULL;
    uint32_t w, h;
    char why[512];
    if (size < 1 || size > (1u << 20))
        return 0;
    buf = malloc(size + 12);
    if (data[0] & 1) { /* KTX2: the signature, then the rest */
        memcpy(buf, ktx2, 12);
        memcpy(buf + 12, data + 1, size - 1);
        size = size - 1 + 12;
    } else { /* WebP: RIFF, the input's size, WEBP, then the rest */
        uint32_t n = (uint32_t)(size - 1 + 4);
        memcpy(buf, "RIFF", 4);
        memcpy(buf + 4, &n, 4);
        memcpy(buf + 8, "WEBP", 4);
        memcpy(buf + 12, data + 1, size - 1);
        size = size - 1 + 12;
    }
    if (image_decode(buf, size, NULL, 1u << 20, &rgba, &w, &h, why, sizeof why) == IMAGE_DECODED)
        free(rgba);
    free(buf);
    return 0;
}
