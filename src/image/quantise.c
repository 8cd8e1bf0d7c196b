/* quantise.c: the integer codes bumpbake writes for float samples.
 *
 * Round-half-up quantisation of v (after the range mapping) to 0..max_code.
 * NaN becomes 0 so that it cannot reach an undefined float-to-int cast.
 * u * max_code + 0.5 lies in [0.5, max_code + 0.5], so truncation is the
 * floor: the same codes as floor(), without a libm call per sample. */
#include "image/quantise.h"

#include <stdlib.h>

static inline int32_t code_of(double u, double max_code) {
  u = u > 0.0 ? u : 0.0; /* NaN fails both comparisons and becomes 0 */
  u = u < 1.0 ? u : 1.0;
  return (int32_t)(u * max_code + 0.5);
}

/* One loop per type and range, so the range test is not in the loop. */
#define QUANTISE(T, NAME)                                                               \
  T *NAME(const bb_image *img, bb_range range) {                                        \
    const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;  \
    T *codes = malloc(n ? n * sizeof(T) : 1);                                           \
    if (!codes) return NULL;                                                            \
    const float *v = img->pixels;                                                       \
    const double max_code = (double)(T) ~(T)0;                                          \
    if (range == BB_RANGE_SIGNED)                                                       \
      for (size_t i = 0; i < n; i++) codes[i] = (T)code_of(0.5 + 0.5 * (double)v[i], max_code); \
    else                                                                                \
      for (size_t i = 0; i < n; i++) codes[i] = (T)code_of((double)v[i], max_code);     \
    return codes;                                                                       \
  }

QUANTISE(uint8_t, bb__quantise_8)
QUANTISE(uint16_t, bb__quantise_16)
