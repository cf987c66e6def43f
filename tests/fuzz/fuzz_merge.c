/* fuzz_merge.c: libFuzzer target over `gonio merge` of two inputs, its header and pixel
 * checks (sizes, windows, channels, identities, seeds, sample counts) and the merge itself.
 * The input is two EXR files: a 4-byte little-endian length n, n bytes of the first file,
 * the rest the second (tests/fuzz/run.sh makes seeds of that form from tiles and seeds of
 * one render). Any input must give a merged file or exit status 1 with an error, never a
 * crash, a sanitizer report, a leak or a hang; and a merge that succeeds must have written
 * only finite values (an abort otherwise: the fuzzer reports it). */
#include <math.h>

#include "cli.h"
#include "fuzz_common.h"
#include "image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint32_t n;
    image out;
    if (size < 4)
        return 0;
    memcpy(&n, data, 4);
    if (n > size - 4)
        return 0;
    util_set_quiet(true);
    util_set_silent(true);
    const char *a = fuzz_write_input("a.exr", data + 4, n);
    const char *b = fuzz_write_input("b.exr", data + 4 + n, size - 4 - n);
    const char *o = fuzz_input_path("out.exr");
    char *argv[] = {"merge", (char *)a, (char *)b, "-o", (char *)o, NULL};
    unlink(o);
    if (cmd_merge(5, argv) == 0) {
        if (!image_read_exr(&out, o))
            abort();
        for (int c = 0; c < out.num_channels; c++)
            for (size_t p = 0; p < (size_t)out.width * (size_t)out.height; p++)
                if (!isfinite(out.planes[c][p]))
                    abort();
        image_destroy(&out);
    }
    return 0;
}
