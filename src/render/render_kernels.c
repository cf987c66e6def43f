/* render_kernels.c: the render modes' kernels as pipelines (render_kernels.h). */
#include "render_kernels.h"

#include <assert.h>
#include <string.h>

const VkSpecializationInfo *render_kernel_specialize(const render_kernel_key *key, render_spec *spec)
{
    const GnFeatures specialised = render_mode_kernel(key->mode)->specialised;
    const GnFeatures features = (GN_FEAT_ALL & ~specialised) | (key->scene_features & specialised);
    spec->values[0] = key->mode;
    spec->values[GN_SPEC_FEATURES] = (uint32_t)features;
    spec->values[GN_SPEC_WALK_REGS] = key->walk_regs;
    spec->values[GN_SPEC_LOOP_CAP] = render_mode_kernel(key->mode)->batched ? key->loop_cap : 0u;
    spec->values[GN_SPEC_FEATURES_HI] = (uint32_t)(features >> 32);
    spec->values[GN_SPEC_INSTANCES] = key->instances;
    spec->values[GN_SPEC_SAMPLER] = render_mode_kernel(key->mode)->batched ? key->sampler : 0u;
    _Static_assert(GN_SPEC_FEATURES < RENDER_SPEC_COUNT && GN_SPEC_FEATURES_HI < RENDER_SPEC_COUNT &&
                       GN_SPEC_WALK_REGS < RENDER_SPEC_COUNT && GN_SPEC_LOOP_CAP < RENDER_SPEC_COUNT &&
                       GN_SPEC_INSTANCES < RENDER_SPEC_COUNT && GN_SPEC_SAMPLER < RENDER_SPEC_COUNT,
                   "a specialisation constant's id beyond render_spec's values");
    for (uint32_t i = 0; i < RENDER_SPEC_COUNT; i++)
        spec->entries[i] = (VkSpecializationMapEntry){i, i * (uint32_t)sizeof(uint32_t), sizeof(uint32_t)};
    spec->info = (VkSpecializationInfo){RENDER_SPEC_COUNT, spec->entries, sizeof spec->values, spec->values};
    return &spec->info;
}

gpu_pipeline *render_kernels_get(render_kernels *k, gpu *g, const render_kernel_key *key, const gpu_binding *b,
                                 uint32_t num_bindings, uint32_t generation)
{
    const uint32_t mode = key->mode;
    gpu_pipeline *p = &k->pipelines[mode];
    render_spec spec;
    const VkSpecializationInfo *info = render_kernel_specialize(key, &spec);
    assert(mode < GN_MODE_COUNT);
    if (p->pipeline && memcmp(k->spec[mode], spec.values, sizeof spec.values))
        gpu_pipeline_destroy(g, p); /* built for other features: a new kernel */
    if (!p->pipeline) {
        const render_kernel *kernel = render_mode_kernel(mode);
        gpu_pipeline_desc pd = {
            .name = kernel->name, .code = kernel->code, .code_size = kernel->code_size,
            .local_size = {GN_TILE_X, GN_TILE_Y, 1}, .push_size = sizeof(GnPush),
            .bindings = b, .num_bindings = num_bindings, .specialization = info};
        gpu_pipeline_create(g, p, &pd);
        memcpy(k->spec[mode], spec.values, sizeof spec.values);
    } else if (k->bound[mode] != generation) {
        gpu_pipeline_bind(g, p, b, num_bindings);
    }
    k->bound[mode] = generation;
    return p;
}

void render_kernels_destroy(render_kernels *k, gpu *g)
{
    for (uint32_t i = 0; g && i < GN_MODE_COUNT; i++)
        gpu_pipeline_destroy(g, &k->pipelines[i]);
    memset(k, 0, sizeof *k);
}
