/* maps_internal.h: helpers shared by the map conversions (convert.c,
 * combine.c, program.c); not public. The image checks they share with
 * other families are core's (core/internal.h). */
#ifndef BB_MAPS_INTERNAL_H
#define BB_MAPS_INTERNAL_H

#include "bumpbake.h"
#include "core/internal.h"


#ifdef __cplusplus
extern "C" {
#endif

/* The ranges of bb_compare_limits' fields (compare.c): thresholds >= 0
 * (infinity allowed), percentages 0..100, counts >= 0. */
extern const bb__range bb__range_compare_threshold, bb__range_compare_percent,
    bb__range_compare_count;
/* A blend's factor, 0..1 (combine.c). */
extern const bb__range bb__range_mix;

/* DOOM 3's addnormals on one texel: n = base, z rebuilt from x and y when
 * |n| < 1 (maps that fade to (0, 0, 0) at their edges), n.xy += (dx, dy),
 * out = normalize(n). */
void bb__add_normals(const double base[3], double dx, double dy, double out[3]);


#ifdef __cplusplus
}
#endif

#endif /* BB_MAPS_INTERNAL_H */
