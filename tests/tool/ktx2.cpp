/* ktx2.cpp: testtool ktx2 etc1s|uastc|uastc-zstd IN.png OUT.ktx2 [rg], the tests' writer of
 * KHR_texture_basisu images: Basis Universal's own encoder (the sources deps/basisu.sh
 * fetches) turns a PNG into a KTX2 file, ETC1S with BasisLZ, or UASTC raw or with
 * Zstandard, one level, rows top-down as the PNG has them. `rg`: a red-green texture, red
 * in RGB and green in the alpha slice (the encoder's rrrg swizzle), which ETC1S's DFD then
 * names RRR + GGG and UASTC's RRRG, as KHR_texture_basisu's red-green textures are stored. */
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <gonio_basisu.h>

extern "C" {
#include "image.h"
}

#if GONIO_BASISU
#include <basisu_comp.h>

extern "C" int tool_ktx2(const char *mode, const char *in, const char *out, bool rg)
{
    bool uastc = !strcmp(mode, "uastc") || !strcmp(mode, "uastc-zstd");
    if (!uastc && strcmp(mode, "etc1s") != 0) {
        fprintf(stderr, "testtool ktx2: mode %s (etc1s, uastc or uastc-zstd)\n", mode);
        return 2;
    }
    uint8_t *px = nullptr;
    int w = 0, h = 0;
    if (!image_read_png(in, &px, &w, &h)) {
        fprintf(stderr, "testtool ktx2: cannot read %s\n", in);
        return 1;
    }
    basisu::basisu_encoder_init();
    basisu::job_pool pool(1);
    basisu::basis_compressor_params p;
    p.m_source_images.push_back(basisu::image(px, uint32_t(w), uint32_t(h), 4));
    free(px);
    p.m_uastc = uastc;
    p.m_create_ktx2_file = true;
    p.m_ktx2_uastc_supercompression = !strcmp(mode, "uastc-zstd") ? basist::KTX2_SS_ZSTANDARD : basist::KTX2_SS_NONE;
    p.m_ktx2_srgb_transfer_func = !rg;
    p.m_quality_level = 255; /* ETC1S: the largest codebooks */
    p.m_perceptual = false;  /* errors measured per channel, as the tests do */
    p.m_mip_gen = false;
    p.m_status_output = false;
    p.m_multithreading = false;
    p.m_pJob_pool = &pool;
    if (rg) {
        const char sw[4] = {0, 0, 0, 1};
        memcpy(p.m_swizzle, sw, 4);
        p.m_force_alpha = true;
    }
    basisu::basis_compressor c;
    if (!c.init(p) || c.process() != basisu::basis_compressor::cECSuccess) {
        fprintf(stderr, "testtool ktx2: Basis Universal cannot encode %s\n", in);
        return 1;
    }
    std::vector<uint8_t> file(c.get_output_ktx2_file().begin(), c.get_output_ktx2_file().end());
    if (rg && !uastc && file.size() >= 80) {
        /* The encoder names its two ETC1S slices RGB + AAA; the data is R and G. */
        uint32_t dfd = uint32_t(file[48]) | uint32_t(file[49]) << 8 | uint32_t(file[50]) << 16 | uint32_t(file[51]) << 24;
        if (dfd + 60 <= file.size()) {
            file[dfd + 28 + 3] = uint8_t((file[dfd + 28 + 3] & 0xF0) | 3); /* sample 0: KHR_DF_CHANNEL_ETC1S_RRR */
            file[dfd + 44 + 3] = uint8_t((file[dfd + 44 + 3] & 0xF0) | 4); /* sample 1: KHR_DF_CHANNEL_ETC1S_GGG */
        }
    } else if (rg && file.size() >= 80) {
        uint32_t dfd = uint32_t(file[48]) | uint32_t(file[49]) << 8 | uint32_t(file[50]) << 16 | uint32_t(file[51]) << 24;
        if (dfd + 44 <= file.size())
            file[dfd + 28 + 3] = uint8_t((file[dfd + 28 + 3] & 0xF0) | 5); /* KHR_DF_CHANNEL_UASTC_RRRG */
    }
    FILE *f = fopen(out, "wb");
    if (!f || fwrite(file.data(), 1, file.size(), f) != file.size() || fclose(f) != 0) {
        fprintf(stderr, "testtool ktx2: cannot write %s\n", out);
        return 1;
    }
    return 0;
}
#else
extern "C" int tool_ktx2(const char *, const char *, const char *, bool)
{
    fprintf(stderr, "testtool ktx2: built without Basis Universal (%s)\n", GONIO_BASISU_MISSING);
    return 77;
}
#endif
