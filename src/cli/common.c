/* common.c: the messages, lines and signal handling every
 * subcommand shares. */
#include "common.h"
#include "cli.h"

#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Prints the formatted text escaped, with prefix and a newline, on f. */
static void vprint_line(FILE *f, const char *prefix, const char *fmt, va_list ap) {
  char text[4096], safe[4 * sizeof text];
  vsnprintf(text, sizeof text, fmt, ap);
  fprintf(f, "%s%s\n", prefix, bb_text_printable(text, safe, sizeof safe));
}

/* ----------------------------------------------------------------- errors */

int cli_usage_error(const char *command, const char *fmt, ...) {
  char prefix[64];
  snprintf(prefix, sizeof prefix, "bumpbake %s: ", command);
  va_list ap;
  va_start(ap, fmt);
  vprint_line(stderr, prefix, fmt, ap);
  va_end(ap);
  return BB_EXIT_USAGE;
}

void cli_error_line(const char *message) {
  char safe[4 * sizeof(bb_error)];
  fprintf(stderr, "bumpbake: %s\n",
          bb_text_printable(message && *message ? message : "unknown error", safe, sizeof safe));
}

void cli_file_error(const char *path, const char *reason) {
  const char *why = reason && *reason ? reason : "unknown error";
  /* the library's messages show a path escaped (bb_text_printable) */
  char shown[4096];
  bb_text_printable(path, shown, sizeof shown);
  size_t n = strlen(path), m = strlen(shown);
  char line[8192];
  if ((strncmp(why, path, n) == 0 && why[n] == ':') ||
      (strncmp(why, shown, m) == 0 && why[m] == ':'))
    snprintf(line, sizeof line, "%s", why);
  else
    snprintf(line, sizeof line, "%s: %s", path, why);
  cli_error_line(line);
}

int cli_status_exit(const char *path, bb_status status, const bb_error *err) {
  if (status == BB_OK)
    return 0;
  cli_file_error(path, err->message[0] ? err->message : bb_status_name(status));
  return BB_EXIT_FAILURE;
}

int cli_library_error(const char *command, bb_status status, const bb_error *err) {
  const char *why = err->message[0] ? err->message : bb_status_name(status);
  if (status == BB_ERR_ARGUMENT)
    return cli_usage_error(command, "%s", why);
  cli_error_line(why);
  return BB_EXIT_FAILURE;
}

/* ------------------------------------------------------------------ lines */

void cli_printf_line(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vprint_line(stdout, "", fmt, ap);
  va_end(ap);
}

void cli_put_lines(char *text) {
  if (text)
    fputs(text, stdout);
  free(text);
  fflush(stdout);
}

void cli_put_report(const bb_command_result *result) {
  for (int i = 0; i < result->print_count; i++) {
    const bb_command_print *p = &result->prints[i];
    if (!p->error) {
      fputs(p->text, stdout);
      continue;
    }
    fflush(stdout);
    if (p->path)
      cli_file_error(p->path, p->text);
    else
      cli_error_line(p->text);
  }
  fflush(stdout);
}

void cli_note(void *user, const char *path, const char *text) {
  (void)user;
  char line[2048], safe[4 * sizeof line];
  if (path)
    snprintf(line, sizeof line, "%s: note: %s", path, text);
  else
    snprintf(line, sizeof line, "note: %s", text);
  fprintf(stderr, "bumpbake: %s\n", bb_text_printable(line, safe, sizeof safe));
}

void cli_no_font_note(const char *command) {
  fprintf(stderr,
          "bumpbake %s: no font found for the labels (install fonts-dejavu-core, or set "
          "BUMPBAKE_FONT to a font file); drawn without labels\n",
          command);
}

double cli_now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------- signals */

/* The library removes the temporaries and ends us by the same signal, once
 * no set of outputs is half renamed (bb_signal_cleanup). */
static void on_fatal_signal(int sig) {
  bb_signal_cleanup(sig);
}

void cli_install_signal_handlers(void) {
  /* Over RLIMIT_FSIZE a write then fails with EFBIG, reported and cleaned
   * up like a full disk, instead of SIGXFSZ killing the process with its
   * temporary left behind. */
  struct sigaction ignore;
  memset(&ignore, 0, sizeof ignore);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, NULL);

  static const int fatal[] = {SIGINT, SIGTERM, SIGHUP};
  for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++) {
    struct sigaction old, sa;
    /* A signal ignored by whoever started us (nohup, a background job)
     * stays ignored. */
    if (sigaction(fatal[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
      continue;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(fatal[i], &sa, NULL);
  }
}
