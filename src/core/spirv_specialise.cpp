/* spirv_specialise.cpp: spirv_specialise (spirv_specialise.h) by SPIRV-Tools' optimizer. */
#include "spirv_specialise.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include <spirv-tools/optimizer.hpp>

bool spirv_specialise(const uint32_t *code, size_t code_size, const VkSpecializationInfo *spec, uint32_t **out,
                      size_t *out_size, char *why, size_t why_size)
{
    if (why_size)
        why[0] = '\0';
    if (!spec || !spec->mapEntryCount)
        return false;
    try {
        std::unordered_map<uint32_t, std::vector<uint32_t>> values;
        for (uint32_t i = 0; i < spec->mapEntryCount; i++) {
            const VkSpecializationMapEntry &e = spec->pMapEntries[i];
            uint32_t v;
            if (e.size != sizeof v || e.offset + sizeof v > spec->dataSize) {
                snprintf(why, why_size, "constant %u is %zu bytes (only 4-byte constants are folded)", e.constantID,
                         e.size);
                return false;
            }
            memcpy(&v, static_cast<const char *>(spec->pData) + e.offset, sizeof v);
            values[e.constantID] = {v};
        }
        std::string first_error;
        spvtools::Optimizer opt(SPV_ENV_VULKAN_1_1);
        opt.SetMessageConsumer([&first_error](spv_message_level_t level, const char *, const spv_position_t &,
                                              const char *message) {
            if (level <= SPV_MSG_ERROR && first_error.empty())
                first_error = message;
        });
        /* The constants' values (an id the module lacks is skipped), then constants; what
         * folds; the branches on them and what only they reached. */
        opt.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(values))
            .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
            .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
            .RegisterPass(spvtools::CreateDeadBranchElimPass())
            .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
            .RegisterPass(spvtools::CreateAggressiveDCEPass());
        /* (not validated again here: the build checked the module with spirv-val, and the
         * validation layer, where it is on, checks the module the driver is given) */
        spvtools::OptimizerOptions options;
        options.set_run_validator(false);
        std::vector<uint32_t> folded;
        if (code_size % 4 || !opt.Run(code, code_size / 4, &folded, options) || folded.empty()) {
            snprintf(why, why_size, "SPIRV-Tools' optimizer failed%s%s", first_error.empty() ? "" : ": ",
                     first_error.c_str());
            return false;
        }
        *out = static_cast<uint32_t *>(malloc(folded.size() * 4));
        if (!*out) {
            snprintf(why, why_size, "out of memory");
            return false;
        }
        memcpy(*out, folded.data(), folded.size() * 4);
        *out_size = folded.size() * 4;
        return true;
    } catch (const std::exception &e) {
        snprintf(why, why_size, "SPIRV-Tools' optimizer failed: %s", e.what());
        return false;
    } catch (...) {
        snprintf(why, why_size, "SPIRV-Tools' optimizer failed");
        return false;
    }
}
