/* test_retrace.c: what an edit-local bake asks of the trace. A pyramid
 * brought up to date over a changed rectangle is the pyramid built anew;
 * the horizons found again after a change (bb__retrace_run) are those a
 * whole trace of the new heights finds, and exactly the texels whose
 * horizons changed are marked; a line's seed is where the whole trace
 * starts that line. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bumpbake.h"
#include "bumpbake_cluster.h"
#include "core/internal.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/retrace.h"
#include "trace/sweep.h"
#include "trace/testing.h"
#include "trace/trace.h"

static const bb_addressing modes[] = {BB_ADDRESS_PERIODIC, BB_ADDRESS_CLAMP};

static unsigned state = 1u;
static double uniform(void) {
  state = state * 1103515245u + 12345u;
  return (double)(state >> 8) / 16777216.0;
}

static int below(int n) {
  return (int)(uniform() * n) % n;
}

static bb_image field(int w, int h, double scale) {
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      z.pixels[y * w + x] =
          (float)(scale * (0.5 + 0.3 * sin(0.4 * x + 0.2 * y) + 0.2 * uniform()));
  return z;
}

/* A rectangle of a w x h image: periodic ones may pass the right and
 * bottom sides (they wrap), clamped ones lie inside. */
typedef struct rect {
  int x0, y0, width, height;
} rect;

static rect some_rect(int w, int h, bb_addressing a) {
  rect r = {below(w), below(h), 1 + below(w < 9 ? w : 9), 1 + below(h < 9 ? h : 9)};
  if (a == BB_ADDRESS_CLAMP) {
    if (r.x0 + r.width > w)
      r.width = w - r.x0;
    if (r.y0 + r.height > h)
      r.height = h - r.y0;
  }
  return r;
}

static size_t rect_texel(const rect *r, int i, int j, int w, int h) {
  return (size_t)((r->y0 + j) % h) * (size_t)w + (size_t)((r->x0 + i) % w);
}

static void same_pyramid(const bb_pyramid *got, const bb_pyramid *want,
                         const char *what) {
  cr_assert_eq(got->levels, want->levels, "%s", what);
  for (int k = 0; k < got->levels; k++) {
    const size_t n = (size_t)got->level_width[k] * (size_t)got->level_height[k];
    cr_assert(memcmp(got->level_max[k], want->level_max[k], n * sizeof(float)) == 0,
              "%s: level %d differs from a pyramid built anew", what, k);
  }
  cr_assert(got->global_max == want->global_max && got->global_min == want->global_min &&
                got->border_max == want->border_max,
            "%s: global max, min or border max", what);
}

Test(retrace, pyramid_update_equals_a_build) {
  const int sizes[][2] = {{1, 1},   {5, 1},   {13, 7},  {16, 16},
                          {33, 17}, {64, 20}, {100, 37}};
  for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
    for (int m = 0; m < 2; m++) {
      const int w = sizes[s][0], h = sizes[s][1];
      bb_image z = field(w, h, 10.0);
      bb_pyramid *p = NULL;
      cr_assert_eq(bb__pyramid_build_all_cores(&z, modes[m], &p, NULL), BB_OK);
      for (int e = 0; e < 12; e++) {
        const rect r = some_rect(w, h, modes[m]);
        float old_min = INFINITY;
        /* raise, lower, or make the least or the highest texel */
        const double v = e % 3 == 0 ? -5.0 : (e % 3 == 1 ? 30.0 : uniform() * 10.0);
        for (int j = 0; j < r.height; j++)
          for (int i = 0; i < r.width; i++) {
            const size_t t = rect_texel(&r, i, j, w, h);
            if (p->z[t] < old_min)
              old_min = p->z[t];
            z.pixels[t] = p->z[t] = (float)(v + uniform());
          }
        cr_assert_eq(bb__pyramid_update(p, r.x0, r.y0, r.width, r.height, old_min),
                     BB_OK);
        bb_pyramid *built = NULL;
        cr_assert_eq(bb__pyramid_build_all_cores(&z, modes[m], &built, NULL), BB_OK);
        char what[96];
        snprintf(what, sizeof what, "%dx%d %s, edit %d at (%d, %d) %dx%d", w, h,
                 m ? "clamped" : "periodic", e, r.x0, r.y0, r.width, r.height);
        same_pyramid(p, built, what);
        bb_pyramid_free(built);
      }
      bb_pyramid_free(p);
      bb_image_free(&z);
    }
}

/* Every texel of a line walked from its seed, and the seed is one of those
 * the whole trace starts its lines from (y0 below gcd(b, H), x0 below
 * gcd((H / h) a, W)). */
Test(retrace, line_seeds_are_the_trace_s) {
  const int sizes[][2] = {{12, 8}, {97, 61}, {64, 64}, {30, 45}};
  const int steps[][2] = {{5, 1}, {3, -2}, {-2, 3}, {1, 0}, {0, 1}, {-1, -5}, {7, 4}};
  for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
    const int w = sizes[s][0], h = sizes[s][1];
    bb_image z = field(w, h, 1.0);
    bb_pyramid *p = NULL;
    cr_assert_eq(bb__pyramid_build_all_cores(&z, BB_ADDRESS_PERIODIC, &p, NULL), BB_OK);
    for (size_t d = 0; d < sizeof steps / sizeof steps[0]; d++) {
      const int a = steps[d][0], b = steps[d][1];
      const long period = bb__line_period(p, a, b), rows = h / bb__gcd(b, h);
      for (int e = 0; e < 20; e++) {
        const int x = below(w), y = below(h);
        int x0, y0;
        bb__line_seed(p, a, b, x, y, &x0, &y0);
        cr_expect(y0 >= 0 && y0 < bb__gcd(b, h) && x0 >= 0 && x0 < bb__gcd(rows * a, w),
                  "(%d, %d) along (%d, %d): seed (%d, %d)", x, y, a, b, x0, y0);
        int found = 0;
        for (long j = 0, px = x0, py = y0; j < period && !found; j++) {
          found = px == x && py == y;
          px = ((px + a) % w + w) % w, py = ((py + b) % h + h) % h;
        }
        cr_expect(found, "(%d, %d) is not on the line of (%d, %d) along (%d, %d)", x, y,
                  x0, y0, a, b);
      }
    }
    bb_pyramid_free(p);
    bb_image_free(&z);
  }
}

/* Each slice's horizons of every texel, by the whole trace. */
static bb_image *horizons_of(const bb_pyramid *p, const bb_rayset *rs, double bias) {
  const int n = bb_rayset_slice_count(rs);
  bb_image *h = calloc((size_t)n, sizeof *h);
  int slices[BB_MAX_SLICES];
  for (int s = 0; s < n; s++)
    slices[s] = s;
  bb_trace_options o;
  bb__trace_options_init(&o);
  o.bias_texels = bias;
  o.threads = 2;
  bb_error err = {{0}};
  cr_assert_eq(bb_trace_horizons(p, rs, &o, slices, n, h, &err), BB_OK, "%s",
               err.message);
  return h;
}

/* Heights changed over a rectangle (raised, lowered, a tall peak, a block
 * against a border), the horizons found again from the last trace's equal
 * a whole trace's, and the texels marked are those whose horizons changed. */
static void retrace_equals_trace(int w, int h, bb_addressing a, int slices, double bias) {
  bb_image z = field(w, h, 12.0);
  bb_pyramid *p = NULL;
  cr_assert_eq(bb__pyramid_build_all_cores(&z, a, &p, NULL), BB_OK);
  bb_rayset *rs = NULL;
  cr_assert_eq(bb__rayset_new(slices, 1.0, NULL, &rs, NULL), BB_OK);
  const int n = bb_rayset_slice_count(rs);
  bb_image *kept = horizons_of(p, rs, bias);
  float *horizons[BB_MAX_SLICES];
  for (int s = 0; s < n; s++)
    horizons[s] = kept[s].pixels;
  int order[BB_MAX_SLICES];
  cr_assert_eq(bb_trace_slice_order(rs, order, NULL), BB_OK);
  unsigned char *dirty = calloc((size_t)w * (size_t)h, 1);
  for (int e = 0; e < 10; e++) {
    rect r = some_rect(w, h, a);
    if (e % 5 == 4) { /* against the right side (periodic: across it) */
      r.x0 = a == BB_ADDRESS_CLAMP ? w - r.width : w - r.width / 2 - 1;
    }
    float *old_z = malloc((size_t)r.width * (size_t)r.height * sizeof(float));
    float old_min = INFINITY;
    const double lift = e % 5 == 0 ? -6.0 : (e % 5 == 2 ? 40.0 : (uniform() - 0.4) * 8.0);
    for (int j = 0; j < r.height; j++)
      for (int i = 0; i < r.width; i++) {
        const size_t t = rect_texel(&r, i, j, w, h);
        old_z[j * r.width + i] = p->z[t];
        if (p->z[t] < old_min)
          old_min = p->z[t];
        p->z[t] = (float)(p->z[t] + lift * (0.5 + 0.5 * uniform()));
      }
    cr_assert_eq(bb__pyramid_update(p, r.x0, r.y0, r.width, r.height, old_min), BB_OK);
    bb_image *whole = horizons_of(p, rs, bias); /* the whole trace of the new heights */
    float *old_copy[BB_MAX_SLICES];
    for (int s = 0; s < n; s++) {
      old_copy[s] = malloc((size_t)w * (size_t)h * sizeof(float));
      memcpy(old_copy[s], horizons[s], (size_t)w * (size_t)h * sizeof(float));
    }
    bb__retrace rt = {.p = p,
                      .rs = rs,
                      .horizons = horizons,
                      .order = order,
                      .bias = bias,
                      .threads = 1 + e % 3,
                      .x0 = r.x0,
                      .y0 = r.y0,
                      .width = r.width,
                      .height = r.height,
                      .old_z = old_z,
                      .dirty = dirty};
    bb_error err = {{0}};
    cr_assert_eq(bb__retrace_run(&rt, &err), BB_OK, "%s", err.message);
    for (int s = 0; s < n; s++)
      for (int t = 0; t < w * h; t++)
        cr_assert(memcmp(&horizons[s][t], &whole[s].pixels[t], sizeof(float)) == 0,
                  "%dx%d %s, edit %d at (%d, %d) %dx%d: slice %d, texel (%d, %d): %.9g, "
                  "not %.9g",
                  w, h, a == BB_ADDRESS_CLAMP ? "clamped" : "periodic", e, r.x0, r.y0,
                  r.width, r.height, s, t % w, t / w, (double)horizons[s][t],
                  (double)whole[s].pixels[t]);
    for (int t = 0; t < w * h; t++) {
      int moved = 0;
      for (int s = 0; s < n; s++)
        moved |= memcmp(&horizons[s][t], &old_copy[s][t], 4) != 0;
      cr_assert_eq(dirty[t] != 0, moved, "edit %d: texel (%d, %d) marked %d, moved %d", e,
                   t % w, t / w, dirty[t], moved);
      dirty[t] = 0;
    }
    for (int s = 0; s < n; s++) {
      free(old_copy[s]);
      bb_image_free(&whole[s]);
    }
    free(whole);
    free(old_z);
  }
  for (int s = 0; s < n; s++)
    bb_image_free(&kept[s]);
  free(kept);
  free(dirty);
  bb_rayset_free(rs);
  bb_pyramid_free(p);
  bb_image_free(&z);
}

Test(retrace, horizons_found_again_equal_a_whole_trace) {
  retrace_equals_trace(61, 47, BB_ADDRESS_PERIODIC, 16, 0.55);
  retrace_equals_trace(61, 47, BB_ADDRESS_CLAMP, 16, 0.55);
  retrace_equals_trace(40, 64, BB_ADDRESS_PERIODIC, 7, 0.0);
  retrace_equals_trace(40, 64, BB_ADDRESS_CLAMP, 9, 2.0);
}
