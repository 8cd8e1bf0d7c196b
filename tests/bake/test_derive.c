/* test_derive.c: the Half-Life 2 basis vectors and the weights, ssbump, ao and bent maps
 * (other bases: test_basis.c). */
#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bumpbake.h"
#include "bake/bake_internal.h"
#include "trace/basis.h"

/* An image of `count` texels, every texel set to the same values. */
static void make_uniform(bb_image *img, int count, int channels, const float *values) {
  cr_assert_eq(bb_image_alloc(img, count, 1, channels, NULL), BB_OK);
  for (int i = 0; i < count; i++)
    memcpy(img->pixels + (size_t)i * (size_t)channels, values,
           (size_t)channels * sizeof(float));
}

static void set_normal(bb_image *n, int i, double x, double y, double z) {
  double len = sqrt(x * x + y * y + z * z);
  n->pixels[3 * i] = (float)(x / len);
  n->pixels[3 * i + 1] = (float)(y / len);
  n->pixels[3 * i + 2] = (float)(z / len);
}

static double dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The vectors of docs/conventions.md, unit length, the first three 120 degrees apart
 * around z at the same elevation, and oriented in the +Y-down frame. */
Test(derive, basis_vectors) {
  double b[4][3];
  for (int c = 0; c < 4; c++) {
    bb__basis_vector(c, b[c]);
    cr_assert_float_eq(dot(b[c], b[c]), 1.0, 1e-15, "B%d not unit", c);
  }
  cr_assert_float_eq(b[0][0], sqrt(2.0 / 3.0), 1e-15);
  cr_assert_eq(b[0][1], 0.0);
  for (int c = 0; c < 3; c++)
    cr_assert_float_eq(b[c][2], 1.0 / sqrt(3.0), 1e-15);
  cr_assert_float_eq(b[1][0], -1.0 / sqrt(6.0), 1e-15);
  cr_assert_float_eq(b[1][1], 1.0 / sqrt(2.0), 1e-15, "B1 lights from the bottom: +y");
  cr_assert_float_eq(b[2][1], -1.0 / sqrt(2.0), 1e-15, "B2 lights from the top: -y");
  cr_assert_float_eq(dot(b[0], b[1]), 0.0, 1e-15, "the HL2 basis is orthonormal");
  cr_assert_float_eq(dot(b[1], b[2]), 0.0, 1e-15);
  cr_assert_float_eq(dot(b[0], b[2]), 0.0, 1e-15);
  cr_assert(b[3][0] == 0.0 && b[3][1] == 0.0 && b[3][2] == 1.0);
}

Test(derive, flat_unoccluded_texel) {
  const float up[3] = {0.0f, 0.0f, 1.0f}, all_visible[5] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
  bb_image n = {0}, vis = {0}, w = {0}, s = {0}, ao = {0}, bent = {0};
  make_uniform(&n, 4, 3, up);
  make_uniform(&vis, 4, 4, all_visible);
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &w, NULL), BB_OK);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis, NULL, &s, NULL), BB_OK);
  cr_assert_eq(bb__derive_ao_all_cores(&vis, &ao, NULL), BB_OK);
  cr_assert_eq(bb__derive_bent_all_cores(&s, NULL, &bent, NULL), BB_OK);
  cr_assert_eq(s.channels, 3);
  cr_assert_eq(ao.channels, 1);
  for (int i = 0; i < 4; i++) {
    for (int c = 0; c < 3; c++) {
      cr_assert_float_eq(w.pixels[3 * i + c], 1.0f / 3.0f, 1e-7f);
      cr_assert_float_eq(s.pixels[3 * i + c], 0.57735027f, 1e-7f);
    }
    cr_assert_eq(ao.pixels[i], 1.0f);
    cr_assert_float_eq(bent.pixels[3 * i], 0.0f, 1e-7f);
    cr_assert_float_eq(bent.pixels[3 * i + 1], 0.0f, 1e-7f);
    cr_assert_float_eq(bent.pixels[3 * i + 2], 1.0f, 1e-7f);
  }
  bb_image_free(&n), bb_image_free(&vis), bb_image_free(&w);
  bb_image_free(&s), bb_image_free(&ao), bb_image_free(&bent);
}

/* With B3 = (0, 0, 1) a flat texel gets 1 in the fourth channel. */
Test(derive, flat_with_z_channel) {
  const float up[3] = {0.0f, 0.0f, 1.0f}, vis5[5] = {0.5f, 1.0f, 1.0f, 1.0f, 0.75f};
  bb_image n = {0}, vis = {0}, s = {0}, bent = {0};
  make_uniform(&n, 1, 3, up);
  make_uniform(&vis, 1, 5, vis5);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis, NULL, &s, NULL), BB_OK);
  cr_assert_eq(s.channels, 4);
  cr_assert_float_eq(s.pixels[3], 0.75f, 1e-7f);
  cr_assert_eq(bb__derive_bent_all_cores(&s, NULL, &bent, NULL), BB_OK);
  cr_assert_float_eq(bent.pixels[2], 1.0f, 1e-7f);
  bb_image_free(&n), bb_image_free(&vis), bb_image_free(&s), bb_image_free(&bent);
}

Test(derive, normal_along_a_basis_vector_takes_all_weight) {
  bb_image n = {0}, w = {0};
  cr_assert_eq(bb_image_alloc(&n, 3, 1, 3, NULL), BB_OK);
  for (int c = 0; c < 3; c++) {
    double b[3];
    bb__basis_vector(c, b);
    set_normal(&n, c, b[0], b[1], b[2]);
  }
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &w, NULL), BB_OK);
  for (int i = 0; i < 3; i++)
    for (int c = 0; c < 3; c++)
      cr_assert_float_eq(w.pixels[3 * i + c], i == c ? 1.0f : 0.0f, 1e-6f,
                         "texel %d ch %d", i, c);
  bb_image_free(&n), bb_image_free(&w);
}

/* Squared and saturated: N = (B0 + B1) / sqrt(2) splits evenly between them,
 * and a normal facing away from every direction falls back to 1/3 each. */
Test(derive, weights_between_and_beyond) {
  double b0[3], b1[3];
  bb__basis_vector(0, b0);
  bb__basis_vector(1, b1);
  bb_image n = {0}, w = {0};
  cr_assert_eq(bb_image_alloc(&n, 2, 1, 3, NULL), BB_OK);
  set_normal(&n, 0, b0[0] + b1[0], b0[1] + b1[1], b0[2] + b1[2]);
  set_normal(&n, 1, 0.0, 0.0, -1.0);
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &w, NULL), BB_OK);
  cr_assert_float_eq(w.pixels[0], 0.5f, 1e-6f);
  cr_assert_float_eq(w.pixels[1], 0.5f, 1e-6f);
  cr_assert_float_eq(w.pixels[2], 0.0f, 1e-6f);
  for (int c = 0; c < 3; c++)
    cr_assert_float_eq(w.pixels[3 + c], 1.0f / 3.0f, 1e-7f);
  bb_image_free(&n), bb_image_free(&w);
}

/* A normal tilted hard to the right faces away from B1 and B2. */
Test(derive, ssbump_is_zero_where_the_normal_faces_away) {
  const float zero[3] = {0.0f, 0.0f, 0.0f}, vis4[4] = {0.3f, 0.9f, 0.8f, 0.7f};
  bb_image n = {0}, vis = {0}, s = {0};
  make_uniform(&n, 1, 3, zero);
  set_normal(&n, 0, 1.0, 0.0, 0.2);
  make_uniform(&vis, 1, 4, vis4);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis, NULL, &s, NULL), BB_OK);
  double b0[3];
  bb__basis_vector(0, b0);
  double n0[3] = {n.pixels[0], n.pixels[1], n.pixels[2]};
  cr_assert_float_eq(s.pixels[0], dot(n0, b0) * 0.9, 1e-6, "vis_0 is channel 1 of vis");
  cr_assert_eq(s.pixels[1], 0.0f);
  cr_assert_eq(s.pixels[2], 0.0f);
  bb_image_free(&n), bb_image_free(&vis), bb_image_free(&s);
}

/* Light through one basis direction only bends the normal onto it. */
Test(derive, bent_of_a_single_light_follows_its_basis_vector) {
  bb_image s = {0}, bent = {0};
  cr_assert_eq(bb_image_alloc(&s, 4, 1, 4, NULL), BB_OK);
  for (int c = 0; c < 4; c++)
    s.pixels[4 * c + c] = 0.4f;
  cr_assert_eq(bb__derive_bent_all_cores(&s, NULL, &bent, NULL), BB_OK);
  for (int c = 0; c < 4; c++) {
    double b[3];
    bb__basis_vector(c, b);
    for (int k = 0; k < 3; k++)
      cr_assert_float_eq(bent.pixels[3 * c + k], b[k], 1e-6, "light %d axis %d", c, k);
  }
  bb_image_free(&s), bb_image_free(&bent);
}

Test(derive, bent_of_a_dark_texel_is_straight_up) {
  const float dark[3] = {0.0f, 0.0f, 0.0f};
  bb_image s = {0}, bent = {0};
  make_uniform(&s, 2, 3, dark);
  cr_assert_eq(bb__derive_bent_all_cores(&s, NULL, &bent, NULL), BB_OK);
  for (int i = 0; i < 2; i++)
    cr_assert(bent.pixels[3 * i] == 0.0f && bent.pixels[3 * i + 1] == 0.0f &&
              bent.pixels[3 * i + 2] == 1.0f);
  bb_image_free(&s), bb_image_free(&bent);
}

Test(derive, ao_is_channel_zero) {
  bb_image vis = {0}, ao = {0};
  cr_assert_eq(bb_image_alloc(&vis, 3, 2, 4, NULL), BB_OK);
  for (int i = 0; i < 6; i++)
    for (int c = 0; c < 4; c++)
      vis.pixels[4 * i + c] = (float)(0.1 * i + 0.01 * c);
  cr_assert_eq(bb__derive_ao_all_cores(&vis, &ao, NULL), BB_OK);
  cr_assert_eq(ao.width, 3);
  cr_assert_eq(ao.height, 2);
  for (int i = 0; i < 6; i++)
    cr_assert_eq(ao.pixels[i], vis.pixels[4 * i]);
  bb_image_free(&vis), bb_image_free(&ao);
}

/* Deterministic pseudo-random numbers in [0, 1) (64-bit LCG, high bits). */
static double next_random(uint64_t *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) * (1.0 / 9007199254740992.0);
}

static int same_bits(float a, float b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

/* The maps on many rows (they run row by row on all cores) against direct
 * per-texel formulas, bit for bit; one normal is NaN, which ssbump maps to 0
 * as fmax does (a bake's normals never are; bb__derive_weights_all_cores refuses a
 * caller's, so its weights are derived before the NaN is put in). */
static void check_maps_against_formulas(int count) {
  const int w = 37, h = 29, texels = w * h;
  bb_image n = {0}, vis = {0}, wt = {0}, s = {0}, ao = {0}, bent = {0};
  uint64_t state = 21;
  cr_assert_eq(bb_image_alloc(&n, w, h, 3, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&vis, w, h, 1 + count, NULL), BB_OK);
  for (int i = 0; i < texels; i++) {
    set_normal(&n, i, 2.0 * next_random(&state) - 1.0, 2.0 * next_random(&state) - 1.0,
               next_random(&state) - 0.2);
    for (int c = 0; c <= count; c++)
      vis.pixels[(1 + count) * i + c] = (float)next_random(&state);
  }
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &wt, NULL), BB_OK);
  const float normal_x_100 = n.pixels[3 * 100];
  n.pixels[3 * 100] = NAN;
  bb_image refused = {0};
  bb_error e = {{0}};
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &refused, &e), BB_ERR_VALUE);
  cr_assert(strstr(e.message, "texel (26, 2) channel 0 is NaN") != NULL, "%s", e.message);
  cr_assert_null(refused.pixels);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis, NULL, &s, NULL), BB_OK);
  cr_assert_eq(bb__derive_ao_all_cores(&vis, &ao, NULL), BB_OK);
  cr_assert_eq(bb__derive_bent_all_cores(&s, NULL, &bent, NULL), BB_OK);
  double b[4][3];
  for (int c = 0; c < count; c++)
    bb__basis_vector(c, b[c]);
  for (int i = 0; i < texels; i++) {
    const float *ni = n.pixels + 3 * i, *vi = vis.pixels + (1 + count) * i;
    double d[4], wsum = 0.0, bv[3] = {0.0, 0.0, 0.0};
    const double x = i == 100 ? (double)normal_x_100 : (double)ni[0]; /* weights' */
    for (int c = 0; c < count; c++)
      d[c] = x * b[c][0] + (double)ni[1] * b[c][1] + (double)ni[2] * b[c][2];
    for (int c = 0; c < 3; c++) {
      double sat = d[c] < 0.0 ? 0.0 : (d[c] > 1.0 ? 1.0 : d[c]);
      wsum += sat * sat;
    }
    for (int c = 0; c < 3; c++) {
      double sat = d[c] < 0.0 ? 0.0 : (d[c] > 1.0 ? 1.0 : d[c]);
      float want = (float)(wsum > 0.0 ? sat * sat / wsum : 1.0 / 3.0);
      cr_assert(same_bits(wt.pixels[3 * i + c], want), "weights texel %d", i);
    }
    for (int c = 0; c < count; c++) /* ssbump's, with the NaN */
      d[c] = (double)ni[0] * b[c][0] + (double)ni[1] * b[c][1] + (double)ni[2] * b[c][2];
    for (int c = 0; c < count; c++) {
      float want = (float)(fmax(0.0, d[c]) * (double)vi[1 + c]);
      cr_assert(same_bits(s.pixels[count * i + c], want), "ssbump texel %d", i);
      for (int k = 0; k < 3; k++)
        bv[k] += (double)want * b[c][k];
    }
    cr_assert(same_bits(ao.pixels[i], vi[0]), "ao texel %d", i);
    double len = sqrt(bv[0] * bv[0] + bv[1] * bv[1] + bv[2] * bv[2]);
    for (int k = 0; k < 3; k++) {
      float want = len > 0.0 ? (float)(bv[k] / len) : (k == 2 ? 1.0f : 0.0f);
      cr_assert(same_bits(bent.pixels[3 * i + k], want), "bent texel %d", i);
    }
  }
  cr_assert_eq(s.pixels[count * 100], 0.0f, "a NaN normal lights nothing");
  bb_image_free(&n), bb_image_free(&vis), bb_image_free(&wt);
  bb_image_free(&s), bb_image_free(&ao), bb_image_free(&bent);
}

Test(derive, maps_match_per_texel_formulas_bit_for_bit) {
  check_maps_against_formulas(3);
  check_maps_against_formulas(4);
}

Test(derive, rejects_mismatched_inputs) {
  bb_image n = {0}, n_small = {0}, vis = {0}, vis2 = {0}, s2 = {0}, out = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&n, 4, 4, 3, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&n_small, 4, 3, 3, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&vis, 4, 4, 4, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&vis2, 4, 4, 2, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&s2, 4, 4, 2, NULL), BB_OK);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n_small, &vis, NULL, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "4x3") != NULL, "%s", err.message);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis2, NULL, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__derive_ssbump_all_cores(&vis, &vis, NULL, &out, &err), BB_ERR_ARGUMENT,
               "normals need 3 channels");
  cr_assert_eq(bb__derive_weights_all_cores(&vis, NULL, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &n, &err), BB_ERR_ARGUMENT, "output aliases input");
  cr_assert_eq(bb__derive_bent_all_cores(&s2, NULL, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__derive_ao_all_cores(NULL, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_null(out.pixels);
  cr_assert_not_null(n.pixels);
  bb_image_free(&n), bb_image_free(&n_small), bb_image_free(&vis);
  bb_image_free(&vis2), bb_image_free(&s2);
}
