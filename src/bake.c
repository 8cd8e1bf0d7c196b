/* bake.c: the pipeline smooth -> normals -> pyramid -> trace -> derive over
 * one height field, with the time of each stage. No file I/O here. */
#include "internal.h"
#include "trace_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void bb_bake_options_init(bb_bake_options *o) {
  memset(o, 0, sizeof *o);
  o->height_scale = 0.0f; /* must be set: there is no meaningful default */
  o->rays = 256;
  bb_smooth_options_init(&o->smooth);
  bb_trace_options_init(&o->trace);
  o->power = 1.0;
  bb_basis_init(&o->basis);
  o->normal_filter = BB_NORMAL_VERTEX;
  o->want_trace = 1;
}

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

static bb_status check_options(const bb_bake_options *o, bb_error *err) {
  if (!(o->height_scale > 0.0f) || !isfinite(o->height_scale))
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: height scale must be > 0 (got %g)",
                    (double)o->height_scale);
  if (o->want_trace && !o->slices && (o->rays < 1 || o->rays > 65536))
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: rays must be in 1..65536 (got %d)", o->rays);
  if (o->want_trace && (o->slices < 0 || o->slices > BB_MAX_SLICES))
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: slices must be in 1..%d (got %d)",
                    BB_MAX_SLICES, o->slices);
  if (!(o->power >= 1.0) || !isfinite(o->power))
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: power must be >= 1 (got %g)", o->power);
  if (!(o->trace.bias_texels >= 0.0) || !isfinite(o->trace.bias_texels))
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: bias must be >= 0 (got %g)",
                    o->trace.bias_texels);
  return bb__basis_check(&o->basis, "bake", err);
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

/* pyramid -> trace -> ssbump, ao, bent. */
static bb_status trace_and_derive(const bb_bake_options *o, bb_bake_result *r,
                                  bb_error *err) {
  double t0 = bb__now_seconds();
  bb_image z = {0};
  bb_pyramid *pyramid = NULL;
  bb_rayset rays = {0};
  bb_status st = scaled_heights(&r->filtered, o->height_scale, &z, err);
  if (st == BB_OK) st = bb_pyramid_build(&z, o->smooth.addressing, &pyramid, err);
  bb_image_free(&z);
  const int slices = o->slices ? o->slices : bb_slices_for_rays(o->rays);
  if (st == BB_OK) st = bb_rayset_make(slices, o->power, &o->basis, &rays, err);
  double t1 = bb__now_seconds();
  r->seconds_pyramid = t1 - t0;
  if (st == BB_OK) {
    snprintf(r->rayset_id, sizeof r->rayset_id, "%s", rays.id);
    bb_trace_options whole = o->trace;
    whole.region = (bb_region){0, 0, 0, 0}; /* a bake traces every texel */
    st = bb_trace_occlusion(pyramid, &rays, &whole, &r->vis, &r->horizons_found, err);
  }
  double t2 = bb__now_seconds();
  r->seconds_trace = t2 - t1;
  bb_rayset_free(&rays);
  bb_pyramid_free(pyramid);
  if (st == BB_OK) st = bb_derive_ssbump(&r->normal, &r->vis, &o->basis, &r->ssbump, err);
  if (st == BB_OK) st = bb_derive_ao(&r->vis, &r->ao, err);
  if (st == BB_OK) st = bb_derive_bent(&r->ssbump, &o->basis, &r->bent, err);
  r->seconds_derive += bb__now_seconds() - t2;
  return st;
}

bb_status bb_bake(const bb_image *height, const bb_bake_options *o, bb_bake_result *r,
                  bb_error *err) {
  memset(r, 0, sizeof *r);
  if (!height || !height->pixels || height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: need a 1-channel height field");
  bb_status st = check_options(o, err);
  /* Before any stage: an overflow of scale x height is named as such. */
  if (st == BB_OK) st = bb__check_scaled_height(height, o->height_scale, err);
  if (st != BB_OK) return st;
  r->basis = o->basis;
  double t0 = bb__now_seconds();
  st = bb_smooth_bilateral(height, height, &o->smooth, &r->filtered, err);
  double t1 = bb__now_seconds();
  r->seconds_smooth = t1 - t0;
  if (st == BB_OK)
    st = bb_normals_compute(&r->filtered, o->height_scale, o->normal_filter,
                            o->smooth.addressing, &r->normal, err);
  if (st == BB_OK) st = bb_derive_weights(&r->normal, &o->basis, &r->weights, err);
  r->seconds_derive = bb__now_seconds() - t1;
  if (st == BB_OK && o->want_trace) st = trace_and_derive(o, r, err);
  if (st == BB_OK && o->normal_y_up) {
    bb_image_flip_green(&r->normal);
    if (r->bent.pixels) bb_image_flip_green(&r->bent);
  }
  if (st != BB_OK) bb_bake_result_free(r);
  return st;
}
