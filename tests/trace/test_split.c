/* test_split.c: a trace split over processes (bb_trace_horizons,
 * bb_trace_accumulate, bb_trace_finish) against the whole trace, bit for
 * bit, whatever the split of the slices and the order the horizons were
 * found in. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bumpbake.h"
#include "bumpbake_cluster.h"
#include "trace/basis.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/trace.h"

static uint64_t rng_state;
static double rnd(void) {
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

/* Rough noise over smooth bumps, in texels: horizons of every size. */
static bb_image field(int w, int h, float scale) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  const double ph = rnd() * 6.28;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      img.pixels[y * w + x] =
          (float)(scale * (0.5 + 0.3 * sin(6.283 * 2 * x / w + ph) * cos(6.283 * y / h) +
                           0.2 * rnd()));
  return img;
}

typedef struct setup {
  bb_pyramid *p;
  bb_rayset *rs;
  bb_trace_options o;
} setup;

static setup make_setup(const bb_image *z, bb_addressing a, int slices, const char *basis) {
  setup s = {0};
  bb_error err;
  bb_basis b;
  cr_assert_eq(bb__basis_parse(basis, &b, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__pyramid_build_all_cores(z, a, &s.p, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__rayset_new(slices, 1.0, &b, &s.rs, &err), BB_OK, "%s", err.message);
  bb__trace_options_init(&s.o);
  s.o.threads = 2;
  return s;
}

static void free_setup(setup *s) {
  bb_pyramid_free(s->p);
  bb_rayset_free(s->rs);
}

/* The split trace: the slices dealt to `parts` workers by `deal` (0: ranks
 * in turn, 1: contiguous runs of ranks, 2: at random), each worker's
 * horizons found in one call with its slices in a shuffled order, then
 * added up by rank and finished. */
static bb_image split_trace(const setup *s, int parts, int deal) {
  const int n = bb_rayset_slice_count(s->rs);
  int order[256], owner[256];
  bb_error err;
  cr_assert_eq(bb_trace_slice_order(s->rs, order, &err), BB_OK, "%s", err.message);
  for (int k = 0; k < n; k++)
    owner[k] = deal == 0 ? k % parts : deal == 1 ? k * parts / n : (int)(rnd() * parts);
  bb_image *horizon_of_rank = calloc((size_t)n, sizeof(bb_image));
  for (int w = 0; w < parts; w++) {
    int slices[256], ranks[256], count = 0;
    for (int k = 0; k < n; k++)
      if (owner[k] == w) ranks[count++] = k;
    for (int i = count - 1; i > 0; i--) { /* the worker asks in any order */
      const int j = (int)(rnd() * (i + 1)), t = ranks[i];
      ranks[i] = ranks[j], ranks[j] = t;
    }
    for (int i = 0; i < count; i++) slices[i] = order[ranks[i]];
    bb_image *h = calloc((size_t)count + 1, sizeof(bb_image));
    cr_assert_eq(bb_trace_horizons(s->p, s->rs, &s->o, slices, count, h, &err), BB_OK, "%s",
                 err.message);
    for (int i = 0; i < count; i++) horizon_of_rank[ranks[i]] = h[i];
    free(h);
  }
  bb_image sums;
  cr_assert_eq(bb_image_alloc(&sums, horizon_of_rank[0].width, horizon_of_rank[0].height,
                              1 + bb_rayset_lobe_count(s->rs), &err),
               BB_OK);
  for (int k = 0; k < n; k++) {
    cr_assert_eq(bb_trace_accumulate(s->rs, k, &horizon_of_rank[k], &sums, 1 + k % 2, &err),
                 BB_OK, "%s", err.message);
    bb_image_free(&horizon_of_rank[k]);
  }
  free(horizon_of_rank);
  cr_assert_eq(bb_trace_finish(s->rs, &sums, 2, &err), BB_OK, "%s", err.message);
  return sums;
}

static void assert_same_bits(const bb_image *a, const bb_image *b, const char *what) {
  cr_assert_eq(a->width, b->width);
  cr_assert_eq(a->height, b->height);
  cr_assert_eq(a->channels, b->channels);
  const size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
  size_t differ = 0;
  for (size_t i = 0; i < n; i++) differ += memcmp(&a->pixels[i], &b->pixels[i], 4) != 0;
  cr_assert_eq(differ, 0, "%s: %zu of %zu floats differ", what, differ, n);
}

Test(split, any_split_of_the_slices_gives_the_whole_trace_bit_for_bit) {
  /* sizes that are not powers of two, both addressings, 1..16 slices (odd
   * counts leave a slice without its opposite), Half-Life 2's basis, hl2+z
   * and six directions (more than 4 lobes: the out-of-line sums) */
  const int sizes[][2] = {{37, 29}, {50, 50}, {64, 23}, {97, 61}};
  const int slices[] = {1, 3, 8, 16};
  const char *bases[] = {"hl2", "hl2+z", "dirs:6"};
  rng_state = 0x2545F4914F6CDD1DULL;
  int cases = 0, positive = 0;
  for (int a = 0; a < 2; a++)
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++)
      for (size_t ni = 0; ni < sizeof slices / sizeof slices[0]; ni++) {
        const char *basis = bases[(si + ni) % 3];
        bb_image z = field(sizes[si][0], sizes[si][1], 12.0f);
        setup s = make_setup(&z, a ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC, slices[ni], basis);
        bb_image whole;
        bb_error err;
        cr_assert_eq(bb__trace_occlusion(s.p, s.rs, &s.o, &whole, NULL, &err), BB_OK, "%s",
                     err.message);
        for (int deal = 0; deal < 3; deal++) {
          bb_image split = split_trace(&s, 1 + (deal + (int)ni) % 3, deal);
          assert_same_bits(&whole, &split, basis);
          bb_image_free(&split);
          cases++;
        }
        /* the fields shadow: not a test of ones */
        for (int i = 0; i < z.width * z.height; i++) positive += whole.pixels[i * whole.channels] < 1.0f;
        bb_image_free(&whole);
        free_setup(&s);
        bb_image_free(&z);
      }
  cr_assert_eq(cases, 2 * 4 * 4 * 3);
  cr_assert_gt(positive, 1000, "few texels are occluded: the test compares little");
}

Test(split, horizons_are_what_every_trace_adds) {
  /* A slice's horizons, added alone to zero sums and finished, give that
   * one-slice trace; and horizons are never negative or NaN. */
  rng_state = 7;
  bb_image z = field(40, 33, 8.0f);
  setup s = make_setup(&z, BB_ADDRESS_PERIODIC, 8, "hl2");
  bb_error err;
  int order[8];
  cr_assert_eq(bb_trace_slice_order(s.rs, order, &err), BB_OK);
  for (int k = 0; k < 8; k++) /* each slice followed by its opposite */
    cr_assert(k % 2 == 0 || order[k] == (order[k - 1] + 4) % 8, "order %d: %d", k, order[k]);
  bb_image h[8];
  cr_assert_eq(bb_trace_horizons(s.p, s.rs, &s.o, order, 8, h, &err), BB_OK, "%s", err.message);
  for (int k = 0; k < 8; k++)
    for (int i = 0; i < 40 * 33; i++) cr_assert(h[k].pixels[i] >= 0.0f, "slice %d", order[k]);
  for (int k = 0; k < 8; k++) bb_image_free(&h[k]);
  free_setup(&s);
  bb_image_free(&z);
}

Test(split, refuses_what_it_cannot_do) {
  rng_state = 11;
  bb_image z = field(20, 20, 4.0f);
  setup s = make_setup(&z, BB_ADDRESS_PERIODIC, 4, "hl2");
  bb_error err;
  bb_image h[2], sums;
  const int twice[] = {1, 1}, outside[] = {4}, one[] = {0};
  cr_assert_eq(bb_trace_horizons(s.p, s.rs, &s.o, twice, 2, h, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "asked twice"), "%s", err.message);
  cr_assert_null(h[0].pixels);
  cr_assert_eq(bb_trace_horizons(s.p, s.rs, &s.o, outside, 1, h, &err), BB_ERR_ARGUMENT);
  s.o.region = (bb_region){0, 0, 4, 4};
  cr_assert_eq(bb_trace_horizons(s.p, s.rs, &s.o, one, 1, h, &err), BB_ERR_ARGUMENT);
  s.o.region = (bb_region){0, 0, 0, 0};
  cr_assert_eq(bb_trace_horizons(s.p, s.rs, &s.o, one, 1, h, &err), BB_OK);
  cr_assert_eq(bb_image_alloc(&sums, 20, 20, 3, &err), BB_OK);
  cr_assert_eq(bb_trace_accumulate(s.rs, 0, &h[0], &sums, 0, &err), BB_ERR_ARGUMENT,
               "3 channels for hl2's 1 + 3");
  bb_image_free(&sums);
  cr_assert_eq(bb_image_alloc(&sums, 20, 20, 4, &err), BB_OK);
  cr_assert_eq(bb_trace_accumulate(s.rs, 4, &h[0], &sums, 0, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "rank 4"), "%s", err.message);
  cr_assert_eq(bb_trace_accumulate(s.rs, 0, &h[0], &sums, 0, &err), BB_OK);
  bb_image_free(&sums);
  bb_image_free(&h[0]);
  free_setup(&s);
  bb_image_free(&z);
}
