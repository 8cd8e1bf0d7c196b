/* quantise.h: float samples to the integer codes of 8- and 16-bit files
 * (quantise.c). */
#ifndef BB_IMAGE_QUANTISE_H
#define BB_IMAGE_QUANTISE_H

#include "bumpbake.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Every sample of img as a code of 0..255 (or 0..65535): the value mapped
 * by range onto [0, 1] (BB_RANGE_SIGNED: 0.5 + 0.5 v), clamped, times the
 * largest code, rounded half up; NaN becomes 0. malloc'd (width x height x
 * channels codes); NULL when out of memory. */
uint8_t *bb__quantise_8(const bb_image *img, bb_range range);
uint16_t *bb__quantise_16(const bb_image *img, bb_range range);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_QUANTISE_H */
