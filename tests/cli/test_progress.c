/* test_progress.c: the progress bar on a terminal and the lines printed
 * while it is up: a note clears the bar first and starts its own line
 * (the bar's final clear before "wrote" is test_cli_bounce.c's). */
#define _DEFAULT_SOURCE /* forkpty */

#include "cli/common.h"
#include "cli/progress.h"

#include <criterion/criterion.h>
#include <pty.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

Test(progress, a_note_clears_the_bar_before_its_line) {
  int master;
  const pid_t pid = forkpty(&master, NULL, NULL, NULL);
  cr_assert_neq(pid, -1, "forkpty");
  if (pid == 0) { /* stderr is the terminal: the bar is drawn */
    cli_progress p;
    cli_progress_start(&p, "bake", 0);
    p.start_seconds -= 5.0; /* drawn at once, as after a second of work */
    const bb_progress_fn draw = cli_progress_fn(&p);
    if (!draw)
      _exit(3);
    draw(&p, 1, 2);
    cli_progress_note(&p, "h.png", "a note");
    _exit(0);
  }
  size_t got = 0;
  char out[4096];
  ssize_t n;
  while (got + 1 < sizeof out && (n = read(master, out + got, sizeof out - 1 - got)) > 0)
    got += (size_t)n; /* EIO once the child is gone */
  out[got] = '\0';
  close(master);
  int status;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  cr_assert(WIFEXITED(status) && WEXITSTATUS(status) == 0, "child: %d", status);
  const char *bar = strstr(out, "bake ["), *note = strstr(out, "bumpbake: h.png: note: a note");
  cr_assert(bar && note && bar < note, "%s", out);
  const char *clear = "\r\033[K";
  cr_expect(note - out >= (long)strlen(clear) &&
                !strncmp(note - strlen(clear), clear, strlen(clear)),
            "the bar is not cleared right before the note: %s", out);
}
