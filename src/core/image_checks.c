/* image_checks.c: the checks of an image's size, channels and values every
 * family makes with the same words (core/internal.h). */

#include "core/internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

bb_status bb__check_channels(const bb_image *img, int min_channels, const char *what,
                             bb_error *err) {
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: missing or empty image", what);
  if (img->channels < min_channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s has %d channel%s, needs %d or more", what,
                    img->channels, img->channels == 1 ? "" : "s", min_channels);
  return BB_OK;
}

/* 1 when none of v[0..n) is a NaN or an infinity (all exponent bits set):
 * a loop the compiler runs several samples at a time. */
static int all_finite(const float *v, size_t n) {
  uint32_t bad = 0;
  for (size_t i = 0; i < n; i++) {
    uint32_t u;
    memcpy(&u, v + i, sizeof u);
    bad |= (u & 0x7f800000u) == 0x7f800000u;
  }
  return !bad;
}

int bb__image_all_finite(const bb_image *img) {
  return all_finite(img->pixels,
                    (size_t)img->width * (size_t)img->height * (size_t)img->channels);
}

bb_status bb__check_finite(const bb_image *img, int channels, const char *what,
                           bb_error *err) {
  /* Every sample finite (the usual case) passes in one quick sweep; else
   * the texel by texel walk below finds and names the first (the image's
   * non-finite samples may also all be in channels not checked). */
  if (bb__image_all_finite(img))
    return BB_OK;
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++) {
      const float *t = bb_image_texel(img, x, y);
      for (int c = 0; c < channels; c++)
        if (!isfinite(t[c]))
          return bb__fail(err, BB_ERR_VALUE, "%s: texel (%d, %d) channel %d is %s", what,
                          x, y, c, isnan(t[c]) ? "NaN" : "infinite");
    }
  return BB_OK;
}

bb_status bb__check_same_size(const bb_image *a, const char *name_a, const bb_image *b,
                              const char *name_b, bb_error *err) {
  if (a->width != b->width || a->height != b->height)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s is %dx%d but %s is %dx%d", name_a, a->width,
                    a->height, name_b, b->width, b->height);
  return BB_OK;
}
