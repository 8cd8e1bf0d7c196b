/* bounce_bake.c: a bake with inter-reflection, ao and ssbump to float EXR,
 * with the gather's inner settings open, for the bench and experiments.
 *
 *   bounce_bake MAP SCALE PREFIX [--rays N] [--rho R] [--bounces N]
 *               [--bias B] [--filter-radius R] [--normal-filter NAME]
 *               [--clamp] [--threads T]
 *               [--lift L] [--steep S] [--column-samples N]
 *               [--estimate-passes N] [--surface-slices N] [--surface-turns N]
 *               [--texel-slopes T,T,...] [--surface-slopes T,T,...]
 *               [--small-band T] [--chain N] [--level F]
 *
 * Writes PREFIX.ao.exr and PREFIX.ss.exr. Without the settings of the last
 * line it is bb__bake_checked with bounce_albedo = R (the library's own defaults,
 * what `bumpbake bake --bounce R` makes); with any of them, the same
 * stages run one by one (smooth, normals, pyramid, trace, bb__bounce_add
 * with those settings, derive), so the bench can show what, say, fewer
 * fixed rays (--texel-slopes 0) or no columns (--steep 0) cost, or the
 * horizon-point approximation (--small-band 1e6 --steep 0: every band sees
 * its horizon point's light), or what a coarse level (--level 2: the bounce
 * on a height field twice as coarse, lifted) does to a map of any size.
 * Defaults: 256 rays, rho 0.5, bounces 0, bias 0.55, filter radius 0 (no
 * smoothing, as README "Accuracy"), Valve's normal. Prints one JSON line
 * (seconds of the trace and of the bounce, bounces followed) on stdout;
 * exits 1 on a failure, 2 on a bad command line.
 */
#include "job/job_internal.h"
#include "bumpbake.h"
#include "core/internal.h"
#include "trace/bounce.h"
#include "bake/bake_internal.h"
#include "image/image_write.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/trace.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int usage(const char *reason) {
  fprintf(stderr,
          "bounce_bake: %s\n"
          "usage: bounce_bake MAP SCALE PREFIX [--rays N] [--rho R] [--bounces N] [--bias B]\n"
          "                   [--filter-radius R] [--normal-filter NAME] [--clamp] [--threads T]\n"
          "                   [--lift L] [--steep S] [--column-samples N]\n"
          "                   [--estimate-passes N] [--surface-slices N] [--surface-turns N]\n"
          "                   [--texel-slopes T,T,...] [--surface-slopes T,T,...]\n"
          "                   [--small-band T] [--chain N] [--level F]\n",
          reason);
  return 2;
}

static int parse_number(const char *s, double lo, double hi, double *out) {
  char *end;
  errno = 0;
  const double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi) return 1;
  *out = v;
  return 0;
}

/* "t0,t1,...": rising tangents into slopes, NAN after the last. */
static int slopes_parse(const char *text, double *slopes) {
  int n = 0;
  for (const char *at = text; *at && n < BB__BOUNCE_MAX_SLOPES;) {
    char *end;
    errno = 0;
    const double v = strtod(at, &end);
    if (errno || end == at || !isfinite(v) || (n && !(v > slopes[n - 1]))) return 1;
    slopes[n++] = v;
    at = *end == ',' ? end + 1 : end;
    if (*end && *end != ',') return 1;
  }
  for (int k = n; k < BB__BOUNCE_MAX_SLOPES; k++) slopes[k] = NAN;
  return n == 0;
}

typedef struct args {
  const char *map, *prefix;
  bb_bake_options bake;
  bb__bounce_options bounce;
  int inner; /* a setting of the gather's was given */
} args;

static int parse_args(int argc, char **argv, args *a) {
  if (argc < 4) return usage("MAP, SCALE and PREFIX are needed");
  memset(a, 0, sizeof *a);
  a->map = argv[1], a->prefix = argv[3];
  bb__bake_options_init(&a->bake);
  bb__bounce_options_init(&a->bounce);
  a->bake.smooth.radius_texels = 0;
  a->bake.normal_filter = BB_NORMAL_VALVE;
  a->bake.bounce_albedo = 0.5;
  a->bake.outputs = BB_MAP_BIT(BB_MAP_AO) | BB_MAP_BIT(BB_MAP_SSBUMP);
  double v;
  if (parse_number(argv[2], 1e-9, 1e30, &v)) return usage("SCALE must be > 0");
  a->bake.height_scale = (float)v;
  for (int i = 4; i < argc; i++) {
    const char *o = argv[i];
    if (!strcmp(o, "--clamp")) {
      a->bake.smooth.addressing = BB_ADDRESS_CLAMP;
      continue;
    }
    if (i + 1 >= argc) return usage("an option lacks its value");
    const char *s = argv[++i];
    if (!strcmp(o, "--normal-filter")) {
      bb_error err;
      if (bb__normal_filter_parse(s, &a->bake.normal_filter, &err) != BB_OK) return usage(err.message);
      continue;
    }
    if (!strcmp(o, "--texel-slopes") || !strcmp(o, "--surface-slopes")) {
      double *slopes = o[2] == 't' ? a->bounce.texel_slopes : a->bounce.surface_slopes;
      if (slopes_parse(s, slopes)) return usage("slopes are up to 8 rising numbers, comma separated");
      a->inner = 1;
      continue;
    }
    if (parse_number(s, 0.0, 1e9, &v)) return usage("bad option value");
    if (!strcmp(o, "--rays")) a->bake.rays = (int)v;
    else if (!strcmp(o, "--rho")) a->bake.bounce_albedo = v;
    else if (!strcmp(o, "--bounces")) a->bake.bounces = (int)v;
    else if (!strcmp(o, "--bias")) a->bake.trace.bias_texels = v;
    else if (!strcmp(o, "--filter-radius")) a->bake.smooth.radius_texels = (int)v;
    else if (!strcmp(o, "--threads")) a->bake.trace.threads = (int)v;
    else if (!strcmp(o, "--lift")) a->bounce.lift = v, a->inner = 1;
    else if (!strcmp(o, "--steep")) a->bounce.steep = v, a->inner = 1;
    else if (!strcmp(o, "--column-samples") && v >= 2) a->bounce.column_samples = (int)v, a->inner = 1;
    else if (!strcmp(o, "--chain")) a->bounce.chain = (int)v, a->inner = 1;
    else if (!strcmp(o, "--small-band")) a->bounce.small_band = v, a->inner = 1;
    else if (!strcmp(o, "--estimate-passes")) a->bounce.estimate_passes = (int)v, a->inner = 1;
    else if (!strcmp(o, "--surface-slices")) a->bounce.surface_slices = (int)v, a->inner = 1;
    else if (!strcmp(o, "--surface-turns") && v >= 1) a->bounce.surface_turns = (int)v, a->inner = 1;
    else if (!strcmp(o, "--level") && (v == 1 || v == 2 || v == 4 || v == 8))
      a->bounce.level = (int)v, a->inner = 1;
    else return usage("unknown option");
  }
  bb_error err;
  if (bb__bake_options_check(&a->bake, &err) != BB_OK) return usage(err.message);
  return 0;
}

/* The bake's stages one by one, with a->bounce for the inter-reflection. */
static bb_status staged_bake(const args *a, const bb_image *height, bb_bake_result *r,
                             bb_error *err) {
  const bb_bake_options *o = &a->bake;
  bb_image z = {0};
  bb_pyramid *pyramid = NULL;
  bb_rayset *rays = NULL;
  memset(r, 0, sizeof *r);
  bb_status st = bb__smooth_bilateral_all_cores(height, height, &o->smooth, &r->filtered, err);
  if (st == BB_OK)
    st = bb__normals_compute_all_cores(&r->filtered, o->height_scale, o->normal_filter, o->smooth.addressing,
                            &r->normal, err);
  if (st == BB_OK) st = bb_image_alloc(&z, height->width, height->height, 1, err);
  if (st == BB_OK) {
    for (size_t i = 0; i < (size_t)z.width * (size_t)z.height; i++)
      z.pixels[i] = o->height_scale * r->filtered.pixels[i];
    st = bb__pyramid_build_all_cores(&z, o->smooth.addressing, &pyramid, err);
  }
  if (st == BB_OK) st = bb__rayset_new(bb__bake_slices(o), o->power, &o->basis, &rays, err);
  const double t0 = bb__now_seconds();
  bb_trace_options to = o->trace;
  if (st == BB_OK) st = bb__trace_occlusion(pyramid, rays, &to, &r->vis, NULL, err);
  const double t1 = bb__now_seconds();
  r->seconds_trace = t1 - t0;
  bb__bounce_options bo = a->bounce;
  bo.rho = o->bounce_albedo;
  bo.bounces = o->bounces;
  bo.bias = o->trace.bias_texels;
  bo.threads = o->trace.threads;
  if (st == BB_OK && bo.rho > 0.0) st = bb__bounce_add(pyramid, rays, &bo, &r->vis, &r->bounces, err);
  r->seconds_bounce = bb__now_seconds() - t1;
  if (st == BB_OK) st = bb__derive_ssbump_all_cores(&r->normal, &r->vis, &o->basis, &r->ssbump, err);
  if (st == BB_OK) { /* a channel of the ssbump holds at most 1, as the bake caps it */
    const size_t n = (size_t)r->ssbump.width * (size_t)r->ssbump.height * (size_t)r->ssbump.channels;
    for (size_t i = 0; i < n; i++) r->ssbump.pixels[i] = fminf(r->ssbump.pixels[i], 1.0f);
  }
  if (st == BB_OK) st = bb__derive_ao_all_cores(&r->vis, &r->ao, err);
  bb_rayset_free(rays);
  bb_pyramid_free(pyramid);
  bb_image_free(&z);
  return st;
}

int main(int argc, char **argv) {
  args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc;
  bb_image height = {0};
  bb_bake_result r = {0};
  bb_error err = {{0}};
  bb_status st = bb__height_file_read(a.map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, &height, NULL, &err);
  if (st == BB_OK) st = a.inner ? staged_bake(&a, &height, &r, &err) : bb__bake_checked(&height, &a.bake, &r, &err);
  char path[4200];
  const bb_write_options wo = {BB_DEPTH_FLOAT, BB_RANGE_UNIT, NULL, NULL};
  if (st == BB_OK) {
    snprintf(path, sizeof path, "%s.ao.exr", a.prefix);
    st = bb__image_write(path, &r.ao, &wo, &err);
  }
  if (st == BB_OK) {
    snprintf(path, sizeof path, "%s.ss.exr", a.prefix);
    st = bb__image_write(path, &r.ssbump, &wo, &err);
  }
  if (st != BB_OK) {
    fprintf(stderr, "bounce_bake: %s\n", err.message);
    rc = 1;
  } else {
    printf("{\"trace_seconds\":%.3f,\"bounce_seconds\":%.3f,\"bounces\":%d}\n", r.seconds_trace,
           r.seconds_bounce, r.bounces);
  }
  bb_bake_result_free(&r);
  bb_image_free(&height);
  return rc;
}
