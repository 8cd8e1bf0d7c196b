/* info.c: `bumpbake info`, what image files are (size, channels, format,
 * sample type, alpha) and the provenance bumpbake stored in them. Reads
 * headers only: no pixel is decoded. The library runs it (bb_command_run)
 * and words its report, a file that cannot be read included (exit 1);
 * this prints it (cli_put_report). */
#include "cli.h"
#include "common.h"

#include "bumpbake.h"

int cli_run_info(const cli_run *r) {
  bb_command_result result;
  bb_error err = {{0}};
  bb_status st = bb_command_run(r->command, NULL, &result, &err);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    return BB_EXIT_FAILURE;
  }
  cli_put_report(&result);
  const int code = result.exit_code ? BB_EXIT_FAILURE : BB_EXIT_OK;
  bb_command_result_free(&result);
  return code;
}
