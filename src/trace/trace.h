/* trace.h: the batch trace's choice of path, for tests
 * (trace.c). */
#ifndef BB_TRACE_TRACE_H
#define BB_TRACE_TRACE_H

#include "bumpbake.h"

/* How bb_trace_occlusion finds each texel's horizons. */
typedef enum bb__trace_path {
  BB__TRACE_MARCH, /* texel by texel, every slice by a max-mip march */
  BB__TRACE_SWEEP  /* slice by slice, line sweeps */
} bb__trace_path;

/* bb_trace_occlusion with the path chosen by the caller. For tests. */
bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err);

#endif /* BB_TRACE_TRACE_H */
