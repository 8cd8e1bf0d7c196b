/* renderbump.c: `bumpbake renderbumpflat`, DOOM 3's RenderBumpFlat: a
 * flat sculpt (a model file) to its normal map, and optionally its height
 * with the scale that `bumpbake bake` needs to make ssbump and ao from it. */
#include "cli.h"
#include "common.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct rbf_args {
  bb_renderbump_options render;
  const char *model, *output, *height;
  int quiet, normal_y_up;
} rbf_args;

/* The library's notes on a render name no file (it sees a mesh, not a path);
 * note_user carries the model's, so they read like every other note. */
static void rbf_note(void *model, const char *path, const char *text) {
  cli_note(NULL, path ? path : (const char *)model, text);
}

/* ------------------------------------------------------------- running */

static void print_summary(const rbf_args *a, const bb_mesh *mesh, const bb_renderbump_result *r) {
  cli_printf_line("renderbumpflat: %s: %zu triangles, %s normals, seen along %s; rectangle "
         "[%g, %g] x [%g, %g]; %d x %d texels, %d samples each",
         a->model, mesh->triangle_count, r->used_vertex_normals ? "vertex" : "face",
         bb_axis_name(a->render.axis), r->rect[0], r->rect[2], r->rect[1], r->rect[3],
         a->render.width, a->render.height, a->render.samples * a->render.samples);
}

static int write_outputs(const char *command_line, const rbf_args *a, const bb_mesh *mesh,
                         const bb_renderbump_result *r) {
  bb_error err = {{0}};
  bb_status st = bb_renderbump_write(r, &a->render, a->normal_y_up, a->model,
                                     bb_mesh_hash(mesh), command_line, a->output, a->height,
                                     &err);
  if (st != BB_OK) {
    cli_error_line(err.message);
    return BB_EXIT_FAILURE;
  }
  if (!a->quiet) {
    cli_printf_line("wrote normal %s", a->output);
    if (a->height)
      cli_printf_line("wrote height %s", a->height);
  }
  if (a->height && r->height_scale > 0.0)
    /* The one number the height is useless without: printed even with -q. */
    cli_printf_line("height scale %.6g texels per unit (bumpbake bake %s --scale %.6g ...)",
                    r->height_scale, a->height, r->height_scale);
  else if (a->height)
    cli_printf_line("height scale 0: the model is flat along %s, so its height is 0 "
                    "everywhere and a bake of it would trace nothing",
                    bb_axis_name(a->render.axis));
  return 0;
}

static int rbf_run(const char *command_line, rbf_args *a) {
  bb_mesh mesh;
  bb_renderbump_result result;
  memset(&mesh, 0, sizeof mesh);
  memset(&result, 0, sizeof result);
  bb_error err = {{0}};
  char note[512];
  bb_status st = bb_mesh_load_noted(a->model, &mesh, note, sizeof note, &err);
  if (st == BB_OK && note[0]) /* a missing .mtl and the like */
    cli_note(NULL, a->model, note);
  if (st == BB_OK)
    st = bb_renderbump_flat(&mesh, &a->render, &result, &err);
  int rc = cli_status_exit(a->model, st, &err);
  if (!rc) {
    if (!a->quiet)
      print_summary(a, &mesh, &result);
    rc = write_outputs(command_line, a, &mesh, &result);
  }
  bb_renderbump_result_free(&result);
  bb_mesh_free(&mesh);
  return rc;
}

int cli_run_renderbumpflat(const cli_run *r) {
  const bb_command_options *o = r->options;
  rbf_args a = {o->renderbump, bb_command_input(r->command, 0), o->output, o->height_output,
                o->quiet, o->maps_normal_y_up};
  a.render.note = rbf_note;
  a.render.note_user = (void *)a.model;
  return rbf_run(r->record, &a);
}
