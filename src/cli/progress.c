/* progress.c: the progress bar of long bakes on a terminal. */
#include "common.h"
#include "progress.h"

#include <string.h>
#include <unistd.h>

/* --------------------------------------------------------------- progress */

enum { PROGRESS_BAR_WIDTH = 20 };

/* Never cancels: Ctrl-C ends the process (cli_install_signal_handlers). */
static int progress_draw(void *user, long done, long total) {
  cli_progress *p = user;
  const double now = cli_now_seconds(), elapsed = now - p->start_seconds;
  /* A job's block compression is a stage of its own: its units start
   * anew, and so does the ETA's clock. */
  const char *stage = p->job ? bb_job_stage(p->job) : NULL;
  if (stage != p->stage)
    p->stage = stage, p->stage_seconds = now, p->redraw = 1;
  const int compressing = stage && !strcmp(stage, "compress");
  /* Short bakes stay silent; long ones redraw ten times a second at most,
   * and at once when the stage changes or its work is done. */
  if (elapsed < 1.0 || total <= 0 ||
      (!p->redraw && done < total && now - p->last_draw_seconds < 0.1))
    return 0;
  p->redraw = 0;
  p->last_draw_seconds = now;
  double frac = done <= 0 ? 0.0 : (double)done / (double)total;
  if (frac > 1.0)
    frac = 1.0;
  int filled = (int)(frac * PROGRESS_BAR_WIDTH); /* full only when done */
  char bar[PROGRESS_BAR_WIDTH + 1];
  for (int i = 0; i < PROGRESS_BAR_WIDTH; i++)
    bar[i] = i < filled ? '#' : '.';
  bar[PROGRESS_BAR_WIDTH] = '\0';
  fprintf(stderr, "\r%s%s [%s] %3d%%", p->label, compressing ? ": compressing blocks" : "",
          bar, (int)(frac * 100.0));
  if (frac > 0.0)
    fprintf(stderr, " ETA %.1fs", (now - p->stage_seconds) * (1.0 - frac) / frac);
  fputs("\033[K", stderr); /* erase what a longer previous line left */
  fflush(stderr);
  p->shown = 1;
  return 0;
}

void cli_progress_start(cli_progress *p, const char *label, int quiet) {
  memset(p, 0, sizeof *p);
  p->label = label;
  p->start_seconds = p->stage_seconds = cli_now_seconds();
  p->active = !quiet && isatty(STDERR_FILENO);
}

bb_progress_fn cli_progress_fn(const cli_progress *p) {
  return p->active ? progress_draw : NULL;
}

void cli_progress_attach(cli_progress *p, const char *label, int quiet,
                         bb_trace_options *trace) {
  cli_progress_start(p, label, quiet);
  trace->progress = cli_progress_fn(p);
  trace->progress_user = p;
}

void cli_progress_finish(cli_progress *p) {
  if (!p->shown)
    return;
  fputs("\r\033[K", stderr);
  fflush(stderr);
  p->shown = 0;
}

void cli_progress_note(void *user, const char *path, const char *text) {
  if (user)
    cli_progress_finish(user);
  cli_note(NULL, path, text);
}
