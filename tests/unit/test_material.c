/* test_material.c: the one declaration of a material (glsl/lib/material.h) end to end: the
 * kernels' reader (tests/kernels/material_test.comp runs material_at) gives back every field
 * as the host wrote it. */
#include <stdio.h>
#include <string.h>

#include "gpu.h"
#include "material_test.h" /* spv_material_test: tests/kernels/material_test.comp */
#include "shared.h"
#include "test.h"
#include "util.h"

/* Every field's name by word, from the table (a field of n components names n words). */
static const char *word_names[GN_MATERIAL_WORDS];
#define NAME_FIELD(name, type, word)                       \
    for (int k = 0; k < GN_MAT_COUNT_##type; k++)          \
        word_names[(word) + k] = #name;
#define NAME_PARAM(name, type, word, ext, json, def, lo, hi, rule, brdf) NAME_FIELD(name, type, word)
#define NAME_TEX(name, word, ext, json, space, gate, uses) NAME_FIELD(name, uint, word)

/* Materials whose every word holds its own value (a float that is also a distinct bit
 * pattern), read by material_at on the GPU and written back: each word must come back as
 * it went, so two fields of one type swapped in the reader (or in the table's places) fail. */
TEST(material, gpu_reader_round_trip)
{
    enum { N = 3 };
    GnMaterial in[N], out[N];
    float *w = (float *)in;
    gpu g = {0};
    gpu_buffer texels, result;
    gpu_pipeline p;
    GN_MATERIAL(NAME_PARAM, NAME_TEX, NAME_FIELD)
    for (uint32_t i = 0; i < GN_MATERIAL_WORDS; i++)
        CHECKF(word_names[i] != NULL, "word %u of GnMaterial is in no row of GN_MATERIAL", i);
    for (uint32_t i = 0; i < N * GN_MATERIAL_WORDS; i++)
        w[i] = 1.0f + (float)i * 0.25f; /* distinct, normal floats */
    if (!test_open_gpu(&g))
        return;
    gpu_buffer_create_texels(&g, &texels, in, sizeof in);
    gpu_buffer_create(&g, &result, sizeof out, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    memset(result.mapped, 0, sizeof out);
    {
        const gpu_binding bind[] = {{GN_BIND_MATERIALS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &texels},
                                    {GN_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &result}};
        gpu_pipeline_desc pd = {.name = "material_test", .code = spv_material_test,
                                .code_size = sizeof spv_material_test, .local_size = {64, 1, 1},
                                .push_size = sizeof(GnPush), .bindings = bind, .num_bindings = 2};
        GnPush push = {N, 0, 0, 0};
        VkCommandBuffer cmd;
        gpu_pipeline_create(&g, &p, &pd);
        cmd = gpu_begin(&g);
        gpu_dispatch(cmd, &p, &push, N, 1, 1);
        gpu_submit_wait(&g, cmd);
    }
    memcpy(out, result.mapped, sizeof out);
    {
        const uint32_t *a = (const uint32_t *)in, *b = (const uint32_t *)out;
        int bad = 0;
        for (uint32_t i = 0; i < N * GN_MATERIAL_WORDS; i++)
            if (a[i] != b[i] && bad++ < 8)
                CHECKF(0, "material %u, word %u (%s): wrote 0x%08x, the GPU read 0x%08x", i / GN_MATERIAL_WORDS,
                       i % GN_MATERIAL_WORDS, word_names[i % GN_MATERIAL_WORDS], a[i], b[i]);
        CHECKF(bad == 0, "%d of %u words differ", bad, N * GN_MATERIAL_WORDS);
    }
    gpu_pipeline_destroy(&g, &p);
    gpu_buffer_destroy(&g, &result);
    gpu_buffer_destroy(&g, &texels);
    gpu_destroy(&g);
}
