/* test_convert.c: normal-map decoding (normal2ssbump's input) and basis maps
 * back to normals (ssbump2normal), against the bake's own maps. */
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bumpbake.h"
#include "bake/bake_internal.h"
#include "maps/maps_internal.h"

static bb_image image(int w, int h, int channels) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  return img;
}

static void set3(bb_image *img, int x, int y, float a, float b, float c) {
  float *t = bb_image_texel(img, x, y);
  t[0] = a, t[1] = b, t[2] = c;
}

/* A gentle tiling wave: slopes under 11 degrees, so every N.B_c > 0 and
 * (with the default bias) no ray of the bake is blocked. */
static bb_image gentle_height(int w, int h) {
  bb_image img = image(w, h, 1);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      img.pixels[y * w + x] =
          (float)(0.5 + 0.25 * sin(2 * 3.14159265358979323846 * x / w) *
                            cos(2 * 3.14159265358979323846 * 2 * y / h));
  return img;
}

static bb_bake_result bake(const bb_image *h, float scale) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = scale;
  o.outputs = BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_WEIGHTS);
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(h, &o, &r, &err), BB_OK, "%s", err.message);
  return r;
}

static double max_difference(const bb_image *a, const bb_image *b) {
  cr_assert_eq(a->width, b->width);
  cr_assert_eq(a->height, b->height);
  cr_assert_eq(a->channels, b->channels);
  double worst = 0.0;
  size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
  for (size_t i = 0; i < n; i++)
    worst = fmax(worst, fabs((double)a->pixels[i] - (double)b->pixels[i]));
  return worst;
}

Test(convert, integer_codes_decode_with_127_5_as_zero) {
  bb_image v = image(4, 1, 3);
  set3(&v, 0, 0, 0.5f, 0.5f, 1.0f);                 /* 127.5: exactly flat */
  set3(&v, 1, 0, 128.0f / 255, 128.0f / 255, 1.0f); /* DOOM 3's zero */
  set3(&v, 2, 0, 1.0f, 0.5f, 0.5f);                 /* +x */
  set3(&v, 3, 0, 0.0f, 0.0f, 0.0f);                 /* (-1, -1, -1) */
  bb_image n;
  bb_error err;
  cr_assert_eq(bb_normal_map_decode(&v, 0, 0, 0, &n, &err), BB_OK, "%s", err.message);
  cr_assert_eq(n.channels, 3);
  const float *t = bb_image_texel(&n, 0, 0);
  cr_assert(t[0] == 0.0f && t[1] == 0.0f && t[2] == 1.0f);
  t = bb_image_texel(&n, 1, 0);
  cr_assert_float_eq(t[0], 1.0 / 255.0, 1e-7, "128 reads as +1/255, as in Valve's tool");
  t = bb_image_texel(&n, 2, 0);
  cr_assert(t[0] == 1.0f && t[1] == 0.0f && t[2] == 0.0f);
  t = bb_image_texel(&n, 3, 0);
  cr_assert(t[0] == -1.0f && t[1] == -1.0f && t[2] == -1.0f);
  bb_image_free(&n);
  bb_image_free(&v);
}

Test(convert, float_files_hold_n_and_options_apply) {
  bb_image v = image(2, 1, 4); /* an alpha channel is dropped */
  set3(&v, 0, 0, 0.0f, 0.6f, 0.8f);
  set3(&v, 1, 0, 0.0f, 0.0f, 0.0f);
  bb_image n;
  cr_assert_eq(bb_normal_map_decode(&v, 1, 1, 1, &n, NULL), BB_OK);
  cr_assert_eq(n.channels, 3);
  const float *t = bb_image_texel(&n, 0, 0);
  cr_assert_float_eq(t[1], -0.6, 1e-7, "--normal-y up negates green");
  cr_assert_float_eq(t[2], 0.8, 1e-7);
  t = bb_image_texel(&n, 1, 0);
  cr_assert(t[0] == 0.0f && t[1] == 0.0f && t[2] == 1.0f, "a zero vector becomes flat");
  bb_image_free(&n);

  /* Normalisation rescales a short vector. */
  set3(&v, 0, 0, 0.0f, 0.3f, 0.4f);
  cr_assert_eq(bb_normal_map_decode(&v, 1, 0, 1, &n, NULL), BB_OK);
  cr_assert_float_eq(bb_image_texel(&n, 0, 0)[1], 0.6, 1e-7);
  bb_image_free(&n);
  bb_image_free(&v);
}

Test(convert, bad_inputs_are_refused) {
  bb_image grey = image(3, 3, 1), v = image(3, 3, 3), n;
  bb_error err;
  cr_assert_eq(bb_normal_map_decode(&grey, 0, 0, 1, &n, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "1 channel"), "%s", err.message);
  cr_assert_null(n.pixels);
  cr_assert_eq(bb__ssbump_to_normal(&grey, BB_MAP_SSBUMP, &n, &err), BB_ERR_ARGUMENT);
  bb_image_texel(&v, 2, 1)[1] = NAN;
  cr_assert_eq(bb_normal_map_decode(&v, 1, 0, 1, &n, &err), BB_ERR_VALUE);
  cr_assert(strstr(err.message, "(2, 1)"), "%s", err.message);
  cr_assert_eq(bb__ssbump_to_normal(&v, BB_MAP_SSBUMP, &n, &err), BB_ERR_VALUE);
  cr_assert_eq(bb__ssbump_to_normal(&v, (bb_map_kind)7, &n, &err), BB_ERR_ARGUMENT);
  bb_image_free(&grey);
  bb_image_free(&v);
}

/* height -> normal -> normal2ssbump (decode + weights) equals the bake's own
 * weights: the file round trip is in test_cli_convert.c. */
Test(convert, normal2ssbump_of_a_baked_normal_is_the_baked_weights) {
  bb_image h = gentle_height(40, 24);
  for (int i = 0; i < 40 * 24; i++) /* steeper here: some N.B_c < 0 too */
    h.pixels[i] = (float)(h.pixels[i] + 0.3 * sin(i * 0.7));
  bb_bake_result r = bake(&h, 24.0f);
  bb_image n, w;
  cr_assert_eq(bb_normal_map_decode(&r.normal, 1, 0, 1, &n, NULL), BB_OK);
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &w, NULL), BB_OK);
  double d = max_difference(&w, &r.weights);
  cr_assert_lt(d, 1e-5, "weights differ by %g", d);
  bb_image_free(&w);
  bb_image_free(&n);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* The paper's formula gives back the normal of an unoccluded bake. */
Test(convert, ssbump2normal_of_an_unoccluded_bake_is_its_normal) {
  bb_image h = gentle_height(48, 32);
  /* Exact horizons see any crest above the ray origin, however low: with a
   * bias over the field's 1-texel relief nothing is. */
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 2.0f;
  o.rays = 64;
  o.trace.bias_texels = 1.5;
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_OK, "%s", err.message);
  for (int i = 0; i < 48 * 32; i++)
    cr_assert_eq(r.ao.pixels[i], 1.0f, "texel %d is occluded: not the case under test",
                 i);
  bb_image n;
  cr_assert_eq(bb__ssbump_to_normal(&r.ssbump, BB_MAP_SSBUMP, &n, &err), BB_OK, "%s",
               err.message);
  double d = max_difference(&n, &r.normal);
  cr_assert_lt(d, 1e-3, "normal differs by %g", d);
  cr_assert_lt(d, 1e-5, "all N.B_c > 0 here, so the sum is exact: %g", d);
  bb_image_free(&n);

  /* The weights need their square root first. */
  cr_assert_eq(bb__ssbump_to_normal(&r.weights, BB_MAP_WEIGHTS, &n, NULL), BB_OK);
  d = max_difference(&n, &r.normal);
  cr_assert_lt(d, 1e-5, "normal from weights differs by %g", d);
  bb_image_free(&n);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* A fourth channel (Valve's alpha height) is not a basis weight. */
Test(convert, ssbump_alpha_is_ignored) {
  bb_image s3 = image(2, 2, 3), s4 = image(2, 2, 4);
  for (int i = 0; i < 4; i++) {
    float v[4] = {0.7f, 0.2f, 0.4f, (float)i / 3.0f};
    memcpy(s3.pixels + 3 * i, v, 3 * sizeof(float));
    memcpy(s4.pixels + 4 * i, v, 4 * sizeof(float));
  }
  bb_image n3, n4;
  cr_assert_eq(bb__ssbump_to_normal(&s3, BB_MAP_SSBUMP, &n3, NULL), BB_OK);
  cr_assert_eq(bb__ssbump_to_normal(&s4, BB_MAP_SSBUMP, &n4, NULL), BB_OK);
  cr_assert_eq(memcmp(n3.pixels, n4.pixels, 12 * sizeof(float)), 0);
  /* Flat in, flat out; the weights' flat too. */
  for (int i = 0; i < 12; i++)
    s3.pixels[i] = (float)(1.0 / sqrt(3.0));
  bb_image_free(&n3);
  cr_assert_eq(bb__ssbump_to_normal(&s3, BB_MAP_SSBUMP, &n3, NULL), BB_OK);
  for (int i = 0; i < 4; i++) {
    cr_assert_float_eq(n3.pixels[3 * i], 0.0, 1e-7);
    cr_assert_float_eq(n3.pixels[3 * i + 1], 0.0, 1e-7);
    cr_assert_float_eq(n3.pixels[3 * i + 2], 1.0, 1e-7);
  }
  bb_image_free(&n3);
  bb_image_free(&n4);
  bb_image_free(&s3);
  bb_image_free(&s4);
}
