/* bake_harness.h: small helpers for the library tests that bake (header-only;
 * include after bumpbake.h and criterion.h). */
#ifndef BB_BAKE_HARNESS_H
#define BB_BAKE_HARNESS_H

#include "bake/bake_internal.h"

/* A w x h one-channel image, every texel value. */
static inline bb_image harness_field(int w, int h, float value) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
    img.pixels[i] = value;
  return img;
}

/* bb__bake_checked that must succeed; the test fails with the library's message. */
static inline bb_bake_result harness_bake(const bb_image *h, const bb_bake_options *o) {
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(h, o, &r, &err), BB_OK, "%s", err.message);
  return r;
}

#endif /* BB_BAKE_HARNESS_H */
