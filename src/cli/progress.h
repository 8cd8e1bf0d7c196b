/* progress.h: the progress bar of long bakes (cli_progress.c). */
#ifndef BB_CLI_PROGRESS_H
#define BB_CLI_PROGRESS_H

#include "bumpbake.h"

/* --------------------------------------------------------------- progress */

/* A one-line progress bar on stderr: "bake [#####.....] 42% ETA 1.3s". It
 * appears only once the work has run for about a second, so short bakes
 * print nothing, and only when stderr is a terminal. */
typedef struct cli_progress {
  const char *label;
  const bb_job *job;    /* names the stage when set: "bake: compressing blocks" */
  const char *stage;    /* the job's stage at the last call (bb_job_stage) */
  double start_seconds; /* of the command: the bar waits a second */
  double stage_seconds; /* when the stage began: the ETA's clock */
  int redraw;           /* the stage changed: draw at the next chance */
  double last_draw_seconds;
  int shown;  /* a line is on screen and must be cleared */
  int active; /* stderr is a terminal and the command is not quiet */
} cli_progress;

/* Sets up p; the bar is drawn only when stderr is a terminal and not quiet. */
void cli_progress_start(cli_progress *p, const char *label, int quiet);
/* The callback for the library's progress argument (p as its user), or
 * NULL when no bar is drawn. */
bb_progress_fn cli_progress_fn(const cli_progress *p);

/* cli_progress_start, pointing the trace options' progress callback at p. */
void cli_progress_attach(cli_progress *p, const char *label, int quiet,
                         bb_trace_options *trace);
/* Clears the bar's line if one was drawn. */
void cli_progress_finish(cli_progress *p);

/* The library's notes (bb_note_fn) while a bar may be up: user is the
 * cli_progress, whose bar is cleared first so the note starts its own line
 * (then as cli_note). */
void cli_progress_note(void *user, const char *path, const char *text);

#endif /* BB_CLI_PROGRESS_H */
