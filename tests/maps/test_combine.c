/* test_combine.c: blending and detail overlays of ssbump, weights, ao and
 * normal maps: identities bit for bit, formulas on hand-made texels. */
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bumpbake.h"
#include "core/internal.h"
#include "maps/maps_internal.h"

static bb_image noise_map(int w, int h, int channels, unsigned seed, float lo, float hi) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  unsigned s = seed;
  for (size_t i = 0; i < (size_t)w * (size_t)h * (size_t)channels; i++) {
    s = s * 1664525u + 1013904223u;
    img.pixels[i] = lo + (hi - lo) * (float)(s >> 8) / (float)(1u << 24);
  }
  return img;
}

static bb_image uniform(int w, int h, int channels, const float *texel) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int i = 0; i < w * h; i++)
    memcpy(img.pixels + i * channels, texel, (size_t)channels * sizeof(float));
  return img;
}

static void normalise_all(bb_image *n) {
  for (int i = 0; i < n->width * n->height; i++) {
    float *t = n->pixels + 3 * i;
    t[2] = fabsf(t[2]) + 0.5f;
    float len = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int k = 0; k < 3; k++)
      t[k] /= len;
  }
}

static int same_bits(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         memcmp(a->pixels, b->pixels,
                (size_t)a->width * (size_t)a->height * (size_t)a->channels *
                    sizeof(float)) == 0;
}

Test(combine, kind_names) {
  bb_map_kind k = BB_MAP_AO;
  cr_assert_eq(bb__map_kind_parse("normal", &k, NULL), 0);
  cr_assert_eq(k, BB_MAP_NORMAL);
  cr_assert_eq(bb__map_kind_parse("Weights", &k, NULL), 0);
  cr_assert_eq(k, BB_MAP_WEIGHTS);
  cr_assert_neq(bb__map_kind_parse("height", &k, NULL), 0);
  cr_assert_eq(k, BB_MAP_WEIGHTS, "a failed parse must not write");
  cr_assert_str_eq(bb__map_kind_name(BB_MAP_SSBUMP), "ssbump");
  cr_assert_eq(bb_map_kind_get(BB_MAP_AO)->file_channels, 1);
  cr_assert_eq(bb_map_kind_get(BB_MAP_NORMAL)->file_channels, 3);
}

Test(combine, flat_texels_as_files_hold_them) {
  float t[3];
  bb__map_flat_texel(BB_MAP_SSBUMP, 8, 0, t);
  cr_assert_eq(t[0], 147.0f / 255.0f);
  bb__map_flat_texel(BB_MAP_SSBUMP, 16, 0, t);
  cr_assert_eq(t[2], (float)(37837.0 / 65535.0)); /* 0.57735 * 65535 = 37837.0 */
  bb__map_flat_texel(BB_MAP_SSBUMP, 32, 1, t);
  cr_assert_eq(t[1], (float)(1.0 / sqrt(3.0)));
  bb__map_flat_texel(BB_MAP_SSBUMP, 16, 1, t);
  cr_assert_eq(t[0], 1182.0f / 2048.0f, "half: 11 significant bits, got %.9g",
               (double)t[0]);
  bb__map_flat_texel(BB_MAP_WEIGHTS, 8, 0, t);
  cr_assert_eq(t[0], 85.0f / 255.0f);
  bb__map_flat_texel(BB_MAP_AO, 8, 0, t);
  cr_assert_eq(t[0], 1.0f);
  bb__map_flat_texel(BB_MAP_NORMAL, 8, 0, t);
  cr_assert_float_eq(t[0], 1.0 / 255.0, 1e-7, "code 128 decodes to +1/255");
  cr_assert_eq(t[2], 1.0f);
  bb__map_flat_texel(BB_MAP_NORMAL, 32, 1, t);
  cr_assert(t[0] == 0.0f && t[1] == 0.0f && t[2] == 1.0f);
}

Test(combine, blend_end_points_are_bit_exact) {
  bb_image a = noise_map(17, 11, 4, 1, 0.0f, 1.0f),
           b = noise_map(17, 11, 4, 2, 0.0f, 1.0f);
  bb_image zero_mask = uniform(17, 11, 1, (const float[]){0.0f}), out;
  cr_assert_eq(bb__combine_blend(&a, &b, NULL, 0.0f, BB_MAP_SSBUMP, &out, NULL), BB_OK);
  cr_assert(same_bits(&out, &a), "mix 0 must give the first map bit for bit");
  bb_image_free(&out);
  cr_assert_eq(bb__combine_blend(&a, &b, &zero_mask, 0.7f, BB_MAP_SSBUMP, &out, NULL),
               BB_OK);
  cr_assert(same_bits(&out, &a), "a zero mask must give the first map bit for bit");
  bb_image_free(&out);
  cr_assert_eq(bb__combine_blend(&a, &b, NULL, 1.0f, BB_MAP_WEIGHTS, &out, NULL), BB_OK);
  cr_assert(same_bits(&out, &b));
  bb_image_free(&out);

  bb_image na = noise_map(17, 11, 3, 3, -1.0f, 1.0f),
           nb = noise_map(17, 11, 3, 4, -1.0f, 1.0f);
  normalise_all(&na);
  normalise_all(&nb);
  cr_assert_eq(bb__combine_blend(&na, &nb, &zero_mask, 0.5f, BB_MAP_NORMAL, &out, NULL),
               BB_OK);
  cr_assert(same_bits(&out, &na), "normals: a zero mask gives the base bit for bit");
  bb_image_free(&out);
  bb_image_free(&na);
  bb_image_free(&nb);
  bb_image_free(&zero_mask);
  bb_image_free(&a);
  bb_image_free(&b);
}

Test(combine, blend_is_linear_for_weights_and_renormalised_for_normals) {
  bb_image a = uniform(3, 2, 3, (const float[]){0.2f, 0.4f, 0.6f});
  bb_image b = uniform(3, 2, 3, (const float[]){1.0f, 0.0f, 0.5f});
  bb_image mask = uniform(3, 2, 1, (const float[]){0.25f}), out;
  cr_assert_eq(bb__combine_blend(&a, &b, &mask, 0.0f, BB_MAP_SSBUMP, &out, NULL), BB_OK);
  cr_assert_float_eq(out.pixels[0], 0.75 * 0.2 + 0.25 * 1.0, 1e-7);
  cr_assert_float_eq(out.pixels[1], 0.75 * 0.4, 1e-7);
  cr_assert_float_eq(out.pixels[2], 0.75 * 0.6 + 0.25 * 0.5, 1e-7);
  bb_image_free(&out);
  /* A mask over 1 is clamped, not extrapolated. */
  mask.pixels[0] = 3.0f;
  cr_assert_eq(bb__combine_blend(&a, &b, &mask, 0.0f, BB_MAP_SSBUMP, &out, NULL), BB_OK);
  cr_assert_eq(out.pixels[0], 1.0f);
  bb_image_free(&out);

  bb_image nx = uniform(2, 2, 3, (const float[]){1.0f, 0.0f, 0.0f});
  bb_image nz = uniform(2, 2, 3, (const float[]){0.0f, 0.0f, 1.0f});
  cr_assert_eq(bb__combine_blend(&nx, &nz, NULL, 0.5f, BB_MAP_NORMAL, &out, NULL), BB_OK);
  cr_assert_float_eq(out.pixels[0], sqrt(0.5), 1e-7, "half way between x and z");
  cr_assert_float_eq(out.pixels[2], sqrt(0.5), 1e-7);
  bb_image_free(&out);
  bb_image_free(&nx);
  bb_image_free(&nz);
  bb_image_free(&mask);
  bb_image_free(&a);
  bb_image_free(&b);
}

Test(combine, flat_detail_leaves_the_base_bit_for_bit) {
  const bb_map_kind kinds[] = {BB_MAP_SSBUMP, BB_MAP_WEIGHTS, BB_MAP_AO, BB_MAP_NORMAL};
  for (int k = 0; k < 4; k++) {
    int channels = kinds[k] == BB_MAP_NORMAL ? 3 : 4; /* alpha rides along */
    bb_image base = noise_map(13, 7, channels, 10u + (unsigned)k, 0.0f, 1.0f), out;
    if (kinds[k] == BB_MAP_NORMAL)
      normalise_all(&base);
    /* The exact flat (flat = NULL) and an 8-bit file's flat. */
    for (int bits = 0; bits <= 8; bits += 8) {
      float flat[3];
      bb__map_flat_texel(kinds[k], bits ? 8 : 32, bits ? 0 : 1, flat);
      bb_image detail = uniform(13, 7, 3, flat);
      cr_assert_eq(
          bb__combine_detail(&base, &detail, kinds[k], bits ? flat : NULL, &out, NULL),
          BB_OK);
      cr_assert(same_bits(&out, &base), "%s, %d-bit flat detail changed the base",
                bb__map_kind_name(kinds[k]), bits ? 8 : 32);
      bb_image_free(&out);
      bb_image_free(&detail);
    }
    bb_image_free(&base);
  }
}

/* base (x) detail = base * detail / flat: visibilities multiply, and a flat
 * base gives the detail back. */
Test(combine, ssbump_detail_multiplies_relative_to_flat) {
  const float f = (float)(1.0 / sqrt(3.0));
  bb_image base = uniform(2, 2, 4, (const float[]){0.5f, 0.25f, f, 0.9f});
  bb_image detail = uniform(2, 2, 3, (const float[]){0.5f * f, f, 2.0f * f}), out;
  cr_assert_eq(bb__combine_detail(&base, &detail, BB_MAP_SSBUMP, NULL, &out, NULL), BB_OK);
  cr_assert_eq(out.channels, 4);
  cr_assert_float_eq(out.pixels[0], 0.25, 1e-7);
  cr_assert_float_eq(out.pixels[1], 0.25, 1e-7);
  cr_assert_float_eq(out.pixels[2], 2.0 * f, 1e-6);
  cr_assert_eq(out.pixels[3], 0.9f, "alpha is copied from the base");
  bb_image_free(&out);

  bb_image flat_base = uniform(2, 2, 3, (const float[]){f, f, f});
  cr_assert_eq(bb__combine_detail(&flat_base, &detail, BB_MAP_SSBUMP, NULL, &out, NULL),
               BB_OK);
  for (int c = 0; c < 3; c++)
    cr_assert_float_eq(out.pixels[c], detail.pixels[c], 1e-7,
                       "flat base (x) detail = detail");
  bb_image_free(&out);
  bb_image_free(&flat_base);
  bb_image_free(&base);
  bb_image_free(&detail);
}

/* DOOM 3's addnormals: base.xy + detail.xy, renormalised. */
Test(combine, normal_detail_is_doom3_addnormals) {
  const double s = sqrt(0.5);
  bb_image base = uniform(1, 1, 3, (const float[]){(float)s, 0.0f, (float)s});
  bb_image detail = uniform(1, 1, 3, (const float[]){0.0f, 0.6f, 0.8f}), out;
  cr_assert_eq(bb__combine_detail(&base, &detail, BB_MAP_NORMAL, NULL, &out, NULL), BB_OK);
  double n[3] = {s, 0.6, s}, len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; k++)
    cr_assert_float_eq(out.pixels[k], n[k] / len, 1e-6);
  bb_image_free(&out);
  /* A base that fades to (0, 0, 0) gets its z rebuilt first, as id does. */
  base.pixels[0] = 0.0f, base.pixels[1] = 0.0f, base.pixels[2] = 0.0f;
  cr_assert_eq(bb__combine_detail(&base, &detail, BB_MAP_NORMAL, NULL, &out, NULL), BB_OK);
  cr_assert_float_eq(out.pixels[1], 0.6 / sqrt(1.36), 1e-6);
  cr_assert_float_eq(out.pixels[2], 1.0 / sqrt(1.36), 1e-6);
  bb_image_free(&out);
  bb_image_free(&base);
  bb_image_free(&detail);
}

Test(combine, mismatches_are_refused) {
  bb_image a = noise_map(4, 4, 3, 1, 0, 1), b = noise_map(5, 4, 3, 2, 0, 1);
  bb_image c4 = noise_map(4, 4, 4, 3, 0, 1), grey = noise_map(4, 4, 1, 4, 0, 1), out;
  bb_error err;
  cr_assert_eq(bb__combine_blend(&a, &b, NULL, 0.5f, BB_MAP_SSBUMP, &out, &err),
               BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "4x4") && strstr(err.message, "5x4"), "%s", err.message);
  cr_assert_null(out.pixels);
  cr_assert_eq(bb__combine_blend(&a, &c4, NULL, 0.5f, BB_MAP_SSBUMP, &out, &err),
               BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "channels"), "%s", err.message);
  cr_assert_eq(bb__combine_blend(&a, &a, NULL, 1.5f, BB_MAP_SSBUMP, &out, &err),
               BB_ERR_ARGUMENT);
  cr_assert_eq(bb__combine_detail(&grey, &a, BB_MAP_SSBUMP, NULL, &out, &err),
               BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "base has 1 channel"), "%s", err.message);
  cr_assert_eq(bb__combine_detail(&a, &b, BB_MAP_NORMAL, NULL, &out, &err),
               BB_ERR_ARGUMENT);
  a.pixels[5] = NAN;
  cr_assert_eq(bb__combine_detail(&a, &a, BB_MAP_AO, NULL, &out, &err), BB_ERR_VALUE);
  bb_image_free(&a);
  bb_image_free(&b);
  bb_image_free(&c4);
  bb_image_free(&grey);
}
