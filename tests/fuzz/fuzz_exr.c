/* fuzz_exr.c: libFuzzer target over image_read_exr (scanline and tiled, every compression
 * OpenEXR reads). Any input must give an image or false with an error, never a crash, a
 * sanitizer report, a leak or a hang. */
#include "fuzz_common.h"
#include "image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    image img;
    util_set_quiet(true);
    util_set_silent(true);
    if (image_read_exr(&img, fuzz_write_input("in.exr", data, size)))
        image_destroy(&img);
    return 0;
}
