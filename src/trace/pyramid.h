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

/* bb_pyramid_build with the bake's thread count (the same bits for any). */
bb_status bb__pyramid_build(const bb_image *height_texels, bb_addressing addressing,
                            int threads, bb_pyramid **out, bb_error *err);

#endif /* BB_TRACE_PYRAMID_H */
