/* slope.c: flipcode's 1999 slope map (one byte of slopes per texel) and
 * the 16 x 16 table that lights it (docs/commands/bake.md, "Slope map"). */

#include "core/internal.h"
#include "maps/maps_internal.h"
#include <math.h>
#include <string.h>

static int clamp7(long v) {
  return v < -7 ? -7 : (v > 7 ? 7 : (int)v);
}

uint8_t bb__slope_encode(int dx, int dy) {
  unsigned lo = (unsigned)clamp7(dx) & 0xFu, hi = (unsigned)clamp7(dy) & 0xFu;
  return (uint8_t)(hi << 4 | lo);
}

/* A 4-bit two's complement nibble as a signed number. */
static int nibble_value(unsigned nibble) {
  return nibble >= 8 ? (int)nibble - 16 : (int)nibble;
}

void bb__slope_decode(uint8_t byte, int *dx, int *dy) {
  if (dx)
    *dx = nibble_value(byte & 0xFu);
  if (dy)
    *dy = nibble_value((unsigned)byte >> 4);
}

/* A height difference in texels as the article's integer slope: nearest,
 * halves away from zero, clamped to -7..7. */
static int slope_step(double difference_texels) {
  return clamp7(lround(fmax(-8.0, fmin(8.0, difference_texels))));
}

bb_status bb__slope_map(const bb_image *height, float height_scale,
                       bb_addressing addressing, bb_image *out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "slope map: out is NULL");
  memset(out, 0, sizeof *out);
  bb_status st = bb__check_channels(height, 1, "height", err);
  if (st != BB_OK)
    return st;
  if (height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "slope map: the height needs 1 channel, not %d",
                    height->channels);
  if (!(height_scale > 0.0f) || !isfinite(height_scale))
    return bb__fail(err, BB_ERR_ARGUMENT, "slope map: height scale must be > 0 (got %g)",
                    (double)height_scale);
  st = bb__check_finite(height, 1, "height", err);
  if (st == BB_OK)
    st = bb_image_alloc(out, height->width, height->height, 1, err);
  if (st != BB_OK)
    return st;
  const int w = height->width, h = height->height;
  const double s = (double)height_scale;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double here = *bb_image_texel(height, x, y);
      double right = *bb_image_texel(height, bb__address(x + 1, w, addressing), y);
      double below = *bb_image_texel(height, x, bb__address(y + 1, h, addressing));
      uint8_t b =
          bb__slope_encode(slope_step(s * (right - here)), slope_step(s * (below - here)));
      *bb_image_texel(out, x, y) = (float)b / 255.0f;
    }
  return BB_OK;
}

void bb__slope_table(const double light[3], float table[256]) {
  for (int b = 0; b < 256; b++) {
    int dx, dy;
    bb__slope_decode((uint8_t)b, &dx, &dy);
    /* The surface rises dx texels per texel to the right and dy downwards. */
    double n[3] = {-(double)dx, -(double)dy, 1.0};
    bb__normalize3(n);
    double d = n[0] * light[0] + n[1] * light[1] + n[2] * light[2];
    table[b] = (float)(d > 0.0 ? d : 0.0);
  }
}

bb_status bb__slope_light(const bb_image *slope, const float table[256], bb_image *out,
                         bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "slope light: out is NULL");
  memset(out, 0, sizeof *out);
  if (!table)
    return bb__fail(err, BB_ERR_ARGUMENT, "slope light: table is NULL");
  bb_status st = bb__check_channels(slope, 1, "slope map", err);
  if (st == BB_OK)
    st = bb__check_finite(slope, 1, "slope map", err);
  if (st == BB_OK)
    st = bb_image_alloc(out, slope->width, slope->height, 1, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)slope->width * (size_t)slope->height;
  for (size_t i = 0; i < n; i++) {
    double code = 255.0 * (double)slope->pixels[i * (size_t)slope->channels] + 0.5;
    int b = code < 0.0 ? 0 : (code > 255.0 ? 255 : (int)code);
    out->pixels[i] = table[b];
  }
  return BB_OK;
}
