/* test_slope.c: flipcode's slope byte (nibbles, negative nibbles, rounding
 * and clamping) on ramps, and the 16 x 16 lighting table. */
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bumpbake.h"
#include "maps/maps_internal.h"
#include "render/render_internal.h"

static int byte_at(const bb_image *slope, int x, int y) {
  return (int)lrintf(bb_image_texel(slope, x, y)[0] * 255.0f);
}

Test(slope, nibbles_round_trip_and_negatives_are_twos_complement) {
  for (int dy = -7; dy <= 7; dy++)
    for (int dx = -7; dx <= 7; dx++) {
      uint8_t b = bb__slope_encode(dx, dy);
      int gx = 99, gy = 99;
      bb__slope_decode(b, &gx, &gy);
      cr_assert(gx == dx && gy == dy, "(%d, %d) -> 0x%02x -> (%d, %d)", dx, dy, b, gx,
                gy);
    }
  cr_assert_eq(bb__slope_encode(3, -2), 0xE3, "dx in the low nibble, dy in the high one");
  cr_assert_eq(bb__slope_encode(-1, 0), 0x0F);
  cr_assert_eq(bb__slope_encode(-7, 7), 0x79);
  cr_assert_eq(bb__slope_encode(20, -20), 0x97, "clamped to -7..7");
  int dx, dy;
  bb__slope_decode(0x88, &dx, &dy);
  cr_assert(dx == -8 && dy == -8, "0x8 is -8 (never written)");
}

/* h rises k / S per texel to the right: every byte holds dx = k, dy = 0,
 * except where the ramp wraps (periodic: a cliff down, clamped to -7) or
 * ends (clamp: flat). */
Test(slope, bytes_on_a_ramp) {
  const int w = 10, h = 3;
  bb_image ramp;
  cr_assert_eq(bb_image_alloc(&ramp, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      ramp.pixels[y * w + x] = (float)x / 255.0f;
  for (int k = 1; k <= 3; k++) {
    bb_image slope;
    bb_error err;
    cr_assert_eq(
        bb__slope_map(&ramp, 255.0f * (float)k, BB_ADDRESS_PERIODIC, &slope, &err), BB_OK,
        "%s", err.message);
    cr_assert_eq(slope.channels, 1);
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        int expected = x < w - 1 ? k : -7;
        cr_assert_eq(byte_at(&slope, x, y), bb__slope_encode(expected, 0),
                     "k %d (%d, %d): byte 0x%02x", k, x, y, byte_at(&slope, x, y));
      }
    bb_image_free(&slope);
    cr_assert_eq(bb__slope_map(&ramp, 255.0f * (float)k, BB_ADDRESS_CLAMP, &slope, NULL),
                 BB_OK);
    cr_assert_eq(byte_at(&slope, w - 1, 1), 0, "clamp: the last column is flat");
    cr_assert_eq(byte_at(&slope, w - 2, 1), bb__slope_encode(k, 0));
    bb_image_free(&slope);
  }
  /* The same ramp turned to run downwards fills the high nibble, and a ramp
   * falling to the right is negative. */
  bb_image down;
  cr_assert_eq(bb_image_alloc(&down, 3, 10, 1, NULL), BB_OK);
  for (int y = 0; y < 10; y++)
    for (int x = 0; x < 3; x++)
      down.pixels[y * 3 + x] = (float)(9 - y) / 255.0f;
  bb_image slope;
  cr_assert_eq(bb__slope_map(&down, 510.0f, BB_ADDRESS_CLAMP, &slope, NULL), BB_OK);
  cr_assert_eq(byte_at(&slope, 1, 4), bb__slope_encode(0, -2));
  cr_assert_eq(byte_at(&slope, 1, 4), 0xE0);
  bb_image_free(&slope);
  bb_image_free(&down);
  bb_image_free(&ramp);
}

Test(slope, rounding_is_to_nearest_with_halves_away_from_zero) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 5, 1, 1, NULL), BB_OK);
  const float heights[5] = {0.0f, 0.5f, 0.0f, 7.6f,
                            0.0f}; /* scale 1: differences in texels */
  memcpy(h.pixels, heights, sizeof heights);
  bb_image s;
  cr_assert_eq(bb__slope_map(&h, 1.0f, BB_ADDRESS_PERIODIC, &s, NULL), BB_OK);
  const int expected_dx[5] = {1, -1, 7, -7, 0};
  for (int x = 0; x < 5; x++)
    cr_assert_eq(byte_at(&s, x, 0), bb__slope_encode(expected_dx[x], 0), "x %d", x);
  bb_image_free(&s);
  bb_error err;
  cr_assert_eq(bb__slope_map(&h, 0.0f, BB_ADDRESS_PERIODIC, &s, &err), BB_ERR_ARGUMENT);
  h.pixels[2] = NAN;
  cr_assert_eq(bb__slope_map(&h, 1.0f, BB_ADDRESS_PERIODIC, &s, &err), BB_ERR_VALUE);
  bb_image_free(&h);
}

Test(slope, table_lights_slopes_facing_the_light) {
  double l[3];
  float table[256];
  bb__light_direction(0.0, 45.0, l);
  bb__slope_table(l, table);
  cr_assert_float_eq(table[0], sin(45.0 * 3.14159265358979323846 / 180.0), 1e-6,
                     "flat: N.L = sin(elevation)");
  /* A surface falling to the right (dx < 0) faces a light from the right. */
  cr_assert_gt(table[bb__slope_encode(-1, 0)], table[0]);
  cr_assert_lt(table[bb__slope_encode(1, 0)], table[0]);
  cr_assert_float_eq(table[bb__slope_encode(-1, 0)], 1.0, 1e-6, "N = L exactly");
  cr_assert_eq(table[bb__slope_encode(7, 0)], 0.0f, "facing away: 0, not negative");
  cr_assert_float_eq(table[bb__slope_encode(0, 3)], table[bb__slope_encode(0, -3)], 1e-7,
                     "light across y: symmetric");

  bb_image s, lit;
  cr_assert_eq(bb_image_alloc(&s, 2, 1, 1, NULL), BB_OK);
  s.pixels[0] = bb__slope_encode(-1, 0) / 255.0f;
  s.pixels[1] = bb__slope_encode(2, 5) / 255.0f;
  cr_assert_eq(bb__slope_light(&s, table, &lit, NULL), BB_OK);
  cr_assert_eq(lit.pixels[0], table[0x0F]);
  cr_assert_eq(lit.pixels[1], table[0x52]);
  bb_image_free(&lit);
  bb_image_free(&s);
}
