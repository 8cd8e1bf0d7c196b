/* test_rebake.c: bakes through a context that keeps what it made
 * (bb_bake_context_keep) give, after any edit of the height, every map of
 * a whole bake of the new height, bit for bit: single texels, brush
 * strokes, blocks across a border and tall peaks, on periodic and clamped
 * maps, with and without a brightness map, on several thread counts. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "trace/basis.h"

/* A small deterministic generator, so a failure names an edit to replay. */
typedef struct rng {
  unsigned state;
} rng;

static double uniform(rng *r) {
  r->state = r->state * 1103515245u + 12345u;
  return (double)(r->state >> 8) / 16777216.0;
}

static int below(rng *r, int n) {
  return (int)(uniform(r) * n) % n;
}

/* Rough relief: waves, a ridge and noise, so horizons reach far in some
 * directions and stay near in others. */
static bb_image relief(int w, int h, rng *r) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      img.pixels[y * w + x] =
          (float)(0.45 + 0.2 * sin(0.31 * x) * cos(0.23 * y) +
                  0.25 * exp(-pow((x - 0.4 * w) / (0.08 * w), 2.0)) + 0.08 * uniform(r));
  return img;
}

static void maps_equal(const bb_bake_result *got, const bb_bake_result *want,
                       const char *what) {
  const bb_image *a[] = {&got->filtered, &got->normal, &got->weights, &got->vis,
                         &got->ssbump,   &got->ao,     &got->bent};
  const bb_image *b[] = {&want->filtered, &want->normal, &want->weights, &want->vis,
                         &want->ssbump,   &want->ao,     &want->bent};
  const char *names[] = {"filtered", "normal", "weights", "vis", "ssbump", "ao", "bent"};
  for (int i = 0; i < 7; i++) {
    cr_assert_eq(a[i]->pixels != NULL, b[i]->pixels != NULL,
                 "%s: %s made by one bake only", what, names[i]);
    if (!a[i]->pixels)
      continue;
    cr_assert(a[i]->width == b[i]->width && a[i]->height == b[i]->height &&
                  a[i]->channels == b[i]->channels,
              "%s: %s's shape", what, names[i]);
    const size_t n = (size_t)a[i]->width * (size_t)a[i]->height * (size_t)a[i]->channels;
    size_t first = n;
    for (size_t k = 0; k < n && first == n; k++)
      if (memcmp(&a[i]->pixels[k], &b[i]->pixels[k], sizeof(float)) != 0)
        first = k;
    cr_assert_eq(first, n,
                 "%s: %s differs from the whole bake at texel (%zu, %zu): %.9g, not %.9g",
                 what, names[i], first / (size_t)a[i]->channels % (size_t)a[i]->width,
                 first / (size_t)a[i]->channels / (size_t)a[i]->width,
                 (double)a[i]->pixels[first], (double)b[i]->pixels[first]);
  }
}

/* Adds v to texel (x, y), taken round the map's edges. */
static void add_at(bb_image *h, int x, int y, double v) {
  x = ((x % h->width) + h->width) % h->width;
  y = ((y % h->height) + h->height) % h->height;
  h->pixels[(size_t)y * (size_t)h->width + (size_t)x] += (float)v;
}

typedef enum edit_kind {
  EDIT_TEXEL,
  EDIT_STROKE,
  EDIT_BORDER_BLOCK,
  EDIT_PEAK,
  EDIT_DIG
} edit_kind;

/* One edit of the height; returns what it was, for the messages. */
static const char *edit(bb_image *h, edit_kind kind, int clamp, rng *r) {
  const int w = h->width, hh = h->height;
  const int x = below(r, w), y = below(r, hh);
  switch (kind) {
  case EDIT_TEXEL:
    add_at(h, x, y, (uniform(r) - 0.5) * 0.4);
    return "a texel";
  case EDIT_STROKE: { /* a soft brush dragged across */
    const double dx = uniform(r) * 2.0 - 1.0, dy = uniform(r) * 2.0 - 1.0,
                 amount = uniform(r) * 0.1;
    for (int s = 0; s < 24; s++)
      for (int j = -2; j <= 2; j++)
        for (int i = -2; i <= 2; i++)
          add_at(h, x + (int)lround(s * dx) + i, y + (int)lround(s * dy) + j,
                 amount * exp(-(i * i + j * j) / 3.0));
    return "a stroke";
  }
  case EDIT_BORDER_BLOCK: { /* a block set flat, across an edge (clamped: against it) */
    const int side = 5 + below(r, 6), level = below(r, 4);
    int bx = x, by = y;
    if (below(r, 2))
      bx = clamp ? w - side : w - side / 2;
    else
      by = clamp ? 0 : hh - side / 2;
    for (int j = 0; j < side; j++)
      for (int i = 0; i < side; i++) {
        const int X = clamp ? (bx + i < w ? bx + i : w - 1) : (bx + i) % w;
        const int Y = clamp ? (by + j < hh ? by + j : hh - 1) : (by + j) % hh;
        h->pixels[(size_t)Y * (size_t)w + (size_t)X] = (float)(0.2 + 0.25 * level);
      }
    return "a block at a border";
  }
  case EDIT_PEAK: /* taller than anything: it shadows along whole lines */
    for (int j = -3; j <= 3; j++)
      for (int i = -3; i <= 3; i++)
        add_at(h, x + i, y + j, 0.9 * exp(-(i * i + j * j) / 4.0));
    return "a tall peak";
  default: /* the opposite: what shadowed far now falls away */
    for (int j = -4; j <= 4; j++)
      for (int i = -4; i <= 4; i++)
        add_at(h, x + i, y + j, -0.3 * exp(-(i * i + j * j) / 6.0));
    return "a dig";
  }
}

/* Bakes a height through a keeping context, then edits it again and again,
 * each bake through the context compared with a whole bake of the height
 * (its thread count changes from bake to bake). */
static void edits_equal_whole_with(int w, int h, const bb_bake_options *base,
                                   int brightness, int edits, unsigned seed) {
  rng r = {seed};
  bb_image height = relief(w, h, &r), bright = {0};
  bb_bake_options o = *base;
  const bb_addressing addressing = o.smooth.addressing;
  if (brightness) {
    cr_assert_eq(bb_image_alloc(&bright, w, h, 3, NULL), BB_OK);
    for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++)
      bright.pixels[i] = (float)(0.4 + 1.2 * uniform(&r));
    o.brightness = &bright;
  }
  bb_bake_context *context = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_bake_context_new(&context, &err), BB_OK);
  bb_bake_context_keep(context, 1);
  bb_bake_result got, want;
  bb_region changed;
  cr_assert_eq(bb__bake_context_bake(context, &height, &o, &got, &changed, &err), BB_OK,
               "%s", err.message);
  cr_assert(changed.width == w && changed.height == h, "the first bake is whole");
  bb_bake_result_free(&got);
  const int threads[] = {1, 2, 3, 0};
  int local = 0;
  for (int e = 0; e < edits; e++) {
    const char *what =
        edit(&height, (edit_kind)(e % 5), addressing == BB_ADDRESS_CLAMP, &r);
    if (brightness && e % 4 == 3) /* the brightness map is edited too */
      for (int j = 0; j < 4; j++)
        bright.pixels[3 * (size_t)below(&r, w * h)] = (float)uniform(&r);
    o.trace.threads = threads[e % 4];
    cr_assert_eq(bb__bake_context_bake(context, &height, &o, &got, &changed, &err), BB_OK,
                 "%s", err.message);
    local += bb__context_last_local(context);
    cr_assert_eq(bb__bake_checked(&height, &o, &want, &err), BB_OK, "%s", err.message);
    char label[160];
    snprintf(label, sizeof label, "%dx%d %s%s, edit %d (%s), %d threads", w, h,
             addressing == BB_ADDRESS_CLAMP ? "clamped" : "periodic",
             brightness ? " with brightness" : "", e, what, o.trace.threads);
    maps_equal(&got, &want, label);
    cr_assert(changed.x0 >= 0 && changed.y0 >= 0 && changed.x0 + changed.width <= w &&
                  changed.y0 + changed.height <= h,
              "%s: the changed rectangle lies in the image", label);
    bb_bake_result_free(&got);
    bb_bake_result_free(&want);
  }
  /* most edits are baked edit by edit, not whole */
  cr_assert_gt(local, edits / 2, "only %d of %d bakes were edit-local", local, edits);
  bb_bake_context_free(context);
  bb_image_free(&height);
  bb_image_free(&bright);
}

static bb_bake_options options_of(bb_addressing addressing, unsigned outputs) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 24.0f;
  o.outputs = outputs;
  o.smooth.addressing = addressing;
  return o;
}

static void edits_equal_whole(int w, int h, bb_addressing addressing, int brightness,
                              unsigned outputs, int edits, unsigned seed) {
  const bb_bake_options o = options_of(addressing, outputs);
  edits_equal_whole_with(w, h, &o, brightness, edits, seed);
}

TestSuite(rebake);

/* 20 edits give each of the 5 kinds on each of the 4 thread counts once
 * (edit e is kind e % 5 on threads[e % 4]); 10 give each kind twice. */
Test(rebake, periodic_edits_equal_whole_bakes) {
  edits_equal_whole(97, 61, BB_ADDRESS_PERIODIC, 0, BB_MAPS_BAKED, 20, 1u);
  edits_equal_whole(128, 128, BB_ADDRESS_PERIODIC, 0, BB_MAPS_BAKED, 10, 2u);
}

Test(rebake, clamped_edits_equal_whole_bakes) {
  edits_equal_whole(97, 61, BB_ADDRESS_CLAMP, 0, BB_MAPS_BAKED, 20, 3u);
  edits_equal_whole(64, 120, BB_ADDRESS_CLAMP, 0, BB_MAPS_BAKED, 10, 4u);
}

Test(rebake, edits_with_brightness_equal_whole_bakes) {
  edits_equal_whole(80, 72, BB_ADDRESS_PERIODIC, 1, BB_MAPS_BAKED, 20, 5u);
  edits_equal_whole(80, 72, BB_ADDRESS_CLAMP, 1, BB_MAPS_BAKED, 20, 6u);
}

Test(rebake, edits_of_some_maps_equal_whole_bakes) {
  /* ao alone (no normals kept), and the untraced maps alone */
  edits_equal_whole(72, 90, BB_ADDRESS_PERIODIC, 0, BB_MAP_BIT(BB_MAP_AO), 10, 7u);
  edits_equal_whole(72, 90, BB_ADDRESS_CLAMP, 0,
                    BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_WEIGHTS) |
                        BB_MAP_BIT(BB_MAP_FILTERED),
                    10, 8u);
  edits_equal_whole(72, 90, BB_ADDRESS_PERIODIC, 0,
                    BB_MAP_BIT(BB_MAP_BENT) | BB_MAP_BIT(BB_MAP_FILTERED), 10, 9u);
}

Test(rebake, edits_with_other_options_equal_whole_bakes) {
  /* a basis of 4 lobes (5 channels of visibility), OpenGL's green, Valve's
   * normals, no smoothing, an odd number of slices (one without an
   * opposite), a power, a wider bias */
  bb_bake_options o = options_of(BB_ADDRESS_PERIODIC, BB_MAPS_BAKED);
  cr_assert_eq(bb__basis_parse("hl2+z", &o.basis, NULL), BB_OK);
  o.normal_y_up = 1;
  edits_equal_whole_with(70, 66, &o, 0, 10, 10u);
  o = options_of(BB_ADDRESS_CLAMP, BB_MAPS_BAKED);
  o.normal_filter = BB_NORMAL_VALVE;
  o.smooth.radius_texels = 0;
  o.slices = 7;
  edits_equal_whole_with(70, 66, &o, 0, 10, 11u);
  o = options_of(BB_ADDRESS_PERIODIC, BB_MAPS_BAKED);
  o.slices = 9;
  o.power = 3.0;
  o.trace.bias_texels = 2.0;
  o.smooth.radius_texels = 3;
  o.normal_filter = BB_NORMAL_SOBEL;
  edits_equal_whole_with(70, 66, &o, 1, 10, 12u);
}

/* A bake through a keeping context, which must succeed. */
static bb_bake_result context_bake(bb_bake_context *c, const bb_image *h,
                                   const bb_bake_options *o, bb_region *changed) {
  bb_bake_result r;
  bb_error err = {{0}};
  cr_assert_eq(bb__bake_context_bake(c, h, o, &r, changed, &err), BB_OK, "%s",
               err.message);
  return r;
}

static void equals_whole(const bb_bake_result *got, const bb_image *h,
                         const bb_bake_options *o, const char *what) {
  bb_bake_result want;
  bb_error err = {{0}};
  cr_assert_eq(bb__bake_checked(h, o, &want, &err), BB_OK, "%s", err.message);
  maps_equal(got, &want, what);
  bb_bake_result_free(&want);
}

static bb_bake_context *keeping_context(void) {
  bb_bake_context *c = NULL;
  cr_assert_eq(bb_bake_context_new(&c, NULL), BB_OK);
  bb_bake_context_keep(c, 1);
  return c;
}

/* A keeping context that has baked h with o once (whole). */
static bb_bake_context *baked_once(const bb_image *h, const bb_bake_options *o) {
  bb_bake_context *c = keeping_context();
  bb_bake_result got = context_bake(c, h, o, NULL);
  bb_bake_result_free(&got);
  return c;
}

/* The same height again changes nothing; other options, or another size,
 * bake whole. */
Test(rebake, what_is_baked_again) {
  rng r = {21u};
  bb_image h = relief(60, 50, &r);
  bb_bake_options o = options_of(BB_ADDRESS_PERIODIC, BB_MAPS_BAKED);
  bb_bake_context *c = keeping_context();
  bb_region changed;
  bb_bake_result got = context_bake(c, &h, &o, &changed);
  bb_bake_result_free(&got);
  got = context_bake(c, &h, &o, &changed);
  cr_expect_eq(changed.width, 0, "the same height changed a %dx%d rectangle",
               changed.width, changed.height);
  cr_expect_eq(got.horizons_found, 0.0);
  cr_expect(bb__context_last_local(c));
  equals_whole(&got, &h, &o, "the same height");
  bb_bake_result_free(&got);
  o.height_scale = 30.0f;
  got = context_bake(c, &h, &o, &changed);
  cr_expect(changed.width == 60 && changed.height == 50, "another scale bakes whole");
  cr_expect(!bb__context_last_local(c));
  equals_whole(&got, &h, &o, "another scale");
  bb_bake_result_free(&got);
  bb_region asked = bb_bake_context_changed(c);
  cr_expect(asked.width == 60 && asked.height == 50);
  bb_image other = relief(61, 50, &r);
  got = context_bake(c, &other, &o, &changed);
  cr_expect(changed.width == 61 && !bb__context_last_local(c),
            "another size bakes whole");
  equals_whole(&got, &other, &o, "another size");
  bb_bake_result_free(&got);
  /* a small edit, then: edit-local, and said where */
  other.pixels[10 * 61 + 20] += 0.05f;
  got = context_bake(c, &other, &o, &changed);
  cr_expect(bb__context_last_local(c));
  cr_expect(changed.width > 0 && changed.width < 61 * 50, "%dx%d at (%d, %d)",
            changed.width, changed.height, changed.x0, changed.y0);
  cr_expect(changed.x0 <= 20 && changed.x0 + changed.width > 20 && changed.y0 <= 10 &&
                changed.y0 + changed.height > 10,
            "the changed rectangle holds the edited texel");
  equals_whole(&got, &other, &o, "a texel of another size");
  bb_bake_result_free(&got);
  bb_bake_context_free(c);
  bb_image_free(&h);
  bb_image_free(&other);
}

/* Inter-reflection bakes whole every time; so does a context that does
 * not keep. Both are still a whole bake's bits. */
Test(rebake, bounce_and_plain_contexts_bake_whole) {
  rng r = {22u};
  bb_image h = relief(40, 36, &r);
  bb_bake_options o = options_of(BB_ADDRESS_PERIODIC, BB_MAPS_BAKED);
  o.bounce_albedo = 0.6;
  bb_bake_context *c = keeping_context();
  bb_region changed;
  for (int e = 0; e < 2; e++) {
    h.pixels[e * 40 + 7] += 0.1f;
    bb_bake_result got = context_bake(c, &h, &o, &changed);
    cr_expect(changed.width == 40 && changed.height == 36 && !bb__context_last_local(c));
    equals_whole(&got, &h, &o, "with inter-reflection");
    bb_bake_result_free(&got);
  }
  bb_bake_context_free(c);
  cr_assert_eq(bb_bake_context_new(&c, NULL), BB_OK);
  o.bounce_albedo = 0.0;
  for (int e = 0; e < 2; e++) {
    h.pixels[e * 40 + 9] += 0.1f;
    bb_bake_result got = context_bake(c, &h, &o, &changed);
    cr_expect(changed.width == 40 && changed.height == 36);
    equals_whole(&got, &h, &o, "a context that does not keep");
    bb_bake_result_free(&got);
  }
  bb_bake_context_free(c);
  bb_image_free(&h);
}

/* A bad height is refused with the whole bake's words, and the next good
 * one is baked right. */
Test(rebake, bad_height_refused_then_baked) {
  rng r = {23u};
  bb_image h = relief(40, 36, &r);
  bb_bake_options o = options_of(BB_ADDRESS_CLAMP, BB_MAPS_BAKED);
  bb_bake_context *c = baked_once(&h, &o);
  bb_bake_result got;
  const float good = h.pixels[5 * 40 + 5];
  h.pixels[5 * 40 + 5] = NAN;
  bb_error err = {{0}}, whole = {{0}};
  bb_bake_result none;
  cr_expect_eq(bb__bake_context_bake(c, &h, &o, &got, NULL, &err), BB_ERR_VALUE);
  cr_expect_eq(bb__bake_checked(&h, &o, &none, &whole), BB_ERR_VALUE);
  cr_expect_str_eq(err.message, whole.message);
  cr_expect_null(got.ssbump.pixels, "nothing is returned");
  h.pixels[5 * 40 + 5] = good + 0.2f;
  got = context_bake(c, &h, &o, NULL);
  equals_whole(&got, &h, &o, "after a refused height");
  bb_bake_result_free(&got);
  /* a brightness map gone bad, likewise */
  bb_image bright;
  cr_assert_eq(bb_image_alloc(&bright, 40, 36, 1, NULL), BB_OK);
  for (int i = 0; i < 40 * 36; i++)
    bright.pixels[i] = 0.8f;
  o.brightness = &bright;
  got = context_bake(c, &h, &o, NULL);
  bb_bake_result_free(&got);
  bright.pixels[77] = INFINITY;
  cr_expect_eq(bb__bake_context_bake(c, &h, &o, &got, NULL, &err), BB_ERR_VALUE);
  cr_expect_eq(bb__bake_checked(&h, &o, &none, &whole), BB_ERR_VALUE);
  cr_expect_str_eq(err.message, whole.message);
  bright.pixels[77] = 0.5f;
  got = context_bake(c, &h, &o, NULL);
  equals_whole(&got, &h, &o, "after a refused brightness map");
  bb_bake_result_free(&got);
  bb_image_free(&bright);
  bb_bake_context_free(c);
  bb_image_free(&h);
}

static int cancel_at(void *user, long done, long total) {
  (void)done, (void)total;
  int *calls = user;
  return ++*calls >= 2; /* past the first checkpoint, in the trace */
}

/* An edit cancelled by the progress callback returns nothing and lets the
 * kept bake go; the next bake is whole and right. */
Test(rebake, cancelled_edit_then_whole) {
  rng r = {24u};
  bb_image h = relief(48, 48, &r);
  bb_bake_options o = options_of(BB_ADDRESS_PERIODIC, BB_MAPS_BAKED);
  bb_bake_context *c = baked_once(&h, &o);
  bb_bake_result got;
  h.pixels[20 * 48 + 20] += 0.3f;
  int calls = 0;
  o.trace.progress = cancel_at;
  o.trace.progress_user = &calls;
  bb_error err = {{0}};
  cr_expect_eq(bb__bake_context_bake(c, &h, &o, &got, NULL, &err), BB_ERR_CANCELLED);
  cr_expect_null(got.normal.pixels);
  cr_expect_geq(calls, 2);
  o.trace.progress = NULL;
  bb_region changed;
  got = context_bake(c, &h, &o, &changed);
  cr_expect(changed.width == 48 && !bb__context_last_local(c), "whole after a cancel");
  equals_whole(&got, &h, &o, "after a cancelled edit");
  bb_bake_result_free(&got);
  bb_bake_context_free(c);
  bb_image_free(&h);
}
