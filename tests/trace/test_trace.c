/* test_trace.c: the max-mip march against its brute-force twin, hand-made
 * rays with known answers, and the batch trace's invariances. */
#include "trace/rayset.h"
#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bumpbake.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/sweep.h"
#include "trace/testing.h"
#include "trace/trace.h"

/* xorshift64*: a small deterministic generator for the property tests. */
static uint64_t rng_state;
static double rnd(void) {
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

/* A random field of one of three kinds: white noise, quantised noise (flat
 * plateaus and exact ties) or a few smooth bumps, times scale. */
static bb_image random_field(int w, int h, float scale, int kind) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  double fx = 1 + floor(rnd() * 3), fy = 1 + floor(rnd() * 3), ph = rnd() * 6.28;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double v;
      if (kind == 0) v = rnd();
      else if (kind == 1) v = floor(rnd() * 4) / 4;
      else v = 0.5 + 0.25 * sin(6.283 * fx * x / w + ph) * cos(6.283 * fy * y / h) + 0.1 * rnd();
      img.pixels[y * w + x] = (float)(scale * v);
    }
  return img;
}

static bb_pyramid *pyramid_of(const bb_image *z, bb_addressing a) {
  bb_pyramid *p = NULL;
  bb_error err;
  cr_assert_eq(bb__pyramid_build_all_cores(z, a, &p, &err), BB_OK, "%s", err.message);
  return p;
}

/* A random ray: from a vertex lifted by a random bias, or from anywhere
 * above the field; elevation from grazing (0.5 deg) to steep. */
static bb__ray random_ray(const bb_image *z) {
  bb__ray r;
  int vx = (int)(rnd() * z->width), vy = (int)(rnd() * z->height);
  if (rnd() < 0.7) {
    r.origin[0] = vx;
    r.origin[1] = vy;
    r.origin[2] = z->pixels[vy * z->width + vx] + (rnd() < 0.2 ? 0.0 : rnd());
  } else {
    r.origin[0] = rnd() * z->width;
    r.origin[1] = rnd() * z->height;
    r.origin[2] = z->pixels[vy * z->width + vx] + rnd() * 2.0;
  }
  double phi = rnd() * 6.283185307179586, elev = (0.5 + rnd() * 60.0) * 3.14159265 / 180;
  r.direction[0] = cos(phi) * cos(elev);
  r.direction[1] = sin(phi) * cos(elev);
  r.direction[2] = sin(elev);
  return r;
}

Test(trace, maxmip_equals_brute_force_on_random_rays) {
  const int sizes[][2] = {{1, 1}, {2, 3}, {5, 5}, {7, 13}, {16, 16}, {17, 9}, {31, 33}, {64, 40}};
  const float scales[] = {0.5f, 2.0f, 8.0f, 64.0f};
  rng_state = 0x9E3779B97F4A7C15ULL;
  long rays = 0, blocked = 0;
  for (int a = 0; a < 2; a++)
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++)
      for (size_t ci = 0; ci < sizeof scales / sizeof scales[0]; ci++)
        for (int kind = 0; kind < 3; kind++) {
          bb_image z = random_field(sizes[si][0], sizes[si][1], scales[ci], kind);
          bb_pyramid *p = pyramid_of(&z, a ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC);
          for (int i = 0; i < 1100; i++, rays++) {
            bb__ray r = random_ray(&z);
            int fast = bb__ray_occluded(p, &r), slow = bb__ray_occluded_brute(p, &r);
            cr_assert_eq(fast, slow,
                         "%dx%d scale %g %s kind %d: origin (%.17g, %.17g, %.17g) dir (%.17g, "
                         "%.17g, %.17g): max-mip %d, brute force %d",
                         z.width, z.height, (double)scales[ci], a ? "clamp" : "periodic", kind,
                         r.origin[0], r.origin[1], r.origin[2], r.direction[0], r.direction[1],
                         r.direction[2], fast, slow);
            blocked += fast;
          }
          bb_pyramid_free(p);
          bb_image_free(&z);
        }
  cr_assert_geq(rays, 100000);
  /* The test means something only if both answers are common. */
  cr_assert(blocked > rays / 5 && blocked < rays * 4 / 5, "blocked %ld of %ld", blocked, rays);
}

/* The horizon march finds, bit for bit, what the brute-force twin finds,
 * for rays in any direction from anywhere, in both addressing modes, and a
 * ray is blocked exactly when its tangent is at or under the horizon. */
Test(trace, horizon_march_equals_brute_force_on_random_rays) {
  const int sizes[][2] = {{1, 1}, {2, 3}, {7, 13}, {16, 16}, {31, 33}, {64, 40}};
  rng_state = 0x5DEECE66DULL;
  long rays = 0, positive = 0;
  for (int a = 0; a < 2; a++)
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++)
      for (int kind = 0; kind < 3; kind++) {
        bb_image z = random_field(sizes[si][0], sizes[si][1], 4.0f + 20.0f * (float)kind, kind);
        bb_pyramid *p = pyramid_of(&z, a ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC);
        const double reach = 3.0 * (z.width + z.height);
        for (int i = 0; i < 400; i++, rays++) {
          bb__ray r = random_ray(&z);
          const double far = a && i % 2 ? INFINITY : reach * rnd();
          const double fast = bb__ray_horizon(p, &r, far), slow = bb__ray_horizon_brute(p, &r, far);
          cr_assert(fast == slow, "%dx%d %s kind %d ray %d: max-mip %.17g, brute force %.17g",
                    z.width, z.height, a ? "clamp" : "periodic", kind, i, fast, slow);
          cr_assert_geq(fast, 0.0);
          positive += fast > 0.0;
          if (far == INFINITY || (!a && far == reach)) {
            const double h = hypot(r.direction[0], r.direction[1]);
            r.direction[2] = fast * h * (1 + 1e-9) + 1e-12;
            cr_assert_eq(bb__ray_occluded(p, &r), 0, "just above the horizon");
          }
        }
        bb_pyramid_free(p);
        bb_image_free(&z);
      }
  cr_assert(positive > rays / 4 && positive < rays, "%ld positive horizons of %ld", positive, rays);
}

Test(trace, ray_horizon_rejects_what_it_cannot_answer) {
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, 8, 8, 1, NULL), BB_OK);
  bb_pyramid *p = pyramid_of(&z, BB_ADDRESS_PERIODIC);
  bb__ray r = {{1, 1, 0.5}, {1, 0, 0.1}};
  cr_assert_eq(bb__ray_horizon(p, &r, INFINITY), -1.0, "periodic rays need a finite reach");
  cr_assert_eq(bb__ray_horizon(p, &r, 0.0), -1.0);
  r.direction[0] = 0.0;
  cr_assert_eq(bb__ray_horizon(p, &r, 10.0), -1.0, "vertical");
  bb_pyramid_free(p);
  bb_image_free(&z);
}

static bb_image flat_with_peak(int w, int h, int px, int py, float peak) {
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, w, h, 1, NULL), BB_OK);
  z.pixels[py * w + px] = peak;
  return z;
}

static bb__ray ray_to(double ox, double oy, double oz, double dx, double dy, double dz) {
  bb__ray r = {{ox, oy, oz}, {dx, dy, dz}};
  return r;
}

/* A single spike of height 10 at (20, 8) on a flat 32x16 field, seen from
 * (10, 8, 0.5) along +x: the spike subtends a slope of 9.5 / 10. */
Test(trace, ray_just_over_and_just_under_a_peak) {
  bb_image z = flat_with_peak(32, 16, 20, 8, 10.0f);
  bb_pyramid *p = pyramid_of(&z, BB_ADDRESS_PERIODIC);
  bb__ray over = ray_to(10, 8, 0.5, 1, 0, 0.95 + 1e-6);
  bb__ray under = ray_to(10, 8, 0.5, 1, 0, 0.95 - 1e-6);
  cr_assert_eq(bb__ray_occluded(p, &over), 0);
  cr_assert_eq(bb__ray_occluded(p, &under), 1);
  cr_assert_eq(bb__ray_occluded_brute(p, &over), 0);
  cr_assert_eq(bb__ray_occluded_brute(p, &under), 1);
  bb_pyramid_free(p);
  bb_image_free(&z);
}

/* The spike sits just across the seam: seen from x = 30 going +x, it is 6
 * texels away at x = 36 (= 4 + 32) in periodic mode, and absent in clamp. */
Test(trace, ray_crosses_the_wrap_seam) {
  bb_image z = flat_with_peak(32, 16, 4, 8, 12.0f);
  bb_pyramid *periodic = pyramid_of(&z, BB_ADDRESS_PERIODIC);
  bb_pyramid *clamp = pyramid_of(&z, BB_ADDRESS_CLAMP);
  bb__ray r = ray_to(30, 8, 0.0, 1, 0, 1.9); /* slope 1.9 < 12 / 6 = 2 */
  cr_assert_eq(bb__ray_occluded(periodic, &r), 1);
  cr_assert_eq(bb__ray_occluded(clamp, &r), 0);
  r.direction[2] = 2.1;
  cr_assert_eq(bb__ray_occluded(periodic, &r), 0);
  bb_pyramid_free(periodic);
  bb_pyramid_free(clamp);
  bb_image_free(&z);
}

/* A low ray on a 16x16 tile with a spike at (8, 8): from (8.5, 0) heading
 * almost along +y with a tiny x drift, it misses the spike's cell on the
 * first passes and hits it only after wrapping around several times. */
Test(trace, ray_wraps_several_times_before_it_is_blocked) {
  bb_image z = flat_with_peak(16, 16, 8, 8, 100.0f);
  bb_pyramid *p = pyramid_of(&z, BB_ADDRESS_PERIODIC);
  /* x drifts by 1/16 texel per tile, so it reaches the spike's cells (x in
   * (7, 9)) only after passing x = 9.0 -> it starts at x = 10.2, drifting
   * backwards: 10.2 - 0.0625 k enters (7, 9) at k >= 20 tiles. */
  bb__ray r = ray_to(10.2, 0.0, 1.0, -0.0625 / 16.0, 1.0, 0.05);
  int fast = bb__ray_occluded(p, &r), slow = bb__ray_occluded_brute(p, &r);
  cr_assert_eq(fast, 1, "the spike (100 high) must block a ray that is ~17 high there");
  cr_assert_eq(slow, 1);
  /* The same ray in clamp mode never meets the spike. */
  bb_pyramid *c = pyramid_of(&z, BB_ADDRESS_CLAMP);
  cr_assert_eq(bb__ray_occluded(c, &r), 0);
  bb_pyramid_free(c);
  bb_pyramid_free(p);
  bb_image_free(&z);
}

Test(trace, tilted_plane_blocks_rays_below_it) {
  /* z = 0.5 x in clamp mode: going +x the plane rises with slope 0.5. */
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, 40, 8, 1, NULL), BB_OK);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 40; x++) z.pixels[y * 40 + x] = 0.5f * (float)x;
  bb_pyramid *p = pyramid_of(&z, BB_ADDRESS_CLAMP);
  bb__ray r = ray_to(10, 4, 5.0, 1, 0, 0.49);
  cr_assert_eq(bb__ray_occluded(p, &r), 1);
  r.direction[2] = 0.51; /* above the plane: past x = 39 the surface is flat */
  cr_assert_eq(bb__ray_occluded(p, &r), 0);
  r.direction[0] = -1; /* downhill */
  r.direction[2] = 0.01;
  cr_assert_eq(bb__ray_occluded(p, &r), 0);
  bb_pyramid_free(p);
  bb_image_free(&z);
}

Test(trace, vertical_ray_is_never_blocked) {
  bb_image z = flat_with_peak(8, 8, 2, 2, 5.0f);
  bb_pyramid *p = pyramid_of(&z, BB_ADDRESS_PERIODIC);
  bb__ray r = ray_to(2, 2, 5.0, 0, 0, 1);
  cr_assert_eq(bb__ray_occluded(p, &r), 0);
  bb_pyramid_free(p);
  bb_image_free(&z);
}

/* ---------------------------------------------------------- batch trace */

static bb_rayset rayset_of(int slices) {
  bb_rayset rs;
  bb_error err;
  cr_assert_eq(bb__rayset_make(slices, 1.0, NULL, 0, &rs, &err), BB_OK, "%s", err.message);
  return rs;
}

static bb_image trace_field(const bb_image *z, bb_addressing a, int threads, int slices) {
  bb_pyramid *p = pyramid_of(z, a);
  bb_rayset rs = rayset_of(slices);
  bb_trace_options o;
  bb__trace_options_init(&o);
  o.threads = threads;
  bb_image vis;
  bb_error err;
  cr_assert_eq(bb__trace_occlusion(p, &rs, &o, &vis, NULL, &err), BB_OK, "%s", err.message);
  bb__rayset_release(&rs);
  bb_pyramid_free(p);
  return vis;
}

/* Every texel's horizon in slice s and its opposite by one line sweep. */
static void sweep_horizons(const bb_pyramid *p, const bb_rayset *rs, int s, int t, double bias,
                           long long_line, float *along, float *opposite) {
  const size_t texels = (size_t)p->width * (size_t)p->height;
  float *sums = calloc(texels * (size_t)(1 + rs->basis_count), sizeof(float));
  cr_assert(sums);
  const bb__sweep_dir a = {rs, s, sums, along}, o = {rs, t, sums, opposite};
  bb_error err;
  cr_assert_eq(bb__sweep_lines(p, rs->slice_step[2 * s], rs->slice_step[2 * s + 1], &a,
                               t >= 0 ? &o : NULL, bias, 2, long_line, &err),
               BB_OK, "%s", err.message);
  free(sums);
}

/* The three ways to a slice's horizon agree bit for bit: line sweeps (whole
 * periodic lines, lines cut in chunks whose far texels are marched, clamped
 * lines), the max-mip march and the brute-force DDA, on odd and non-square
 * sizes, with and without bias, for 16 and 20 slices. */
Test(trace, sweeps_march_and_brute_force_find_the_same_horizons) {
  const int sizes[][2] = {{1, 1}, {5, 3}, {17, 17}, {40, 23}, {64, 64}};
  rng_state = 4242;
  long compared = 0, positive = 0;
  for (int a = 0; a < 2; a++)
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++)
      for (int kind = 0; kind < 3; kind++) {
        bb_image z = random_field(sizes[si][0], sizes[si][1], 3.0f + 20.0f * (float)kind, kind);
        bb_pyramid *p = pyramid_of(&z, a ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC);
        bb_rayset rs = rayset_of(si % 2 ? 20 : 16);
        const double bias = kind == 1 ? 0.0 : 0.55;
        const long long_line = si % 2 ? 0 : 7; /* cut periodic lines into 7-step chunks */
        const size_t texels = (size_t)z.width * (size_t)z.height;
        float *along = malloc(texels * sizeof(float)), *opposite = malloc(texels * sizeof(float));
        for (int s = 0; s < rs.slice_count; s++) {
          int t = -1; /* its opposite, swept along with it */
          for (int u = 0; u < rs.slice_count; u++)
            if (rs.slice_step[2 * u] == -rs.slice_step[2 * s] &&
                rs.slice_step[2 * u + 1] == -rs.slice_step[2 * s + 1])
              t = u;
          sweep_horizons(p, &rs, s, t, bias, long_line, along, opposite);
          const int steps[2][2] = {{rs.slice_step[2 * s], rs.slice_step[2 * s + 1]},
                                   {-rs.slice_step[2 * s], -rs.slice_step[2 * s + 1]}};
          for (int side = 0; side < (t >= 0 ? 2 : 1); side++)
            for (size_t i = 0; i < texels; i += 1 + texels / 700) {
              const int x = (int)(i % (size_t)z.width), y = (int)(i / (size_t)z.width);
              const float swept = side ? opposite[i] : along[i];
              const float marched = bb__slice_horizon(p, x, y, bias, steps[side][0], steps[side][1]);
              const float brute = bb__slice_horizon_brute(p, x, y, bias, steps[side][0], steps[side][1]);
              cr_assert(swept == marched && marched == brute,
                        "%dx%d %s kind %d, step (%d, %d), texel (%d, %d): sweep %.9g, march %.9g, "
                        "brute force %.9g",
                        z.width, z.height, a ? "clamp" : "periodic", kind, steps[side][0],
                        steps[side][1], x, y, (double)swept, (double)marched, (double)brute);
              compared++;
              positive += swept > 0.0f;
            }
        }
        free(along);
        free(opposite);
        bb__rayset_release(&rs);
        bb_pyramid_free(p);
        bb_image_free(&z);
      }
  cr_assert(positive > compared / 4 && positive < compared, "%ld positive of %ld", positive, compared);
}

Test(trace, flat_field_is_fully_visible) {
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, 9, 7, 1, NULL), BB_OK);
  for (int a = 0; a < 2; a++) {
    bb_image vis = trace_field(&z, a ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC, 0, 16);
    cr_assert_eq(vis.channels, 4);
    for (int i = 0; i < 9 * 7 * 4; i++) cr_assert_eq(vis.pixels[i], 1.0f);
    bb_image_free(&vis);
  }
  bb_image_free(&z);
}

Test(trace, bit_identical_for_any_thread_count) {
  rng_state = 77;
  bb_image z = random_field(45, 38, 16.0f, 2);
  bb_image v1 = trace_field(&z, BB_ADDRESS_PERIODIC, 1, 10);
  bb_image v2 = trace_field(&z, BB_ADDRESS_PERIODIC, 2, 10);
  bb_image v3 = trace_field(&z, BB_ADDRESS_PERIODIC, 3, 10);
  size_t bytes = (size_t)45 * 38 * 4 * sizeof(float);
  cr_assert_eq(memcmp(v1.pixels, v2.pixels, bytes), 0);
  cr_assert_eq(memcmp(v1.pixels, v3.pixels, bytes), 0);
  bb_image_free(&v1);
  bb_image_free(&v2);
  bb_image_free(&v3);
  bb_image_free(&z);
}

/* The same slices from every texel make the trace a pure function of the
 * neighbourhood: shifting the periodic input shifts the output exactly. */
Test(trace, periodic_shift_shifts_the_output_exactly) {
  rng_state = 99;
  const int w = 27, h = 19, sx = 5, sy = 11;
  bb_image z = random_field(w, h, 12.0f, 0), shifted;
  cr_assert_eq(bb_image_alloc(&shifted, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      shifted.pixels[((y + sy) % h) * w + (x + sx) % w] = z.pixels[y * w + x];
  bb_image a = trace_field(&z, BB_ADDRESS_PERIODIC, 0, 8);
  bb_image b = trace_field(&shifted, BB_ADDRESS_PERIODIC, 0, 8);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 4; c++)
        cr_assert_eq(a.pixels[(y * w + x) * 4 + c],
                     b.pixels[(((y + sy) % h) * w + (x + sx) % w) * 4 + c], "texel (%d, %d)", x, y);
  bb_image_free(&a);
  bb_image_free(&b);
  bb_image_free(&shifted);
  bb_image_free(&z);
}

Test(trace, rejects_negative_bias_and_a_region_outside) {
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, 4, 4, 1, NULL), BB_OK);
  bb_pyramid *p = pyramid_of(&z, BB_ADDRESS_PERIODIC);
  bb_rayset rs = rayset_of(4);
  bb_trace_options o;
  bb__trace_options_init(&o);
  o.bias_texels = -1.0;
  bb_image vis;
  bb_error err;
  cr_assert_eq(bb__trace_occlusion(p, &rs, &o, &vis, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "bias") != NULL);
  o.bias_texels = 0.55;
  o.region = (bb_region){2, 1, 3, 2};
  cr_assert_eq(bb__trace_occlusion(p, &rs, &o, &vis, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "region") != NULL, "%s", err.message);
  bb__rayset_release(&rs);
  bb_pyramid_free(p);
  bb_image_free(&z);
}

/* The whole trace by line sweeps, the same by marches texel by texel, and
 * a region of it by marches give the same bits, in both addressing modes. */
Test(trace, sweeps_marches_and_regions_trace_the_same_bits) {
  const int sizes[][2] = {{1, 1}, {5, 3}, {17, 17}, {40, 23}};
  rng_state = 31337;
  for (int a = 0; a < 2; a++)
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
      bb_image z = random_field(sizes[si][0], sizes[si][1], 24.0f, (int)si % 3);
      bb_pyramid *p = pyramid_of(&z, a ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC);
      bb_rayset rs = rayset_of(si % 2 ? 7 : 16);
      bb_trace_options o;
      bb__trace_options_init(&o);
      bb_image sweeps, marches, region;
      bb_error err;
      cr_assert_eq(bb__trace_occlusion_path(p, &rs, &o, BB__TRACE_SWEEP, &sweeps, &err), BB_OK, "%s",
                   err.message);
      cr_assert_eq(bb__trace_occlusion_path(p, &rs, &o, BB__TRACE_MARCH, &marches, &err), BB_OK, "%s",
                   err.message);
      const size_t n = (size_t)z.width * (size_t)z.height * 4;
      for (size_t i = 0; i < n; i++)
        cr_assert_eq(sweeps.pixels[i], marches.pixels[i], "%dx%d %s: texel %zu channel %zu",
                     z.width, z.height, a ? "clamp" : "periodic", i / 4, i % 4);
      o.region = (bb_region){z.width / 3, z.height / 2, z.width - z.width / 3, z.height - z.height / 2};
      double found = 0;
      cr_assert_eq(bb__trace_occlusion(p, &rs, &o, &region, &found, &err), BB_OK, "%s", err.message);
      cr_assert_eq(region.width, o.region.width);
      cr_assert_eq(found, (double)o.region.width * o.region.height * rs.slice_count);
      for (int y = 0; y < region.height; y++)
        for (int x = 0; x < region.width; x++)
          cr_assert_eq(memcmp(bb_image_texel(&region, x, y),
                              bb_image_texel(&sweeps, x + o.region.x0, y + o.region.y0),
                              4 * sizeof(float)),
                       0, "region texel (%d, %d)", x, y);
      bb_image_free(&sweeps);
      bb_image_free(&marches);
      bb_image_free(&region);
      bb__rayset_release(&rs);
      bb_pyramid_free(p);
      bb_image_free(&z);
    }
}
