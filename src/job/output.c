/* output.c: the job's rules for a command that makes one map or picture
 * (normal2ssbump, ssbump2normal, combine, program, render, sheet), the
 * ones a bake's outputs follow in run.c: the depth a default follows, the
 * provenance assembled from where the output came from, and the write,
 * staged and put in place all or nothing (every frame of an orbit with
 * the others). The outputs' paths were checked against the inputs before
 * any work (bb_outputs_check, paths.c). */
#include "core/internal.h"
#include "job/job_internal.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

bb_provenance bb__job_provenance(const bb__job_source *s, const char *kind) {
  const char *input = s->input_text ? s->input_text : s->input ? bb__file_name(s->input) : NULL;
  return (bb_provenance){.command = s->command,
                         .input_name = input,
                         .input_hash = s->input_hash,
                         .output_kind = kind,
                         .options = s->bake,
                         .channel = s->channel,
                         .rayset_id = s->rayset_id,
                         .input_file_hash = s->input_file_hash,
                         .extra = s->extra};
}

char *bb__job_describe(const bb__job_source *s, const char *kind) {
  const bb_provenance p = bb__job_provenance(s, kind);
  return bb_provenance_format(&p);
}

bb_depth bb__job_depth(bb_depth asked, int bits_per_sample, int is_float, const char *path) {
  return asked != BB_DEPTH_DEFAULT ? asked : bb_depth_like_input(bits_per_sample, is_float, path);
}

static bb_depth depth_of(const bb__job_output *o) {
  if (!o->like)
    return o->depth;
  return bb__job_depth(o->depth, o->like->bits_per_sample, o->like->is_float, o->path);
}

bb_status bb__job_write(const bb__job_output *o, const bb_image *img, const bb__job_source *s,
                        bb_error *err) {
  char *description = bb__job_describe(s, o->kind);
  if (!description)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->path);
  const bb_output_file file = {o->path, o->kind,      img,  o->range, depth_of(o),
                               o->mips, description, NULL, 0,        o->texture};
  bb_error e = {{0}};
  bb_status st = bb_outputs_write(&file, 1, 1, &e);
  free(description);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, o->path, &e);
}

/* ---------------------------------------------------------------- frames */

static int is_gif(const char *path) {
  const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash + 1 : path, '.');
  return dot && strcasecmp(dot, ".gif") == 0;
}

bb_status bb__job_output_check(const bb__job_output *o, int frames, const char *const *reads,
                               int read_count, bb_error *err) {
  const int gif = o->path && is_gif(o->path);
  const int n = frames && !gif ? frames : 1;
  bb_output_spec *specs = calloc((size_t)n, sizeof *specs);
  char **names = calloc((size_t)n, sizeof *names);
  bb_status st = specs && names ? BB_OK : bb__fail(err, BB_ERR_MEMORY, "out of memory");
  for (int f = 0; f < n && st == BB_OK; f++) {
    const char *path = o->path;
    if (frames && !gif) {
      if (!(names[f] = bb_render_frame_path(o->path, f, frames)))
        st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
      path = names[f];
    }
    /* a GIF is written by the animation writer, not bb_image_write: its
     * name is checked as a file's, its format by the command */
    specs[f] = (bb_output_spec){.path = path,
                                .kind = o->kind,
                                .depth = o->depth,
                                .mips = o->mips,
                                .text = path && is_gif(path),
                                .range = o->range,
                                .texture = o->texture};
  }
  if (st == BB_OK)
    st = bb_outputs_check(specs, n, reads, read_count, err);
  for (int f = 0; names && f < n; f++)
    free(names[f]);
  free(names);
  free(specs);
  return st;
}

/* One frame made and staged under a temporary name; the caller commits it. */
static bb_status stage_frame(const bb__job_output *o, const bb__job_frames *f, int frame,
                             const char *path, bb_staged_file **staged, bb_error *err) {
  bb_image picture = {0};
  char *extra = NULL, *text = NULL;
  bb_status st = f->make(f->user, frame, &picture, &extra, err);
  if (st == BB_OK) {
    bb__job_source s = *f->source;
    s.extra = extra;
    text = extra ? bb__job_describe(&s, f->recorded_kind) : NULL;
    if (!text)
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  if (st == BB_OK) {
    const bb_write_options wo = {o->depth, o->range, text, NULL};
    bb_error e = {{0}};
    if ((st = bb_image_write_staged(path, &picture, &wo, staged, &e)) != BB_OK)
      bb__fail_at(err, st, path, &e);
  }
  free(text);
  free(extra);
  bb_image_free(&picture);
  return st;
}

/* The picture, or every frame of an orbit, staged one by one (a frame in
 * memory at a time) and then put in place together: an orbit interrupted
 * or failed leaves the old frames, all of them. */
static bb_status write_files(const bb__job_output *o, const bb__job_frames *f, char ***written,
                             int *count, bb_error *err) {
  const int n = f->frames ? f->frames : 1;
  bb_staged_file **staged = calloc((size_t)n, sizeof *staged);
  char **paths = calloc((size_t)n, sizeof *paths);
  const char **kinds = calloc((size_t)n, sizeof *kinds);
  bb_status st = staged && paths && kinds
                     ? BB_OK
                     : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->path);
  for (int i = 0; i < n && st == BB_OK; i++) {
    paths[i] = f->frames ? bb_render_frame_path(o->path, i, f->frames) : strdup(o->path);
    kinds[i] = o->kind;
    st = paths[i] ? stage_frame(o, f, i, paths[i], &staged[i], err)
                  : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->path);
  }
  if (st == BB_OK)
    st = bb_staged_files_commit(staged, kinds, n, err);
  for (int i = 0; staged && i < n; i++)
    if (st != BB_OK)
      bb_staged_file_discard(staged[i]);
  free(kinds);
  free(staged);
  if (st != BB_OK) {
    for (int i = 0; paths && i < n; i++)
      free(paths[i]);
    free(paths);
    return st;
  }
  *written = paths;
  *count = n;
  return BB_OK;
}

/* An orbit as one GIF (no provenance: GIF stores none), made and put in
 * place by bb_animation_close. */
static bb_status write_gif(const bb__job_output *o, const bb__job_frames *f, char ***written,
                           int *count, bb_error *err) {
  bb_animation *anim = NULL;
  bb_error e = {{0}};
  bb_status st = BB_OK;
  for (int i = 0; i < f->frames && st == BB_OK; i++) {
    bb_image picture = {0};
    st = f->make(f->user, i, &picture, NULL, err);
    if (st == BB_OK && !anim)
      st = bb_animation_open(o->path, picture.width, picture.height, 10.0, &anim, &e);
    if (st == BB_OK)
      st = bb_animation_add_frame(anim, &picture, &e);
    if (st != BB_OK && e.message[0])
      bb__fail_at(err, st, o->path, &e);
    bb_image_free(&picture);
  }
  if (st != BB_OK) {
    bb_animation_abort(anim);
    return st;
  }
  if ((st = bb_animation_close(anim, &e)) != BB_OK)
    return bb__fail_at(err, st, o->path, &e);
  char **paths = malloc(sizeof *paths);
  if (!paths || !(paths[0] = strdup(o->path))) {
    free(paths);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  *written = paths;
  *count = 1;
  return BB_OK;
}

bb_status bb__job_write_frames(const bb__job_output *o, const bb__job_frames *f, char ***written,
                               int *count, const char **kind, bb_error *err) {
  *written = NULL;
  *count = 0;
  const int gif = f->frames && is_gif(o->path);
  *kind = gif ? "orbit" : o->kind;
  return gif ? write_gif(o, f, written, count, err) : write_files(o, f, written, count, err);
}
