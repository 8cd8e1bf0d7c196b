/* testing.h: what the tracer's tests and benchmarks call beyond the public
 * API: single rays and the brute-force twins of the marches, the pyramid's
 * nodes, one slice's loss, and the batch trace by a path of the caller's
 * choice.
 * Nothing of the library calls these but the tests and tools. */
#ifndef BB_TRACE_TESTING_H
#define BB_TRACE_TESTING_H

#include "bumpbake.h"

/* Number of levels (level 0 = one node per cell, the last = one root node). */
int bb__pyramid_levels(const bb_pyramid *p);

/* Max over the surface of node (x, y) of a level. */
float bb__pyramid_node_max(const bb_pyramid *p, int level, int x, int y);

/* A ray in texel space: origin and direction (need not be unit; z > 0). */
typedef struct bb__ray {
  double origin[3];
  double direction[3];
} bb__ray;

/* 1 when the ray meets the surface at a distance > 0, else 0. Rays have no
 * maximum length: periodic rays wrap as often as needed. Max-mip march. */
int bb__ray_occluded(const bb_pyramid *p, const bb__ray *ray);

/* The horizon of the ray's vertical half-plane: the largest slope
 * (surface - origin z) / d, in texels of rise per texel of horizontal
 * distance, over every breakpoint of the surface (cell edge or diagonal
 * crossing) at 0 < d <= max_distance along the ray's horizontal direction
 * (its z is ignored), or 0 when none is positive: a direction is open
 * exactly when its tangent of elevation exceeds it. max_distance is in
 * texels, > 0; it may be INFINITY in clamp mode (past the border the surface
 * turns flat), not in periodic mode, where a ray that never rises above its
 * origin would wrap for ever. Returns -1 for a bad max_distance or a
 * vertical direction. Max-mip march. */
double bb__ray_horizon(const bb_pyramid *p, const bb__ray *ray, double max_distance);

/* bb__ray_occluded and bb__ray_horizon by the brute-force twin: a 2D DDA
 * through every cell with the same exact cell test and no pyramid. */
int bb__ray_occluded_brute(const bb_pyramid *p, const bb__ray *ray);
double bb__ray_horizon_brute(const bb_pyramid *p, const bb__ray *ray, double max_distance);

/* What slice `slice` loses to a horizon of tangent tan_horizon (rise per
 * horizontal texel; <= 0 loses nothing) from each integral: blocked[0] for
 * ao, blocked[1 + c] for lobe c (1 + lobe count values). */
void bb__rayset_blocked(const bb_rayset *rs, int slice, double tan_horizon, double *blocked);

/* How bb__trace_occlusion finds each texel's horizons. */
typedef enum bb__trace_path {
  BB__TRACE_MARCH, /* texel by texel, every slice by a max-mip march */
  BB__TRACE_SWEEP  /* slice by slice, line sweeps */
} bb__trace_path;

/* bb__trace_occlusion with the path chosen by the caller. For tests. */
bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err);

#endif /* BB_TRACE_TESTING_H */
