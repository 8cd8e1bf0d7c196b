/* run.c: the commands the library runs in one call (render, sheet,
 * normal2ssbump, ssbump2normal, combine, program: bb_command_run), and what
 * the command line says of them: the files written, a progress bar while a
 * height bakes, a note when labels could not be drawn. */
#include "cli.h"
#include "common.h"
#include "progress.h"

#include <stdio.h>

static int run_and_report(const cli_run *r) {
  const char *name = bb_command_describe(r->command)->name;
  cli_progress progress;
  cli_progress_start(&progress, name, r->quiet);
  const bb_command_hooks hooks = {cli_progress_note, &progress, cli_progress_fn(&progress), &progress,
                                  NULL, NULL};
  bb_command_result result;
  bb_error err = {{0}};
  bb_status st = bb_command_run(r->command, &hooks, &result, &err);
  cli_progress_finish(&progress);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    return BB_EXIT_FAILURE;
  }
  if (!result.labels_drawn)
    cli_no_font_note(name);
  const int n = result.file_count;
  if (r->quiet || !n) {
    /* the exit code says it */
  } else if (result.frames && n == 1) { /* an animation */
    cli_printf_line("wrote %s %s (%d frames)", result.files[0].kind, result.files[0].path,
                    result.frames);
  } else if (result.frames) {
    cli_printf_line("wrote %d frames %s%s%s", result.frames, result.files[0].path,
                    n > 1 ? " .. " : "", n > 1 ? result.files[n - 1].path : "");
  } else {
    for (int i = 0; i < n; i++)
      cli_printf_line("wrote %s %s", result.files[i].kind, result.files[i].path);
  }
  bb_command_result_free(&result);
  return BB_EXIT_OK;
}

int cli_run_render(const cli_run *r) { return run_and_report(r); }
int cli_run_sheet(const cli_run *r) { return run_and_report(r); }
int cli_run_normal2ssbump(const cli_run *r) { return run_and_report(r); }
int cli_run_ssbump2normal(const cli_run *r) { return run_and_report(r); }
int cli_run_combine(const cli_run *r) { return run_and_report(r); }
int cli_run_program(const cli_run *r) { return run_and_report(r); }
