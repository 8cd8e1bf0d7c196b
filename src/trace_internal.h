/* trace_internal.h: the pyramid's layout and the march, shared by pyramid.c,
 * trace.c and the tracer's tests. */
#ifndef BB_TRACE_INTERNAL_H
#define BB_TRACE_INTERNAL_H

#include "bumpbake.h"

#include <stdint.h>

#define BB__MAX_LEVELS 32

struct bb_pyramid {
  int width, height;              /* texels = cells per row / column */
  bb_addressing addressing;
  float *z;                       /* heights in texels, width*height */
  int levels;                     /* level levels-1 has one node */
  int level_width[BB__MAX_LEVELS];
  int level_height[BB__MAX_LEVELS];
  float *level_max[BB__MAX_LEVELS]; /* node maxima, row-major per level */
  float global_max, global_min;
  float border_max;               /* max over the border vertices (clamp mode) */
};

/* A ray for the march: origin, unit horizontal direction; the elevation is
 * given separately as thresholds on the tangent (dz per horizontal texel). */
typedef struct bb__march_ray {
  double ox, oy, oz;
  double dx, dy;
} bb__march_ray;

/* Marches the ray's vertical half-plane and returns how many of the n rising
 * tangent thresholds tan_el[0..n-1] are blocked by the surface: a ray of
 * tangent T is blocked when some breakpoint of the surface along the line
 * (cell edge or diagonal crossing, distance t > 0) has slope
 * (surface - oz) / t >= T. Uses the pyramid to skip what cannot block. */
int bb__march(const bb_pyramid *p, const bb__march_ray *r, const double *tan_el, int n);

/* The same answer from a 2D DDA through every cell, with no pyramid. */
int bb__march_brute(const bb_pyramid *p, const bb__march_ray *r, const double *tan_el,
                    int n);

/* How bb_trace_occlusion finds each texel's blocked rays. */
typedef enum bb__trace_path {
  BB__TRACE_SQUARE, /* texel by texel, every slice marched through square nodes */
  BB__TRACE_BANDS,  /* slice by slice, marched through direction bands */
  BB__TRACE_SWEEP   /* slice by slice, line sweeps */
} bb__trace_path;

/* bb_trace_occlusion with the path chosen by the caller. For tests. */
bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err);

/* One direction of a line sweep: its n rising tangent thresholds tan_el
 * (dz per horizontal texel) and where the count of them blocked at each
 * texel goes (one per texel). */
typedef struct bb__sweep_dir {
  const double *tan_el;
  int n;
  uint16_t *blocked;
} bb__sweep_dir;

/* Either addressing mode: for the lattice step (a, b), the blocked counts
 * of `along` (rays along (a, b)) and of `opposite` (along (-a, -b)) at every
 * texel, origins lifted by bias, by line sweeps (sweep.c). Either direction
 * may be NULL; both share one profile of each line. */
bb_status bb__sweep_lines(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                          const bb__sweep_dir *opposite, double bias, int threads,
                          bb_error *err);

/* Directional max bands of the pyramid's cells for one azimuth (band.c). */
#define BB__BAND_LEVELS 8
typedef struct bb__band {
  int levels;                      /* level k spans 2^k cells along the major axis */
  int major_x, major_y;            /* unit cell step along the major axis */
  int minor_x, minor_y;            /* unit cell step along the minor axis */
  double slope;                    /* |minor / major| <= 1 */
  float *level_max[BB__MAX_LEVELS]; /* per level, one bound per cell, row-major */
} bb__band;

/* Builds the bands of direction (dx, dy) over p's cells, rows on `threads`
 * threads. Free with bb__band_free. */
bb_status bb__band_build(const bb_pyramid *p, double dx, double dy, int threads,
                         bb__band *band, bb_error *err);
void bb__band_free(bb__band *band);

#endif /* BB_TRACE_INTERNAL_H */
