/* bake.c: the pipeline smooth -> normals -> pyramid -> trace -> derive over
 * one height field, with the time of each stage. No file I/O here. */

#include "bake/bake_internal.h"
#include "trace/basis.h"
#include "core/internal.h"
#include "trace/bounce.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/retrace.h"
#include "trace/trace.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

void bb_bake_result_free(bb_bake_result *r) {
  bb_image_free(&r->filtered);
  bb_image_free(&r->normal);
  bb_image_free(&r->weights);
  bb_image_free(&r->vis);
  bb_image_free(&r->ssbump);
  bb_image_free(&r->ao);
  bb_image_free(&r->bent);
  memset(r, 0, sizeof *r);
}

static int wants(const bb_bake_options *o, unsigned bits) {
  return (o->outputs & bits) != 0;
}

/* Heights in texels, the field the tracer sees. */
static bb_status scaled_heights(const bb_image *h, float scale, bb_image *out,
                                bb_error *err) {
  bb_status st = bb_image_alloc(out, h->width, h->height, 1, err);
  if (st != BB_OK) return st;
  size_t n = (size_t)h->width * (size_t)h->height;
  for (size_t i = 0; i < n; i++) out->pixels[i] = scale * h->pixels[i];
  return BB_OK;
}

/* The trace of the caller's (bb_trace_options.trace) in place of
 * bb__trace_occlusion; what it makes is checked to be what that would make. */
static bb_status caller_trace(const bb_pyramid *p, const bb_rayset *rs, const bb_trace_options *o,
                              bb_image *vis, double *horizons_found, bb_error *err) {
  memset(vis, 0, sizeof *vis);
  bb_error local = {{0}};
  bb_status st = o->trace(o->trace_user, p, rs, o, vis, &local);
  if (st != BB_OK) {
    bb_image_free(vis);
    return bb__fail(err, st, "%s", local.message[0] ? local.message : "trace: failed");
  }
  if (!vis->pixels || vis->width != p->width || vis->height != p->height ||
      vis->channels != 1 + rs->basis_count) {
    bb_image_free(vis);
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "trace: the caller's trace made no %dx%d image of %d channels", p->width,
                    p->height, 1 + rs->basis_count);
  }
  *horizons_found = (double)p->width * (double)p->height * (double)rs->slice_count;
  return BB_OK;
}

/* The grey of the bounce albedo map per vertex, clamped to [0, 1]. */
static bb_status albedo_grey(const bb_image *map, int width, int height, bb_image *out,
                             bb_error *err) {
  bb_status st = bb__image_grey(map, width, height, "bake: the bounce albedo map", out, err);
  if (st != BB_OK) return st;
  const size_t n = (size_t)width * (size_t)height;
  for (size_t i = 0; i < n; i++) out->pixels[i] = fminf(fmaxf(out->pixels[i], 0.0f), 1.0f);
  return BB_OK;
}

/* The inter-reflection's options for a bake of the pyramid (its albedo map
 * set apart), its coarse level chosen by the map's size. */
static void bounce_options(const bb_bake_options *o, const bb_pyramid *p, int threads,
                           bb__bounce_options *bo) {
  bb__bounce_options_init(bo);
  bo->rho = o->bounce_albedo;
  bo->bounces = o->bounces;
  bo->bias = o->trace.bias_texels;
  bo->level = bb__bounce_level(bo, p->width, p->height, p->addressing);
  bo->threads = threads;
  bo->progress = o->trace.progress;
  bo->progress_user = o->trace.progress_user;
}

/* With inter-reflection, the trace's progress is the first part of the
 * whole (its slices against the bounce's weighted passes), so the bar
 * runs once from 0 to 100% over both. */
typedef struct trace_progress {
  bb_progress_fn progress;
  void *user;
  long span, total; /* the trace's part of the whole, and the whole */
} trace_progress;

static int trace_progress_of(void *user, long done, long total) {
  const trace_progress *t = user;
  const long part = total > 0 ? (long)((double)t->span * (double)done / (double)total) : 0;
  return t->progress(t->user, part < t->span ? part : t->span, t->total);
}

/* Inter-reflection, added to r->vis (bounce.c); the trace did trace_work
 * of the progress before it. With r->vis not yet made, the bounce's passes
 * are the trace too (its sweeps find the texels' horizons, and r->vis is
 * bb__trace_occlusion's, bit for bit, before the bounce is added). */
static bb_status bounce(const bb_bake_options *o, const bb_pyramid *pyramid,
                        const bb_rayset *rays, int threads, long trace_work, bb_bake_result *r,
                        bb_error *err) {
  bb_image grey = {0};
  bb_status st = BB_OK;
  if (o->bounce_albedo_map)
    st = albedo_grey(o->bounce_albedo_map, pyramid->width, pyramid->height, &grey, err);
  bb__bounce_options bo;
  bounce_options(o, pyramid, threads, &bo);
  bo.albedo = grey.pixels ? &grey : NULL;
  bo.progress_before = trace_work;
  if (st == BB_OK) st = bb__bounce_add(pyramid, rays, &bo, &r->vis, &r->bounces, err);
  bb_image_free(&grey);
  return st;
}

/* Inter-reflection can make a lobe brighter than its open sky, but a
 * channel of the ssbump holds at most 1. */
static void ssbump_cap(bb_image *ssbump) {
  const size_t n = (size_t)ssbump->width * (size_t)ssbump->height * (size_t)ssbump->channels;
  for (size_t i = 0; i < n; i++)
    if (ssbump->pixels[i] > 1.0f) ssbump->pixels[i] = 1.0f;
}

/* pyramid -> trace -> ssbump, ao, bent: the asked ones, and ssbump for bent.
 * What is done with goes as soon as it is: the pyramid after the trace, vis
 * (unless keep_vis) once ssbump and ao are made, the smoothed height once
 * nothing needs it; the normal map is made after the trace, when vis is
 * gone, and ssbump without one takes its normals a band at a time. */
static bb_status trace_and_derive(const bb_bake_options *o, int threads, int keep_vis,
                                  bb_bake_context *context, bb__bake_keep *keep,
                                  bb_bake_result *r, bb_error *err) {
  double t0 = bb__now_seconds();
  bb_image z = {0};
  bb_pyramid *pyramid = NULL;
  bb_rayset rays = {0};
  int rays_owned = 1; /* a context lends its ray set */
  trace_progress progress = {o->trace.progress, o->trace.progress_user, 0, 0};
  bb_status st = scaled_heights(&r->filtered, o->height_scale, &z, err);
  if (st == BB_OK) st = bb__pyramid_build(&z, o->smooth.addressing, threads, &pyramid, err);
  bb_image_free(&z);
  if (st == BB_OK)
    st = bb__context_rayset(context, o->slices, o->power, &o->basis, threads, &rays, &rays_owned,
                            err);
  double t1 = bb__now_seconds();
  r->seconds_pyramid = t1 - t0;
  if (st == BB_OK) {
    snprintf(r->rayset_id, sizeof r->rayset_id, "%s", rays.id);
    bb_trace_options whole = o->trace;
    whole.region = (bb_region){0, 0, 0, 0}; /* a bake traces every texel */
    whole.threads = threads;
    bb__bounce_options bo;
    bounce_options(o, pyramid, threads, &bo);
    /* on a coarse level, the bounce's passes are not the map's trace */
    const int coarse = bo.level > 1;
    if (o->bounce_albedo > 0.0 && o->trace.progress && (o->trace.trace || coarse)) {
      progress.span = (long)rays.slice_count * BB__BOUNCE_TRACE_WORK;
      progress.total = progress.span + bb__bounce_work(&rays, &bo);
      whole.progress = trace_progress_of;
      whole.progress_user = &progress;
    }
    if (o->trace.trace)
      st = caller_trace(pyramid, &rays, &whole, &r->vis, &r->horizons_found, err);
    else if (keep)
      st = bb__trace_keeping_horizons(pyramid, &rays, &whole, keep->horizons, &r->vis,
                                      err);
    else if (o->bounce_albedo > 0.0 && !coarse) /* the bounce's passes are the trace */
      r->horizons_found = (double)pyramid->width * (double)pyramid->height * rays.slice_count;
    else
      st = bb__trace_occlusion(pyramid, &rays, &whole, &r->vis, &r->horizons_found, err);
    if (st == BB_OK && keep)
      r->horizons_found =
          (double)pyramid->width * (double)pyramid->height * rays.slice_count;
  }
  double t2 = bb__now_seconds();
  r->seconds_trace = t2 - t1;
  if (st == BB_OK && o->bounce_albedo > 0.0) {
    st = bounce(o, pyramid, &rays, threads, progress.span, r, err);
    const double t3 = bb__now_seconds();
    r->seconds_bounce = t3 - t2;
    t2 = t3;
  }
  if (rays_owned)
    bb__rayset_release(&rays);
  if (keep && st == BB_OK)
    keep->pyramid = pyramid; /* the kept bake's */
  else
    bb_pyramid_free(pyramid);
  const int keep_filtered = wants(o, BB_MAP_BIT(BB_MAP_FILTERED)) || keep;
  const unsigned ssbump_or_bent =
      BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_BENT);
  const int normal_later = wants(o, BB_MAP_BIT(BB_MAP_NORMAL)) && !r->normal.pixels;
  if (st == BB_OK && wants(o, ssbump_or_bent))
    st = r->normal.pixels
             ? bb__derive_ssbump(&r->normal, &r->vis, &o->basis, threads, &r->ssbump, err)
             : bb__derive_ssbump_from_height(&r->filtered, o->height_scale, o->normal_filter,
                                             o->smooth.addressing, &r->vis, &o->basis, threads,
                                             &r->ssbump, err);
  if (st == BB_OK && r->ssbump.pixels && o->bounce_albedo > 0.0) ssbump_cap(&r->ssbump);
  if (!normal_later && !keep_filtered)
    bb_image_free(&r->filtered);
  if (st == BB_OK && wants(o, BB_MAP_BIT(BB_MAP_AO)))
    st = bb__derive_ao(&r->vis, threads, &r->ao, err);
  if (!keep_vis)
    bb_image_free(&r->vis);
  if (st == BB_OK && normal_later)
    st = bb__normals_compute(&r->filtered, o->height_scale, o->normal_filter,
                             o->smooth.addressing, threads, NULL, &r->normal, err);
  if (!keep_filtered)
    bb_image_free(&r->filtered);
  if (st == BB_OK && wants(o, BB_MAP_BIT(BB_MAP_BENT)))
    st = bb__derive_bent(&r->ssbump, &o->basis, threads, &r->bent, err);
  r->seconds_derive += bb__now_seconds() - t2;
  return st;
}

/* smooth -> normals -> weights, as far as the asked maps need them: the
 * normal map waits for the trace (trace_and_derive) unless weights need it
 * now or nothing is traced. */
static bb_status smooth_and_normals(const bb_image *height, const bb_bake_options *o,
                                    int threads, int take_height, bb_bake_result *r,
                                    bb_error *err) {
  double t0 = bb__now_seconds();
  /* Neither stage reports progress; both are cancel points (Ctrl-C in
   * Python, a newer save in serve): a large map smooths for seconds. */
  const bb__checkpoint checkpoint = {o->trace.progress, o->trace.progress_user};
  bb_status st =
      bb__smooth_bilateral(height, height, &o->smooth, threads, &checkpoint, &r->filtered, err);
  if (take_height) /* smoothed: the bake reads only its own maps from now on */
    bb_image_free((bb_image *)height);
  double t1 = bb__now_seconds();
  r->seconds_smooth = t1 - t0;
  const int normal_now = wants(o, BB_MAP_BIT(BB_MAP_WEIGHTS)) ||
                         (wants(o, BB_MAP_BIT(BB_MAP_NORMAL)) &&
                          !wants(o, BB_MAPS_TRACED));
  if (st == BB_OK && normal_now)
    st = bb__normals_compute(&r->filtered, o->height_scale, o->normal_filter,
                             o->smooth.addressing, threads, &checkpoint, &r->normal, err);
  if (st == BB_OK && wants(o, BB_MAP_BIT(BB_MAP_WEIGHTS)))
    st = bb__derive_weights(&r->normal, &o->basis, threads, &r->weights, err);
  r->seconds_derive = bb__now_seconds() - t1;
  return st;
}

/* The brightness map on ssbump and weights, every basis channel (bent was
 * derived before, from the ssbump's own directions). */
static bb_status brightness(const bb_bake_options *o, int threads, bb_bake_result *r,
                            bb_error *err) {
  bb_image *maps[2] = {wants(o, BB_MAP_BIT(BB_MAP_SSBUMP)) ? &r->ssbump : NULL,
                       wants(o, BB_MAP_BIT(BB_MAP_WEIGHTS)) ? &r->weights : NULL};
  for (int i = 0; i < 2; i++) {
    if (!maps[i] || !maps[i]->pixels) continue;
    bb_image scaled;
    bb_status st = bb__derive_brightness(maps[i], maps[i]->channels, o->brightness, "bake",
                                         threads, &scaled, err);
    if (st != BB_OK) return st;
    bb_image_free(maps[i]);
    *maps[i] = scaled;
  }
  return BB_OK;
}

/* Frees what was made only because another map needed it (a kept bake
 * keeps its smoothed height). */
static void drop_unasked(const bb_bake_options *o, const bb__bake_keep *keep,
                         bb_bake_result *r) {
  if (!wants(o, BB_MAP_BIT(BB_MAP_FILTERED)) && !keep)
    bb_image_free(&r->filtered);
  if (!wants(o, BB_MAP_BIT(BB_MAP_NORMAL))) bb_image_free(&r->normal);
  if (!wants(o, BB_MAP_BIT(BB_MAP_SSBUMP))) bb_image_free(&r->ssbump);
}

bb_status bb__bake_checked(const bb_image *height, const bb_bake_options *o, bb_bake_result *r,
                           bb_error *err) {
  bb_bake_options prepared;
  if (r)
    memset(r, 0, sizeof *r);
  bb_status st = bb__bake_prepare(o, &prepared, err);
  /* no flag: height is only read */
  return st == BB_OK ? bb__bake((bb_image *)height, &prepared, 0, NULL, r, err) : st;
}

static bb_status bake_stages(const bb_image *height, const bb_bake_options *o,
                             unsigned flags, bb_bake_context *context,
                             bb__bake_keep *keep, bb_bake_result *r, bb_error *err);

bb_status bb__bake(bb_image *height, const bb_bake_options *o, unsigned flags,
                   bb_bake_context *context, bb_bake_result *r, bb_error *err) {
  const bb_region whole = {0, 0, height ? height->width : 0, height ? height->height : 0};
  bb_status st = bake_stages(height, o, flags, context, NULL, r, err);
  if (st == BB_OK && context)
    bb__context_set_changed(context, whole);
  if (flags & BB__BAKE_TAKE_HEIGHT)
    bb_image_free(height);
  return st;
}

/* Before anything is allocated: refuses a bake the machine cannot hold
 * (bb__bake_memory against bb__memory_available), with the figures. */
static bb_status check_memory(const bb_image *height, const bb_bake_options *o, unsigned flags,
                              bb_error *err) {
  char what[64];
  snprintf(what, sizeof what, "bake: %d x %d", height->width, height->height);
  return bb__memory_check(bb__bake_memory(height->width, height->height, o, flags, 0.0, NULL),
                          what, err);
}

bb_status bb__bake_keeping(const bb_image *height, const bb_bake_options *o,
                           bb_bake_context *context, bb__bake_keep *keep,
                           bb_bake_result *r, bb_error *err) {
  return bake_stages(height, o, 0, context, keep, r, err);
}

static bb_status bake_stages(const bb_image *height, const bb_bake_options *o,
                             unsigned flags, bb_bake_context *context,
                             bb__bake_keep *keep, bb_bake_result *r, bb_error *err) {
  memset(r, 0, sizeof *r);
  if (!height || !height->pixels || height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: need a 1-channel height field");
  bb_status st = BB_OK;
  /* Before any stage: an overflow of scale x height is named as such, a
   * map of another size as such. */
  if (st == BB_OK) st = bb__check_scaled_height(height, o->height_scale, err);
  const bb_image *sized[2] = {o->bounce_albedo > 0.0 ? o->bounce_albedo_map : NULL, o->brightness};
  const char *sized_name[2] = {"bounce albedo map", "brightness map"};
  for (int i = 0; st == BB_OK && i < 2; i++)
    if (sized[i] && (sized[i]->width != height->width || sized[i]->height != height->height))
      st = bb__fail(err, BB_ERR_SIZE, "bake: the %s is %dx%d, the height %dx%d", sized_name[i],
                    sized[i]->width, sized[i]->height, height->width, height->height);
  if (st == BB_OK) st = check_memory(height, o, flags, err);
  if (st != BB_OK) return st;
  r->basis = o->basis;
  const int threads = bb__thread_count(o->trace.threads);
  st = smooth_and_normals(height, o, threads, (flags & BB__BAKE_TAKE_HEIGHT) != 0, r, err);
  if (st == BB_OK && wants(o, BB_MAPS_TRACED))
    st =
        trace_and_derive(o, threads, !(flags & BB__BAKE_DROP_VIS), context, keep, r, err);
  if (st == BB_OK && o->brightness) st = brightness(o, threads, r, err);
  if (st == BB_OK && o->normal_y_up) {
    if (wants(o, BB_MAP_BIT(BB_MAP_NORMAL))) bb__image_flip_green(&r->normal);
    if (r->bent.pixels) bb__image_flip_green(&r->bent);
  }
  if (st == BB_ERR_CANCELLED)
    bb__fail(err, st, "bake: cancelled by the progress callback");
  if (st != BB_OK) {
    bb_bake_result_free(r);
    return st;
  }
  drop_unasked(o, keep, r);
  r->threads = threads;
  return BB_OK;
}
