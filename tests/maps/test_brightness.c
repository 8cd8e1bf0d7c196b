/* test_brightness.c: the brightness modulation stored in the ssbump and
 * weights (bb__combine_brightness, bb_bake_options.brightness) and its
 * provenance. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "job/job_internal.h"
#include "bumpbake.h"
#include "bake_harness.h"
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "maps/maps_internal.h"
#include "files/provenance.h"
#include "trace/basis.h"

static bb_image image(int w, int h, int channels, const float *texel) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int i = 0; i < w * h; i++) memcpy(img.pixels + i * channels, texel, (size_t)channels * sizeof(float));
  return img;
}

static bb_image brightened(const bb_image *map, const bb_image *b, bb_map_kind kind) {
  bb_image out;
  bb_error err;
  cr_assert_eq(bb__combine_brightness(map, b, kind, &out, &err), BB_OK, "%s", err.message);
  return out;
}

Test(brightness, one_is_the_map_bit_for_bit) {
  const float ss[4] = {0.31f, 0.577f, 0.9f, 0.25f};
  bb_image map = image(5, 3, 4, ss), one = harness_field(5, 3, 1.0f);
  bb_image out = brightened(&map, &one, BB_MAP_SSBUMP);
  cr_expect_eq(memcmp(out.pixels, map.pixels, sizeof(float) * 5 * 3 * 4), 0);
  bb_image_free(&out);
  bb_image ao = harness_field(5, 3, 0.73f);
  out = brightened(&ao, &one, BB_MAP_AO);
  cr_expect_eq(memcmp(out.pixels, ao.pixels, sizeof(float) * 5 * 3), 0);
  bb_image_free(&out);
  bb_image_free(&ao);
  bb_image_free(&map);
  bb_image_free(&one);
}

Test(brightness, multiplies_the_basis_channels_and_copies_alpha) {
  const float ss[4] = {0.4f, 0.2f, 0.1f, 0.77f};
  bb_image map = image(2, 2, 4, ss), half = harness_field(2, 2, 0.5f);
  bb_image out = brightened(&map, &half, BB_MAP_SSBUMP);
  for (int i = 0; i < 4; i++) {
    const float *t = out.pixels + 4 * i;
    cr_expect_eq(t[0], 0.2f);
    cr_expect_eq(t[1], 0.1f);
    cr_expect_eq(t[2], 0.05f);
    cr_expect_eq(t[3], 0.77f, "alpha is copied");
  }
  bb_image_free(&out);
  bb_image_free(&map);
  bb_image_free(&half);
}

/* Over 1 the brightness clips, not the direction: the texel is scaled so
 * that its largest channel is 1, and the bent normal (the direction the
 * engine derives) is the same as without it. */
Test(brightness, over_one_clips_the_brightness_and_keeps_the_direction) {
  const float ss[3] = {0.6f, 0.3f, 0.1f};
  bb_image map = image(1, 1, 3, ss), two = harness_field(1, 1, 2.0f);
  bb_image out = brightened(&map, &two, BB_MAP_SSBUMP);
  cr_expect_float_eq(out.pixels[0], 1.0, 1e-7);
  cr_expect_float_eq(out.pixels[1], 0.5, 1e-7);
  cr_expect_float_eq(out.pixels[2], 0.1 / 0.6, 1e-7);
  bb_image bent_a, bent_b;
  cr_assert_eq(bb__derive_bent_all_cores(&map, NULL, &bent_a, NULL), BB_OK);
  cr_assert_eq(bb__derive_bent_all_cores(&out, NULL, &bent_b, NULL), BB_OK);
  for (int k = 0; k < 3; k++) cr_expect_float_eq(bent_a.pixels[k], bent_b.pixels[k], 1e-6);
  /* a flat texel takes sqrt(3) before it clips */
  const float flat[3] = {0.57735027f, 0.57735027f, 0.57735027f};
  bb_image f = image(1, 1, 3, flat), root3 = harness_field(1, 1, 1.7f);
  bb_image g = brightened(&f, &root3, BB_MAP_SSBUMP);
  cr_expect_float_eq(g.pixels[0], 0.57735027 * 1.7, 1e-6);
  /* ao clips at 1 */
  bb_image ao = harness_field(1, 1, 0.8f), o2 = brightened(&ao, &two, BB_MAP_AO);
  cr_expect_eq(o2.pixels[0], 1.0f);
  bb_image_free(&ao), bb_image_free(&o2), bb_image_free(&g), bb_image_free(&f);
  bb_image_free(&root3), bb_image_free(&bent_a), bb_image_free(&bent_b);
  bb_image_free(&out), bb_image_free(&map), bb_image_free(&two);
}

Test(brightness, grey_of_a_colour_map_and_negatives) {
  const float ss[3] = {0.5f, 0.5f, 0.5f}, rgb[3] = {1.0f, 0.0f, 0.0f}, neg = -0.5f;
  bb_image map = image(1, 1, 3, ss), red = image(1, 1, 3, rgb), below = image(1, 1, 1, &neg);
  bb_image out = brightened(&map, &red, BB_MAP_WEIGHTS);
  cr_expect_float_eq(out.pixels[0], 0.5 * 0.2126, 1e-7, "Rec. 709 luma of pure red");
  bb_image z = brightened(&map, &below, BB_MAP_SSBUMP);
  cr_expect_eq(z.pixels[0], 0.0f);
  bb_image_free(&z), bb_image_free(&out), bb_image_free(&map), bb_image_free(&red);
  bb_image_free(&below);
}

Test(brightness, refuses_what_it_cannot_do) {
  const float n[3] = {0.0f, 0.0f, 1.0f};
  bb_image normal = image(2, 2, 3, n), b = harness_field(2, 2, 0.5f), small = harness_field(1, 1, 0.5f);
  bb_image out;
  bb_error err;
  cr_expect_eq(bb__combine_brightness(&normal, &b, BB_MAP_NORMAL, &out, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "normal") != NULL, "%s", err.message);
  cr_expect_eq(bb__combine_brightness(&normal, &small, BB_MAP_SSBUMP, &out, &err), BB_ERR_SIZE);
  cr_expect(strstr(err.message, "brightness") != NULL, "%s", err.message);
  b.pixels[3] = NAN;
  cr_expect_eq(bb__combine_brightness(&normal, &b, BB_MAP_SSBUMP, &out, &err), BB_ERR_VALUE);
  const float five[5] = {0.1f, 0.1f, 0.1f, 0.1f, 0.1f};
  bb_image wide = image(2, 2, 5, five), ok = harness_field(2, 2, 0.5f);
  cr_expect_eq(bb__combine_brightness(&wide, &ok, BB_MAP_SSBUMP, &out, &err), BB_ERR_ARGUMENT,
               "a basis of 5 directions is not Half-Life 2's");
  bb_image_free(&wide), bb_image_free(&ok), bb_image_free(&normal), bb_image_free(&b);
  bb_image_free(&small);
}

/* The bake's option is bb__combine_brightness on its ssbump and weights,
 * over every basis channel; ao and bent stay as without it. */
Test(brightness, the_bake_option_modulates_ssbump_and_weights) {
  const int W = 32, H = 24;
  bb_image h = harness_field(W, H, 0.0f), b = harness_field(W, H, 0.0f);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      *bb_image_texel(&h, x, y) = (float)(0.5 + 0.5 * sin(x * 0.4) * cos(y * 0.3));
      *bb_image_texel(&b, x, y) = (float)(0.25 + 1.5 * x / (W - 1)); /* 0.25 .. 1.75 */
    }
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 6.0f;
  bb_bake_result plain = harness_bake(&h, &o);
  o.brightness = &b;
  bb_bake_result lit = harness_bake(&h, &o);
  bb_image ss = brightened(&plain.ssbump, &b, BB_MAP_SSBUMP);
  bb_image wt = brightened(&plain.weights, &b, BB_MAP_WEIGHTS);
  const size_t n3 = (size_t)W * (size_t)H * 3;
  cr_expect_eq(memcmp(lit.ssbump.pixels, ss.pixels, n3 * sizeof(float)), 0);
  cr_expect_eq(memcmp(lit.weights.pixels, wt.pixels, n3 * sizeof(float)), 0);
  cr_expect_eq(memcmp(lit.ao.pixels, plain.ao.pixels, (size_t)W * (size_t)H * sizeof(float)), 0);
  cr_expect_eq(memcmp(lit.bent.pixels, plain.bent.pixels, n3 * sizeof(float)), 0);
  /* and with a basis of 6 directions, every one of them */
  cr_assert_eq(bb__basis_parse("dirs:6", &o.basis, NULL), BB_OK);
  bb_bake_result six = harness_bake(&h, &o);
  o.brightness = NULL;
  bb_bake_result six_plain = harness_bake(&h, &o);
  for (int c = 0; c < 6; c++) {
    const double v = bb_image_texel(&six_plain.ssbump, 3, 5)[c];
    const double bb = *bb_image_texel(&b, 3, 5);
    cr_expect_float_eq(bb_image_texel(&six.ssbump, 3, 5)[c], v * bb, 1e-6, "channel %d", c);
  }
  bb_bake_result_free(&six), bb_bake_result_free(&six_plain);
  /* a map of another size is refused before anything is made */
  bb_image small = harness_field(4, 4, 1.0f);
  o.brightness = &small;
  bb_bake_result r;
  bb_error err;
  cr_expect_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_SIZE);
  cr_expect(strstr(err.message, "brightness") != NULL, "%s", err.message);
  bb_image_free(&small), bb_image_free(&ss), bb_image_free(&wt);
  bb_bake_result_free(&plain), bb_bake_result_free(&lit);
  bb_image_free(&h), bb_image_free(&b);
}

Test(brightness, provenance_names_the_maps_it_was_made_with) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 4.0f;
  bb_provenance p = {.output_kind = "ssbump", .options = &o};
  char *text = bb__provenance_format(&p), value[64];
  cr_assert_not_null(text);
  cr_expect_eq(bb__provenance_value(text, "brightness", value, sizeof value), 0);
  cr_expect_eq(bb__provenance_value(text, "bounce", value, sizeof value), 0);
  free(text);
  bb_image b = harness_field(3, 3, 0.5f), albedo = harness_field(3, 3, 0.25f);
  o.brightness = &b;
  o.bounce_albedo = 0.4;
  o.bounce_albedo_map = &albedo;
  text = bb__provenance_format(&p);
  char want[32];
  snprintf(want, sizeof want, "%016llx", (unsigned long long)bb__image_hash(&b));
  cr_expect_eq(bb__provenance_value(text, "brightness", value, sizeof value), 1);
  cr_expect_str_eq(value, want);
  cr_expect_eq(bb__provenance_value(text, "bounce", value, sizeof value), 1);
  cr_expect_str_eq(value, "0.4");
  cr_expect_eq(bb__provenance_value(text, "bounces", value, sizeof value), 1);
  cr_expect_str_eq(value, "0");
  snprintf(want, sizeof want, "%016llx", (unsigned long long)bb__image_hash(&albedo));
  cr_expect_eq(bb__provenance_value(text, "bounce_albedo_map", value, sizeof value), 1);
  cr_expect_str_eq(value, want);
  free(text);
  bb_image_free(&b), bb_image_free(&albedo);
}
