/* spirv_specialise.h: a kernel's specialisation constants folded into its SPIR-V on the host,
 * before the driver sees it (SPIRV-Tools' optimizer: the constants' values set and frozen,
 * then the branches and functions they make dead removed).
 *
 * Why: lavapipe translates and optimises the whole module it is given before its own
 * dead-code passes see the constants, so a kernel specialised on a scene's few features
 * costs it as much as the kernel with all of them. Handing it the module already folded
 * takes about 40 % off a small render's CPU time (docs/performance.md, "Specialisation on
 * the host"), with the same pixels: the constants are those the driver would have applied,
 * and the passes only remove code no value of the constants can reach. */
#ifndef GONIO_SPIRV_SPECIALISE_H
#define GONIO_SPIRV_SPECIALISE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <vulkan/vulkan.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The module code (code_size bytes) with spec's constants folded in, into a new buffer
 * (free()) and its size in bytes. False, with nothing allocated, when spec is NULL or has
 * no constants (why ""), or when it cannot be done (why says why: a constant that is not 4
 * bytes, the optimizer's error). The caller then gives the driver the module as it is, with
 * spec, which is always correct. */
bool spirv_specialise(const uint32_t *code, size_t code_size, const VkSpecializationInfo *spec, uint32_t **out,
                      size_t *out_size, char *why, size_t why_size);

#ifdef __cplusplus
}
#endif

#endif
