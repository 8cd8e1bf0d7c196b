/* options.c: a bake's options: their defaults, their ranges (each written
 * once here; the command line's and Python's options refer to these), the
 * one check of the whole struct, and the one place a ray budget becomes
 * azimuth slices. */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "trace/basis.h"
#include "trace/rayset.h"
#include "trace/trace.h"

#include <float.h>
#include <math.h>
#include <string.h>

const bb__range bb__range_height_scale = {"scale", 0.0, FLT_MAX, 1, 0};
const bb__range bb__range_rays = {"rays", 1, BB_MAX_RAYS, 0, 1};
const bb__range bb__range_slices = {"slices", 1, BB_MAX_SLICES, 0, 1};
const bb__range bb__range_filter_radius = {"filter radius", 0, BB_MAX_FILTER_RADIUS, 0, 1};
const bb__range bb__range_filter_threshold = {"filter threshold", 0.0, FLT_MAX, 1, 0};
const bb__range bb__range_bias = {"bias", 0.0, BB_MAX_BIAS_TEXELS, 0, 0};
const bb__range bb__range_power = {"power", 1.0, BB_MAX_POWER, 0, 0};
const bb__range bb__range_bounce_albedo = {"bounce", 0.0, 1.0, 0, 0};
const bb__range bb__range_bounces = {"bounces", 0, BB_MAX_BOUNCES, 0, 1};

void bb__bake_options_init(bb_bake_options *o) {
  memset(o, 0, sizeof *o);
  o->height_scale = 0.0f; /* must be set: there is no meaningful default */
  o->rays = 256;
  bb__smooth_options_init(&o->smooth);
  bb__trace_options_init(&o->trace);
  o->power = 1.0;
  bb__basis_init(&o->basis);
  o->normal_filter = BB_NORMAL_VERTEX;
  o->outputs = BB_MAPS_BAKED;
}

int bb__bake_slices(const bb_bake_options *o) {
  return o->slices ? o->slices : bb__slices_for_rays(o->rays);
}

static bb_status in_range(const bb__range *r, double v, bb_error *err) {
  char who[64] = "bake: ";
  strncat(who, r->what, sizeof who - strlen(who) - 1);
  return bb__range_check(r, v, who, err);
}

bb_status bb__bake_options_check(const bb_bake_options *o, bb_error *err) {
  if (!o)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: missing options");
  bb_status st = in_range(&bb__range_height_scale, (double)o->height_scale, err);
  if (st == BB_OK && (o->outputs == 0 || (o->outputs & ~BB_MAPS_BAKED) != 0))
    st = bb__fail(err, BB_ERR_ARGUMENT,
                  "bake: outputs must be a non-empty set of BB_MAP_BIT(kind) (got 0x%x)",
                  o->outputs);
  /* the trace's options mean nothing without a trace */
  if (st == BB_OK && (o->outputs & BB_MAPS_TRACED)) {
    if (!o->slices)
      st = in_range(&bb__range_rays, o->rays, err);
    else
      st = in_range(&bb__range_slices, o->slices, err);
  }
  if (st == BB_OK) st = in_range(&bb__range_filter_radius, o->smooth.radius_texels, err);
  if (st == BB_OK) st = in_range(&bb__range_filter_threshold, (double)o->smooth.threshold, err);
  if (st == BB_OK && o->smooth.addressing != BB_ADDRESS_PERIODIC &&
      o->smooth.addressing != BB_ADDRESS_CLAMP)
    st = bb__fail(err, BB_ERR_ARGUMENT, "bake: unknown addressing mode %d",
                  (int)o->smooth.addressing);
  if (st == BB_OK) st = in_range(&bb__range_power, o->power, err);
  if (st == BB_OK) st = in_range(&bb__range_bias, o->trace.bias_texels, err);
  if (st == BB_OK) st = bb__range_check(&bb__range_threads, o->trace.threads, "bake: threads", err);
  if (st == BB_OK) st = in_range(&bb__range_bounce_albedo, o->bounce_albedo, err);
  if (st == BB_OK) st = in_range(&bb__range_bounces, o->bounces, err);
  if (st == BB_OK && o->bounce_albedo_map &&
      (!o->bounce_albedo_map->pixels || o->bounce_albedo_map->channels < 1))
    st = bb__fail(err, BB_ERR_ARGUMENT, "bake: the bounce albedo map has no pixels");
  if (st == BB_OK && o->brightness && (!o->brightness->pixels || o->brightness->channels < 1))
    st = bb__fail(err, BB_ERR_ARGUMENT, "bake: the brightness map has no pixels");
  if (st == BB_OK && strcmp(bb__normal_filter_name(o->normal_filter), "unknown") == 0)
    st = bb__fail(err, BB_ERR_ARGUMENT, "bake: unknown normal filter %d",
                  (int)o->normal_filter);
  return st == BB_OK ? bb__basis_check(&o->basis, "bake", err) : st;
}

void bb__bake_resolve(bb_bake_options *o) {
  if (o->outputs & BB_MAPS_TRACED)
    o->slices = bb__bake_slices(o);
}

bb_status bb__bake_prepare(const bb_bake_options *in, bb_bake_options *out, bb_error *err) {
  bb_status st = bb__bake_options_check(in, err);
  if (st != BB_OK)
    return st;
  *out = *in;
  bb__bake_resolve(out);
  return BB_OK;
}

static const char *const normal_y_names[2] = {"down", "up"};

bb_status bb__normal_y_parse(const char *name, int *normal_y_up, bb_error *err) {
  int i = 0;
  bb_status st = bb__parse_name("normal y", name, normal_y_names, 2, 0, &i, err);
  if (st == BB_OK && normal_y_up)
    *normal_y_up = i;
  return st;
}

const char *bb__normal_y_name(int normal_y_up) {
  return normal_y_names[normal_y_up ? 1 : 0];
}

const char *bb__addressing_name(bb_addressing addressing) {
  switch (addressing) {
  case BB_ADDRESS_PERIODIC: return "periodic";
  case BB_ADDRESS_CLAMP: return "clamp";
  }
  return "unknown";
}
