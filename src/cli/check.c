/* check.c: `bumpbake check`, a suite of maps against their goldens: the
 * library plans and runs the check (bb_check_plan; bb_check_run_input of
 * each input, then bb_check_run_rest, as Python runs it) and
 * writes its reports; this prints each map that does not pass as it is
 * decided and the summary, and exits as idiff does for the worst map
 * (0 pass, 1 warning, 2 failure, 3 different size, 4 unreadable or a usage
 * error, as compare). */
#include "cli.h"
#include "common.h"
#include "progress.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct printer {
  const bb_check *check;
  cli_progress *progress;
} printer;

static void print_case(void *user, const bb_check_case *c) {
  printer *p = user;
  cli_progress_finish(p->progress);
  cli_put_lines(bb_check_case_lines(p->check, c));
}

int cli_run_check(const cli_run *r) {
  cli_progress progress;
  cli_progress_start(&progress, "check", r->quiet);
  const bb_command_hooks hooks = {cli_progress_note, &progress, NULL, NULL, NULL, NULL};
  bb_check *check = NULL;
  bb_error err = {{0}};
  bb_status st = bb_check_plan(r->command, &hooks, &check, &err);
  if (st != BB_OK) {
    /* nothing was compared: idiff's "could not compare", a usage error's too */
    if (st == BB_ERR_ARGUMENT)
      cli_usage_error("check", "%s", err.message);
    else
      cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    return BB_COMPARE_CANNOT_READ;
  }
  printer p = {check, &progress};
  for (int i = 0; i < bb_check_input_count(check) && st == BB_OK; i++)
    st = bb_check_run_input(check, i, cli_progress_fn(&progress), &progress, print_case, &p,
                            &err);
  if (st == BB_OK)
    st = bb_check_run_rest(check, print_case, &p, &err);
  cli_progress_finish(&progress);
  int rc = bb_check_exit_code(check);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    rc = BB_COMPARE_CANNOT_READ;
  }
  /* the reports of what was checked, also after a failure part way */
  bb_error report_err = {{0}};
  if (bb_check_write_reports(check, &report_err) != BB_OK) {
    cli_error_line(report_err.message);
    rc = BB_COMPARE_CANNOT_READ;
  } else if (!r->quiet && !r->json) {
    char junit[PATH_MAX], html[PATH_MAX];
    if (cli_text(r, "junit", junit, sizeof junit))
      cli_printf_line("wrote junit %s", junit);
    if (cli_text(r, "html", html, sizeof html))
      cli_printf_line("wrote report %s/index.html", html);
  }
  cli_put_lines(bb_check_summary_lines(check));
  bb_check_free(check);
  return rc;
}
