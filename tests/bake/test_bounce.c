/* test_bounce.c: the bake's inter-reflection (bounce_albedo) against the
 * exact 2D radiosity of a trench, the closed form of a plane, the path
 * tracer tools/bounce_ref, and its invariances. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bumpbake.h"
#include "image/height_channel.h"
#include "bake_harness.h"
#include "bake/bake_internal.h"
#include "image/image_write.h"
#include "trace/basis.h"
#include "trace/bounce.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/trace.h"

static const double PI = 3.14159265358979323846;

static bb_bake_options options(float scale, int rays, double rho) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = scale;
  o.rays = rays;
  o.smooth.radius_texels = 0;
  o.bounce_albedo = rho;
  return o;
}

static const float *at(const bb_image *img, int x, int y) {
  return bb_image_texel(img, x, y);
}

static int same_image(const bb_image *a, const bb_image *b) {
  if (!a->pixels || !b->pixels) return !a->pixels && !b->pixels;
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         memcmp(a->pixels, b->pixels,
                (size_t)a->width * (size_t)a->height * (size_t)a->channels * sizeof(float)) == 0;
}

static void expect_same_bake(const bb_bake_result *a, const bb_bake_result *b, const char *what) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    cr_expect(same_image(bb__bake_result_image(a, (bb_map_kind)k),
                         bb__bake_result_image(b, (bb_map_kind)k)),
              "%s: %s differs", what, bb_map_kind_get((bb_map_kind)k)->name);
  cr_expect(same_image(&a->vis, &b->vis), "%s: vis differs", what);
}

static bb_image load_fixture(const char *name) {
  const char *dir = getenv("BB_FIXTURES");
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir && *dir ? dir : "fixtures", name);
  bb_image h;
  bb_error err;
  cr_assert_eq(bb__height_load(path, BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, &err), BB_OK, "%s", err.message);
  return h;
}

/* ---- rho = 0 is the bake without the option, bit for bit ---------------- */

Test(bounce, rho_zero_is_the_bake_without_it) {
  static const char *const maps[] = {"noise_96x80.png", "pit_65x65.png", "bricks_128x64.png",
                                     "rock06_128.png"};
  bb_image grey = harness_field(4, 4, 0.5f); /* a map that must not be looked at */
  for (size_t m = 0; m < sizeof maps / sizeof maps[0]; m++) {
    bb_image h = load_fixture(maps[m]);
    for (int threads = 1; threads <= 3; threads++) {
      bb_bake_options plain;
      bb__bake_options_init(&plain);
      plain.height_scale = 8.0f;
      plain.trace.threads = threads;
      bb_bake_options zero = plain;
      zero.bounce_albedo = 0.0;
      zero.bounces = 7;
      zero.bounce_albedo_map = &grey;
      bb_bake_result a = harness_bake(&h, &plain), b = harness_bake(&h, &zero);
      char what[128];
      snprintf(what, sizeof what, "%s, %d threads", maps[m], threads);
      expect_same_bake(&a, &b, what);
      cr_expect_eq(b.bounces, 0);
      bb_bake_result_free(&a);
      bb_bake_result_free(&b);
    }
    bb_image_free(&h);
  }
  bb_image_free(&grey);
}

/* ---- progress: once from 0 to the whole over the trace and every pass ---- */

typedef struct progress_log {
  long done[256], total[256];
  int calls, checkpoints;
} progress_log;

/* Logs the progress; a checkpoint (0, 0: smoothing and normals, which
 * report no progress of their own) is counted apart. */
static int log_progress(void *user, long done, long total) {
  progress_log *l = user;
  if (done == 0 && total == 0) {
    l->checkpoints++;
    return 0;
  }
  if (l->calls < 256) l->done[l->calls] = done, l->total[l->calls] = total;
  l->calls++;
  return 0;
}

static bb_image tiled(const bb_image *h, int times);

/* On the map's level (96 x 80) and on the coarse one (576 x 80): the
 * trace, then the coarse level's passes, one bar. */
Test(bounce, progress_is_monotone_over_the_whole_bake) {
  bb_image tile = load_fixture("noise_96x80.png");
  for (int m = 0; m < 2; m++) {
    bb_image h = m ? tiled(&tile, 6) : tile;
    const int counts[] = {0, 3};
    for (size_t c = 0; c < 2; c++) {
      bb_bake_options o = options(8.0f, 256, 0.5);
      o.bounces = counts[c];
      progress_log l = {{0}, {0}, 0, 0};
      o.trace.progress = log_progress;
      o.trace.progress_user = &l;
      bb_bake_result r = harness_bake(&h, &o);
      /* a call after every sweep of every pass: at least the 8 sweeps of the
       * trace's 16 slices, which the direct light and the texels' gathers share */
      cr_assert(l.calls >= 8 && l.calls <= 256, "bounces %d: %d calls", counts[c], l.calls);
      for (int i = 0; i < l.calls; i++) {
        cr_assert_eq(l.total[i], l.total[0], "bounces %d: the whole changes at call %d (%ld, then %ld)",
                     counts[c], i, l.total[0], l.total[i]);
        cr_assert(l.done[i] >= 0 && l.done[i] <= l.total[i], "bounces %d: call %d: %ld of %ld",
                  counts[c], i, l.done[i], l.total[i]);
        if (i)
          cr_assert(l.done[i] >= l.done[i - 1], "bounces %d: back from %ld to %ld at call %d",
                    counts[c], l.done[i - 1], l.done[i], i);
        /* no sweep is a large part of the whole: the bar moves all along */
        cr_expect_leq((l.done[i] - (i ? l.done[i - 1] : 0)) * 5, l.total[0],
                      "bounces %d: call %d moves from %ld to %ld of %ld", counts[c], i,
                      i ? l.done[i - 1] : 0, l.done[i], l.total[0]);
      }
      cr_expect_eq(l.done[l.calls - 1], l.total[0], "bounces %d: ends at %ld of %ld", counts[c],
                   l.done[l.calls - 1], l.total[0]);
      bb_bake_result_free(&r);
    }
    if (m) bb_image_free(&h);
  }
  bb_image_free(&tile);
}

/* The trace's part of the units is bb__bake_slices(o), one a slice, as
 * bumpbake.h says (a client names the stage from it: bumpbake serve): a
 * trace of the caller's, counting the calls made while it runs, sees them
 * end at exactly that; the inter-reflection's calls come after, beyond it. */
typedef struct trace_count {
  progress_log *log;
  int calls_in_trace;
} trace_count;

static bb_status counting_trace(void *user, const bb_pyramid *p, const bb_rayset *rs,
                                const bb_trace_options *o, bb_image *vis, bb_error *err) {
  trace_count *t = user;
  double found = 0.0;
  bb_status st = bb__trace_occlusion(p, rs, o, vis, &found, err);
  t->calls_in_trace = t->log->calls;
  return st;
}

Test(bounce, the_trace_is_the_first_slices_units) {
  bb_image h = load_fixture("noise_96x80.png");
  bb_bake_options o = options(8.0f, 256, 0.5);
  progress_log l = {{0}, {0}, 0, 0};
  trace_count t = {&l, 0};
  o.trace.progress = log_progress;
  o.trace.progress_user = &l;
  o.trace.trace = counting_trace;
  o.trace.trace_user = &t;
  bb_bake_result r = harness_bake(&h, &o);
  const long slices = bb__bake_slices(&o);
  cr_assert(t.calls_in_trace > 0 && t.calls_in_trace < l.calls, "%d of %d calls",
            t.calls_in_trace, l.calls);
  cr_expect_eq(l.done[t.calls_in_trace - 1], slices, "the trace ends at %ld, not %ld",
               l.done[t.calls_in_trace - 1], slices);
  for (int i = t.calls_in_trace; i < l.calls && i < 256; i++)
    cr_expect_geq(l.done[i], slices, "call %d after the trace: %ld", i, l.done[i]);
  cr_expect_gt(l.done[l.calls - 1], slices);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* ---- what bouncing light may and may not do ------------------------------- */

Test(bounce, never_darker_and_ao_never_above_one) {
  bb_image h = load_fixture("rock06_128.png");
  bb_bake_options o = options(16.0f, 256, 0.0);
  bb_bake_result base = harness_bake(&h, &o);
  const double rhos[] = {0.6, 1.0};
  for (size_t i = 0; i < 2; i++) {
    o.bounce_albedo = rhos[i];
    bb_bake_result r = harness_bake(&h, &o);
    double added = 0.0;
    for (int y = 0; y < h.height; y++)
      for (int x = 0; x < h.width; x++) {
        const float ao = at(&r.ao, x, y)[0], ao0 = at(&base.ao, x, y)[0];
        cr_assert(ao >= ao0 && ao <= 1.0f, "rho %g, (%d, %d): ao %g, without %g", rhos[i], x, y,
                  (double)ao, (double)ao0);
        added += ao - ao0;
        for (int c = 0; c < 3; c++) {
          const float s = at(&r.ssbump, x, y)[c], s0 = at(&base.ssbump, x, y)[c];
          cr_assert(s >= s0 && s <= 1.0f, "rho %g, (%d, %d): ssbump %d %g, without %g", rhos[i],
                    x, y, c, (double)s, (double)s0);
          cr_assert(at(&r.vis, x, y)[1 + c] >= at(&base.vis, x, y)[1 + c]);
        }
        const float *b = at(&r.bent, x, y);
        cr_assert_float_eq(b[0] * b[0] + b[1] * b[1] + b[2] * b[2], 1.0, 1e-5);
      }
    cr_expect_gt(added / (h.width * h.height), 0.005 * rhos[i], "rho %g adds %g on average",
                 rhos[i], added / (h.width * h.height));
    cr_expect(same_image(&r.weights, &base.weights), "the weights hold no visibility");
    cr_expect_eq(r.bounces > 1, 1, "bounces 0 follows more than one bounce (%d)", r.bounces);
    bb_bake_result_free(&r);
  }
  bb_bake_result_free(&base);
  bb_image_free(&h);
}

Test(bounce, flat_stays_exactly_one) {
  bb_image h = harness_field(24, 20, 0.5f);
  bb_bake_options o = options(32.0f, 256, 0.0);
  bb_bake_result base = harness_bake(&h, &o);
  o.bounce_albedo = 1.0;
  bb_bake_result r = harness_bake(&h, &o);
  for (int y = 0; y < 20; y++)
    for (int x = 0; x < 24; x++) cr_assert_eq(at(&r.ao, x, y)[0], 1.0f);
  expect_same_bake(&base, &r, "a flat map at rho 1");
  bb_bake_result_free(&base);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* Any thread count gives the same bits. A periodic shift gives the same
 * bits where the bounce has no part (normal, weights, filtered); where it
 * has, the gathers' choices (how many pieces a band is cut into, whether a
 * band is small enough to see its horizon point only) are thresholds on
 * walk coordinates counted from a line's first texel, which the shift
 * moves, so a texel near a threshold can fall the other way: within 0.001
 * in ao and 0.005 in ssbump and bent. */
Test(bounce, any_thread_count_gives_the_same_bits_and_a_periodic_shift_close_ones) {
  bb_image h = load_fixture("noise_96x80.png");
  const int W = h.width, H = h.height, sx = 37, sy = 11;
  bb_image shifted = harness_field(W, H, 0.0f);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) *bb_image_texel(&shifted, (x + sx) % W, (y + sy) % H) = at(&h, x, y)[0];
  bb_bake_options o = options(8.0f, 256, 0.5);
  o.trace.threads = 1;
  bb_bake_result one = harness_bake(&h, &o);
  for (int threads = 2; threads <= 5; threads += 3) {
    o.trace.threads = threads;
    bb_bake_result r = harness_bake(&h, &o);
    char what[64];
    snprintf(what, sizeof what, "%d threads against 1", threads);
    expect_same_bake(&one, &r, what);
    bb_bake_result_free(&r);
  }
  o.trace.threads = 2;
  bb_bake_result s = harness_bake(&shifted, &o);
  cr_expect_eq(s.bounces, one.bounces);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    const bb_image *a = bb__bake_result_image(&one, (bb_map_kind)k);
    const bb_image *b = bb__bake_result_image(&s, (bb_map_kind)k);
    int differ = 0;
    double most = 0.0;
    for (int y = 0; y < H; y++)
      for (int x = 0; x < W; x++) {
        const float *va = at(a, x, y), *vb = at(b, (x + sx) % W, (y + sy) % H);
        differ += memcmp(va, vb, (size_t)a->channels * sizeof(float)) != 0;
        for (int c = 0; c < a->channels; c++) most = fmax(most, fabs((double)va[c] - (double)vb[c]));
      }
    const double within =
        k == BB_MAP_AO ? 0.001 : (BB_MAPS_TRACED & BB_MAP_BIT(k) ? 0.005 : 0.0);
    cr_log_info("%s: %d texels differ after a periodic shift, by at most %.3g",
                bb_map_kind_get((bb_map_kind)k)->name, differ, most);
    cr_expect(most <= within, "%s: %d texels differ after a periodic shift, by at most %g",
              bb_map_kind_get((bb_map_kind)k)->name, differ, most);
  }
  bb_bake_result_free(&one);
  bb_bake_result_free(&s);
  bb_image_free(&shifted);
  bb_image_free(&h);
}

/* The surface pass over turned slices (bb__bounce_options.surface_turns 2,
 * not the default): 8 slices swept for 4, each line walked in one sweep of
 * two, its gathers weighed twice. The same bits for any thread count, and
 * close to the 4 slices every texel gathers in, but not the same (they
 * differ by the azimuths' placing, docs/accuracy.md "The surface passes'
 * slices turned, tried"): measured 0.000031 in mean |difference| of ao,
 * 0.00085 at most, of 0.0067 added on average. */
Test(bounce, turned_surface_slices_give_the_same_bits_for_any_thread_count) {
  bb_image h = load_fixture("noise_96x80.png");
  const size_t n = (size_t)h.width * (size_t)h.height;
  bb_image z = harness_field(h.width, h.height, 0.0f);
  for (size_t i = 0; i < n; i++) z.pixels[i] = 8.0f * h.pixels[i];
  bb_pyramid *p = NULL;
  bb_rayset *rs = NULL;
  cr_assert_eq(bb__pyramid_build_all_cores(&z, BB_ADDRESS_PERIODIC, &p, NULL), BB_OK);
  cr_assert_eq(bb__rayset_new(16, 1.0, NULL, &rs, NULL), BB_OK);
  bb_trace_options to;
  bb__trace_options_init(&to);
  bb_image vis = {0};
  cr_assert_eq(bb__trace_occlusion(p, rs, &to, &vis, NULL, NULL), BB_OK);
  const size_t floats = n * (size_t)vis.channels;
  float *added[3]; /* the visibility with the bounce added */
  for (int run = 0; run < 3; run++) { /* turns 2 on 1 and 3 threads, turns 1 */
    bb__bounce_options o;
    bb__bounce_options_init(&o);
    o.rho = 0.5, o.bias = to.bias_texels, o.level = 1;
    o.surface_turns = run < 2 ? 2 : 1;
    o.threads = run == 1 ? 3 : 1;
    bb_image out = vis;
    out.pixels = added[run] = malloc(floats * sizeof(float));
    cr_assert(added[run]);
    memcpy(added[run], vis.pixels, floats * sizeof(float));
    bb_error err;
    cr_assert_eq(bb__bounce_add(p, rs, &o, &out, NULL, &err), BB_OK, "%s", err.message);
  }
  cr_expect(memcmp(added[0], added[1], floats * sizeof(float)) == 0,
            "turned slices: 3 threads against 1 differ");
  double most = 0.0, sum = 0.0, turned = 0.0;
  for (size_t v = 0; v < n; v++) {
    const size_t i = v * (size_t)vis.channels; /* ao */
    most = fmax(most, fabs((double)added[0][i] - (double)added[2][i]));
    sum += fabs((double)added[0][i] - (double)added[2][i]);
    turned += (double)added[0][i] - (double)vis.pixels[i];
  }
  cr_log_info("turned against not: ao added %.5f on average, mean |difference| %.6f, "
              "largest %.5f", turned / (double)n, sum / (double)n, most);
  cr_expect(sum > 0.0, "the turned slices change nothing");
  cr_expect(sum / (double)n <= 0.0001 && most <= 0.003,
            "turned against not: mean |difference| %.6f, largest %.5f in ao", sum / (double)n,
            most);
  for (int run = 0; run < 3; run++) free(added[run]);
  bb_image_free(&vis);
  bb_rayset_free(rs);
  bb_pyramid_free(p);
  bb_image_free(&z);
  bb_image_free(&h);
}

Test(bounce, options_are_checked) {
  bb_image h = harness_field(8, 8, 0.5f);
  const double bad_rho[] = {-0.1, 1.5, NAN};
  for (size_t i = 0; i < 3; i++) {
    bb_bake_options o = options(4.0f, 16, bad_rho[i]);
    bb_error err;
    cr_expect_eq(bb__bake_options_check(&o, &err), BB_ERR_ARGUMENT, "rho %g", bad_rho[i]);
  }
  bb_bake_options o = options(4.0f, 16, 0.5);
  o.bounces = BB_MAX_BOUNCES + 1;
  bb_error err;
  cr_expect_eq(bb__bake_options_check(&o, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "bounces") != NULL, "%s", err.message);
  /* an albedo map of another size is named as such */
  bb_image small = harness_field(4, 4, 1.0f);
  o.bounces = 0;
  o.bounce_albedo_map = &small;
  bb_bake_result r;
  cr_expect_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_SIZE);
  cr_expect(strstr(err.message, "albedo") != NULL, "%s", err.message);
  small.pixels[5] = NAN;
  bb_image nan_map = harness_field(8, 8, 1.0f);
  nan_map.pixels[9] = NAN;
  o.bounce_albedo_map = &nan_map;
  cr_expect_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_VALUE);
  bb_image_free(&nan_map);
  bb_image_free(&small);
  bb_image_free(&h);
}

/* An albedo map of 0 where half the surface is bounces nothing from there:
 * a black floor around a white wall, against the same all white. */
Test(bounce, the_albedo_map_scales_rho_per_vertex) {
  const int W = 40, H = 8;
  bb_image h = harness_field(W, H, 0.0f);
  for (int y = 0; y < H; y++)
    for (int x = 18; x < 22; x++) *bb_image_texel(&h, x, y) = 1.0f;
  bb_bake_options o = options(6.0f, 256, 0.8);
  o.smooth.addressing = BB_ADDRESS_CLAMP;
  bb_bake_result white = harness_bake(&h, &o);
  bb_image black = harness_field(W, H, 1.0f);
  for (int i = 0; i < W * H; i++) black.pixels[i] = 0.0f;
  o.bounce_albedo_map = &black;
  bb_bake_result none = harness_bake(&h, &o);
  o.bounce_albedo = 0.0;
  o.bounce_albedo_map = NULL;
  bb_bake_result base = harness_bake(&h, &o);
  /* the floor beside the wall: lit by the wall with a white map only */
  const double from_wall = at(&white.ao, 16, 4)[0] - at(&base.ao, 16, 4)[0];
  cr_expect_gt(from_wall, 0.01, "the white wall adds %g", from_wall);
  cr_expect_eq(at(&none.ao, 16, 4)[0], at(&base.ao, 16, 4)[0], "a black surface adds nothing");
  bb_bake_result_free(&white);
  bb_bake_result_free(&none);
  bb_bake_result_free(&base);
  bb_image_free(&black);
  bb_image_free(&h);
}

/* ---- a plane: one bounce in closed form ------------------------------------

 * A plane of slope s along +x, z = s x (clamp mode; the texel in the middle,
 * bias 0). Every point of it sees the sky above the plane and above the
 * horizon, nothing of itself: its irradiance is E_k = integral over those
 * directions of sky_k(w) n.w, the same everywhere, and a texel's blocked
 * directions (below the plane, uphill) all meet it. One bounce gives
 *   ao'    = ao + (1 - ao) rho (1 + cos a) / 2,  tan a = s
 *   vis_c' = vis_c + Omega rho E_c / pi / T_c,
 * Omega = integral over cos(phi) > 0 of sin(atan(s cos phi)) dphi the
 * blocked solid angle. E_c and T_c by a midpoint rule here. One bounce,
 * since the plane sees nothing of itself (its ends, far off, would). */
static double lobe_sky(const double b[3], const double w[3]) {
  const double v = b[0] * w[0] + b[1] * w[1] + b[2] * w[2];
  return v > 0.0 ? v : 0.0;
}

Test(bounce, a_plane_reflects_its_closed_form) {
  const int w = 61, h = 9, x0 = 30, y0 = 4;
  const float scale = 30.0f; /* slope 0.5 */
  const double s = (double)scale / (w - 1), rho = 0.5;
  bb_image height = harness_field(w, h, 0.0f);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) *bb_image_texel(&height, x, y) = (float)x / (float)(w - 1);
  bb_bake_options o = options(scale, 256, 0.0);
  o.smooth.addressing = BB_ADDRESS_CLAMP;
  o.trace.bias_texels = 0.0;
  bb_bake_result base = harness_bake(&height, &o);
  o.bounce_albedo = rho;
  o.bounces = 1;
  bb_bake_result r = harness_bake(&height, &o);
  const double len = sqrt(1.0 + s * s), n[3] = {-s / len, 0.0, 1.0 / len};
  const double ao0 = at(&base.ao, x0, y0)[0];
  const double want_ao = ao0 + (1.0 - ao0) * rho * (1.0 + 1.0 / len) / 2.0;
  cr_log_info("plane: ao %+.5f", at(&r.ao, x0, y0)[0] - want_ao);
  cr_expect(fabs(at(&r.ao, x0, y0)[0] - want_ao) <= 0.002, "ao %.5f, closed form %.5f",
            (double)at(&r.ao, x0, y0)[0], want_ao);
  const int ne = 1000, na = 2000;
  double omega = 0.0;
  for (int j = 0; j < na; j++) {
    const double phi = 2.0 * PI * (j + 0.5) / na;
    if (cos(phi) > 0.0) omega += sin(atan(s * cos(phi))) * 2.0 * PI / na;
  }
  for (int c = 0; c < 3; c++) {
    double b[3], e = 0.0, total = 0.0;
    bb__basis_vector(c, b);
    for (int i = 0; i < ne; i++) {
      const double el = 0.5 * PI * (i + 0.5) / ne;
      for (int j = 0; j < na; j++) {
        const double phi = 2.0 * PI * (j + 0.5) / na;
        const double wv[3] = {cos(el) * cos(phi), cos(el) * sin(phi), sin(el)};
        const double dw = cos(el) * (0.5 * PI / ne) * (2.0 * PI / na);
        const double nw = n[0] * wv[0] + n[1] * wv[1] + n[2] * wv[2];
        total += lobe_sky(b, wv) * dw;
        if (nw > 0.0) e += lobe_sky(b, wv) * nw * dw;
      }
    }
    const float *nn = at(&r.normal, x0, y0);
    const double ndotb = nn[0] * b[0] + nn[1] * b[1] + nn[2] * b[2];
    const double vis0 = at(&base.ssbump, x0, y0)[c] / ndotb, vis = at(&r.ssbump, x0, y0)[c] / ndotb;
    const double want = vis0 + omega * rho * e / PI / total;
    cr_log_info("plane: vis_%d %+.5f", c, vis - want);
    cr_expect(fabs(vis - want) <= 0.0015, "vis_%d %.5f, closed form %.5f", c, vis, want);
  }
  bb_bake_result_free(&base);
  bb_bake_result_free(&r);
  bb_image_free(&height);
}

/* ---- the trench: exact 2D radiosity ---------------------------------------

 * A trench constant along y (clamp mode): a floor at 0 from x = 1 to
 * x = W - 2 between walls that rise over one cell to H, the plateau beyond
 * (the border extruded). The surface is its cross-section extruded, so the
 * light it reflects is a 2D problem: the cavity (two walls and the floor)
 * is convex, every strip of it sees every other whole, and the view factor
 * between two infinitely long strips is Hottel's crossed strings,
 *   F_ij = (|a_i b_j| + |b_i a_j| - |a_i a_j| - |b_i b_j|) / (2 L_i);
 * what a strip does not see of the cavity is sky (the opening). With the
 * sky's radiance 1, each strip's radiance J_i solves
 *   J_i = rho (F_i,sky + sum_j F_ij J_j),
 * one bounce being J = rho F_sky. The texel's origin P (the floor's centre
 * line, bias above it) sees a strip above it by the view factor of a
 * horizontal element to an infinite strip, (sin p_b - sin p_a) / 2 (p the
 * angle of each end from the vertical): ao' - ao = sum over the strips of
 * that times J_i, the part of a strip under P's horizontal cut off. */
typedef struct strip {
  double ax, az, bx, bz;
} strip;

static double distance2d(double x0, double z0, double x1, double z1) {
  return hypot(x1 - x0, z1 - z0);
}

static int trench_strips(double H, int W, int per_wall, int per_floor, strip *s, int *segment) {
  int n = 0;
  const double wall[2][4] = {{0.0, H, 1.0, 0.0}, {W - 2.0, 0.0, W - 1.0, H}};
  for (int part = 0; part < 3; part++) {
    double x0, z0, x1, z1;
    if (part == 1) x0 = 1.0, z0 = 0.0, x1 = W - 2.0, z1 = 0.0;
    else {
      const double *g = wall[part / 2];
      x0 = g[0], z0 = g[1], x1 = g[2], z1 = g[3];
    }
    const int count = part == 1 ? per_floor : per_wall;
    for (int i = 0; i < count; i++) {
      const double t0 = (double)i / count, t1 = (double)(i + 1) / count;
      s[n] = (strip){x0 + (x1 - x0) * t0, z0 + (z1 - z0) * t0, x0 + (x1 - x0) * t1,
                     z0 + (z1 - z0) * t1};
      segment[n++] = part;
    }
  }
  return n;
}

/* The light the bounces add to ao at (xc, bias) over a floor at 0, for
 * `bounces` bounces (0: to convergence); *direct (may be NULL) receives
 * ao without them, the view factor of P to the opening. */
static double crossed_strings(const strip *i, const strip *j) {
  return fabs(distance2d(i->ax, i->az, j->bx, j->bz) + distance2d(i->bx, i->bz, j->ax, j->az) -
              distance2d(i->ax, i->az, j->ax, j->az) - distance2d(i->bx, i->bz, j->bx, j->bz)) /
         (2.0 * distance2d(i->ax, i->az, i->bx, i->bz));
}

/* Hottel's rule against view factors known in closed form: two strips
 * meeting at a right angle (widths a, b: (a + b - sqrt(a^2 + b^2)) / 2a)
 * and two parallel strips facing each other (width w, h apart:
 * sqrt(1 + (h/w)^2) - h/w). */
Test(bounce, crossed_strings_give_known_view_factors) {
  const double a = 2.0, b = 3.0, w = 1.5, h = 0.7;
  const strip floor_ = {0.0, 0.0, a, 0.0}, wall = {0.0, b, 0.0, 0.0};
  cr_expect_float_eq(crossed_strings(&floor_, &wall), (a + b - sqrt(a * a + b * b)) / (2.0 * a), 1e-12);
  const strip bottom = {0.0, 0.0, w, 0.0}, top = {w, h, 0.0, h};
  cr_expect_float_eq(crossed_strings(&bottom, &top), sqrt(1.0 + (h / w) * (h / w)) - h / w, 1e-12);
}

static double trench_added_at(double H, int W, double px, double bias, double rho, int bounces,
                              double *direct);
static double trench_added(double H, int W, double bias, double rho, int bounces, double *direct) {
  return trench_added_at(H, W, (W - 1) / 2.0, bias, rho, bounces, direct);
}

static double trench_added_at(double H, int W, double px, double bias, double rho, int bounces,
                              double *direct) {
  enum { PER_WALL = 200, PER_FLOOR = 900, N = 2 * PER_WALL + PER_FLOOR };
  static strip s[N];
  static int segment[N];
  const int n = trench_strips(H, W, PER_WALL, PER_FLOOR, s, segment);
  double *F = malloc((size_t)n * (size_t)n * sizeof(double));
  double *sky = malloc((size_t)n * sizeof(double)), *J = calloc((size_t)n, sizeof(double));
  double *next = malloc((size_t)n * sizeof(double)), *len = malloc((size_t)n * sizeof(double));
  cr_assert(F && sky && J && next && len);
  for (int i = 0; i < n; i++) len[i] = distance2d(s[i].ax, s[i].az, s[i].bx, s[i].bz);
  for (int i = 0; i < n; i++) {
    double seen = 0.0;
    for (int j = 0; j < n; j++) {
      double f = 0.0;
      if (segment[i] != segment[j]) /* strips of one straight side see nothing of each other */
        f = crossed_strings(&s[i], &s[j]);
      F[(size_t)i * (size_t)n + (size_t)j] = f;
      seen += f;
    }
    cr_assert(seen <= 1.0 + 1e-9, "strip %d sees %g of the cavity", i, seen);
    sky[i] = 1.0 - seen;
  }
  for (int i = 0; i < n; i += 97) /* reciprocity, L_i F_ij = L_j F_ji */
    for (int j = 0; j < n; j += 89)
      cr_assert_float_eq(len[i] * F[(size_t)i * (size_t)n + (size_t)j],
                         len[j] * F[(size_t)j * (size_t)n + (size_t)i], 1e-12);
  for (int it = 0; bounces ? it < bounces : it < 2000; it++) {
    double change = 0.0;
    for (int i = 0; i < n; i++) {
      double e = sky[i];
      for (int j = 0; j < n; j++) e += F[(size_t)i * (size_t)n + (size_t)j] * J[j];
      next[i] = rho * e;
      change = fmax(change, fabs(next[i] - J[i]));
    }
    memcpy(J, next, (size_t)n * sizeof(double));
    if (!bounces && change < 1e-14) break;
  }
  double added = 0.0;
  for (int i = 0; i < n; i++) {
    double ax = s[i].ax, az = s[i].az, bx = s[i].bx, bz = s[i].bz;
    if (fmax(az, bz) <= bias) continue;
    if (az < bias) ax += (bx - ax) * (bias - az) / (bz - az), az = bias;
    if (bz < bias) bx += (ax - bx) * (bias - bz) / (az - bz), bz = bias;
    const double sa = (ax - px) / distance2d(px, bias, ax, az);
    const double sb = (bx - px) / distance2d(px, bias, bx, bz);
    added += fabs(sb - sa) / 2.0 * J[i];
  }
  if (direct) { /* the opening, from the top of one wall to the other (a point seeing both) */
    const double sa = (0.0 - px) / distance2d(px, bias, 0.0, H);
    const double sb = (W - 1.0 - px) / distance2d(px, bias, W - 1.0, H);
    *direct = (sb - sa) / 2.0;
  }
  free(F), free(sky), free(J), free(next), free(len);
  return added;
}

Test(bounce, trench_matches_the_exact_2d_radiosity) {
  const int W = 21, H = 8; /* floor 19 texels wide between walls 8 high */
  const double rho = 0.5, bias = 0.55;
  bb_image height = harness_field(W, H, 0.0f);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) *bb_image_texel(&height, x, y) = (x == 0 || x == W - 1) ? 1.0f : 0.0f;
  bb_bake_options o = options((float)H, 1024, 0.0);
  o.smooth.addressing = BB_ADDRESS_CLAMP;
  bb_bake_result base = harness_bake(&height, &o);
  const int xc = (W - 1) / 2, yc = H / 2;
  double direct;
  const double one = trench_added(H, W, bias, rho, 1, &direct);
  const double two = trench_added(H, W, bias, rho, 2, NULL), all = trench_added(H, W, bias, rho, 0, NULL);
  cr_expect(0.0 < one && one < two && two < all, "bounces only add: %g %g %g", one, two, all);
  /* the geometry: without bounces, the bake's own known accuracy */
  cr_expect(fabs(at(&base.ao, xc, yc)[0] - direct) <= 0.0015, "ao %.5f, the opening's view %.5f",
            (double)at(&base.ao, xc, yc)[0], direct);
  const int counts[] = {1, 0};
  const double exact[] = {one, all};
  for (size_t i = 0; i < 2; i++) {
    o.bounce_albedo = rho;
    o.bounces = counts[i];
    bb_bake_result r = harness_bake(&height, &o);
    const double added = at(&r.ao, xc, yc)[0] - at(&base.ao, xc, yc)[0];
    cr_log_info("trench, %s: added %.5f, exact %.5f (%+.5f)", counts[i] ? "1 bounce" : "converged",
                added, exact[i], added - exact[i]);
    cr_expect(fabs(added - exact[i]) <= 0.002, "%s: the bounce adds %.5f to ao, exactly %.5f",
              counts[i] ? "1 bounce" : "to convergence", added, exact[i]);
    bb_bake_result_free(&r);
  }
  bb_bake_result_free(&base);
  bb_image_free(&height);
}

/* The wall case: walls many texels high rising within one texel (a trench
 * cut into a plateau at a high scale). The light the bounce adds to ao, to
 * convergence, on the floor's centre line and one texel from a wall's
 * foot, against the exact 2D radiosity. A wall's light is its column's,
 * sampled at 5 heights from its foot to its top, so the light that falls
 * off fast below the top is seen where it is; between the samples it is
 * linear. Walls 8 high are within 0.0025; deeper ones a little too bright
 * still (docs/accuracy.md "The wall case"), and this holds what they are
 * now: within 10% of the exact added light at 32 high, 25% at 64. */
Test(bounce, deep_trench_walls_against_the_exact_2d_radiosity, .timeout = 120) {
  const int W = 21;
  const double heights[] = {8.0, 32.0, 64.0}, rho = 0.5, bias = 0.55;
  const double within[] = {0.0, 0.1, 0.25}; /* of the exact added light, beyond 0.0025 */
  const int xs[] = {(W - 1) / 2, 2};
  bb_image height = harness_field(W, 8, 0.0f);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < W; x++) *bb_image_texel(&height, x, y) = (x == 0 || x == W - 1) ? 1.0f : 0.0f;
  for (size_t i = 0; i < sizeof heights / sizeof heights[0]; i++) {
    bb_bake_options o = options((float)heights[i], 1024, 0.0);
    o.smooth.addressing = BB_ADDRESS_CLAMP;
    bb_bake_result base = harness_bake(&height, &o);
    o.bounce_albedo = rho;
    bb_bake_result r = harness_bake(&height, &o);
    for (size_t k = 0; k < 2; k++) {
      const int x = xs[k];
      const double exact = trench_added_at(heights[i], W, x, bias, rho, 0, NULL);
      const double added = at(&r.ao, x, 4)[0] - at(&base.ao, x, 4)[0];
      cr_log_info("wall %g high, x %d: added %.5f, exact %.5f (%+.5f, %+.1f%%)", heights[i], x,
                  added, exact, added - exact, 100.0 * (added - exact) / exact);
      cr_expect(fabs(added - exact) <= within[i] * exact + 0.0025,
                "walls %g high, x %d: the bounce adds %.5f to ao, exactly %.5f", heights[i], x,
                added, exact);
    }
    bb_bake_result_free(&base);
    bb_bake_result_free(&r);
  }
  bb_image_free(&height);
}

/* ---- against the path tracer (tools/bounce_ref), loosely -------------------

 * The tight comparison is tools/bench_bounce.sh's; here a small map and
 * 4096 paths per texel (standard error about 0.001) must agree within
 * 0.004 (mean |error|) and 0.0025 (bias) in ao and every ssbump channel. */
static void tool_path(const char *tool, char *out, size_t cap) {
  const char *bin = getenv("BB_BIN");
  char dir[1024];
  snprintf(dir, sizeof dir, "%s", bin && *bin ? bin : "build/bumpbake");
  char *slash = strrchr(dir, '/');
  if (slash) slash[1] = '\0';
  else dir[0] = '\0';
  snprintf(out, cap, "%stools/%s", dir, tool);
}

static int run_capture(char *const argv[], char *out, size_t cap) {
  int pipefd[2];
  cr_assert_eq(pipe(pipefd), 0);
  const pid_t pid = fork();
  cr_assert_neq(pid, -1);
  if (pid == 0) {
    dup2(pipefd[1], 1);
    const int quiet = open("/dev/null", O_WRONLY);
    if (quiet >= 0) dup2(quiet, 2);
    close(pipefd[0]);
    execv(argv[0], argv);
    _exit(127);
  }
  close(pipefd[1]);
  size_t got = 0;
  ssize_t n;
  while (got + 1 < cap && (n = read(pipefd[0], out + got, cap - 1 - got)) > 0) got += (size_t)n;
  out[got] = '\0';
  close(pipefd[0]);
  int status;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

Test(bounce, agrees_with_the_path_tracer_on_a_small_map, .timeout = 600) {
  char dir[] = "/tmp/bb-bounce-XXXXXX", ref[1100], ao[1100], ss[1100], pair[2300], tool[1100];
  cr_assert_not_null(mkdtemp(dir));
  const char *dirfix = getenv("BB_FIXTURES");
  char map[1100];
  snprintf(map, sizeof map, "%s/noise_96x80.png", dirfix && *dirfix ? dirfix : "fixtures");
  snprintf(ref, sizeof ref, "%s/ref.exr", dir);
  snprintf(ao, sizeof ao, "%s/ao.exr", dir);
  snprintf(ss, sizeof ss, "%s/ss.exr", dir);
  tool_path("bounce_ref", tool, sizeof tool);
  char out[8192];
  char *trace[] = {tool, "trace", map, "8", "-o", ref, "--rho", "0.6", "--paths", "4096",
                   "--stride", "8", NULL};
  cr_assert_eq(run_capture(trace, out, sizeof out), 0, "%s failed: %s", tool, out);
  bb_image h;
  bb_error err;
  cr_assert_eq(bb__height_load(map, BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, &err), BB_OK, "%s", err.message);
  bb_bake_options o = options(8.0f, 256, 0.6);
  o.normal_filter = BB_NORMAL_VALVE;
  bb_bake_result r = harness_bake(&h, &o);
  const bb_write_options wo = {BB_DEPTH_FLOAT, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(ao, &r.ao, &wo, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__image_write(ss, &r.ssbump, &wo, &err), BB_OK, "%s", err.message);
  snprintf(pair, sizeof pair, "bake=%s,%s", ao, ss);
  char *compare[] = {tool, "compare", ref, map, "8", pair, NULL};
  cr_assert_eq(run_capture(compare, out, sizeof out), 0, "compare failed: %s", out);
  /* {"reference":..,"results":[{"name":"bake","channels":[{"mean":..,"mean_abs":..},...]}]} */
  const char *p = strstr(out, "\"channels\":[");
  cr_assert_not_null(p, "%s", out);
  for (int c = 0; c < 4; c++) {
    double mean, mean_abs;
    p = strstr(p, "{\"mean\":");
    cr_assert_not_null(p, "%s", out);
    cr_assert_eq(sscanf(p, "{\"mean\":%lf,\"mean_abs\":%lf", &mean, &mean_abs), 2, "%s", p);
    cr_log_info("against the path tracer, channel %d: mean |error| %.5f, bias %+.5f", c, mean_abs,
                mean);
    cr_expect(mean_abs <= 0.004 && fabs(mean) <= 0.0025,
              "channel %d (0 ao, then ssbump): mean |error| %.5f, bias %+.5f", c, mean_abs, mean);
    p++;
  }
  bb_bake_result_free(&r);
  bb_image_free(&h);
  unlink(ref), unlink(ao), unlink(ss), rmdir(dir);
}

/* ---- the coarse level ------------------------------------------------------ */

Test(bounce, the_coarse_level_is_chosen_by_size) {
  bb__bounce_options o;
  bb__bounce_options_init(&o);
  const struct { int w, h, addressing, want; } cases[] = {
      {256, 256, BB_ADDRESS_PERIODIC, 1}, {511, 300, BB_ADDRESS_CLAMP, 1},
      {512, 512, BB_ADDRESS_PERIODIC, 2}, {1024, 1024, BB_ADDRESS_PERIODIC, 2},
      {2048, 2048, BB_ADDRESS_PERIODIC, 2}, {2048, 64, BB_ADDRESS_PERIODIC, 2},
      {4096, 4096, BB_ADDRESS_PERIODIC, 4}, {8192, 8192, BB_ADDRESS_PERIODIC, 8},
      {16384, 1024, BB_ADDRESS_PERIODIC, 8}, {1025, 1024, BB_ADDRESS_PERIODIC, 1},
      {1025, 1024, BB_ADDRESS_CLAMP, 2}, {4096, 4098, BB_ADDRESS_PERIODIC, 2},
      {600, 3, BB_ADDRESS_CLAMP, 1}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    cr_expect_eq(bb__bounce_level(&o, cases[i].w, cases[i].h, (bb_addressing)cases[i].addressing),
                 cases[i].want, "%dx%d (%s)", cases[i].w, cases[i].h,
                 cases[i].addressing == BB_ADDRESS_PERIODIC ? "periodic" : "clamp");
  o.level = 4;
  cr_expect_eq(bb__bounce_level(&o, 256, 256, BB_ADDRESS_PERIODIC), 4);
  o.level = 1;
  cr_expect_eq(bb__bounce_level(&o, 4096, 4096, BB_ADDRESS_PERIODIC), 1);
}

/* noise_96x80 tiled 6 times along x: 576 x 80, periodic, so its bounce is
 * found on the coarse level (every other vertex), while the tile's own
 * (96 x 80) is the map's level. The light each adds must agree, texel by
 * texel of the tiling against the tile: within 0.0002 in mean |error| in ao
 * and 0.0025 in each ssbump channel, biases within a third of that, and no
 * texel further than 0.01 (ao) and 0.06 (ssbump) (measured: 0.00005, 0.0015
 * to 0.0018, largest 0.0054 and 0.049; docs/accuracy.md "The coarse
 * level"). A texel the map's trace finds open to the whole sky gets
 * nothing. The direct maps are the bake's without the bounce. */
static bb_image tiled(const bb_image *h, int times) {
  bb_image t = harness_field(h->width * times, h->height, 0.0f);
  for (int y = 0; y < t.height; y++)
    for (int x = 0; x < t.width; x++) *bb_image_texel(&t, x, y) = at(h, x % h->width, y)[0];
  return t;
}

Test(bounce, the_coarse_level_agrees_with_the_maps_own, .timeout = 120) {
  bb_image h = load_fixture("noise_96x80.png");
  bb_image t = tiled(&h, 6);
  bb_bake_options o = options(8.0f, 256, 0.0);
  bb_bake_result tile0 = harness_bake(&h, &o), tiling0 = harness_bake(&t, &o);
  o.bounce_albedo = 0.6;
  bb_bake_result tile = harness_bake(&h, &o), tiling = harness_bake(&t, &o);
  const bb_map_kind kinds[2] = {BB_MAP_AO, BB_MAP_SSBUMP};
  const double mean_within[2] = {0.0002, 0.0025}, most_within[2] = {0.01, 0.06};
  for (int m = 0; m < 2; m++) {
    const bb_image *a0 = bb__bake_result_image(&tile0, kinds[m]), *a = bb__bake_result_image(&tile, kinds[m]);
    const bb_image *b0 = bb__bake_result_image(&tiling0, kinds[m]), *b = bb__bake_result_image(&tiling, kinds[m]);
    for (int c = 0; c < a->channels; c++) {
      double abs_sum = 0.0, sum = 0.0, most = 0.0, open_added = 0.0;
      for (int y = 0; y < t.height; y++)
        for (int x = 0; x < t.width; x++) {
          const double want = (double)at(a, x % h.width, y)[c] - (double)at(a0, x % h.width, y)[c];
          const double got = (double)at(b, x, y)[c] - (double)at(b0, x, y)[c];
          abs_sum += fabs(got - want), sum += got - want, most = fmax(most, fabs(got - want));
          if (m == 0 && at(b0, x, y)[c] >= 1.0f) open_added = fmax(open_added, got);
        }
      const double n = (double)t.width * t.height;
      cr_log_info("coarse level, %s channel %d: mean |error| %.5f, bias %+.5f, largest %.4f",
                  m ? "ssbump" : "ao", c, abs_sum / n, sum / n, most);
      cr_expect(abs_sum / n <= mean_within[m] && fabs(sum / n) <= mean_within[m] / 3.0 &&
                    most <= most_within[m],
                "%s channel %d: the coarse level's added light is %.5f from the map's own "
                "(bias %+.5f, largest %.4f)",
                m ? "ssbump" : "ao", c, abs_sum / n, sum / n, most);
      cr_expect_eq(open_added, 0.0, "a texel open to the whole sky got %g", open_added);
    }
  }
  /* the direct maps: the bake's without the bounce, bit for bit */
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (!(BB_MAPS_TRACED & BB_MAP_BIT(k)))
      cr_expect(same_image(bb__bake_result_image(&tiling0, (bb_map_kind)k),
                           bb__bake_result_image(&tiling, (bb_map_kind)k)),
                "%s differs with the bounce", bb_map_kind_get((bb_map_kind)k)->name);
  bb_bake_result_free(&tile0), bb_bake_result_free(&tiling0);
  bb_bake_result_free(&tile), bb_bake_result_free(&tiling);
  bb_image_free(&t), bb_image_free(&h);
}

/* On the coarse level too: any thread count gives the same bits; a
 * periodic shift by an even number of texels moves the coarse lattice with
 * the map, so it is close as on the map's level (0.001 in ao, 0.005 in
 * ssbump and bent; measured 0.0002 and 0.0023); by an odd number the
 * coarse level is made of the other vertices, a different (as good)
 * sampling of the surface: within 0.005 in ao and 0.07 in ssbump and bent
 * (measured 0.0038 and 0.056, at a texel or two of a steep slope). */
Test(bounce, the_coarse_level_is_deterministic_and_close_under_a_shift, .timeout = 120) {
  bb_image h = load_fixture("noise_96x80.png");
  bb_image t = tiled(&h, 6);
  const int W = t.width, H = t.height;
  bb_bake_options o = options(8.0f, 128, 0.5);
  o.trace.threads = 1;
  bb_bake_result one = harness_bake(&t, &o);
  o.trace.threads = 2;
  bb_bake_result two = harness_bake(&t, &o);
  expect_same_bake(&one, &two, "2 threads against 1 (coarse level)");
  const int shifts[2][2] = {{38, 12}, {37, 11}};
  const double within[2][2] = {{0.001, 0.005}, {0.005, 0.07}};
  for (int i = 0; i < 2; i++) {
    const int sx = shifts[i][0], sy = shifts[i][1];
    bb_image shifted = harness_field(W, H, 0.0f);
    for (int y = 0; y < H; y++)
      for (int x = 0; x < W; x++)
        *bb_image_texel(&shifted, (x + sx) % W, (y + sy) % H) = at(&t, x, y)[0];
    bb_bake_result s = harness_bake(&shifted, &o);
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
      const bb_image *a = bb__bake_result_image(&one, (bb_map_kind)k);
      const bb_image *b = bb__bake_result_image(&s, (bb_map_kind)k);
      if (!a->pixels) continue;
      double most = 0.0;
      for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
          const float *va = at(a, x, y), *vb = at(b, (x + sx) % W, (y + sy) % H);
          for (int c = 0; c < a->channels; c++) most = fmax(most, fabs((double)va[c] - (double)vb[c]));
        }
      const double w = k == BB_MAP_AO ? within[i][0] : (BB_MAPS_TRACED & BB_MAP_BIT(k) ? within[i][1] : 0.0);
      cr_log_info("coarse level, shift (%d, %d), %s: at most %.4g", sx, sy,
                  bb_map_kind_get((bb_map_kind)k)->name, most);
      cr_expect(most <= w, "shift (%d, %d), %s: differs by %g", sx, sy,
                bb_map_kind_get((bb_map_kind)k)->name, most);
    }
    bb_bake_result_free(&s);
    bb_image_free(&shifted);
  }
  bb_bake_result_free(&one), bb_bake_result_free(&two);
  bb_image_free(&t), bb_image_free(&h);
}
