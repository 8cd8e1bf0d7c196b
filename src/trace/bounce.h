/* bounce.h: light the surrounding height field reflects into each texel's
 * ao and lobes, added to a trace's visibility (bounce.c). */
#ifndef BB_TRACE_BOUNCE_H
#define BB_TRACE_BOUNCE_H

#include "bumpbake.h"

/* Most fixed rays a gather's lines follow. */
#define BB__BOUNCE_MAX_SLOPES 8

typedef struct bb__bounce_options {
  double rho;             /* albedo, in [0, 1] */
  const bb_image *albedo; /* 1 channel, the pyramid's size: rho multiplies it; or NULL */
  int bounces;            /* 1..BB_MAX_BOUNCES, exactly that many; or 0: the
                             converged light, from each sample's estimate
                             (estimate_passes surface passes from it, the
                             rest of the series then added as geometric) */
  int estimate_passes;    /* of bounces 0: surface passes from the estimate, >= 1 */
  double bias;            /* the texels' lift, as the trace's */
  double lift;            /* the samples' lift (texels): where a triangle's
                             light is sampled, above its corner vertex */
  double steep;           /* texels: a triangle rising more than this has a
                             column of samples (0: none) */
  int column_samples;     /* samples up a column, >= 2 */
  int surface_slices;     /* slices of the bounces after the first, whose
                             light is smooth; 0: a quarter of the trace's,
                             at least 4 (or the trace's, when fewer) */
  int surface_turns;      /* 1 (the default): every sample gathers in each
                             of the surface passes' slices; T > 1: they sweep
                             T times as many, each line walked in one sweep
                             of T (by its class, b x - a y mod T) and its
                             gathers weighed T times, when the trace has
                             that many slices (else 1). docs/accuracy.md
                             "The surface passes' slices turned, tried" */
  /* the tangents of elevation of the fixed rays the gathers follow, rising,
   * NAN after the last: the texels' (from 0 up) and the samples' (below
   * their horizontal too) */
  double texel_slopes[BB__BOUNCE_MAX_SLOPES], surface_slopes[BB__BOUNCE_MAX_SLOPES];
  double small_band; /* a texel's band under this horizon (tangent) sees
                        its horizon point's light only */
  int chain;         /* the hull vertices a gather knows at most, the
                        tangent among them (0: every one) */
  int level;        /* 1: the bounce on the map's own texels; 2, 4, 8: on a
                       height field that many times coarser, its added light
                       lifted to the map (bb__bounce_level); 0: by size */
  int threads;
  bb_progress_fn progress; /* called after every sweep with the work done
                              and the whole (bb__bounce_work), plus
                              progress_before before and progress_after
                              after, and as a checkpoint (0, 0) every 50 ms
                              within a sweep; nonzero cancels */
  void *progress_user;
  long progress_before, progress_after;
} bb__bounce_options;

/* The defaults a bake uses (rho, albedo and bias left at 0/NULL): bounces
 * 0 with 1 estimate pass, lift 0.1, columns on triangles rising more than
 * 2 texels with 5 samples, the direct light and the texels' gathers over
 * the trace's sweeps (half each), the surface passes over a quarter of its
 * slices, the texels' rays at tangents 0 and 1 and the samples' at -1 and
 * 0, bands under tangent 0.25 seeing their horizon point, at most 48 hull
 * vertices known (chain 0). docs/conventions.md "Inter-reflection" says why. */
void bb__bounce_options_init(bb__bounce_options *o);

/* The coarse level bb__bounce_add computes the bounce on for a map of
 * width x height: o->level when set, else by size (1 under 512 texels on
 * the longer side; from 512, 2, doubled while the coarse level's longer
 * side would pass 1024, at most 8); halved until it tiles a periodic map.
 * With f > 1 (and the visibility given, not made by the passes) the bounce
 * is found on the heights at every f-th vertex, and the light it adds per
 * unit of blocked visibility is lifted to the map's texels bilinearly,
 * times each texel's own blocked visibility, and added to vis. */
int bb__bounce_level(const bb__bounce_options *o, int width, int height,
                     bb_addressing addressing);

/* The work bb__bounce_add does with these options and ray set, in the
 * units its progress counts: a trace of the same slices is
 * BB__BOUNCE_TRACE_WORK per slice (what progress_before and _after are
 * measured in); o->level scales it by the coarse level's texels. */
enum { BB__BOUNCE_TRACE_WORK = 1 };
long bb__bounce_work(const bb_rayset *rs, const bb__bounce_options *o);

/* Adds to vis (1 + lobes channels, as bb__trace_occlusion made it for the
 * whole pyramid with the same rayset and bias) what the surface reflects
 * (docs/conventions.md "Inter-reflection"): ao += B_ao / pi and
 * vis_c += B_c / total_c, ao capped at 1. The same bits for any thread
 * count. Errors: BB_ERR_MEMORY, BB_ERR_CANCELLED (vis is then left as it
 * was given or partly changed; the caller frees it). */
bb_status bb__bounce_add(const bb_pyramid *p, const bb_rayset *rs,
                         const bb__bounce_options *o, bb_image *vis, int *bounces_done,
                         bb_error *err);

#endif /* BB_TRACE_BOUNCE_H */
