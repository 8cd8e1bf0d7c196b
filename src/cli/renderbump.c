/* renderbump.c: `bumpbake renderbumpflat`, DOOM 3's RenderBumpFlat: a
 * flat sculpt (a model file) to its normal map, and optionally its height
 * with the scale that `bumpbake bake` needs to make ssbump and ao from it.
 * The library runs it (bb_command_renderbump); this prints what it made. */
#include "cli.h"
#include "common.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

/* size ("W H"), samples and axis ("-y") as the checked command holds them. */
static void print_summary(const cli_run *run, const char *model,
                          const bb_renderbump_result *r) {
  double size[2] = {0.0, 0.0}, samples = 0.0;
  char axis[8] = "";
  bb_command_numbers(run->command, "size", size, 2, NULL, NULL);
  bb_command_numbers(run->command, "samples", &samples, 1, NULL, NULL);
  cli_text(run, "axis", axis, sizeof axis);
  const int width = (int)size[0], height = (int)size[1], n = (int)samples;
  cli_printf_line("renderbumpflat: %s: %zu triangles, %s normals, seen along %s; rectangle "
                  "[%g, %g] x [%g, %g]; %d x %d texels, %d samples each",
                  model, r->triangles, r->used_vertex_normals ? "vertex" : "face", axis,
                  r->rect[0], r->rect[2], r->rect[1], r->rect[3], width, height, n * n);
}

/* The one number the height is useless without: printed even with -q. */
static void print_height_scale(const cli_run *run, const char *height,
                               const bb_renderbump_result *r) {
  char *word = bb_text_shell_quoted(height); /* the line, typed in a shell */
  char axis[8] = "";
  cli_text(run, "axis", axis, sizeof axis);
  if (r->height_scale > 0.0)
    cli_printf_line("height scale %.6g texels per unit (bumpbake bake %s --scale %.6g ...)",
                    r->height_scale, word ? word : height, r->height_scale);
  else
    cli_printf_line("height scale 0: the model is flat along %s, so its height is 0 "
                    "everywhere and a bake of it would trace nothing",
                    axis);
  free(word);
}

int cli_run_renderbumpflat(const cli_run *r) {
  const char *model = bb_command_input(r->command, 0);
  const bb_command_hooks hooks = {cli_note, NULL, NULL, NULL, NULL, NULL};
  bb_renderbump_result render;
  bb_command_result written;
  bb_error err = {{0}};
  bb_status st = bb_command_renderbump(r->command, &hooks, &render, &written, &err);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    return BB_EXIT_FAILURE;
  }
  if (!r->quiet) {
    print_summary(r, model, &render);
    for (int i = 0; i < written.file_count; i++)
      cli_printf_line("wrote %s %s", written.files[i].kind, written.files[i].path);
  }
  char height[PATH_MAX];
  if (cli_text(r, "height", height, sizeof height))
    print_height_scale(r, height, &render);
  bb_command_result_free(&written);
  bb_renderbump_result_free(&render);
  return BB_EXIT_OK;
}
