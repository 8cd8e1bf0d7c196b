/* test_split_bake.c: a bake whose trace is the caller's (bb_trace_options.trace)
 * and done by a split trace over its own copy of the trace's input
 * (bb__bake_trace_input) makes every map of a plain bake, bit for bit. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "bumpbake_cluster.h"
#include "trace/basis.h"

static bb_image bumps(int w, int h) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      img.pixels[y * w + x] = (float)(0.5 + 0.3 * sin(0.7 * x) * cos(0.45 * y) +
                                      0.2 * sin(0.05 * x * y));
  return img;
}

/* What the hook is given: the height, to build the trace's input anew as
 * another process would, and the options. */
typedef struct split_user {
  const bb_image *height;
  const bb_bake_options *options;
  int calls;
} split_user;

/* Each slice's horizons found alone (one "worker" per slice), from a pyramid
 * built apart from the bake's, then added up by rank. */
static bb_status split_trace(void *user, const bb_pyramid *p, const bb_rayset *rs,
                             const bb_trace_options *o, bb_image *vis, bb_error *err) {
  split_user *u = user;
  u->calls++;
  (void)p;
  bb_pyramid *mine = NULL;
  bb_rayset *my_rays = NULL;
  bb_status st = bb__bake_trace_input(u->height, u->options, &mine, &my_rays, err);
  if (st != BB_OK) return st;
  cr_assert_str_eq(bb_rayset_id(my_rays), bb_rayset_id(rs));
  const int n = bb_rayset_slice_count(my_rays);
  int order[256];
  cr_assert_eq(bb_trace_slice_order(my_rays, order, err), BB_OK);
  bb_trace_options mine_o = *o;
  mine_o.threads = 1;
  for (int k = 0; k < n && st == BB_OK; k++) {
    bb_image h;
    st = bb_trace_horizons(mine, my_rays, &mine_o, &order[k], 1, &h, err);
    if (st == BB_OK && k == 0)
      st = bb_image_alloc(vis, h.width, h.height, 1 + bb_rayset_lobe_count(my_rays), err);
    if (st == BB_OK) st = bb_trace_accumulate(my_rays, k, &h, vis, 2, err);
    bb_image_free(&h);
  }
  if (st == BB_OK) st = bb_trace_finish(my_rays, vis, 2, err);
  bb_pyramid_free(mine);
  bb_rayset_free(my_rays);
  return st;
}

static void assert_same(const bb_image *a, const bb_image *b, const char *what) {
  cr_assert_eq(a->pixels != NULL, b->pixels != NULL, "%s made by one bake only", what);
  if (!a->pixels) return;
  cr_assert(a->width == b->width && a->height == b->height && a->channels == b->channels, "%s",
            what);
  cr_assert(memcmp(a->pixels, b->pixels,
                   (size_t)a->width * (size_t)a->height * (size_t)a->channels * 4) == 0,
            "%s differs", what);
}

Test(split_bake, the_callers_split_trace_makes_the_bakes_bits) {
  /* the last with inter-reflection, which the bake adds to the vis the
   * hook made (bounce.c, on the bake's own pyramid) */
  const struct {
    int w, h, slices;
    bb_addressing a;
    const char *basis;
    double bounce;
  } cases[] = {{45, 38, 8, BB_ADDRESS_PERIODIC, "hl2", 0.0},
               {45, 38, 16, BB_ADDRESS_CLAMP, "dirs:6", 0.0},
               {31, 50, 5, BB_ADDRESS_PERIODIC, "hl2+z", 0.0},
               {40, 36, 8, BB_ADDRESS_PERIODIC, "hl2", 0.6}};
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    bb_image height = bumps(cases[c].w, cases[c].h);
    bb_bake_options o;
    bb__bake_options_init(&o);
    o.height_scale = 9.0f;
    o.slices = cases[c].slices;
    o.smooth.addressing = cases[c].a;
    o.bounce_albedo = cases[c].bounce;
    cr_assert_eq(bb__basis_parse(cases[c].basis, &o.basis, NULL), BB_OK);
    bb_bake_result plain, split;
    bb_error err;
    cr_assert_eq(bb__bake_checked(&height, &o, &plain, &err), BB_OK, "%s", err.message);
    split_user u = {&height, &o, 0};
    bb_bake_options with_hook = o;
    with_hook.trace.trace = split_trace;
    with_hook.trace.trace_user = &u;
    cr_assert_eq(bb__bake_checked(&height, &with_hook, &split, &err), BB_OK, "%s", err.message);
    cr_assert_eq(u.calls, 1);
    cr_assert_eq(plain.bounces > 0, cases[c].bounce > 0.0, "bounces %d", plain.bounces);
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      assert_same(bb__bake_result_image(&plain, (bb_map_kind)k),
                  bb__bake_result_image(&split, (bb_map_kind)k),
                  bb_map_kind_get((bb_map_kind)k)->name);
    assert_same(&plain.vis, &split.vis, "vis");
    cr_assert_eq(plain.horizons_found, split.horizons_found);
    cr_assert_str_eq(plain.rayset_id, split.rayset_id);
    bb_bake_result_free(&plain);
    bb_bake_result_free(&split);
    bb_image_free(&height);
  }
}

static bb_status wrong_size(void *user, const bb_pyramid *p, const bb_rayset *rs,
                            const bb_trace_options *o, bb_image *vis, bb_error *err) {
  (void)user, (void)p, (void)o;
  return bb_image_alloc(vis, 3, 3, 1 + bb_rayset_lobe_count(rs), err);
}

static bb_status failing(void *user, const bb_pyramid *p, const bb_rayset *rs,
                         const bb_trace_options *o, bb_image *vis, bb_error *err) {
  (void)user, (void)p, (void)rs, (void)o, (void)vis;
  snprintf(err->message, sizeof err->message, "worker tcp://10.0.0.2 lost");
  return BB_ERR_IO;
}

Test(split_bake, a_trace_that_fails_or_makes_the_wrong_image_fails_the_bake) {
  bb_image height = bumps(20, 20);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 4.0f;
  o.trace.trace = wrong_size;
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&height, &o, &r, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "made no 20x20 image of 4 channels"), "%s", err.message);
  cr_assert_null(r.normal.pixels);
  o.trace.trace = failing;
  cr_assert_eq(bb__bake_checked(&height, &o, &r, &err), BB_ERR_IO);
  cr_assert(strstr(err.message, "worker tcp://10.0.0.2 lost"), "%s", err.message);
  o.trace.trace = NULL;
  o.outputs = BB_MAP_BIT(BB_MAP_NORMAL);
  bb_pyramid *p;
  bb_rayset *rs;
  cr_assert_eq(bb__bake_trace_input(&height, &o, &p, &rs, &err), BB_ERR_ARGUMENT,
               "a bake of normals alone traces nothing");
  bb_image_free(&height);
}
