/* pattern_image.h: an image whose texels vary smoothly, for the tests that
 * run maps and bakes on images in memory (header-only; include after
 * bumpbake.h and criterion.h). */
#ifndef BB_TESTS_PATTERN_IMAGE_H
#define BB_TESTS_PATTERN_IMAGE_H

#include <math.h>

/* w x h x channels texels in (lo, hi), a sine of x, y and the channel,
 * shifted by phase (another phase: another image of the same kind). */
static inline bb_image pattern_image(int w, int h, int channels, float lo, float hi,
                                     float phase) {
  bb_image img = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, &err), BB_OK, "%s", err.message);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int k = 0; k < channels; k++) {
        const float t =
            0.5f + 0.5f * sinf(0.37f * (float)x + 0.23f * (float)y + 1.3f * (float)k + phase);
        bb_image_texel(&img, x, y)[k] = lo + (hi - lo) * t;
      }
  return img;
}

#endif /* BB_TESTS_PATTERN_IMAGE_H */
