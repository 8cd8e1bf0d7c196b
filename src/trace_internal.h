/* trace_internal.h: the pyramid's layout and the march, shared by pyramid.c,
 * trace.c and the tracer's tests. */
#ifndef BB_TRACE_INTERNAL_H
#define BB_TRACE_INTERNAL_H

#include "bumpbake.h"

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

#endif /* BB_TRACE_INTERNAL_H */
