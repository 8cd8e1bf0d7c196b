/* compare.c: `bumpbake compare`, an idiff-style image diff for CI.
 *
 * Options and exit codes are OpenImageIO idiff's (2.4), so a CI script
 * written for idiff works unchanged: -fail, -failpercent, -hardfail,
 * -allowfailures, -warn, -warnpercent, -hardwarn (also with two dashes), and
 *   0 pass, 1 warning, 2 failure, 3 different size or channel count,
 *   4 a file cannot be read.
 * Usage errors also exit 4: idiff returns 1 (EXIT_FAILURE) for a bad
 * command line, which a script would take for a mere warning; 4 ("could not
 * compare") makes a broken CI invocation fail loudly instead.
 * The library runs it (bb_command_run) and words its report; this prints
 * it (cli_put_report).
 */
#include "cli.h"
#include "common.h"

#include "bumpbake.h"

int cli_run_compare(const cli_run *run) {
  /* what it will cost, said (cli_note) before it starts when that is much */
  const bb_command_hooks hooks = {cli_note, NULL, NULL, NULL, NULL, NULL};
  bb_command_result result;
  bb_error err = {{0}};
  bb_status st = bb_command_run(run->command, &hooks, &result, &err);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    /* A file that cannot be read, a file over the size limits included,
     * is idiff's 4; two readable files of different sizes are a report
     * (exit 3), never an error. */
    return BB_COMPARE_CANNOT_READ;
  }
  cli_put_report(&result);
  const int code = result.exit_code;
  bb_command_result_free(&result);
  return code;
}
