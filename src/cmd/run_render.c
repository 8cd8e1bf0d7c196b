/* run_render.c: render's and sheet's runs: the maps read (or baked from a
 * HEIGHT), the picture (or every frame of an orbit, or the contact sheet)
 * made, and written by the job (job/output.c: frame names, provenance,
 * staged all-or-nothing writes), the paths checked against the inputs
 * before (bb_command_check). */
#include "bake/bake_internal.h"
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "core/internal.h"
#include "maps/maps_internal.h"
#include "render/render_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What render reads from its options. */
typedef struct render_args {
  const bb_command_options *o;
  bb_render_options render; /* the options', and the relief height once baked */
  bb_bake_options bake;
  const char *height_path, *output;
  int compare, orbit, green_up;
  const bb_command_hooks *hooks;
} render_args;

/* The maps the picture reads: the mode's, or all three for --compare. */
static unsigned needed_maps(const render_args *a) {
  if (a->compare)
    return BB_RENDER_NEEDS_NORMAL | BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO;
  return bb__render_mode_needs(a->render.mode);
}

/* Everything a picture is made from, and what the provenance says of it. */
typedef struct render_inputs {
  bb_image height;
  bb_height_source source; /* the height's, when one was baked */
  bb_bake_result bake;
  bb_image maps[BB_MAP_KIND_COUNT]; /* read from files */
  bb_image albedo;
  bb_image slope;      /* made from the bake's filtered height for --mode slope */
  bb_render_maps view; /* pointers into the above */
  bb_render_sources sources;
  const char *input;   /* the file the provenance's input keys describe */
  uint64_t input_hash;
} render_inputs;

static void inputs_free(render_inputs *in) {
  bb_image_free(&in->height);
  bb_bake_result_free(&in->bake);
  for (int m = 0; m < BB_MAP_KIND_COUNT; m++)
    bb_image_free(&in->maps[m]);
  bb_image_free(&in->albedo);
  bb_image_free(&in->slope);
}

bb_status bb__render_view_check(const bb_render_options *o, int width, int height,
                                bb_error *err) {
  const long w = (long)width * o->tile_x, h = (long)height * o->tile_y;
  if (w > BB_MAX_DIMENSION || h > BB_MAX_DIMENSION || w * h > BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--tile %d makes a %ldx%ld picture, over the maximum (%ld texels)",
                    o->tile_x, w, h, (long)BB_MAX_PIXELS);
  if (o->crop_width > 0 &&
      ((long)o->crop_x + o->crop_width > w || (long)o->crop_y + o->crop_height > h))
    return bb__fail(err, BB_ERR_ARGUMENT, "--crop %d,%d,%d,%d is not inside the %ldx%ld picture",
                    o->crop_x, o->crop_y, o->crop_width, o->crop_height, w, h);
  return BB_OK;
}

/* A crop must fit the tiled picture (render_check looked already, from the
 * headers). */
static bb_status check_view(const render_args *a, const bb_image *size, bb_error *err) {
  return bb__render_view_check(&a->render, size->width, size->height, err);
}

static bb_status load_maps(const render_args *a, render_inputs *in, bb_error *err) {
  const bb_image *size = NULL;
  in->sources.maps_normal_y_up = a->green_up;
  for (int m = 0; m < BB_MAP_KIND_COUNT; m++) {
    const char *path = a->o->render_maps[m];
    if (!path)
      continue;
    bb_error e = {{0}};
    uint64_t hash = 0;
    bb_status st = bb_render_map_read(path, (bb_map_kind)m, a->green_up, size, &in->maps[m],
                                      &hash, &e);
    if (st != BB_OK)
      return bb__fail_at(err, st, path, &e);
    in->sources.maps[m] = path;
    if (!in->input) {
      in->input = path;
      in->input_hash = hash;
    }
    if (!size)
      size = &in->maps[m];
  }
  bb_status st = check_view(a, size, err);
  if (st != BB_OK)
    return st;
  for (int m = 0; m < BB_MAP_KIND_COUNT; m++) {
    const bb_image *map = in->maps[m].pixels ? &in->maps[m] : NULL;
    switch ((bb_map_kind)m) {
    case BB_MAP_NORMAL: in->view.normal = map; break;
    case BB_MAP_SSBUMP: in->view.ssbump = map; break;
    case BB_MAP_AO: in->view.ao = map; break;
    case BB_MAP_BENT: in->view.bent = map; break;
    case BB_MAP_SLOPE: in->view.slope = map; break;
    default: break;
    }
  }
  return BB_OK;
}

/* The maps the picture needs, baked from a height field as `bumpbake
 * bake` bakes them: the normal always (every mode lights with it), the
 * filtered height for the slope map and the relief, the traced maps when
 * the picture shows one. what names the height in messages. */
static bb_status bake_for_picture(render_args *a, const bb_image *height, const char *what,
                                  render_inputs *in, bb_error *err) {
  const bb_command_hooks *hooks = a->hooks;
  bb_status st = check_view(a, height, err);
  if (st != BB_OK)
    return st;
  const int traced = (needed_maps(a) & (BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO)) != 0;
  a->bake.outputs = BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_FILTERED) |
                    (traced ? BB_MAPS_TRACED : 0u);
  a->bake.trace.progress = hooks ? hooks->progress : NULL;
  a->bake.trace.progress_user = hooks ? hooks->progress_user : NULL;
  bb_error e = {{0}};
  st = bb__bake_checked(height, &a->bake, &in->bake, &e);
  if (st != BB_OK)
    return bb__fail_at(err, st, what, &e);
  bb_bake_result *r = &in->bake;
  a->render.relief_height = &r->filtered; /* --relief: the height as baked */
  a->render.relief_depth = (double)a->bake.height_scale;
  in->view = (bb_render_maps){&r->normal, r->ssbump.pixels ? &r->ssbump : NULL,
                              r->ao.pixels ? &r->ao : NULL, r->bent.pixels ? &r->bent : NULL,
                              NULL, NULL};
  if (needed_maps(a) & BB_RENDER_NEEDS_SLOPE) {
    /* The slope map bake --slope would write, from the same filtered height. */
    st = bb__slope_map(&r->filtered, a->bake.height_scale, a->bake.smooth.addressing, &in->slope,
                      &e);
    if (st != BB_OK)
      return bb__fail_at(err, st, what, &e);
    in->view.slope = &in->slope;
  }
  return BB_OK;
}

static bb_status bake_height(render_args *a, render_inputs *in, bb_error *err) {
  const bb_command_hooks *hooks = a->hooks;
  bb_error e = {{0}};
  bb_status st = bb__height_file_read(a->height_path, a->o->job.channel, a->bake.height_scale,
                                     hooks ? hooks->note : NULL, hooks ? hooks->note_user : NULL,
                                     &in->height, &in->source, &e);
  if (st != BB_OK)
    return bb__fail_at(err, st, a->height_path, &e);
  st = bake_for_picture(a, &in->height, a->height_path, in, err);
  in->input = a->height_path;
  in->input_hash = in->source.height_hash;
  in->sources.height = a->height_path;
  return st;
}

static bb_status load_albedo(const render_args *a, render_inputs *in, bb_error *err) {
  const char *path = a->o->albedo;
  if (!path)
    return BB_OK;
  bb_error e = {{0}};
  bb_status st = bb_image_read(path, &in->albedo, NULL, &e);
  if (st != BB_OK)
    return bb__fail_at(err, st, path, &e);
  const bb_image *size = in->view.normal ? in->view.normal : in->view.ssbump;
  if (size && (in->albedo.width != size->width || in->albedo.height != size->height))
    return bb__fail(err, BB_ERR_SIZE, "%s: albedo is %dx%d, but the maps are %dx%d", path,
                    in->albedo.width, in->albedo.height, size->width, size->height);
  in->view.albedo = &in->albedo;
  in->sources.albedo = path;
  in->sources.albedo_hash = bb__image_hash(&in->albedo);
  return BB_OK;
}

/* One picture (a render or the comparison) with the light at azimuth. */
static bb_status make_picture(const render_args *a, const render_inputs *in, double azimuth,
                              bb_image *out, int *labels_drawn, bb_error *err) {
  bb_render_options o = a->render;
  o.light_azimuth = azimuth;
  bb_error e = {{0}};
  bb_status st;
  int labels = 1;
  if (a->compare) {
    bb_panel_layout layout;
    bb__panel_layout_init(&layout);
    st = bb__render_compare(&in->view, &o, &layout, out, &labels, &e);
  } else {
    st = bb__render(&in->view, &o, out, &e);
  }
  *labels_drawn &= labels;
  if (st == BB_ERR_ARGUMENT) /* the maps were checked as they were read: the view */
    return bb__fail(err, st, "%s", e.message);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, a->output, &e);
}

/* The render's own provenance lines of one picture (bb__render_provenance). */
static char *render_lines(const render_args *a, const render_inputs *in, double azimuth,
                          int frame) {
  bb_render_options o = a->render;
  o.light_azimuth = azimuth;
  bb_render_sources sources = in->sources;
  sources.frame = frame;
  sources.frames = a->orbit;
  return bb__render_provenance(&sources, &o);
}

static double frame_azimuth(const render_args *a, int frame) {
  return a->render.light_azimuth + 360.0 * frame / (a->orbit ? a->orbit : 1);
}

/* What the job's frames (bb__job_write_frames) are made from. */
typedef struct render_frames {
  const render_args *a;
  const render_inputs *in;
  int *labels_drawn;
} render_frames;

static bb_status make_frame(void *user, int frame, bb_image *picture, char **extra,
                            bb_error *err) {
  const render_frames *f = user;
  const double azimuth = frame_azimuth(f->a, frame);
  bb_status st = make_picture(f->a, f->in, azimuth, picture, f->labels_drawn, err);
  if (st == BB_OK && extra)
    *extra = render_lines(f->a, f->in, azimuth, frame);
  return st;
}

/* The picture, or every frame of an orbit (or its GIF), written by the job
 * with the input's keys, the bake's when a height was baked, then the
 * render's. */
static bb_status write_pictures(const render_args *a, const char *command_line,
                                const render_inputs *in, bb_command_result *result,
                                bb_error *err) {
  const int baked = a->height_path != NULL;
  const int traced = baked && (a->bake.outputs & BB_MAPS_TRACED);
  const bb__job_source source = {.command = command_line,
                                 .input = in->input,
                                 .input_hash = in->input_hash,
                                 .input_file_hash = baked ? in->source.file_hash : 0,
                                 .bake = baked ? &a->bake : NULL,
                                 .channel = baked ? a->o->job.channel : BB_CHANNEL_AUTO,
                                 .rayset_id = traced ? in->bake.rayset_id : NULL};
  render_frames user = {a, in, &result->labels_drawn};
  const bb__job_frames frames = {a->orbit, a->compare ? "render-compare" : "render", &source,
                                 make_frame, &user};
  const bb__job_output out = {a->output, a->compare ? "comparison" : "render", BB_RANGE_UNIT,
                              a->o->job.depth, NULL, 0, NULL};
  char **paths = NULL;
  int count = 0;
  const char *kind = NULL;
  bb_status st = bb__job_write_frames(&out, &frames, &paths, &count, &kind, err);
  for (int f = 0; st == BB_OK && f < count; f++)
    st = bb__result_add(result, kind, paths[f], err);
  result->frames = a->orbit;
  for (int f = 0; f < count; f++)
    free(paths[f]);
  free(paths);
  return st;
}

bb_status bb__run_render(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                         bb_error *err) {
  const bb_command_options *o = &c->options;
  render_args a = {o, o->render, o->job.bake, c->input_count ? c->inputs[0] : NULL, o->output,
                   o->render_compare, o->orbit, o->maps_normal_y_up, hooks};
  char *record = bb__command_record(c);
  if (!record)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  render_inputs in;
  memset(&in, 0, sizeof in);
  bb_status st = a.height_path ? bake_height(&a, &in, err) : load_maps(&a, &in, err);
  if (st == BB_OK)
    st = load_albedo(&a, &in, err);
  if (st == BB_OK)
    st = write_pictures(&a, record, &in, r, err);
  inputs_free(&in);
  free(record);
  return st;
}

/* ---------------------------------------------------------------- sheet */

static bb_status sheet_picture(const bb_command_options *a, const bb_command_hooks *hooks,
                               const bb_image *height, const char *what,
                               bb_bake_result *result, bb_image *picture, int *labels,
                               bb_error *err) {
  bb_sheet_options sheet;
  bb__sheet_options_init(&sheet);
  sheet.lit = a->render;
  sheet.layout.panel_width = a->panel_size;
  bb_bake_options bake = a->job.bake;
  bake.trace.progress = hooks ? hooks->progress : NULL;
  bake.trace.progress_user = hooks ? hooks->progress_user : NULL;
  bb_error e = {{0}};
  bb_status st = bb__bake_checked(height, &bake, result, &e);
  if (st != BB_OK)
    return bb__fail_at(err, st, what, &e);
  st = bb__sheet_make(height, result, &sheet, picture, labels, &e);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, what, &e);
}

static bb_status picture(bb_command *c, const bb_image *height,
                         const bb_render_maps *maps, const bb_command_hooks *hooks,
                         bb_image *out, int *labels_drawn, bb_error *err) {
  if (!c || !out)
    return bb__fail(err, BB_ERR_ARGUMENT, "picture: bad arguments");
  memset(out, 0, sizeof *out);
  if (!c->checked || !c->in_memory)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: the command is not checked for images in memory", c->def->info.name);
  int labels = 1;
  bb_status st;
  if (c->def->run == bb__run_sheet) {
    if (!height)
      return bb__fail(err, BB_ERR_ARGUMENT, "sheet: a height is needed");
    bb_bake_result result;
    memset(&result, 0, sizeof result);
    st = sheet_picture(&c->options, hooks, height, "sheet", &result, out, &labels, err);
    bb_bake_result_free(&result);
  } else if (c->def->run == bb__run_render) {
    const bb_command_options *o = &c->options;
    render_args a = {o, o->render, o->job.bake, NULL, "render", o->render_compare, 0,
                     o->maps_normal_y_up, hooks};
    render_inputs in;
    memset(&in, 0, sizeof in);
    if (height) {
      st = bake_for_picture(&a, height, "height", &in, err);
      if (st == BB_OK && maps && maps->albedo)
        in.view.albedo = maps->albedo;
    } else if (maps) {
      in.view = *maps;
      const bb_image *size = maps->normal ? maps->normal : maps->ssbump ? maps->ssbump
                             : maps->ao  ? maps->ao
                                         : maps->slope;
      st = size ? check_view(&a, size, err) : BB_OK;
    } else {
      st = bb__fail(err, BB_ERR_ARGUMENT, "render: a height or maps are needed");
    }
    if (st == BB_OK)
      st = make_picture(&a, &in, a.render.light_azimuth, out, &labels, err);
    inputs_free(&in);
  } else {
    st = bb__fail(err, BB_ERR_ARGUMENT, "%s makes no picture", c->def->info.name);
  }
  if (labels_drawn)
    *labels_drawn = labels;
  return st;
}

bb_status bb__run_sheet(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                        bb_error *err) {
  const bb_command_options *a = &c->options;
  const char *input = c->inputs[0];
  bb_sheet_options sheet;
  bb__sheet_options_init(&sheet);
  sheet.lit = a->render;
  sheet.layout.panel_width = a->panel_size;
  bb_image height = {0}, picture = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  bb_height_source source;
  bb_error e = {{0}};
  char *extra = NULL, *record = bb__command_record(c);
  bb_status st = record ? BB_OK : bb__fail(err, BB_ERR_MEMORY, "out of memory");
  if (st == BB_OK &&
      (st = bb__height_file_read(input, a->job.channel, a->job.bake.height_scale,
                                hooks ? hooks->note : NULL, hooks ? hooks->note_user : NULL,
                                &height, &source, &e)) != BB_OK)
    bb__fail_at(err, st, input, &e);
  if (st == BB_OK)
    st = sheet_picture(a, hooks, &height, input, &result, &picture, &r->labels_drawn, err);
  /* the height's and the bake's keys, then the lit panel's options */
  if (st == BB_OK && !(extra = bb__render_options_describe(&sheet.lit)))
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", a->output);
  if (st == BB_OK) {
    const bb__job_source s = {.command = record,
                              .input = input,
                              .input_hash = source.height_hash,
                              .input_file_hash = source.file_hash,
                              .bake = &a->job.bake,
                              .channel = a->job.channel,
                              .rayset_id = result.rayset_id,
                              .extra = extra};
    const bb__job_output out = {a->output, "sheet", BB_RANGE_UNIT, a->job.depth, NULL, 0, NULL};
    st = bb__job_write(&out, &picture, &s, err);
  }
  if (st == BB_OK)
    st = bb__result_add(r, "sheet", a->output, err);
  free(extra);
  free(record);
  bb_image_free(&picture);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  return st;
}

bb_status bb_command_picture(bb_command *c, const bb_image *height,
                             const bb_render_maps *maps, const bb_command_hooks *hooks,
                             bb_image *out, int *labels_drawn, bb_error *err) {
  bb__spelled_hooks h;
  return bb__spelled(c,
                     picture(c, height, maps,
                             c ? bb__spelled_hooks_of(c, hooks, &h) : hooks, out,
                             labels_drawn, err),
                     err);
}
