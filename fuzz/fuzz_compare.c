/* fuzz_compare.c: bb__compare_images on two small images made of raw
 * floats (NaN, infinities and denormals included) with fuzzed thresholds.
 * Layout: width-1, height-1, channels-1 (low bits of 3 bytes), 2 floats of
 * thresholds, then A's samples and B's samples. Properties: no crash or
 * undefined behaviour, counts within the pixel count, max >= mean (to
 * rounding) when both are finite, and a diff image exactly as documented: |A - B| in
 * double rounded to float, 0 for equal values (equal infinities, and NaN on both
 * sides, too), infinity where one side is NaN. */
#include "bumpbake.h"
#include "fuzz_common.h"
#include "maps/maps_internal.h"

#include <math.h>

static float take_float(const uint8_t **p, const uint8_t *end) {
  float v = 0.0f;
  if (end - *p >= (ptrdiff_t)sizeof v) {
    memcpy(&v, *p, sizeof v);
    *p += sizeof v;
  }
  return v;
}

static float expected_difference(float a, float b) {
  if (a == b || (isnan(a) && isnan(b)))
    return 0.0f;
  if (isnan(a) || isnan(b))
    return INFINITY;
  return (float)fabs((double)a - (double)b);
}

static int same_bits(float x, float y) {
  return memcmp(&x, &y, sizeof x) == 0;
}

static void fill(bb_image *img, const uint8_t **p, const uint8_t *end) {
  size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  for (size_t i = 0; i < n; i++)
    img->pixels[i] = take_float(p, end);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 3)
    return 0;
  const int w = 1 + (data[0] & 15), h = 1 + (data[1] & 15), c = 1 + (data[2] & 3);
  /* A mismatched B now and then: the size check must hold. */
  const int bw = (data[0] & 0x80) ? w + 1 : w;
  const uint8_t *p = data + 3, *end = data + size;
  const double fail = take_float(&p, end), warn = take_float(&p, end);
  bb_image a, b, diff = {0};
  bb_error err;
  if (bb_image_alloc(&a, w, h, c, &err) != BB_OK ||
      bb_image_alloc(&b, bw, h, c, &err) != BB_OK)
    abort();
  fill(&a, &p, end);
  fill(&b, &p, end);

  bb_compare_stats s;
  bb_status st = bb__compare_images(&a, &b, fail, warn, &s, &diff, &err);
  if (bw != w) {
    FUZZ_CHECK(st == BB_ERR_SIZE && diff.pixels == NULL);
  } else if (st == BB_OK) {
    FUZZ_CHECK(s.pixels == (long)w * h);
    FUZZ_CHECK(s.over_fail >= 0 && s.over_fail <= s.pixels);
    FUZZ_CHECK(s.over_warn >= 0 && s.over_warn <= s.pixels);
    /* sum / count may round a few ulps above the largest term. */
    if (isfinite(s.max_abs) && isfinite(s.mean_abs))
      FUZZ_CHECK(s.max_abs >= s.mean_abs * (1.0 - 1e-12));
    size_t n = (size_t)w * (size_t)h * (size_t)c;
    for (size_t i = 0; i < n; i++)
      FUZZ_CHECK(
          same_bits(expected_difference(a.pixels[i], b.pixels[i]), diff.pixels[i]));
  } else {
    FUZZ_CHECK(diff.pixels == NULL);
  }
  bb_image_free(&diff);
  bb_image_free(&a);
  bb_image_free(&b);
  return 0;
}
