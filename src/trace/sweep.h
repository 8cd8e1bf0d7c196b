/* sweep.h: every texel's horizon along one lattice step by line
 * sweeps (sweep.c), for the batch trace. */
#ifndef BB_TRACE_SWEEP_H
#define BB_TRACE_SWEEP_H

#include "bumpbake.h"


/* One direction of a line sweep: slice s of rs, whose loss at each texel is
 * added to sums (1 + basis_count floats per texel); horizon (may be NULL)
 * receives each texel's horizon (tests, and bb_trace_horizons, which gives
 * sums NULL: horizons only, nothing added). One of the two is needed; when
 * both directions of a sweep add, they add to the same sums. */
typedef struct bb__sweep_dir {
  const bb_rayset *rs;
  int slice;
  float *sums;
  float *horizon;
} bb__sweep_dir;

/* Either addressing mode: for the lattice step (a, b) of `along` and its
 * opposite, by line sweeps (sweep.c), origins lifted by bias. Either
 * direction may be NULL; both share one profile of each line. Periodic lines
 * longer than long_line steps (0: the default) are cut into chunks whose far
 * texels are checked, and marched when the chunk cannot vouch for them. */
bb_status bb__sweep_lines(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                          const bb__sweep_dir *opposite, double bias, int threads,
                          long long_line, bb_error *err);

#endif /* BB_TRACE_SWEEP_H */
