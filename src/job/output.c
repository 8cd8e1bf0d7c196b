/* output.c: the job's rules for the commands that are not bakes
 * (normal2ssbump, ssbump2normal, combine, program, render, sheet,
 * renderbumpflat, compare's diff), the ones a bake's outputs follow in
 * run.c: the depth a default follows, the provenance assembled from where
 * each output came from, and the write, staged and put in place all or
 * nothing (a command's files together, every frame of an orbit with the
 * others). The outputs' paths were checked against the inputs before any
 * work (bb__job_output_check, bb__job_outputs_check: bb_outputs_check,
 * paths.c). */
#include "core/internal.h"
#include "job/job_internal.h"
#include "files/safe_file.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "render/render_internal.h"

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
  return bb__provenance_format(&p);
}

bb_depth bb__job_depth(bb_depth asked, int bits_per_sample, int is_float, const char *path) {
  return asked != BB_DEPTH_DEFAULT ? asked : bb__depth_like_input(bits_per_sample, is_float, path);
}

static bb_depth depth_of(const bb__job_output *o) {
  if (!o->like)
    return o->depth;
  return bb__job_depth(o->depth, o->like->bits_per_sample, o->like->is_float, o->path);
}

bb_status bb__job_write_set(const bb__job_file *files, int count, bb_error *err) {
  if (!files || count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "job write: no file");
  bb_output_file *out = calloc((size_t)count, sizeof *out);
  char **texts = calloc((size_t)count, sizeof *texts);
  bb_status st = out && texts ? BB_OK
                              : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory",
                                         files[0].output->path);
  for (int i = 0; i < count && st == BB_OK; i++) {
    const bb__job_output *o = files[i].output;
    const char *kind = files[i].recorded_kind ? files[i].recorded_kind : o->kind;
    if (files[i].source && !(texts[i] = bb__job_describe(files[i].source, kind)))
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->path);
    out[i] = (bb_output_file){o->path, o->kind,   files[i].image, o->range, depth_of(o),
                              o->mips, texts[i], NULL,           0,        o->texture};
  }
  if (st == BB_OK) {
    /* one file's message names its path once; a set's name the file at
     * fault and what was (not) written */
    bb_error e = {{0}};
    st = bb_outputs_write(out, count, count, &e);
    if (st != BB_OK && count == 1)
      bb__fail_at(err, st, out[0].path, &e);
    else if (st != BB_OK)
      bb__fail(err, st, "%s", e.message);
  }
  for (int i = 0; texts && i < count; i++)
    free(texts[i]);
  free(texts);
  free(out);
  return st;
}

bb_status bb__job_write(const bb__job_output *o, const bb_image *img, const bb__job_source *s,
                        bb_error *err) {
  const bb__job_file file = {o, img, s, NULL};
  return bb__job_write_set(&file, 1, err);
}

/* ---------------------------------------------------------------- frames */

static int is_gif(const char *path) { return bb__path_has_extension(path, "gif"); }

/* What bb_outputs_check checks of o written at path (o's, or a frame's).
 * A GIF animation is written by the animation writer, not bb__image_write:
 * its name is checked as a file's, its format by the command; a .gif that
 * is not an animation is refused as bb__image_write refuses it. */
static bb_output_spec spec_of(const bb__job_output *o, const char *path, int animation) {
  return (bb_output_spec){.path = path,
                          .kind = o->kind,
                          .depth = o->depth,
                          .mips = o->mips,
                          .text = animation && path && is_gif(path),
                          .range = o->range,
                          .texture = o->texture};
}

bb_status bb__job_outputs_check(const bb__job_output *o, int count, const char *const *reads,
                                int read_count, bb_error *err) {
  bb_output_spec *specs = calloc((size_t)count, sizeof *specs);
  if (!specs)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  for (int i = 0; i < count; i++)
    specs[i] = spec_of(&o[i], o[i].path, 0);
  bb_status st = bb_outputs_check(specs, count, reads, read_count, err);
  free(specs);
  return st;
}

bb_status bb__job_output_check(const bb__job_output *o, int frames, const char *const *reads,
                               int read_count, bb_error *err) {
  const int gif = o->path && is_gif(o->path);
  if (!frames || gif) {
    bb_output_spec spec = spec_of(o, o->path, frames > 0);
    return bb_outputs_check(&spec, 1, reads, read_count, err);
  }
  bb_output_spec *specs = calloc((size_t)frames, sizeof *specs);
  char **names = calloc((size_t)frames, sizeof *names);
  bb_status st = specs && names ? BB_OK : bb__fail(err, BB_ERR_MEMORY, "out of memory");
  for (int f = 0; f < frames && st == BB_OK; f++) {
    if (!(names[f] = bb__render_frame_path(o->path, f, frames)))
      st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
    else
      specs[f] = spec_of(o, names[f], 1);
  }
  if (st == BB_OK)
    st = bb_outputs_check(specs, frames, reads, read_count, err);
  for (int f = 0; names && f < frames; f++)
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
    if ((st = bb__image_write_staged_all_cores(path, &picture, &wo, staged, &e)) != BB_OK)
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
    paths[i] = f->frames ? bb__render_frame_path(o->path, i, f->frames) : strdup(o->path);
    kinds[i] = o->kind;
    st = paths[i] ? stage_frame(o, f, i, paths[i], &staged[i], err)
                  : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->path);
  }
  if (st == BB_OK)
    st = bb__staged_files_commit(staged, kinds, n, err);
  for (int i = 0; staged && i < n; i++)
    if (st != BB_OK)
      bb__staged_file_discard(staged[i]);
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
 * place by bb__animation_close. */
static bb_status write_gif(const bb__job_output *o, const bb__job_frames *f, char ***written,
                           int *count, bb_error *err) {
  bb_animation *anim = NULL;
  bb_error e = {{0}};
  bb_status st = BB_OK;
  for (int i = 0; i < f->frames && st == BB_OK; i++) {
    bb_image picture = {0};
    st = f->make(f->user, i, &picture, NULL, err);
    if (st == BB_OK && !anim)
      st = bb__animation_open(o->path, picture.width, picture.height, 10.0, &anim, &e);
    if (st == BB_OK)
      st = bb__animation_add_frame(anim, &picture, &e);
    if (st != BB_OK && e.message[0])
      bb__fail_at(err, st, o->path, &e);
    bb_image_free(&picture);
  }
  if (st != BB_OK) {
    bb__animation_abort(anim);
    return st;
  }
  if ((st = bb__animation_close(anim, &e)) != BB_OK)
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
