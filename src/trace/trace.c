/* trace.c: the batch trace of a bake: every texel's horizon in every slice,
 * by line sweeps (or, for a region, by marches), integrated into the
 * visibility sums. */
#include "core/internal.h"
#include "trace/integrate.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/retrace.h"
#include "trace/sweep.h"
#include "trace/testing.h"
#include "trace/trace.h"
#include "bumpbake_cluster.h"

#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ batch trace */

void bb__trace_options_init(bb_trace_options *o) {
  memset(o, 0, sizeof *o);
  o->bias_texels = 0.55;
}

typedef struct trace_job {
  const bb_pyramid *p;
  const bb_rayset *rs;
  const bb_trace_options *o;
  bb_region region;  /* the texels traced; vis is its size */
  int channels;      /* 1 + basis_count */
  int *order;        /* slices in the order every path adds them up */
  float *vis;        /* sums of what the slices lose, then the visibility */
  float *const *horizons; /* NULL, or per slice every texel's horizon (kept) */
} trace_job;

static int opposite_steps(const bb_rayset *rs, int s, int t) {
  return rs->slice_step[2 * s] == -rs->slice_step[2 * t] &&
         rs->slice_step[2 * s + 1] == -rs->slice_step[2 * t + 1];
}

/* The order in which every path adds up the slices: each slice is followed
 * by its opposite (lattice step (-a, -b)), when the set has one, so that one
 * line sweep can serve both. A fixed order keeps the paths' float sums, and
 * so their results, bit-identical. Returns -1 when out of memory. */
static int order_slices(const bb_rayset *rs, int *order) {
  unsigned char *placed = calloc((size_t)rs->slice_count, 1);
  if (!placed) return -1;
  int n = 0;
  for (int s = 0; s < rs->slice_count; s++) {
    if (placed[s]) continue;
    placed[s] = 1;
    order[n++] = s;
    for (int t = s + 1; t < rs->slice_count; t++)
      if (!placed[t] && opposite_steps(rs, s, t)) {
        placed[t] = 1;
        order[n++] = t;
        break;
      }
  }
  free(placed);
  return 0;
}

/* A texel's sums of losses become its visibilities: 1 - lost / total. */
static void finish_texel(const bb_rayset *rs, float *v) {
  for (int c = 0; c <= rs->basis_count; c++) {
    const double total = rs->total[c];
    const double open = total > 0.0 ? 1.0 - (double)v[c] / total : 1.0;
    v[c] = (float)(open < 0.0 ? 0.0 : open);
  }
}

static void finish_row(void *user, int y) {
  const trace_job *job = user;
  float *v = job->vis + (size_t)y * (size_t)job->region.width * (size_t)job->channels;
  for (int x = 0; x < job->region.width; x++, v += job->channels) finish_texel(job->rs, v);
}

/* March path: every slice of a texel by the max-mip march, one row of the
 * region per work item. */
static void march_row(void *user, int row) {
  const trace_job *job = user;
  const bb_rayset *rs = job->rs;
  const int y = job->region.y0 + row;
  double hint[BB_MAX_SLICES] = {0}; /* per slice: where the last texel's horizon was */
  float *v = job->vis + (size_t)row * (size_t)job->region.width * (size_t)job->channels;
  for (int i = 0; i < job->region.width; i++, v += job->channels) {
    const int x = job->region.x0 + i;
    for (int k = 0; k < rs->slice_count; k++) {
      const int s = job->order[k];
      const float h = bb__slice_horizon_hinted(job->p, x, y, job->o->bias_texels,
                                               rs->slice_step[2 * s], rs->slice_step[2 * s + 1],
                                               &hint[s]);
      const bb__slice_integral si = bb__slice_integral_of(rs, s);
      bb__slice_accumulate(&si, h, v);
    }
    finish_texel(rs, v);
  }
}

/* The sums start at zero, written row by row on every thread before any
 * slice adds to them. calloc's pages are mapped on first touch, and a
 * slice's first touch is a read (sums[c] += ...): each page then faulted
 * twice, the second time a copy-on-write that interrupts every other thread
 * of the bake to flush its TLB. */
static void zero_row(void *user, int y) {
  const trace_job *job = user;
  const size_t n = (size_t)job->region.width * (size_t)job->channels;
  memset(job->vis + (size_t)y * n, 0, n * sizeof(float));
}

/* Sweep path: slices in the summing order, a slice and its opposite per
 * sweep when they pair up. */
static bb_status trace_sweeps(trace_job *job, bb_error *err) {
  const bb_rayset *rs = job->rs;
  bb_status st = BB_OK;
  for (int k = 0; st == BB_OK && k < rs->slice_count;) {
    const int s = job->order[k];
    const int pair = k + 1 < rs->slice_count && opposite_steps(rs, s, job->order[k + 1]);
    const int t = pair ? job->order[k + 1] : 0;
    const bb__sweep_dir along = {rs, s, job->vis,
                                 job->horizons ? job->horizons[s] : NULL};
    const bb__sweep_dir opposite = {rs, t, job->vis,
                                    job->horizons ? job->horizons[t] : NULL};
    st = bb__sweep_lines(job->p, rs->slice_step[2 * s], rs->slice_step[2 * s + 1], &along,
                         pair ? &opposite : NULL, job->o->bias_texels, job->o->threads, 0, err);
    k += pair ? 2 : 1;
    if (st == BB_OK && job->o->progress &&
        job->o->progress(job->o->progress_user, k, rs->slice_count))
      st = bb__fail(err, BB_ERR_CANCELLED, "trace: cancelled by the progress callback");
  }
  if (st == BB_OK)
    st = bb__parallel_for(job->region.height, job->o->threads, finish_row, job, NULL, NULL, err);
  return st;
}

static bb_status check_trace(const bb_pyramid *p, const bb_rayset *rs, const bb_trace_options *o,
                             bb_error *err) {
  if (!p || !rs || !o || rs->slice_count < 1 || rs->slice_count > BB_MAX_SLICES || !rs->table)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: missing pyramid, ray set or options");
  if (!(o->bias_texels >= 0.0) || !isfinite(o->bias_texels))
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: bias must be finite and >= 0 (got %g)",
                    o->bias_texels);
  const bb_region *r = &o->region;
  if (r->width != 0 && (r->width < 0 || r->height <= 0 || r->x0 < 0 || r->y0 < 0 ||
                        r->x0 > p->width - r->width || r->y0 > p->height - r->height))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "trace: region %dx%d at (%d, %d) is not inside the %dx%d image", r->width,
                    r->height, r->x0, r->y0, p->width, p->height);
  return BB_OK;
}

/* The batch trace by path; with horizons (the sweeps, the whole image),
 * every texel's horizon in slice s is also written to horizons[s]. */
static bb_status trace_occlusion(const bb_pyramid *p, const bb_rayset *rs,
                                 const bb_trace_options *o, bb__trace_path path,
                                 float *const *horizons, bb_image *vis, bb_error *err) {
  memset(vis, 0, sizeof *vis);
  bb_status st = check_trace(p, rs, o, err);
  if (st != BB_OK) return st;
  trace_job job = {
      .p = p, .rs = rs, .o = o, .channels = 1 + rs->basis_count, .horizons = horizons};
  job.region = o->region.width ? o->region : (bb_region){0, 0, p->width, p->height};
  job.order = malloc((size_t)rs->slice_count * sizeof(int));
  if (!job.order || order_slices(rs, job.order) != 0)
    st = bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  if (st == BB_OK)
    st = bb_image_alloc(vis, job.region.width, job.region.height, job.channels, err);
  if (st == BB_OK) {
    job.vis = vis->pixels;
    st = bb__parallel_for(job.region.height, o->threads, zero_row, &job, NULL, NULL, err);
  }
  if (st == BB_OK) {
    st = path == BB__TRACE_MARCH
             ? bb__parallel_for(job.region.height, o->threads, march_row, &job, o->progress,
                                o->progress_user, err)
             : trace_sweeps(&job, err);
  }
  free(job.order);
  if (st != BB_OK) bb_image_free(vis);
  return st;
}

bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err) {
  return trace_occlusion(p, rs, o, path, NULL, vis, err);
}

bb_status bb__trace_keeping_horizons(const bb_pyramid *p, const bb_rayset *rs,
                                     const bb_trace_options *o, float *const *horizons,
                                     bb_image *vis, bb_error *err) {
  if (o && o->region.width != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: horizons are kept for the whole image");
  return trace_occlusion(p, rs, o, BB__TRACE_SWEEP, horizons, vis, err);
}

void bb__trace_texel(const bb_rayset *rs, const int *order, const float *const *horizons,
                     size_t texel, float *vis) {
  memset(vis, 0, (size_t)(1 + rs->basis_count) * sizeof *vis);
  for (int k = 0; k < rs->slice_count; k++) {
    const bb__slice_integral si = bb__slice_integral_of(rs, order[k]);
    bb__slice_accumulate(&si, horizons[order[k]][texel], vis);
  }
  finish_texel(rs, vis);
}

bb_status bb__trace_occlusion(const bb_pyramid *p, const bb_rayset *rs,
                             const bb_trace_options *o, bb_image *vis,
                             double *horizons_found, bb_error *err) {
  const int whole = o && o->region.width == 0;
  bb_status st = bb__trace_occlusion_path(p, rs, o, whole ? BB__TRACE_SWEEP : BB__TRACE_MARCH,
                                          vis, err);
  if (st == BB_OK && horizons_found)
    *horizons_found = (double)vis->width * (double)vis->height * (double)rs->slice_count;
  return st;
}

/* ------------------------------------------------------------ split trace */

/* A trace split over processes: horizons found by any of them, added up by
 * one in the order every path adds them (order_slices), so the sums are the
 * bits bb__trace_occlusion makes. */

bb_status bb_trace_slice_order(const bb_rayset *rs, int *order, bb_error *err) {
  if (!rs || !order || rs->slice_count < 1 || rs->slice_count > BB_MAX_SLICES)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: missing ray set or order");
  if (order_slices(rs, order) != 0) return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  return BB_OK;
}

bb_status bb_trace_horizons(const bb_pyramid *p, const bb_rayset *rs, const bb_trace_options *o,
                            const int *slices, int count, bb_image *horizons, bb_error *err) {
  if (!horizons || count < 0 || (count > 0 && !slices))
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: missing slices or horizons");
  for (int k = 0; k < count; k++) memset(&horizons[k], 0, sizeof horizons[k]);
  bb_status st = check_trace(p, rs, o, err);
  if (st != BB_OK) return st;
  if (o->region.width != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: horizons are found for the whole image, "
                                          "not a region");
  int order[BB_MAX_SLICES];
  if (order_slices(rs, order) != 0) return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  for (int k = 0; k < count; k++) {
    if (slices[k] < 0 || slices[k] >= rs->slice_count)
      return bb__fail(err, BB_ERR_ARGUMENT, "trace: slice %d is not one of the ray set's 0..%d",
                      slices[k], rs->slice_count - 1);
    for (int j = 0; j < k; j++)
      if (slices[j] == slices[k])
        return bb__fail(err, BB_ERR_ARGUMENT, "trace: slice %d asked twice", slices[k]);
  }
  for (int k = 0; k < count && st == BB_OK; k++)
    st = bb_image_alloc(&horizons[k], p->width, p->height, 1, err);
  /* The sweeps of trace_sweeps, walking the summing order: a slice and its
   * opposite share one, the earlier along; a sweep runs for either or both
   * of its directions when asked, so each horizon is found exactly as the
   * whole trace finds it. */
  int sweeps = 0;
  for (int k = 0; k < rs->slice_count; k += 1 + (k + 1 < rs->slice_count &&
                                                    opposite_steps(rs, order[k], order[k + 1])))
    sweeps++;
  int sweep = 0;
  for (int k = 0; st == BB_OK && k < rs->slice_count; sweep++) {
    const int s = order[k];
    const int pair = k + 1 < rs->slice_count && opposite_steps(rs, s, order[k + 1]);
    const int t = pair ? order[k + 1] : -1;
    bb_image *hs = NULL, *ht = NULL;
    for (int j = 0; j < count; j++) {
      if (slices[j] == s) hs = &horizons[j];
      if (slices[j] == t) ht = &horizons[j];
    }
    const bb__sweep_dir along = {rs, s, NULL, hs ? hs->pixels : NULL};
    const bb__sweep_dir opposite = {rs, pair ? t : 0, NULL, ht ? ht->pixels : NULL};
    if (hs || ht)
      st = bb__sweep_lines(p, rs->slice_step[2 * s], rs->slice_step[2 * s + 1],
                           hs ? &along : NULL, ht ? &opposite : NULL, o->bias_texels,
                           o->threads, 0, err);
    k += pair ? 2 : 1;
    if (st == BB_OK && (hs || ht) && o->progress &&
        o->progress(o->progress_user, sweep + 1, sweeps))
      st = bb__fail(err, BB_ERR_CANCELLED, "trace: cancelled by the progress callback");
  }
  if (st != BB_OK)
    for (int k = 0; k < count; k++) bb_image_free(&horizons[k]);
  return st;
}

/* One row of a slice's losses added to the sums (accumulate_row). */
typedef struct accumulate_job {
  bb__slice_integral integral;
  const float *horizon;
  float *sums;
  int width, channels;
} accumulate_job;

static void accumulate_row(void *user, int y) {
  const accumulate_job *job = user;
  const size_t first = (size_t)y * (size_t)job->width;
  for (size_t i = first; i < first + (size_t)job->width; i++)
    bb__slice_accumulate(&job->integral, job->horizon[i], job->sums + i * (size_t)job->channels);
}

bb_status bb_trace_accumulate(const bb_rayset *rs, int rank, const bb_image *horizon,
                              bb_image *sums, int threads, bb_error *err) {
  if (!rs || !horizon || !sums || !horizon->pixels || !sums->pixels || !rs->table)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: missing ray set, horizons or sums");
  if (rank < 0 || rank >= rs->slice_count)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: rank %d is not one of the ray set's 0..%d",
                    rank, rs->slice_count - 1);
  if (horizon->channels != 1 || sums->channels != 1 + rs->basis_count ||
      horizon->width != sums->width || horizon->height != sums->height)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "trace: horizons %dx%d (%d channels) and sums %dx%d (%d channels) do not "
                    "match: sums need 1 + %d lobes channels of the horizons' size",
                    horizon->width, horizon->height, horizon->channels, sums->width,
                    sums->height, sums->channels, rs->basis_count);
  int order[BB_MAX_SLICES];
  if (order_slices(rs, order) != 0) return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  const accumulate_job job = {bb__slice_integral_of(rs, order[rank]), horizon->pixels,
                              sums->pixels, sums->width, sums->channels};
  return bb__parallel_for(sums->height, threads, accumulate_row, (void *)&job, NULL, NULL, err);
}

bb_status bb_trace_finish(const bb_rayset *rs, bb_image *sums, int threads, bb_error *err) {
  if (!rs || !sums || !sums->pixels || sums->channels != 1 + rs->basis_count)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: sums need 1 + %d lobes channels",
                    rs ? rs->basis_count : 0);
  trace_job job = {.rs = rs, .channels = sums->channels};
  job.region = (bb_region){0, 0, sums->width, sums->height};
  job.vis = sums->pixels;
  return bb__parallel_for(sums->height, threads, finish_row, &job, NULL, NULL, err);
}
