/* A progress bar on stderr for the rsmooth command: shown only when stderr is a terminal and the
 * work has taken more than a second, so scripts and quick runs see nothing; --progress forces it
 * (from the start, and into a file or pipe as one line a second). */
#ifndef RSMOOTH_CLI_PROGRESS_H
#define RSMOOTH_CLI_PROGRESS_H

#include <stdbool.h>

typedef struct cli_progress {
    bool enabled; /* stderr is a terminal (or --progress) and the user did not ask for quiet */
    bool lines;   /* forced where stderr is no terminal: whole lines, no carriage returns */
    double show_after_ms, redraw_ms;
    bool drawn;      /* something is on the line, to be cleared */
    bool shown;      /* the bar was drawn at least once */
    double start_ms; /* when the work began */
    double last_draw_ms;
    double stage_from, stage_to; /* the current stage's share of the whole bar */
    const char *stage;           /* "reading", "smoothing", "writing" */
} cli_progress;

/* `force` (--progress): drawn from the start, even where stderr is not a terminal. `quiet` wins. */
void cli_progress_init(cli_progress *bar, bool quiet, bool force);

/* Enters a stage that covers [from, to] of the bar. */
void cli_progress_stage(cli_progress *bar, const char *stage, double from, double to);

/* Reports `fraction` of the current stage done. */
void cli_progress_update(cli_progress *bar, double fraction);

/* rsmooth_progress_fn adapter: `user` is a cli_progress. */
void cli_progress_callback(void *user, double fraction);

/* The work is done: the bar at 100% ("done"), drawn however soon after the last drawing, where it
 * was shown or is forced (--progress), so that a quick run's bar does not end at its first state.
 * --progress on a terminal leaves that line; otherwise cli_progress_clear clears it as before. */
void cli_progress_done(cli_progress *bar);

/* Clears the bar's line (before printing anything else, and at the end). */
void cli_progress_clear(cli_progress *bar);

double cli_now_ms(void);

#endif
