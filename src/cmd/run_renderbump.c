/* run_renderbump.c: renderbumpflat's run, the one sequence the command
 * line and Python both call: the model read (its note to the caller), the
 * flat render bump, and its files written by the job
 * (job/renderbump_files.c: both or neither, provenance, the height's
 * depth), their paths checked against the model before (bb_command_check). */
#include "cmd/cmd_internal.h"
#include "image/oiio_module.h"
#include "job/job_internal.h"
#include "mesh/mesh_internal.h"

#include <stdlib.h>
#include <string.h>

/* The render's notes name no file (it sees a mesh, not a path): they are
 * the model's, as every other note names its file. */
typedef struct model_notes {
  const bb_command_hooks *hooks;
  const char *model;
} model_notes;

static void note_of_model(void *user, const char *path, const char *text) {
  const model_notes *m = user;
  m->hooks->note(m->hooks->note_user, path ? path : m->model, text);
}

/* The run; render (the caller's, or run's own) holds the render after. */
static bb_status run(bb_command *c, const bb_command_hooks *hooks,
                     bb_renderbump_result *render, bb_command_result *r, bb_error *err) {
  const bb_command_options *o = &c->options;
  if (c->input_count < 1) /* checked in memory, without its MODEL */
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbumpflat: a MODEL is needed");
  const char *model = c->inputs[0];
  bb_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  bb_error e = {{0}};
  char note[512];
  bb_status st = bb__mesh_load_noted(model, &mesh, note, sizeof note, &e);
  const int noted = hooks && hooks->note;
  if (st == BB_OK && note[0] && noted) /* a missing .mtl and the like */
    hooks->note(hooks->note_user, model, note);
  bb_renderbump_options ro = o->renderbump;
  model_notes notes = {hooks, model};
  ro.note = noted ? note_of_model : NULL;
  ro.note_user = noted ? &notes : NULL;
  if (st == BB_OK)
    st = bb__renderbump_flat(&mesh, &ro, render, &e);
  bb__mesh_free(&mesh);
  if (st != BB_OK)
    return bb__fail_at(err, st, model, &e);
  if (c->in_memory)
    return BB_OK;
  char *record = bb__command_record(c);
  if (!record)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->output);
  st = bb__renderbump_write(render, &ro, o->maps_normal_y_up, model, render->model_hash,
                           record, o->output, o->height_output, err);
  free(record);
  if (st == BB_OK)
    st = bb__result_add(r, "normal", o->output, err);
  if (st == BB_OK && o->height_output)
    st = bb__result_add(r, "height", o->height_output, err);
  return st;
}

bb_status bb__run_renderbumpflat(bb_command *c, const bb_command_hooks *hooks,
                                 bb_command_result *r, bb_error *err) {
  bb_renderbump_result render;
  memset(&render, 0, sizeof render);
  bb_status st = run(c, hooks, &render, r, err);
  bb_renderbump_result_free(&render);
  return st;
}

static bb_status renderbump(bb_command *c, const bb_command_hooks *hooks,
                            bb_renderbump_result *render, bb_command_result *result,
                            bb_error *err) {
  if (render)
    memset(render, 0, sizeof *render);
  if (result) {
    memset(result, 0, sizeof *result);
    result->labels_drawn = 1;
  }
  if (!c || !render || !result)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: bad arguments");
  if (c->def->run != bb__run_renderbumpflat)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s is not renderbumpflat", c->def->info.name);
  /* The OpenImageIO module before any work, as bb_command_run loads it. */
  if (!bb__oiio_module())
    return bb__oiio_failed(err);
  if (!c->checked)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: the command is not checked (bb_command_check)",
                    c->def->info.name);
  bb_status st = run(c, hooks, render, result, err);
  if (st != BB_OK) {
    bb_renderbump_result_free(render);
    bb_command_result_free(result);
  }
  return st;
}

bb_status bb_command_renderbump(bb_command *c, const bb_command_hooks *hooks,
                                bb_renderbump_result *render, bb_command_result *result,
                                bb_error *err) {
  bb__spelled_hooks h;
  return bb__spelled(
      c,
      renderbump(c, c ? bb__spelled_hooks_of(c, hooks, &h) : hooks, render, result, err),
      err);
}
