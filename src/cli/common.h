/* common.h: what every subcommand prints the same way: usage errors, file
 * errors, notes and plain lines (all of them one line, with control
 * characters escaped so no file name or provenance text can drive the
 * terminal), signals and the clock. Nothing here is part of the library. */
#ifndef BB_CLI_COMMON_H
#define BB_CLI_COMMON_H

#include "bumpbake.h"

#include <stdio.h>

/* ----------------------------------------------------------------- errors */

/* Prints "bumpbake COMMAND: message" on stderr and returns BB_EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Prints "bumpbake: message" on stderr: a library message, which names its
 * file already ("PATH: reason"). */
void cli_error_line(const char *message);

/* Prints the one-line error "bumpbake: FILE: reason" on stderr. The library's
 * messages often start with the file name already; it is not repeated. */
void cli_file_error(const char *path, const char *reason);

/* The exit code of a library call about path: 0 for BB_OK, else
 * BB_EXIT_FAILURE after printing err's message (or the status name when the
 * message is empty) as a file error. */
int cli_status_exit(const char *path, bb_status status, const bb_error *err);

/* The exit code of a library call that checked what the command line asked
 * (a plan, an output check): BB_ERR_ARGUMENT is a usage error ("bumpbake
 * COMMAND: message", BB_EXIT_USAGE), anything else a failure ("bumpbake:
 * message", BB_EXIT_FAILURE). */
int cli_library_error(const char *command, bb_status status, const bb_error *err);

/* ------------------------------------------------------------------ lines */

/* printf to stdout and a newline, with control characters escaped. */
void cli_printf_line(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* The library's lines (bb_job_report_lines, bb_check_case_lines, ...: the
 * library made them printable) on stdout, flushed; text is freed (NULL:
 * nothing). */
void cli_put_lines(char *text);

/* A run's report as the library words it (bb_command_result.prints), in
 * order: lines on stdout, errors on stderr as cli_file_error and
 * cli_error_line print them (stdout flushed before each, and at the end,
 * so the two streams keep their order). */
void cli_put_report(const bb_command_result *result);

/* The library's notes (bb_note_fn) as "bumpbake: PATH: note: TEXT" on
 * stderr. user is unused. */
void cli_note(void *user, const char *path, const char *text);

/* The note for a picture whose labels could not be drawn (render, sheet). */
void cli_no_font_note(const char *command);


/* ---------------------------------------------------------------- signals */

/* Installs the CLI's signal handling, first thing in main: SIGINT, SIGTERM
 * and SIGHUP remove the temporaries of writes in progress and end the
 * process by the same signal, after the renames of a set of outputs in
 * progress (bb_signal_cleanup); SIGXFSZ is ignored, so a write over
 * RLIMIT_FSIZE is an ordinary write error. */
void cli_install_signal_handlers(void);

/* Monotonic seconds. */
double cli_now_seconds(void);

#endif /* BB_CLI_COMMON_H */
