/* trace.h: the whole trace of a pyramid and ray set (trace.c), which
 * bb__bake_checked runs and the tests and tools call alone; not public. */
#ifndef BB_TRACE_TRACE_H
#define BB_TRACE_TRACE_H

#include "bumpbake.h"

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

void bb__trace_options_init(bb_trace_options *o);

/* Finds every texel's horizon in each slice of rs and integrates it (see
 * bb_rayset). Allocates vis with 1 + bb_rayset_lobe_count(rs) channels: ao, vis_0,
 * vis_1, ... in [0, 1], over the whole pyramid or over o->region (which
 * must lie inside it). Sweeps and marches find the same horizons, so a
 * region's texels are bit-identical to the same texels of a whole trace,
 * and the result is bit-identical for any thread count. horizons_found (may
 * be NULL) receives texels * slices. BB_ERR_CANCELLED when o->progress
 * returned nonzero (vis is then left unallocated). */
bb_status bb__trace_occlusion(const bb_pyramid *p, const bb_rayset *rs,
                             const bb_trace_options *o, bb_image *vis,
                             double *horizons_found, bb_error *err);

#endif
