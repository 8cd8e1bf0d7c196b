/* pyramid.h: the max-mip pyramid's layout, read by the march
 * and the sweeps (pyramid.c builds it). */
#ifndef BB_TRACE_PYRAMID_H
#define BB_TRACE_PYRAMID_H

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

/* bb__pyramid_build_all_cores with the bake's thread count (the same bits for any). */
bb_status bb__pyramid_build(const bb_image *height_texels, bb_addressing addressing,
                            int threads, bb_pyramid **out, bb_error *err);

/* The heights of the vertices x0 .. x0+width-1 by y0 .. y0+height-1 of
 * p->z have been changed by the caller (periodic: the rectangle may pass
 * the right and bottom sides and wrap; clamp: inside the image). The nodes
 * over them, the global max and min and the border max are brought up to
 * date: the pyramid bb__pyramid_build_all_cores makes of the new heights, bit for
 * bit. old_min: the least of the heights the rectangle held before. */
bb_status bb__pyramid_update(bb_pyramid *p, int x0, int y0, int width, int height,
                             float old_min);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Builds the pyramid of a 1-channel field of heights in texels (already
 * multiplied by the height scale). The field is copied. */
bb_status bb__pyramid_build_all_cores(const bb_image *height_texels,
                           bb_addressing addressing, bb_pyramid **out,
                           bb_error *err);

#endif /* BB_TRACE_PYRAMID_H */
