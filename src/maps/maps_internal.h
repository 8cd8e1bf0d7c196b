/* maps_internal.h: helpers shared by the map conversions (convert.c,
 * combine.c, program.c, slope.c); not public. */
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

/* BB_ERR_VALUE naming the first texel whose channels 0..channels-1 are not
 * finite; what names the image ("normal map", "detail"). */
bb_status bb__check_finite(const bb_image *img, int channels, const char *what,
                           bb_error *err);

/* BB_ERR_ARGUMENT unless a and b have the same width and height. */
bb_status bb__check_same_size(const bb_image *a, const char *name_a, const bb_image *b,
                              const char *name_b, bb_error *err);

/* BB_ERR_ARGUMENT unless img is allocated with at least min_channels. */
bb_status bb__check_channels(const bb_image *img, int min_channels, const char *what,
                             bb_error *err);

/* Scales v to unit length; a zero (or non-finite) length gives (0, 0, 1),
 * the flat normal, since such a texel has no direction to keep. */
void bb__normalize3(double v[3]);

/* DOOM 3's addnormals on one texel: n = base, z rebuilt from x and y when
 * |n| < 1 (maps that fade to (0, 0, 0) at their edges), n.xy += (dx, dy),
 * out = normalize(n). */
void bb__add_normals(const double base[3], double dx, double dy, double out[3]);


#ifdef __cplusplus
}
#endif

#endif /* BB_MAPS_INTERNAL_H */
