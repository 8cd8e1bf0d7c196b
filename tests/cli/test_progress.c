/* test_progress.c: the progress bar on a terminal and the lines printed
 * while it is up: a note clears the bar first and starts its own line
 * (the bar's final clear before "wrote" is test_cli_bounce.c's). */
#define _DEFAULT_SOURCE /* forkpty */

#include "job/bake_rows.h"
#include "job/job_internal.h"
#include "cli/common.h"
#include "cli/progress.h"
#include "image/image_write.h"

#include <criterion/criterion.h>
#include <pty.h>
#include <stdio.h>
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

Test(progress, a_jobs_block_compression_has_its_own_bar) {
  /* A job writing a VTF: after the bake's bar, one named for the blocks,
   * full at the end. */
  char dir[] = "/tmp/bb_progress_XXXXXX";
  cr_assert_not_null(mkdtemp(dir));
  char height[64], vtf[64];
  snprintf(height, sizeof height, "%s/h.png", dir);
  snprintf(vtf, sizeof vtf, "%s/s.vtf", dir);
  int master;
  const pid_t pid = forkpty(&master, NULL, NULL, NULL);
  cr_assert_neq(pid, -1, "forkpty");
  if (pid == 0) {
    bb_image h;
    if (bb_image_alloc(&h, 64, 64, 1, NULL) != BB_OK)
      _exit(3);
    for (int i = 0; i < 64 * 64; i++)
      h.pixels[i] = (float)((i * 7) % 13) / 12.0f;
    if (bb__image_write(height, &h, NULL, NULL) != BB_OK)
      _exit(4);
    bb_job_options o;
    bb__job_options_init(&o);
    o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
    o.bake.height_scale = 4.0f;
    o.bake.rays = 16;
    o.paths[BB_MAP_SSBUMP] = vtf;
    const char *input = height;
    bb_job *job = NULL;
    if (bb__job_plan_options(&input, 1, &o, &job, NULL) != BB_OK)
      _exit(5);
    cli_progress p;
    cli_progress_start(&p, "bake", 0);
    p.job = job;
    p.start_seconds -= 5.0; /* drawn at once, as after a second of work */
    const bb_progress_fn draw = cli_progress_fn(&p);
    if (!draw || bb_job_run_item(job, 0, draw, &p) != BB_OK)
      _exit(6);
    bb_job_free(job);
    bb_image_free(&h);
    _exit(0);
  }
  size_t got = 0;
  char out[1 << 16];
  ssize_t n;
  while (got + 1 < sizeof out && (n = read(master, out + got, sizeof out - 1 - got)) > 0)
    got += (size_t)n;
  out[got] = '\0';
  close(master);
  int status;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  unlink(vtf), unlink(height), rmdir(dir);
  cr_assert(WIFEXITED(status) && WEXITSTATUS(status) == 0, "child: %d", status);
  const char *bake = strstr(out, "bake ["), *blocks = strstr(out, "bake: compressing blocks [");
  cr_assert(bake && blocks && bake < blocks, "%s", out);
  cr_expect(strstr(blocks, "[####################] 100%"), "%s", blocks);
}
