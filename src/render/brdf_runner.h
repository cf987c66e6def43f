/* brdf_runner.h: a runner that batches BRDF queries through glsl/kernels/brdf_test.comp, i.e.
 * through the renderer's own brdf_*.glsl, for gonio brdf and the unit tests. */
#ifndef GONIO_BRDF_RUNNER_H
#define GONIO_BRDF_RUNNER_H

#include <stddef.h>
#include <stdint.h>

#include "brdf.h"
#include "gpu.h"

/* The GN_FEAT_* the kernel needs for query q (brdf_test.comp is specialised on them, as
 * the renderer's kernels are): its material's (material_features); every feature for the
 * Fresnel queries. */
GnFeatures brdf_query_features(const BrdfQuery *q);

/* Batches BrdfQuery records through brdf_test.comp, a kernel specialised on the features of
 * each batch's queries (one pipeline kept per feature set, BRDF_RUNNER_KERNELS at most; the
 * device keeps the kernels compiled beyond that: gpu.h), or the unspecialised kernel where
 * all_features is set (GONIO_ALL_FEATURES, or a test). */
#define BRDF_RUNNER_KERNELS 32
typedef struct brdf_runner {
    gpu *g;
    gpu_buffer queries, results, sheen;
    gpu_pipeline pipelines[BRDF_RUNNER_KERNELS];
    GnFeatures features[BRDF_RUNNER_KERNELS]; /* pipelines[i]'s, when its pipeline exists */
    uint32_t next;                          /* the slot the next new kernel replaces */
    uint32_t capacity;
    bool all_features;
} brdf_runner;

/* capacity: queries per dispatch (buffers of sizeof(BrdfQuery) and sizeof(BrdfResult) bytes per query). */
void brdf_runner_create(brdf_runner *r, gpu *g, uint32_t capacity);
void brdf_runner_destroy(brdf_runner *r); /* accepts a zeroed struct */
/* Runs n queries (in batches of the capacity) and writes their n results. */
void brdf_runner_run(brdf_runner *r, const BrdfQuery *q, BrdfResult *out, size_t n);

#endif
