/* test_bake.c: the whole bake (smooth -> normals -> trace -> derive) against
 * answers known on paper or by numerical integration of docs/conventions.md's
 * integrals, and its invariances. */
#include "trace/rayset.h"
#include "trace/testing.h"
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bumpbake.h"
#include "bake_harness.h"
#include "bake/bake_internal.h"
#include "trace/basis.h"
#include "trace/pyramid.h"
#include "trace/trace.h"

static const double PI = 3.14159265358979323846;

static bb_bake_options sharp_options(float scale, int rays) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = scale;
  o.rays = rays;
  o.smooth.radius_texels = 0;
  o.trace.bias_texels = 0.0;
  return o;
}

static const float *at(const bb_image *img, int x, int y) {
  return bb_image_texel(img, x, y);
}

Test(bake, flat_map_is_neutral_everywhere) {
  bb_image h = harness_field(13, 9, 0.0f);
  for (int i = 0; i < 13 * 9; i++) h.pixels[i] = 0.5f;
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 32.0f;
  bb_bake_result r = harness_bake(&h, &o);
  for (int y = 0; y < 9; y++)
    for (int x = 0; x < 13; x++) {
      const float *n = at(&r.normal, x, y), *w = at(&r.weights, x, y), *s = at(&r.ssbump, x, y);
      cr_assert_eq(n[0], 0.0f);
      cr_assert_eq(n[1], 0.0f);
      cr_assert_eq(n[2], 1.0f);
      cr_assert_eq(at(&r.ao, x, y)[0], 1.0f);
      for (int c = 0; c < 3; c++) {
        cr_assert_float_eq(w[c], 1.0 / 3.0, 1e-6);
        cr_assert_float_eq(s[c], 0.57735027, 1e-6);
      }
    }
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* ---- known answers: docs/conventions.md's integrals for a horizon t(phi) ---------

 * With the horizon's tangent t(phi) known in every azimuth, ao and vis_c
 * are integrals over phi of closed forms in elevation: for ao,
 * cos^2(atan t) / 2 = 1 / (2 (1 + t^2)); for a lobe max(0, w.B) (power 1),
 * the integral from max(atan t, where w.B turns positive) to pi/2 of
 * (a cos + c sin) cos, a = Bx cos(phi) + By sin(phi), c = Bz > 0. The
 * azimuth integral is a midpoint rule over 7200 azimuths. */
typedef double (*horizon_fn)(const void *ctx, double phi);

static double lobe_above(const double b[3], double phi, double t) {
  const double a = b[0] * cos(phi) + b[1] * sin(phi), c = b[2];
  const double start = fmax(atan(fmax(t, 0.0)), atan2(-a, c)), end = PI / 2;
  if (start >= end) return 0.0;
  return a * ((end - start) / 2 + (sin(2 * end) - sin(2 * start)) / 4) +
         c * (sin(end) * sin(end) - sin(start) * sin(start)) / 2;
}

static void known_answer(horizon_fn horizon, const void *ctx, double *ao, double vis[3]) {
  const int n = 7200;
  double open_ao = 0, open_vis[3] = {0}, all_vis[3] = {0};
  for (int i = 0; i < n; i++) {
    const double phi = 2 * PI * (i + 0.5) / n, t = fmax(horizon(ctx, phi), 0.0);
    open_ao += 1.0 / (1.0 + t * t);
    for (int c = 0; c < 3; c++) {
      double b[3];
      bb__basis_vector(c, b);
      open_vis[c] += lobe_above(b, phi, t);
      all_vis[c] += lobe_above(b, phi, 0.0);
    }
  }
  *ao = open_ao / n;
  for (int c = 0; c < 3; c++) vis[c] = open_vis[c] / all_vis[c];
}

/* ao and vis_c at texel (x, y) of a bake, against the known answer: vis_c
 * is read through ssbump = max(0, N.B_c) vis_c with the bake's own normal. */
static void expect_answer(const bb_bake_result *r, int x, int y, double ao, const double vis[3],
                          double tolerance, const char *what) {
  const double got_ao = at(&r->ao, x, y)[0];
  cr_log_info("%s: ao %+.5f", what, got_ao - ao);
  cr_expect(fabs(got_ao - ao) <= tolerance, "%s: ao %.5f, exact %.5f (tolerance %g)", what, got_ao,
            ao, tolerance);
  const float *n = at(&r->normal, x, y);
  for (int c = 0; c < 3; c++) {
    double b[3];
    bb__basis_vector(c, b);
    const double ndotb = n[0] * b[0] + n[1] * b[1] + n[2] * b[2];
    cr_assert_gt(ndotb, 0.1, "%s: the test needs every lobe facing the surface", what);
    const double got = at(&r->ssbump, x, y)[c] / ndotb;
    cr_log_info("%s: vis_%d %+.5f", what, c, got - vis[c]);
    cr_expect(fabs(got - vis[c]) <= tolerance, "%s: vis_%d %.5f, exact %.5f (tolerance %g)", what,
              c, got, vis[c], tolerance);
  }
}

/* The bake at the default 256 rays (16 slices) and at 1024 (32): the only
 * error left is the horizon of each slice's centre standing for its sector. */
static const struct {
  int rays;
  double tolerance;
} budgets[] = {{256, 0.005}, {1024, 0.0015}};

/* A trench: a flat floor between two straight walls of height H, d_left and
 * d_right texels from the texel, running on for ever (clamp mode). Along
 * phi the nearer wall's top is d / |cos(phi)| away: t = H |cos(phi)| / d,
 * so ao = (1 / sqrt(1 + (H / d_left)^2) + 1 / sqrt(1 + (H / d_right)^2)) / 2. */
typedef struct trench {
  double left, right, wall;
} trench;

static double trench_horizon(const void *ctx, double phi) {
  const trench *t = ctx;
  return t->wall * fabs(cos(phi)) / (cos(phi) < 0 ? t->left : t->right);
}

Test(bake, trench_floor_matches_the_exact_integrals) {
  const trench tr = {8, 12, 8}; /* walls at 45 and 34 degrees */
  const int w = (int)(tr.left + tr.right) + 1, h = 7, x0 = (int)tr.left, y0 = 3;
  bb_image height = harness_field(w, h, 0.0f);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) height.pixels[y * w + x] = (x == 0 || x == w - 1) ? 1.0f : 0.0f;
  double ao, vis[3];
  known_answer(trench_horizon, &tr, &ao, vis);
  const double closed = 0.5 * (1 / sqrt(1 + pow(tr.wall / tr.left, 2)) +
                               1 / sqrt(1 + pow(tr.wall / tr.right, 2)));
  cr_assert_float_eq(ao, closed, 1e-6, "the reference itself: %g vs %g", ao, closed);
  for (size_t i = 0; i < sizeof budgets / sizeof budgets[0]; i++) {
    bb_bake_options o = sharp_options((float)tr.wall, budgets[i].rays);
    o.smooth.addressing = BB_ADDRESS_CLAMP;
    bb_bake_result r = harness_bake(&height, &o);
    expect_answer(&r, x0, y0, ao, vis, budgets[i].tolerance, budgets[i].rays == 256 ? "trench, 256 rays" : "trench, 1024 rays");
    bb_bake_result_free(&r);
  }
  bb_image_free(&height);
}

/* A plane rising with slope s along +x (clamp mode): from a point on it, the
 * horizon along phi is the plane itself, t = max(0, s cos(phi)), and
 * ao = (1 + 1 / sqrt(1 + s^2)) / 2. */
static double slope_horizon(const void *ctx, double phi) {
  return *(const double *)ctx * cos(phi);
}

Test(bake, slope_matches_the_exact_integrals) {
  const int w = 61, h = 9, x0 = 30, y0 = 4;
  const float scale = 30.0f; /* z = scale * x / (w - 1): slope 0.5 */
  const double s = (double)scale / (w - 1);
  bb_image height = harness_field(w, h, 0.0f);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) height.pixels[y * w + x] = (float)x / (float)(w - 1);
  double ao, vis[3];
  known_answer(slope_horizon, &s, &ao, vis);
  cr_assert_float_eq(ao, 0.5 * (1 + 1 / sqrt(1 + s * s)), 1e-6);
  for (size_t i = 0; i < sizeof budgets / sizeof budgets[0]; i++) {
    bb_bake_options o = sharp_options(scale, budgets[i].rays);
    o.smooth.addressing = BB_ADDRESS_CLAMP;
    bb_bake_result r = harness_bake(&height, &o);
    expect_answer(&r, x0, y0, ao, vis, budgets[i].tolerance, budgets[i].rays == 256 ? "slope, 256 rays" : "slope, 1024 rays");
    bb_bake_result_free(&r);
  }
  bb_image_free(&height);
}

/* The centre of a cylindrical pit of radius R and depth D sees the sky
 * through a cone of half-angle atan(R / D): ao = sin^2(atan(R / D)) for a
 * round rim. The mesh's rim is stair-stepped, so the exact answer for this
 * surface takes its horizon in 7200 azimuths from the brute-force twin;
 * the round-rim formula is checked loosely beside it. */
typedef struct pit {
  const bb_pyramid *p;
  double x, y;
} pit;

static double pit_horizon(const void *ctx, double phi) {
  const pit *pt = ctx;
  const bb__ray r = {{pt->x, pt->y, 0.0}, {cos(phi), sin(phi), 0.0}};
  return bb__ray_horizon_brute(pt->p, &r, 100.0);
}

Test(bake, cylindrical_pit_centre_matches_the_exact_integrals) {
  const int size = 128, c = 64;
  const double radius = 40.0, depth = 40.0;
  bb_image h = harness_field(size, size, 0.0f), z = harness_field(size, size, 0.0f);
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++) {
      h.pixels[y * size + x] = hypot(x - c, y - c) < radius ? 0.0f : 1.0f;
      z.pixels[y * size + x] = (float)depth * h.pixels[y * size + x];
    }
  bb_pyramid *p = NULL;
  cr_assert_eq(bb__pyramid_build_all_cores(&z, BB_ADDRESS_PERIODIC, &p, NULL), BB_OK);
  const pit pt = {p, c, c};
  double ao, vis[3];
  known_answer(pit_horizon, &pt, &ao, vis);
  const double round_rim = pow(sin(atan(radius / depth)), 2.0);
  cr_assert_float_eq(ao, round_rim, 0.02, "stair-stepped %g, round %g", ao, round_rim);
  for (size_t i = 0; i < sizeof budgets / sizeof budgets[0]; i++) {
    bb_bake_options o = sharp_options((float)depth, budgets[i].rays);
    bb_bake_result r = harness_bake(&h, &o);
    expect_answer(&r, c, c, ao, vis, budgets[i].tolerance, budgets[i].rays == 256 ? "pit, 256 rays" : "pit, 1024 rays");
    bb_bake_result_free(&r);
  }
  bb_pyramid_free(p);
  bb_image_free(&z);
  bb_image_free(&h);
}

static void noise_field(bb_image *h, unsigned seed) {
  for (int i = 0; i < h->width * h->height; i++) {
    seed = seed * 1103515245u + 12345u;
    h->pixels[i] = (float)((seed >> 8) & 0xffff) / 65535.0f;
  }
}

static const bb_image *outputs(const bb_bake_result *r, int i) {
  const bb_image *all[] = {&r->filtered, &r->normal, &r->weights, &r->ssbump, &r->ao, &r->bent};
  return all[i];
}

/* A periodic shift of the input shifts every float output by the same
 * amount, bit for bit, with and without smoothing, on an odd size. */
Test(bake, periodic_shift_shifts_every_output) {
  const int w = 37, h = 23, sx = 11, sy = 5;
  const int radii[] = {0, 10};
  for (int ri = 0; ri < 2; ri++) {
    bb_image a = harness_field(w, h, 0.0f), b = harness_field(w, h, 0.0f);
    noise_field(&a, 7);
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) b.pixels[((y + sy) % h) * w + (x + sx) % w] = a.pixels[y * w + x];
    bb_bake_options o;
    bb__bake_options_init(&o);
    o.height_scale = 6.0f;
    o.slices = 8;
    o.smooth.radius_texels = radii[ri];
    o.smooth.threshold = 0.2f;
    bb_bake_result ra = harness_bake(&a, &o), rb = harness_bake(&b, &o);
    for (int i = 0; i < 6; i++) {
      const bb_image *ia = outputs(&ra, i), *ib = outputs(&rb, i);
      for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
          cr_assert_eq(memcmp(at(ia, x, y), at(ib, (x + sx) % w, (y + sy) % h),
                              sizeof(float) * (size_t)ia->channels),
                       0, "output %d, radius %d, texel (%d, %d)", i, radii[ri], x, y);
    }
    bb_bake_result_free(&ra);
    bb_bake_result_free(&rb);
    bb_image_free(&a);
    bb_image_free(&b);
  }
}

static size_t image_bytes(const bb_image *img) {
  return (size_t)img->width * (size_t)img->height * (size_t)img->channels * sizeof(float);
}

/* Every stage (smooth, normals, weights, pyramid, ray set, trace, derive)
 * runs on the bake's threads; its work items do not depend on the split, so
 * any count gives the same bits, on an odd size with more rows than
 * threads and fewer (7 threads, 31 rows of 4-row normal bands). */
Test(bake, bit_identical_for_any_thread_count) {
  bb_image h = harness_field(50, 31, 0.0f);
  noise_field(&h, 3);
  const int counts[] = {1, 2, 3, 7, 64};
  enum { RUNS = sizeof counts / sizeof counts[0] };
  bb_bake_result r[RUNS];
  for (int t = 0; t < RUNS; t++) {
    bb_bake_options o;
    bb__bake_options_init(&o);
    o.height_scale = 8.0f;
    o.slices = 10;
    o.smooth.radius_texels = 4;
    o.smooth.threshold = 0.3f;
    o.trace.threads = counts[t];
    r[t] = harness_bake(&h, &o);
    cr_assert_eq(r[t].threads, counts[t], "the result says how many threads ran");
  }
  for (int t = 1; t < RUNS; t++)
    for (int i = 0; i < 6; i++) {
      const bb_image *a = outputs(&r[0], i), *b = outputs(&r[t], i);
      cr_assert_eq(memcmp(a->pixels, b->pixels, image_bytes(a)), 0, "output %d, %d threads", i,
                   counts[t]);
    }
  for (int t = 0; t < RUNS; t++) bb_bake_result_free(&r[t]);
  bb_image_free(&h);
}

/* A bake makes only the maps it is asked for (vis too when it traces), and
 * each is the same bits as in a bake of every map. */
Test(bake, output_mask_makes_only_what_was_asked) {
  bb_image h = harness_field(24, 17, 0.0f);
  noise_field(&h, 5);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 6.0f;
  o.slices = 6;
  o.normal_y_up = 1; /* the flip applies to what is kept, once */
  bb_bake_result all = harness_bake(&h, &o);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    o.outputs = BB_MAP_BIT(k);
    bb_bake_result one = harness_bake(&h, &o);
    const int traced = bb_map_kind_get((bb_map_kind)k)->needs_trace;
    for (int j = 0; j < BB_MAP_BAKED_COUNT; j++) {
      const bb_image *img = bb__bake_result_image(&one, (bb_map_kind)j);
      if (j != k) {
        cr_assert_null(img->pixels, "asked %d, made %d", k, j);
        continue;
      }
      const bb_image *ref = bb__bake_result_image(&all, (bb_map_kind)j);
      cr_assert_eq(img->channels, ref->channels);
      cr_assert_eq(memcmp(img->pixels, ref->pixels, image_bytes(ref)), 0, "kind %d", k);
    }
    cr_assert_eq(one.vis.pixels != NULL, traced, "vis only with a trace (kind %d)", k);
    cr_assert_eq(one.rayset_id[0] != '\0', traced, "ray set only with a trace (kind %d)", k);
    bb_bake_result_free(&one);
  }
  /* Without a traced map, the trace's options are not even checked. */
  o.outputs = BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_FILTERED);
  o.rays = 0;
  bb_bake_result r = harness_bake(&h, &o);
  cr_assert_not_null(r.normal.pixels);
  cr_assert_not_null(r.filtered.pixels);
  bb_bake_result_free(&r);
  bb_bake_result_free(&all);
  bb_image_free(&h);
}

/* Progress callbacks that cancel after `after` calls (never when < 0). */
typedef struct cancel_state {
  int calls, after;
  long last_done, last_total;
} cancel_state;

static int cancel_after(void *user, long done, long total) {
  cancel_state *c = user;
  c->last_done = done;
  c->last_total = total;
  return c->after >= 0 && ++c->calls > c->after;
}

Test(bake, progress_callback_cancels_and_nothing_is_returned) {
  bb_image h = harness_field(40, 30, 0.0f);
  noise_field(&h, 9);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 8.0f;
  o.slices = 16;
  /* Going on: every slice reported, the bake whole. */
  cancel_state go = {0, -1, 0, 0};
  o.trace.progress = cancel_after;
  o.trace.progress_user = &go;
  bb_bake_result r = harness_bake(&h, &o);
  cr_assert_eq(go.last_done, 16);
  cr_assert_eq(go.last_total, 16);
  bb_bake_result_free(&r);
  /* Cancelled at the first report, and at the last one. */
  for (int after = 0; after < 2; after++) {
    cancel_state stop = {0, after == 0 ? 0 : 7, 0, 0};
    o.trace.progress_user = &stop;
    bb_error err;
    memset(&r, 0xff, sizeof r); /* every field must be cleared */
    cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_CANCELLED);
    cr_assert_str_eq(err.message, "bake: cancelled by the progress callback");
    cr_assert_str_eq(bb_status_name(BB_ERR_CANCELLED), "cancelled");
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      cr_assert_null(bb__bake_result_image(&r, (bb_map_kind)k)->pixels, "kind %d", k);
    cr_assert_null(r.vis.pixels);
    bb_bake_result_free(&r);
  }
  bb_image_free(&h);
}

/* Smoothing and normals report no progress but are cancel points: a bake
 * of the normal map alone (no trace) calls the callback with (0, 0), a
 * checkpoint, and stops when it says so. */
Test(bake, smoothing_and_normals_are_cancel_points) {
  bb_image h = harness_field(64, 48, 0.0f);
  noise_field(&h, 5);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 8.0f;
  o.outputs = BB_MAP_BIT(BB_MAP_NORMAL);
  cancel_state go = {0, -1, -1, -1};
  o.trace.progress = cancel_after;
  o.trace.progress_user = &go;
  bb_bake_result r = harness_bake(&h, &o);
  cr_assert_eq(go.last_done, 0);
  cr_assert_eq(go.last_total, 0, "a checkpoint, not progress");
  bb_bake_result_free(&r);
  cancel_state stop = {0, 0, -1, -1};
  o.trace.progress_user = &stop;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_CANCELLED);
  cr_assert_str_eq(err.message, "bake: cancelled by the progress callback");
  cr_assert_null(r.normal.pixels);
  bb_image_free(&h);
}

/* A region is traced by marches on the thread pool, which polls the
 * callback; cancelling there stops the workers and returns no image. */
Test(bake, progress_callback_cancels_a_region_trace) {
  bb_image h = harness_field(64, 64, 0.0f);
  noise_field(&h, 4);
  for (int i = 0; i < 64 * 64; i++) h.pixels[i] *= 20.0f;
  bb_pyramid *p = NULL;
  bb_rayset rs;
  cr_assert_eq(bb__pyramid_build_all_cores(&h, BB_ADDRESS_PERIODIC, &p, NULL), BB_OK);
  cr_assert_eq(bb__rayset_make(64, 1.0, NULL, 0, &rs, NULL), BB_OK);
  bb_trace_options t;
  bb__trace_options_init(&t);
  t.region = (bb_region){0, 0, 64, 64};
  t.threads = 2;
  cancel_state stop = {0, 0, 0, 0};
  t.progress = cancel_after;
  t.progress_user = &stop;
  bb_image vis;
  bb_error err;
  cr_assert_eq(bb__trace_occlusion(p, &rs, &t, &vis, NULL, &err), BB_ERR_CANCELLED);
  cr_assert(strstr(err.message, "cancelled"), "%s", err.message);
  cr_assert_null(vis.pixels);
  cr_assert_geq(stop.calls, 1);
  bb__rayset_release(&rs);
  bb_pyramid_free(p);
  bb_image_free(&h);
}

/* The ranges the command line used to check alone are the library's. */
Test(bake, options_check_holds_every_limit) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 4.0f;
  bb_error err;
  cr_assert_eq(bb__bake_options_check(&o, &err), BB_OK, "%s", err.message);
  static const struct {
    int field; /* 0 radius, 1 threads, 2 bias, 3 power, 4 outputs */
    double ok, bad;
    const char *message;
  } cases[] = {
      {0, 4096, 4097, "bake: filter radius must be in 0..4096 (got 4097)"},
      {0, 0, -1, "bake: filter radius must be in 0..4096 (got -1)"},
      {1, 4096, 4097, "bake: threads must be in 0..4096 (got 4097)"},
      {1, 0, -1, "bake: threads must be in 0..4096 (got -1)"},
      {2, 1e6, 2e6, "bake: bias must be in 0..1e6 (got 2e6)"},
      {2, 0, -1, "bake: bias must be in 0..1e6 (got -1)"},
      {3, 1e6, 1.5e6, "bake: power must be in 1..1e6 (got 1.5e6)"},
      {3, 1, 0.5, "bake: power must be in 1..1e6 (got 0.5)"},
      {4, BB_MAPS_BAKED, 0, "bake: outputs must be a non-empty set"},
      {4, 1, BB_MAPS_BAKED + 1, "bake: outputs must be a non-empty set"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    for (int bad = 0; bad < 2; bad++) {
      bb_bake_options c = o;
      const double v = bad ? cases[i].bad : cases[i].ok;
      switch (cases[i].field) {
      case 0: c.smooth.radius_texels = (int)v; break;
      case 1: c.trace.threads = (int)v; break;
      case 2: c.trace.bias_texels = v; break;
      case 3: c.power = v; break;
      default: c.outputs = (unsigned)v; break;
      }
      memset(&err, 0, sizeof err);
      bb_status st = bb__bake_options_check(&c, &err);
      if (!bad) {
        cr_assert_eq(st, BB_OK, "case %zu: %s", i, err.message);
        continue;
      }
      cr_assert_eq(st, BB_ERR_ARGUMENT, "case %zu", i);
      cr_assert(strncmp(err.message, cases[i].message, strlen(cases[i].message)) == 0,
                "case %zu: %s", i, err.message);
      /* bb__bake_checked refuses them the same way, before any work. */
      bb_image h = harness_field(4, 4, 0.0f);
      bb_bake_result r;
      bb_error err2;
      cr_assert_eq(bb__bake_checked(&h, &c, &r, &err2), BB_ERR_ARGUMENT);
      cr_assert_str_eq(err2.message, err.message);
      bb_image_free(&h);
    }
}

Test(bake, rejects_bad_options) {
  bb_image h = harness_field(4, 4, 0.0f);
  bb_bake_options o;
  bb__bake_options_init(&o);
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_ARGUMENT, "scale 0 must be refused");
  o.height_scale = 1.0f;
  o.power = 0.5;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  o.power = 1.0;
  o.trace.bias_texels = -0.1;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  o.trace.bias_texels = 0.55;
  o.slices = BB_MAX_SLICES + 1;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "slices") != NULL, "%s", err.message);
  bb_image_free(&h);
}

/* Finite heights whose product with the scale leaves the float range are
 * refused before any stage, and the message names the product, not a later
 * stage's symptom (it once read "pyramid: non-finite height"). */
Test(bake, scale_times_height_overflow_is_named) {
  bb_image h = harness_field(4, 4, 0.0f);
  *bb_image_texel(&h, 2, 1) = 3.0e38f;
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 2.0f;
  o.rays = 4;
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_VALUE);
  cr_assert(strstr(err.message, "height scale 2") && strstr(err.message, "(2, 1)") &&
                strstr(err.message, "3e+38"),
            "%s", err.message);
  cr_assert_null(r.normal.pixels);
  /* At the limit itself the bake runs. */
  *bb_image_texel(&h, 2, 1) = (float)(BB_MAX_HEIGHT_TEXELS / 4.0);
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_OK, "%s", err.message);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}
