/* test_valve.c: Valve's RGBA packing (bb__valve_pack) and detail variant
 * (bb__valve_detail). */
#include "maps/maps_internal.h"
#include "bumpbake.h"
#include "bake/bake_internal.h"

#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

/* A w x h image of c channels, every texel set to value[0..c-1]. */
static bb_image filled(int w, int h, int c, const float *value) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, c, NULL), BB_OK);
  for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
    memcpy(img.pixels + i * (size_t)c, value, sizeof(float) * (size_t)c);
  return img;
}

/* A hand-made bake result of 3 x 2 texels with distinct values per map, and
 * texel (1, 1) of ssbump and normal set apart to follow a texel through. */
static bb_bake_result hand_result(void) {
  bb_bake_result r;
  memset(&r, 0, sizeof r);
  r.ssbump = filled(3, 2, 3, (float[]){0.1f, 0.2f, 0.3f});
  r.normal = filled(3, 2, 3, (float[]){0.0f, 0.0f, 1.0f});
  r.filtered = filled(3, 2, 1, (float[]){0.7f});
  r.ao = filled(3, 2, 1, (float[]){0.9f});
  float *s = bb_image_texel(&r.ssbump, 1, 1), *n = bb_image_texel(&r.normal, 1, 1);
  s[0] = 0.5f, s[1] = 0.25f, s[2] = 1.0f;
  n[0] = -1.0f, n[1] = 0.5f, n[2] = 0.0f;
  *bb_image_texel(&r.filtered, 1, 1) = 0.125f;
  *bb_image_texel(&r.ao, 1, 1) = 0.375f;
  return r;
}

static void expect_texel(const bb_image *img, int x, int y, const float *want) {
  const float *t = bb_image_texel(img, x, y);
  for (int c = 0; c < img->channels; c++)
    cr_expect_float_eq(t[c], want[c], 1e-7, "texel (%d, %d) channel %d: %g, want %g", x,
                       y, c, (double)t[c], (double)want[c]);
}

Test(valve, pack_ssbump_with_height_in_alpha_by_default) {
  bb_bake_result r = hand_result();
  bb_valve_options o;
  bb__valve_options_init(&o);
  bb_image out = {0};
  cr_assert_eq(bb__valve_pack(&r, &o, &out, NULL), BB_OK);
  cr_assert(out.width == 3 && out.height == 2 && out.channels == 4);
  expect_texel(&out, 0, 0, (float[]){0.1f, 0.2f, 0.3f, 0.7f});
  expect_texel(&out, 1, 1, (float[]){0.5f, 0.25f, 1.0f, 0.125f});
  bb_image_free(&out);
  bb_bake_result_free(&r);
}

Test(valve, pack_normal_map_encoded_and_ao_in_alpha) {
  bb_bake_result r = hand_result();
  bb_valve_options o = {.normal_map = 1, .ao_in_alpha = 1};
  bb_image out = {0};
  cr_assert_eq(bb__valve_pack(&r, &o, &out, NULL), BB_OK);
  /* 0.5 + 0.5 N: (0, 0, 1) -> (0.5, 0.5, 1); (-1, 0.5, 0) -> (0, 0.75, 0.5). */
  expect_texel(&out, 0, 0, (float[]){0.5f, 0.5f, 1.0f, 0.9f});
  expect_texel(&out, 1, 1, (float[]){0.0f, 0.75f, 0.5f, 0.375f});
  bb_image_free(&out);
  bb_bake_result_free(&r);
}

Test(valve, pack_takes_three_of_four_ssbump_channels) {
  bb_bake_result r = hand_result();
  bb_image_free(&r.ssbump);
  r.ssbump = filled(3, 2, 4, (float[]){0.1f, 0.2f, 0.3f, 0.4f}); /* hl2+z */
  bb_valve_options o;
  bb__valve_options_init(&o);
  bb_image out = {0};
  cr_assert_eq(bb__valve_pack(&r, &o, &out, NULL), BB_OK);
  expect_texel(&out, 2, 1, (float[]){0.1f, 0.2f, 0.3f, 0.7f});
  bb_image_free(&out);
  bb_bake_result_free(&r);
}

Test(valve, pack_refuses_what_was_not_baked) {
  bb_bake_result r = hand_result();
  bb_image_free(&r.ao); /* an untraced bake */
  bb_image_free(&r.ssbump);
  bb_valve_options o = {.normal_map = 1, .ao_in_alpha = 1};
  bb_image out = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb__valve_pack(&r, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(err.message, "ao"), "%s", err.message);
  cr_assert_null(out.pixels);
  o.ao_in_alpha = 0, o.normal_map = 0;
  cr_assert_eq(bb__valve_pack(&r, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(err.message, "ssbump"), "%s", err.message);
  o.normal_map = 1; /* -n with the height in alpha needs no trace */
  cr_assert_eq(bb__valve_pack(&r, &o, &out, &err), BB_OK, "%s", err.message);
  bb_image_free(&out);
  bb_image_free(&r.filtered);
  r.filtered = filled(2, 2, 1, (float[]){0.5f});
  cr_assert_eq(bb__valve_pack(&r, &o, &out, &err), BB_ERR_SIZE);
  bb_bake_result_free(&r);
}

Test(valve, pack_of_a_real_flat_bake) {
  bb_image height = filled(8, 8, 1, (float[]){0.5f});
  bb_bake_options bo;
  bb__bake_options_init(&bo);
  bo.height_scale = 8.0f;
  bo.rays = 16;
  bb_bake_result r;
  bb_error err = {{0}};
  cr_assert_eq(bb__bake_checked(&height, &bo, &r, &err), BB_OK, "%s", err.message);
  bb_valve_options o;
  bb__valve_options_init(&o);
  bb_image out = {0};
  cr_assert_eq(bb__valve_pack(&r, &o, &out, &err), BB_OK, "%s", err.message);
  const float flat = (float)(1.0 / sqrt(3.0));
  expect_texel(&out, 3, 5, (float[]){flat, flat, flat, 0.5f});
  bb_image_free(&out);
  bb_bake_result_free(&r);
  bb_image_free(&height);
}

/* ---------------------------------------------------------------- detail */

static bb_smooth_options smoothing(void) {
  bb_smooth_options s;
  bb__smooth_options_init(&s);
  return s;
}

Test(valve, detail_of_mid_grey_flat_is_the_mod2x_neutral_half) {
  const float flat = (float)(1.0 / sqrt(3.0));
  bb_image rgba = filled(6, 6, 4, (float[]){flat, flat, flat, 0.3f});
  bb_image grey = filled(6, 6, 2, (float[]){0.5f, 0.8f}); /* grey + alpha */
  bb_image height = filled(6, 6, 1, (float[]){0.8f});
  bb_smooth_options s = smoothing();
  cr_assert_eq(bb__valve_detail(&rgba, &grey, &height, &s, NULL), BB_OK);
  expect_texel(&rgba, 2, 4, (float[]){0.5f, 0.5f, 0.5f, 0.3f});
  bb_image_free(&rgba);
  bb_image_free(&grey);
  bb_image_free(&height);
}

Test(valve, detail_factor_is_the_colour_sum_over_sqrt3) {
  bb_image rgba = filled(5, 4, 4, (float[]){0.2f, 0.4f, 0.6f, 1.0f});
  bb_image colour =
      filled(5, 4, 4, (float[]){0.1f, 0.3f, 0.8f, 0.0f}); /* alpha ignored */
  bb_image height = filled(5, 4, 1, (float[]){0.0f});
  bb_smooth_options s = smoothing();
  cr_assert_eq(bb__valve_detail(&rgba, &colour, &height, &s, NULL), BB_OK);
  const float f = 1.2f / sqrtf(3.0f);
  expect_texel(&rgba, 4, 3, (float[]){0.2f * f, 0.4f * f, 0.6f * f, 1.0f});
  bb_image_free(&rgba);
  bb_image_free(&colour);
  bb_image_free(&height);
}

Test(valve, detail_colour_is_smoothed_with_the_height_edges) {
  /* A colour step that follows a height step stays a step (the range term
   * of the filter stops at the height edge); the factor on each side is its
   * own colour's. */
  bb_image rgba = filled(16, 16, 4, (float[]){1.0f, 1.0f, 1.0f, 1.0f});
  bb_image colour = filled(16, 16, 1, (float[]){0.2f});
  bb_image height = filled(16, 16, 1, (float[]){0.0f});
  for (int y = 0; y < 16; y++)
    for (int x = 8; x < 16; x++)
      *bb_image_texel(&colour, x, y) = 0.6f, *bb_image_texel(&height, x, y) = 1.0f;
  bb_smooth_options s = smoothing();
  cr_assert_eq(bb__valve_detail(&rgba, &colour, &height, &s, NULL), BB_OK);
  const float lo = 0.6f / sqrtf(3.0f), hi = 1.8f / sqrtf(3.0f);
  expect_texel(&rgba, 7, 5, (float[]){lo, lo, lo, 1.0f});
  expect_texel(&rgba, 8, 5, (float[]){hi, hi, hi, 1.0f});
  bb_image_free(&rgba);
  bb_image_free(&colour);
  bb_image_free(&height);
}

Test(valve, detail_refuses_mismatched_images) {
  bb_image rgba = filled(4, 4, 4, (float[]){1, 1, 1, 1});
  bb_image colour = filled(4, 3, 3, (float[]){1, 1, 1});
  bb_image height = filled(4, 4, 1, (float[]){0});
  bb_smooth_options s = smoothing();
  bb_error err = {{0}};
  cr_assert_eq(bb__valve_detail(&rgba, &colour, &height, &s, &err), BB_ERR_SIZE);
  cr_assert_eq(bb__valve_detail(&rgba, &height, &colour, &s, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__valve_detail(&rgba, NULL, &height, &s, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(*bb_image_texel(&rgba, 0, 0), 1.0f, "left alone on error");
  bb_image_free(&rgba);
  bb_image_free(&colour);
  bb_image_free(&height);
}
