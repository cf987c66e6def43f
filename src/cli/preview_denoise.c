/* preview_denoise.c: the preview's denoiser thread (preview_denoise.h). It runs what
 * `render --denoise` runs (prefiltered guides, high quality), so the denoised view shows
 * the image that command writes for the same samples. */
#include "preview_denoise.h"

#include <stdlib.h>
#include <string.h>

#include "denoise.h"
#include "util.h"

static void *worker(void *arg)
{
    preview_denoiser *d = arg;
    pthread_mutex_lock(&d->lock);
    for (;;) {
        while (!d->job_ready && !d->quit)
            pthread_cond_wait(&d->wake, &d->lock);
        if (d->quit)
            break;
        image img = d->job;
        int spp = d->job_spp;
        unsigned generation = d->job_generation;
        memset(&d->job, 0, sizeof d->job);
        d->job_ready = false;
        d->running = true;
        pthread_mutex_unlock(&d->lock);

        /* renderer_resolve's channels: R G B A normal.XYZ albedo.RGB. */
        denoise_channels ch = {{0, 1, 2}, {7, 8, 9}, {4, 5, 6}};
        denoise_info info;
        size_t pixels = (size_t)img.width * (size_t)img.height;
        float *rgba = NULL;
        bool ok = img.num_channels == 10 && denoise_image(&img, &ch, true, &info, "preview");
        if (ok) {
            rgba = util_malloc(4 * pixels * sizeof(float));
            for (size_t p = 0; p < pixels; p++) {
                for (int c = 0; c < 3; c++)
                    rgba[4 * p + (size_t)c] = img.planes[c][p]; /* denoise_image puts R, G, B first */
                rgba[4 * p + 3] = 1.0f;
            }
        }

        pthread_mutex_lock(&d->lock);
        free(d->result);
        d->result = rgba;
        d->result_width = img.width;
        d->result_height = img.height;
        d->result_spp = spp;
        d->result_generation = generation;
        d->result_ok = ok;
        d->result_seconds = ok ? info.seconds + info.setup_seconds : 0;
        d->result_ready = true;
        d->running = false;
        image_destroy(&img);
    }
    pthread_mutex_unlock(&d->lock);
    return NULL;
}

bool preview_denoiser_start(preview_denoiser *d)
{
    memset(d, 0, sizeof *d);
    pthread_mutex_init(&d->lock, NULL);
    pthread_cond_init(&d->wake, NULL);
    if (pthread_create(&d->thread, NULL, worker, d) != 0) {
        util_error("cannot start the denoiser's thread");
        pthread_cond_destroy(&d->wake);
        pthread_mutex_destroy(&d->lock);
        return false;
    }
    d->started = true;
    return true;
}

void preview_denoiser_stop(preview_denoiser *d)
{
    if (!d->started)
        return;
    pthread_mutex_lock(&d->lock);
    d->quit = true;
    pthread_cond_signal(&d->wake);
    pthread_mutex_unlock(&d->lock);
    pthread_join(d->thread, NULL);
    image_destroy(&d->job);
    free(d->result);
    pthread_cond_destroy(&d->wake);
    pthread_mutex_destroy(&d->lock);
    memset(d, 0, sizeof *d);
}

bool preview_denoiser_busy(preview_denoiser *d)
{
    pthread_mutex_lock(&d->lock);
    bool busy = d->job_ready || d->running || d->result_ready;
    pthread_mutex_unlock(&d->lock);
    return busy;
}

void preview_denoiser_submit(preview_denoiser *d, image *img, int spp, unsigned generation)
{
    pthread_mutex_lock(&d->lock);
    image_destroy(&d->job);
    d->job = *img;
    memset(img, 0, sizeof *img);
    d->job_spp = spp;
    d->job_generation = generation;
    d->job_ready = true;
    pthread_cond_signal(&d->wake);
    pthread_mutex_unlock(&d->lock);
}

bool preview_denoiser_take(preview_denoiser *d, float **rgba, int *width, int *height, int *spp,
                           unsigned *generation, double *seconds, bool *ok)
{
    bool ready;
    pthread_mutex_lock(&d->lock);
    ready = d->result_ready;
    if (ready) {
        *rgba = d->result;
        *width = d->result_width;
        *height = d->result_height;
        *spp = d->result_spp;
        *generation = d->result_generation;
        *seconds = d->result_seconds;
        *ok = d->result_ok;
        d->result = NULL;
        d->result_ready = false;
    }
    pthread_mutex_unlock(&d->lock);
    return ready;
}
