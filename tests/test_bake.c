/* test_bake.c: the whole bake (smooth -> normals -> trace -> derive) against
 * answers known on paper or by numerical integration of CONVENTIONS'
 * integrals, and its invariances. */
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bumpbake.h"

static const double PI = 3.14159265358979323846;

static bb_image field(int w, int h) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  return img;
}

static bb_bake_result bake(const bb_image *h, const bb_bake_options *o) {
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb_bake(h, o, &r, &err), BB_OK, "%s", err.message);
  return r;
}

static bb_bake_options sharp_options(float scale, int rays) {
  bb_bake_options o;
  bb_bake_options_init(&o);
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
  bb_image h = field(13, 9);
  for (int i = 0; i < 13 * 9; i++) h.pixels[i] = 0.5f;
  bb_bake_options o;
  bb_bake_options_init(&o);
  o.height_scale = 32.0f;
  bb_bake_result r = bake(&h, &o);
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

/* The centre of a cylindrical pit of radius R and depth D sees the sky
 * through a cone of half-angle atan(R / D): ao = sin^2(atan(R / D)). The rim
 * is stair-stepped, so it lies within half a texel of R. */
Test(bake, cylindrical_pit_centre_ao) {
  const int size = 96, c = 48;
  const double radius = 24.0, depth = 20.0;
  bb_image h = field(size, size);
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++)
      h.pixels[y * size + x] = hypot(x - c, y - c) < radius ? 0.0f : 1.0f;
  bb_bake_options o = sharp_options((float)depth, 1024);
  bb_bake_result r = bake(&h, &o);
  const double expected = pow(sin(atan(radius / depth)), 2.0);
  cr_assert_float_eq(at(&r.ao, c, c)[0], expected, 0.02, "ao %g, expected %g",
                     (double)at(&r.ao, c, c)[0], expected);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* A floor boxed in by walls of height H whose tops lie at distances
 * (right, left, down, up) from the texel, extended to infinity by clamp
 * addressing. A direction escapes iff it clears the first wall top it meets:
 * tan(elevation) * distance > H. */
typedef struct box {
  double right, left, down, up, wall;
} box;

static int blocked_in_box(const box *b, double dx, double dy, double dz) {
  const double horizontal = hypot(dx, dy);
  const double cx = dx / horizontal, cy = dy / horizontal;
  double t = INFINITY;
  if (cx > 0) t = fmin(t, b->right / cx);
  if (cx < 0) t = fmin(t, b->left / -cx);
  if (cy > 0) t = fmin(t, b->down / cy);
  if (cy < 0) t = fmin(t, b->up / -cy);
  return dz / horizontal * t <= b->wall;
}

/* CONVENTIONS' ao and vis_c (power 1) by a fine midpoint rule over the
 * upper hemisphere. */
static void box_integrals(const box *b, double *ao, double vis[3]) {
  double open_ao = 0, all_ao = 0, open_vis[3] = {0}, all_vis[3] = {0};
  const int nz = 600, nphi = 1200;
  for (int i = 0; i < nz; i++)
    for (int j = 0; j < nphi; j++) {
      const double z = (i + 0.5) / nz, phi = 2 * PI * (j + 0.5) / nphi, r = sqrt(1 - z * z);
      const double d[3] = {r * cos(phi), r * sin(phi), z};
      const int open = !blocked_in_box(b, d[0], d[1], d[2]);
      all_ao += z;
      open_ao += open * z;
      for (int c = 0; c < 3; c++) {
        double bv[3];
        bb_basis_vector(c, bv);
        const double lobe = fmax(0.0, d[0] * bv[0] + d[1] * bv[1] + d[2] * bv[2]);
        all_vis[c] += lobe;
        open_vis[c] += open * lobe;
      }
    }
  *ao = open_ao / all_ao;
  for (int c = 0; c < 3; c++) vis[c] = open_vis[c] / all_vis[c];
}

Test(bake, floor_between_walls_matches_the_integrals_per_channel) {
  const box b = {.right = 4, .left = 9, .down = 6, .up = 14, .wall = 10};
  const int w = (int)(b.left + b.right) + 1, h = (int)(b.up + b.down) + 1;
  const int x0 = (int)b.left, y0 = (int)b.up;
  bb_image height = field(w, h);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      height.pixels[y * w + x] = (x == 0 || y == 0 || x == w - 1 || y == h - 1) ? 1.0f : 0.0f;
  bb_bake_options o = sharp_options((float)b.wall, 1024);
  o.smooth.addressing = BB_ADDRESS_CLAMP;
  bb_bake_result r = bake(&height, &o);
  double ao, vis[3];
  box_integrals(&b, &ao, vis);
  cr_assert_float_eq(at(&r.ao, x0, y0)[0], ao, 0.02, "ao %g, expected %g",
                     (double)at(&r.ao, x0, y0)[0], ao);
  for (int c = 0; c < 3; c++) /* flat floor: N = (0, 0, 1), so s_c = vis_c / sqrt(3) */
    cr_assert_float_eq(at(&r.ssbump, x0, y0)[c] * sqrt(3.0), vis[c], 0.02,
                       "channel %d: vis %g, expected %g", c,
                       at(&r.ssbump, x0, y0)[c] * sqrt(3.0), vis[c]);
  /* The near wall is on the +y (down) side: it darkens B1, whose light comes
   * from +y, more than B2, whose light comes from -y. */
  cr_assert_lt(at(&r.ssbump, x0, y0)[1], at(&r.ssbump, x0, y0)[2] - 0.05);
  bb_bake_result_free(&r);
  bb_image_free(&height);
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
    bb_image a = field(w, h), b = field(w, h);
    noise_field(&a, 7);
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) b.pixels[((y + sy) % h) * w + (x + sx) % w] = a.pixels[y * w + x];
    bb_bake_options o;
    bb_bake_options_init(&o);
    o.height_scale = 6.0f;
    o.rays = 64;
    o.smooth.radius_texels = radii[ri];
    o.smooth.threshold = 0.2f;
    bb_bake_result ra = bake(&a, &o), rb = bake(&b, &o);
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

Test(bake, bit_identical_for_one_two_and_three_threads) {
  bb_image h = field(50, 31);
  noise_field(&h, 3);
  bb_bake_result r[3];
  for (int t = 0; t < 3; t++) {
    bb_bake_options o;
    bb_bake_options_init(&o);
    o.height_scale = 8.0f;
    o.rays = 100;
    o.trace.threads = t + 1;
    r[t] = bake(&h, &o);
  }
  for (int t = 1; t < 3; t++)
    for (int i = 0; i < 6; i++) {
      const bb_image *a = outputs(&r[0], i), *b = outputs(&r[t], i);
      size_t bytes = (size_t)a->width * (size_t)a->height * (size_t)a->channels * sizeof(float);
      cr_assert_eq(memcmp(a->pixels, b->pixels, bytes), 0, "output %d, %d threads", i, t + 1);
    }
  for (int t = 0; t < 3; t++) bb_bake_result_free(&r[t]);
  bb_image_free(&h);
}

Test(bake, rejects_bad_options) {
  bb_image h = field(4, 4);
  bb_bake_options o;
  bb_bake_options_init(&o);
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb_bake(&h, &o, &r, &err), BB_ERR_ARGUMENT, "scale 0 must be refused");
  o.height_scale = 1.0f;
  o.power = 0.5;
  cr_assert_eq(bb_bake(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  o.power = 1.0;
  o.trace.bias_texels = -0.1;
  cr_assert_eq(bb_bake(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  bb_image_free(&h);
}
