/* retrace.h: the trace found again where the heights changed (retrace.c),
 * from what the whole trace keeps for it (trace.c). */
#ifndef BB_TRACE_RETRACE_H
#define BB_TRACE_RETRACE_H

#include "bumpbake.h"

#include <stddef.h>

/* bb__trace_occlusion of every texel (by the sweeps: o->region must be
 * empty) that also writes each texel's horizon in slice s to horizons[s]
 * (width x height floats each, the caller's): the same vis, bit for bit. */
bb_status bb__trace_keeping_horizons(const bb_pyramid *p, const bb_rayset *rs,
                                     const bb_trace_options *o, float *const *horizons,
                                     bb_image *vis, bb_error *err);

/* One texel's visibility (1 + basis_count floats) from its horizons in
 * every slice (horizons[s][texel]), added up in the order `order`
 * (bb_trace_slice_order) and finished exactly as the whole trace does:
 * the same bits as its vis. */
void bb__trace_texel(const bb_rayset *rs, const int *order, const float *const *horizons,
                     size_t texel, float *vis);

/* The horizons of every slice found again after the heights of a
 * rectangle of texels changed, where the change can have changed them.
 *
 * In each slice a changed height can only move the horizons of the lines
 * whose breakpoints it moves (those crossing the rectangle, widened by the
 * step's reach). Along each such line a texel outside the rectangle keeps
 * its horizon when everything the change moved (old and new) lies clearly
 * below it: the highest changed vertex, at the nearest distance the moved
 * breakpoints can be, is not as steep as the horizon found before (or, for
 * a horizon of 0, not above the origin). The texels that fail that test,
 * and those inside the rectangle (their origin moved), are found again by
 * line sweeps over stretches of their lines (a whole line where the
 * stretches would cover most of it), which find what the whole trace
 * finds. A tall new peak fails the test along whole lines; that is how
 * far it shadows. */
typedef struct bb__retrace {
  const bb_pyramid *p; /* the new heights (bb__pyramid_update done) */
  const bb_rayset *rs;
  float *const *horizons; /* per slice, the last trace's: updated in place */
  const int *order;       /* bb_trace_slice_order's */
  double bias;
  int threads;
  /* the texels whose height changed: x0 .. x0+width-1 by y0 .. y0+height-1
   * (periodic: x0, y0 inside the image, and the rectangle may pass the
   * right and bottom sides and wrap; clamp: inside the image), and the
   * heights they had before (width x height, row-major) */
  int x0, y0, width, height;
  const float *old_z;
  unsigned char *dirty;    /* width x height of the image: bit 1 set (the
                              others kept) where a texel's horizon changed in
                              some slice */
  bb_progress_fn progress; /* may cancel between sweeps */
  void *progress_user;
  double horizons_found; /* out: horizons found again */
} bb__retrace;

/* BB_ERR_CANCELLED (the horizons then partly updated), BB_ERR_MEMORY. */
bb_status bb__retrace_run(bb__retrace *r, bb_error *err);

#endif /* BB_TRACE_RETRACE_H */
