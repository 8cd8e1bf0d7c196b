/* bounce.h: light the surrounding height field reflects into each texel's
 * ao and lobes, added to a trace's visibility (bounce.c). */
#ifndef BB_TRACE_BOUNCE_H
#define BB_TRACE_BOUNCE_H

#include "bumpbake.h"

typedef struct bb__bounce_options {
  double rho;             /* albedo, in [0, 1] */
  const bb_image *albedo; /* 1 channel, the pyramid's size: rho multiplies it; or NULL */
  int bounces;            /* 1..BB_MAX_BOUNCES, exactly that many; or 0: the
                             converged light, from each corner's estimate
                             (estimate_passes surface passes from it, the
                             rest of the series then added as geometric) */
  int estimate_passes;    /* of bounces 0: surface passes from the estimate, >= 1 */
  double bias;            /* the texels' lift, as the trace's */
  double lift;            /* the corners' lift (texels): where a triangle's
                             light is sampled, above its corner vertex */
  int exact_steps;        /* how far (lattice steps) every breakpoint of the
                             surface below each horizon counts, in the
                             texels' gather */
  int surface_exact_steps; /* the same in the corners' gathers */
  int surface_far_steps;  /* far_steps of the corners' gathers */
  int far_steps;          /* how far the line's texels count after that
                             (the surface between two taken as straight);
                             past it the horizon's own point stands for the
                             rest (0 and 0: the horizon-point
                             approximation) */
  int surface_slices;     /* slices of the bounces after the first, whose
                             light is smooth; 0: half the trace's, at least
                             4 (or the trace's, when fewer) */
  int threads;
  bb_progress_fn progress; /* called after every sweep with the work done
                              and the whole (bb__bounce_work), plus
                              progress_before before and progress_after after */
  void *progress_user;
  long progress_before, progress_after;
} bb__bounce_options;

/* The defaults a bake uses (rho, albedo and bias left at 0/NULL): bounces
 * 0 with 1 estimate pass, lift 0.25, exact steps 4 (texels) and 1
 * (corners), far steps 1024 (texels) and 16 (corners: the light of later
 * bounces, where the surface further off weighs little), surface slices 0. docs/conventions.md "Inter-reflection" says why. */
void bb__bounce_options_init(bb__bounce_options *o);

/* Adds to vis (1 + lobes channels, as bb_trace_occlusion made it for the
 * whole pyramid with the same rayset and bias) what the surface reflects
 * (docs/conventions.md "Inter-reflection"): ao += B_ao / pi and
 * vis_c += B_c / total_c, ao capped at 1. The same bits for any thread
 * count. Errors: BB_ERR_MEMORY, BB_ERR_CANCELLED (vis is then left as it
 * was given or partly changed; the caller frees it). */
/* The work bb__bounce_add does with these options and ray set, in the
 * units its progress counts: a trace of the same slices is
 * BB__BOUNCE_TRACE_WORK per slice (what progress_before and _after are
 * measured in). */
enum { BB__BOUNCE_TRACE_WORK = 1 };
long bb__bounce_work(const bb_rayset *rs, const bb__bounce_options *o);

bb_status bb__bounce_add(const bb_pyramid *p, const bb_rayset *rs, const bb__bounce_options *o,
                         bb_image *vis, int *bounces_done, bb_error *err);

#endif /* BB_TRACE_BOUNCE_H */
