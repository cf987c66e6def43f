/* brdf_runner.c: the runner of the BRDF test kernel (brdf_runner.h). */
#include "brdf_runner.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "brdf_test.h" /* spv_brdf_test, generated from glsl/kernels/brdf_test.comp */
#include "render_material.h"

GnFeatures brdf_query_features(const BrdfQuery *q)
{
    if (q->op & BRDF_OP_FRESNEL)
        return GN_FEAT_ALL;
    /* the material's, as the renderer specialises its kernels on them; the NDF queries read
     * the base's GGX at any roughness (where the material alone would have its mirror) */
    return material_features(&q->material) | (q->op & BRDF_OP_NDF ? GN_FEAT_GGX : GN_FEAT_NONE);
}

void brdf_runner_create(brdf_runner *r, gpu *g, uint32_t capacity)
{
    assert(capacity > 0);
    memset(r, 0, sizeof *r);
    r->g = g;
    r->capacity = capacity;
    r->all_features = getenv("GONIO_ALL_FEATURES") != NULL;
    gpu_buffer_create(g, &r->queries, sizeof(BrdfQuery) * (VkDeviceSize)capacity,
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_create(g, &r->results, sizeof(BrdfResult) * (VkDeviceSize)capacity,
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_buffer_create_texels_as(g, &r->sheen, brdf_sheen_table, sizeof(float) * BRDF_SHEEN_TABLE_SIZE,
                                VK_FORMAT_R32_UINT);
}

/* The kernel specialised on features: a kept one, or a new one in the next slot. */
static gpu_pipeline *runner_pipeline(brdf_runner *r, GnFeatures features)
{
    gpu_pipeline *p;
    for (uint32_t i = 0; i < BRDF_RUNNER_KERNELS; i++)
        if (r->pipelines[i].pipeline && r->features[i] == features)
            return &r->pipelines[i];
    p = &r->pipelines[r->next];
    gpu_pipeline_destroy(r->g, p);
    r->features[r->next] = features;
    r->next = (r->next + 1) % BRDF_RUNNER_KERNELS;
    const gpu_binding bind[] = {
        {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->queries},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &r->results},
        {BRDF_BIND_SHEEN, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &r->sheen},
    };
    /* brdf_test.comp's FEATURES and FEATURES_HI, as path.comp's */
    const uint32_t words[2] = {(uint32_t)features, (uint32_t)(features >> 32)};
    const VkSpecializationMapEntry entries[2] = {{GN_SPEC_FEATURES, 0, sizeof(uint32_t)},
                                                 {GN_SPEC_FEATURES_HI, sizeof(uint32_t), sizeof(uint32_t)}};
    VkSpecializationInfo spec = {2, entries, sizeof words, words};
    gpu_pipeline_desc pd = {.name = "brdf_test", .code = spv_brdf_test, .code_size = sizeof spv_brdf_test,
                            .local_size = {64, 1, 1}, .push_size = 4, .bindings = bind, .num_bindings = 3,
                            .specialization = &spec};
    gpu_pipeline_create(r->g, p, &pd);
    return p;
}

void brdf_runner_destroy(brdf_runner *r)
{
    if (!r->g)
        return;
    for (uint32_t i = 0; i < BRDF_RUNNER_KERNELS; i++)
        gpu_pipeline_destroy(r->g, &r->pipelines[i]);
    gpu_buffer_destroy(r->g, &r->sheen);
    gpu_buffer_destroy(r->g, &r->results);
    gpu_buffer_destroy(r->g, &r->queries);
    memset(r, 0, sizeof *r);
}

void brdf_runner_run(brdf_runner *r, const BrdfQuery *q, BrdfResult *out, size_t n)
{
    for (size_t done = 0; done < n;) {
        uint32_t count = (uint32_t)(n - done < r->capacity ? n - done : r->capacity);
        GnFeatures features = GN_FEAT_NONE;
        VkCommandBuffer cmd;
        for (uint32_t i = 0; i < count && !r->all_features && features != GN_FEAT_ALL; i++)
            features |= brdf_query_features(&q[done + i]);
        gpu_pipeline *p = runner_pipeline(r, r->all_features ? GN_FEAT_ALL : features);
        gpu_buffer_upload(r->g, &r->queries, q + done, sizeof *q * count, 0);
        cmd = gpu_begin(r->g);
        gpu_dispatch(cmd, p, &count, count, 1, 1);
        gpu_submit_wait(r->g, cmd);
        gpu_buffer_download(r->g, &r->results, out + done, sizeof *out * count, 0);
        done += count;
    }
}
