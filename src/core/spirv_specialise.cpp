// spirv_specialise.cpp: spirv_specialise (spirv_specialise.h) by SPIRV-Tools' optimizer.
#include "spirv_specialise.h"

#include <cstdlib>
#include <cstring>
#include <unordered_map>
#include <vector>

#include <spirv-tools/optimizer.hpp>

bool spirv_specialise(const uint32_t *code, size_t code_size, const VkSpecializationInfo *spec, uint32_t **out,
                      size_t *out_size)
{
    if (!spec || !spec->mapEntryCount || code_size % 4 || getenv("GONIO_DRIVER_SPECIALISE"))
        return false;
    std::unordered_map<uint32_t, std::vector<uint32_t>> values;
    for (uint32_t i = 0; i < spec->mapEntryCount; i++) {
        const VkSpecializationMapEntry &e = spec->pMapEntries[i];
        uint32_t v;
        if (e.size != sizeof v || e.offset + sizeof v > spec->dataSize)
            return false;
        memcpy(&v, static_cast<const char *>(spec->pData) + e.offset, sizeof v);
        values[e.constantID] = {v};
    }
    try {
        spvtools::Optimizer opt(SPV_ENV_VULKAN_1_1);
        opt.SetMessageConsumer([](spv_message_level_t, const char *, const spv_position_t &, const char *) {});
        // The constants' values (an id the module lacks is skipped), then constants; what
        // folds; the branches on them and what only they reached.
        opt.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(values))
            .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
            .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
            .RegisterPass(spvtools::CreateDeadBranchElimPass())
            .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
            .RegisterPass(spvtools::CreateAggressiveDCEPass());
        spvtools::OptimizerOptions options;
        options.set_run_validator(false); // (the build validated the module: spirv-val)
        std::vector<uint32_t> folded;
        if (!opt.Run(code, code_size / 4, &folded, options) || folded.empty())
            return false;
        *out = static_cast<uint32_t *>(malloc(folded.size() * 4));
        if (!*out)
            return false;
        memcpy(*out, folded.data(), folded.size() * 4);
        *out_size = folded.size() * 4;
        return true;
    } catch (...) {
        return false;
    }
}
