/* progress.c: the progress display of a render on stderr (progress.h). */
#include "progress.h"

#include <stdio.h>
#include <unistd.h>

static double progress_fraction(const render_settings *s, int done, double elapsed)
{
    double f = s->time_limit > 0 ? elapsed / s->time_limit : (double)done / s->spp;
    return f < 1 ? f : 1;
}

/* One report: the bar or a line; `end` replaces the ETA ("done", "interrupted"). */
static void progress_show(const render_settings *s, const cli_progress *p, int done, double elapsed,
                          const char *end)
{
    const double pixels = (double)s->width * s->height, rate = elapsed > 0 ? done / elapsed : 0;
    const double frac = progress_fraction(s, done, elapsed);
    const int width = 30, fill = (int)(frac * width);
    char spp[48], eta[48];
    if (s->time_limit > 0)
        snprintf(spp, sizeof spp, "%d spp", done);
    else
        snprintf(spp, sizeof spp, "%d/%d spp", done, s->spp);
    if (end)
        snprintf(eta, sizeof eta, "%s", end);
    else if (s->time_limit > 0)
        snprintf(eta, sizeof eta, "ETA %.1f s", s->time_limit > elapsed ? s->time_limit - elapsed : 0);
    else
        snprintf(eta, sizeof eta, "ETA %.1f s", rate > 0 ? (s->spp - done) / rate : 0);
    if (p->tty)
        fprintf(stderr, "\r[%.*s%*s] ", fill, "##############################", width - fill, "");
    else
        fputs("gonio: ", stderr);
    /* Camera rays per second: whole paths in path mode, as in the summary line. */
    fprintf(stderr, "%3d%%  %s  %.1f spp/s  %.2f %s  %.1f s  %s%s", (int)(frac * 100), spp, rate,
            rate * pixels * 1e-6, s->mode == GN_MODE_PATH ? "M paths/s" : "Mrays/s", elapsed, eta,
            p->tty ? "\x1b[K" : "\n");
    fflush(stderr);
}

/* After a batch: the bar at most ten times a second, a plain line when one is due. */
static void progress_update(const render_settings *s, cli_progress *p, int done, double elapsed)
{
    double frac = progress_fraction(s, done, elapsed);
    int tenth = (int)(frac * 10);
    if (p->tty && elapsed - p->last >= 0.1) {
        p->last = elapsed;
        progress_show(s, p, done, elapsed, NULL);
    } else if (!p->tty && elapsed >= 1 && tenth > p->tenth && frac < 1) {
        p->tenth = tenth;
        progress_show(s, p, done, elapsed, NULL);
    }
}

void cli_progress_report(void *user, const render_settings *s, render_progress_event event, int done,
                         double elapsed)
{
    cli_progress *p = user;
    switch (event) {
    case RENDER_PROGRESS_START:
        *p = (cli_progress){.tty = isatty(2), .tenth = -1};
        break;
    case RENDER_PROGRESS_BATCH:
        progress_update(s, p, done, elapsed);
        break;
    case RENDER_PROGRESS_END:
        /* The last state: where an interrupt left it, or done (a log only hears of it when
         * it heard of the render at all). */
        if (p->tty || p->tenth >= 0) {
            progress_show(s, p, done, elapsed, s->stop && *s->stop ? "interrupted" : "done");
            if (p->tty)
                fputc('\n', stderr);
        }
        break;
    }
}
