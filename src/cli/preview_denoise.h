/* preview_denoise.h: the preview's denoiser thread. `gonio preview` hands it the resolved
 * image (beauty, albedo, normal) when the render has settled, and goes on rendering and
 * answering the window while OIDN (src/core/denoise.h) works; the main loop picks the result
 * up when it is done. One job at a time: a new one is taken only once the last result has
 * been collected. */
#ifndef GONIO_PREVIEW_DENOISE_H
#define GONIO_PREVIEW_DENOISE_H

#include <pthread.h>
#include <stdbool.h>

#include "image.h"

typedef struct preview_denoiser {
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    bool started, quit;
    /* The job: an image of R, G, B, A, normal.X/Y/Z, albedo.R/G/B (renderer_resolve's
     * order), its spp and the accumulation it belongs to. */
    image job;
    int job_spp;
    unsigned job_generation;
    bool job_ready, running;
    /* The result: RGBA floats per pixel (A = 1), as the display kernel reads its input. */
    float *result;
    int result_width, result_height, result_spp;
    unsigned result_generation;
    bool result_ready, result_ok;
    double result_seconds;
} preview_denoiser;

/* Starts the thread; false (with an error) when it cannot be made. */
bool preview_denoiser_start(preview_denoiser *d);
/* Stops and joins it (waiting for a denoise under way); accepts a zeroed struct. */
void preview_denoiser_stop(preview_denoiser *d);
/* Whether a job is queued, running, or its result not yet taken. */
bool preview_denoiser_busy(preview_denoiser *d);
/* Queues *img (taken: *img is zeroed) for accumulation `generation` at spp samples. */
void preview_denoiser_submit(preview_denoiser *d, image *img, int spp, unsigned generation);
/* The finished result, when there is one: true with *rgba (the caller frees it), its size,
 * spp, generation, seconds and whether it succeeded (false: an error was printed). */
bool preview_denoiser_take(preview_denoiser *d, float **rgba, int *width, int *height, int *spp,
                           unsigned *generation, double *seconds, bool *ok);

#endif
