/* progress.h: a render's progress on stderr, as renderer_render reports it (its
 * render_settings.progress callback). On a terminal, a bar redrawn in place; otherwise (a
 * log) plain lines, one when a render has run for a second and one at each further tenth of
 * the work, so short renders print none. With a time limit the work is the time, not the spp. */
#ifndef GONIO_PROGRESS_H
#define GONIO_PROGRESS_H

#include <stdbool.h>

#include "render.h"

typedef struct cli_progress {
    bool tty;
    int tenth;      /* plain lines: the last tenth printed, -1 = none yet */
    double last;    /* terminal: when the bar was last drawn */
} cli_progress;

/* A render_progress_fn; user: a cli_progress (set up by RENDER_PROGRESS_START). */
void cli_progress_report(void *user, const render_settings *s, render_progress_event event, int done,
                         double elapsed);

#endif
