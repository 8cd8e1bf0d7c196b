/* testing.h: what the tracer's tests and benchmarks call beyond the public
 * API: the brute-force twins of the marches, the pyramid's nodes, one
 * slice's loss, and the batch trace by a path of the caller's choice.
 * Nothing of the library calls these but the tests and tools. */
#ifndef BB_TRACE_TESTING_H
#define BB_TRACE_TESTING_H

#include "bumpbake.h"

/* Number of levels (level 0 = one node per cell, the last = one root node). */
int bb__pyramid_levels(const bb_pyramid *p);

/* Max over the surface of node (x, y) of a level. */
float bb__pyramid_node_max(const bb_pyramid *p, int level, int x, int y);

/* bb_ray_occluded and bb_ray_horizon by the brute-force twin: a 2D DDA
 * through every cell with the same exact cell test and no pyramid. */
int bb__ray_occluded_brute(const bb_pyramid *p, const bb_ray *ray);
double bb__ray_horizon_brute(const bb_pyramid *p, const bb_ray *ray, double max_distance);

/* What slice `slice` loses to a horizon of tangent tan_horizon (rise per
 * horizontal texel; <= 0 loses nothing) from each integral: blocked[0] for
 * ao, blocked[1 + c] for lobe c (1 + lobe count values). */
void bb__rayset_blocked(const bb_rayset *rs, int slice, double tan_horizon, double *blocked);

/* How bb_trace_occlusion finds each texel's horizons. */
typedef enum bb__trace_path {
  BB__TRACE_MARCH, /* texel by texel, every slice by a max-mip march */
  BB__TRACE_SWEEP  /* slice by slice, line sweeps */
} bb__trace_path;

/* bb_trace_occlusion with the path chosen by the caller. For tests. */
bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err);

#endif /* BB_TRACE_TESTING_H */
