/* The rsmooth command's progress bar (see cli_progress.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

#define SHOW_AFTER_MS 1000.0 /* quick runs never show a bar */
#define REDRAW_MS 100.0
#define LINE_MS 1000.0 /* into a file: a line a second */
#define WIDTH 30

double cli_now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

void cli_progress_init(cli_progress *bar, bool quiet, bool force) {
    bool terminal = isatty(STDERR_FILENO);
    bar->enabled = !quiet && (terminal || force);
    bar->lines = !terminal;
    bar->show_after_ms = force ? 0 : SHOW_AFTER_MS;
    bar->redraw_ms = terminal ? REDRAW_MS : LINE_MS;
    bar->drawn = false;
    bar->shown = false;
    bar->start_ms = cli_now_ms();
    bar->last_draw_ms = 0;
    bar->stage_from = 0;
    bar->stage_to = 0;
    bar->stage = "";
}

void cli_progress_stage(cli_progress *bar, const char *stage, double from, double to) {
    bar->stage = stage;
    bar->stage_from = from;
    bar->stage_to = to;
    cli_progress_update(bar, 0);
}

/* Draws the bar at `fraction` of the current stage, `now`. */
static void draw(cli_progress *bar, double fraction, double now) {
    bar->last_draw_ms = now;
    bar->shown = true;
    double whole = bar->stage_from + (bar->stage_to - bar->stage_from) * fraction;
    int filled = (int)(whole * WIDTH + 0.5);
    char cells[WIDTH + 1];
    for (int i = 0; i < WIDTH; i++)
        cells[i] = i < filled ? '#' : '.';
    cells[WIDTH] = '\0';
    fprintf(stderr, "%s[%s] %3d%% %-9s %5.1f s%s", bar->lines ? "" : "\r", cells,
            (int)(whole * 100 + 0.5), bar->stage, (now - bar->start_ms) / 1e3,
            bar->lines ? "\n" : "");
    fflush(stderr);
    bar->drawn = !bar->lines; /* a whole line needs no clearing */
}

void cli_progress_update(cli_progress *bar, double fraction) {
    if (!bar->enabled)
        return;
    double now = cli_now_ms();
    if (now - bar->start_ms < bar->show_after_ms || now - bar->last_draw_ms < bar->redraw_ms)
        return;
    draw(bar, fraction, now);
}

void cli_progress_done(cli_progress *bar) {
    if (!bar->enabled || !(bar->shown || bar->show_after_ms == 0))
        return;
    bar->stage = "done";
    bar->stage_from = 1;
    bar->stage_to = 1;
    draw(bar, 1, cli_now_ms());
    if (bar->drawn && bar->show_after_ms == 0) { /* --progress on a terminal: the line stays */
        fputc('\n', stderr);
        fflush(stderr);
        bar->drawn = false;
    }
}

void cli_progress_callback(void *user, double fraction) {
    cli_progress_update(user, fraction);
}

void cli_progress_clear(cli_progress *bar) {
    if (bar->drawn) {
        fputs("\r\033[K", stderr);
        fflush(stderr);
        bar->drawn = false;
    }
}
