/* test_relief.c: render's camera view and relief (parallax occlusion)
 * mapping against the formulas of shaders/ssbump_relief.glsl, transcribed
 * here on their own, and what a view must and must not change. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bumpbake.h"
#include "bake_harness.h"
#include "render/render_internal.h"

static const double PI = 3.14159265358979323846;

/* Round bumps and a groove: relief in every direction. */
static bb_image bumpy(int w, int h) {
  bb_image img = harness_field(w, h, 0.0f);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      const double u = 2.0 * PI * x / w, v = 2.0 * PI * y / h;
      double z = 0.5 + 0.3 * sin(2.0 * u) * cos(v) + 0.2 * cos(3.0 * u + v);
      *bb_image_texel(&img, x, y) = (float)(z < 0.0 ? 0.0 : (z > 1.0 ? 1.0 : z));
    }
  return img;
}

typedef struct scene {
  bb_image height;
  bb_bake_result bake;
  bb_render_maps maps;
} scene;

static void scene_make(scene *s, float scale) {
  s->height = bumpy(48, 40);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = scale;
  o.smooth.radius_texels = 0;
  s->bake = harness_bake(&s->height, &o);
  s->maps = (bb_render_maps){&s->bake.normal, &s->bake.ssbump, &s->bake.ao, NULL, NULL, NULL};
}

static void scene_free(scene *s) {
  bb_bake_result_free(&s->bake);
  bb_image_free(&s->height);
}

static bb_image render(const bb_render_maps *m, const bb_render_options *o) {
  bb_image out;
  bb_error err;
  cr_assert_eq(bb__render(m, o, &out, &err), BB_OK, "%s", err.message);
  return out;
}

/* ---- the formulas of shaders/ssbump_relief.glsl, on their own ----------- */

/* textureLod with GL_LINEAR and GL_REPEAT at uv = (p + 0.5) / size. */
static double texel_wrap(const bb_image *img, long x, long y, int c) {
  long wx = x % img->width, wy = y % img->height;
  if (wx < 0) wx += img->width;
  if (wy < 0) wy += img->height;
  return bb_image_texel(img, (int)wx, (int)wy)[c];
}

static double lookup(const bb_image *img, double px, double py, int c) {
  /* GL samples texel centres (i + 0.5) / size: uv * size - 0.5 = p */
  const double x = px, y = py, x0 = floor(x), y0 = floor(y), fx = x - x0, fy = y - y0;
  return (1 - fy) * ((1 - fx) * texel_wrap(img, (long)x0, (long)y0, c) +
                     fx * texel_wrap(img, (long)x0 + 1, (long)y0, c)) +
         fy * ((1 - fx) * texel_wrap(img, (long)x0, (long)y0 + 1, c) +
               fx * texel_wrap(img, (long)x0 + 1, (long)y0 + 1, c));
}

static void glsl_relief_hit(const bb_image *h, double px, double py, const double view[3],
                            double depth, double hit[2]) {
  const double reach = depth * sqrt(view[0] * view[0] + view[1] * view[1]) / view[2];
  const double layers = fmin(fmax(ceil(2.0 * reach), 1.0), 1024.0);
  const double dz = depth / layers, dpx = -view[0] / view[2] * dz, dpy = -view[1] / view[2] * dz;
  double z = depth, above = z - depth * lookup(h, px, py, 0);
  hit[0] = px, hit[1] = py;
  if (above <= 0.0) return;
  for (int i = 0; i < (int)layers; i++) {
    const double npx = hit[0] + dpx, npy = hit[1] + dpy, nz = z - dz;
    const double below = nz - depth * lookup(h, npx, npy, 0);
    if (below <= 0.0) {
      hit[0] += above / (above - below) * dpx, hit[1] += above / (above - below) * dpy;
      return;
    }
    hit[0] = npx, hit[1] = npy, z = nz, above = below;
  }
}

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double glsl_specular(const double n[3], const double d[3], const double view[3], double k) {
  if (dot3(n, d) <= 0.0) return 0.0;
  double h[3] = {d[0] + view[0], d[1] + view[1], d[2] + view[2]};
  const double len = sqrt(dot3(h, h));
  for (int i = 0; i < 3; i++) h[i] /= len;
  const double nh = dot3(n, h);
  return nh > 0.0 ? pow(nh, k) : 0.0;
}

/* ssbump_relief_shade with a grey albedo of 1, white dynamic light. */
static void glsl_shade(const scene *s, double px, double py, const double view[3], double depth,
                       const double light[3], const float lightmap[3][3], double k,
                       double out[3]) {
  static const double B[3][3] = {{0.816496580927726, 0.0, 0.577350269189626},
                                 {-0.408248290463863, 0.707106781186548, 0.577350269189626},
                                 {-0.408248290463863, -0.707106781186548, 0.577350269189626}};
  double hit[2];
  glsl_relief_hit(&s->height, px, py, view, depth, hit);
  double ss[3], lb = 0.0, bent[3] = {0, 0, 0};
  for (int c = 0; c < 3; c++) ss[c] = lookup(&s->bake.ssbump, hit[0], hit[1], c);
  for (int c = 0; c < 3; c++) lb += ss[c] * dot3(light, B[c]);
  const double dynamic = fmin(fmax(lb, 0.0), 1.0);
  for (int c = 0; c < 3; c++)
    for (int i = 0; i < 3; i++) bent[i] += ss[c] * B[c][i];
  const double len = sqrt(dot3(bent, bent));
  for (int i = 0; i < 3; i++) bent[i] = len > 0.0 ? bent[i] / len : (i == 2);
  for (int i = 0; i < 3; i++) {
    out[i] = dynamic;
    for (int c = 0; c < 3; c++) out[i] += ss[c] * lightmap[c][i];
    out[i] += glsl_specular(bent, light, view, k);
    for (int c = 0; c < 3; c++) out[i] += lightmap[c][i] * glsl_specular(bent, B[c], view, k);
  }
}

/* The camera of bb__render's view: pixel (i, j) on the polygon. */
static void camera(const double view[3], int width, int height, int i, int j, double p[2]) {
  const double horizontal = sqrt(view[0] * view[0] + view[1] * view[1]);
  const double toward[2] = {view[0] / horizontal, view[1] / horizontal};
  const double right[2] = {toward[1], -toward[0]};
  const double si = i - 0.5 * width, sj = (j - 0.5 * height) / view[2];
  p[0] = 0.5 * width + si * right[0] + sj * toward[0];
  p[1] = 0.5 * height + si * right[1] + sj * toward[1];
}

Test(relief, the_preview_evaluates_the_shader_formulas) {
  scene s;
  scene_make(&s, 6.0f);
  bb_render_options o;
  bb__render_options_init(&o);
  o.view = 1, o.view_azimuth = 300.0, o.view_elevation = 25.0;
  o.relief = 1, o.relief_height = &s.height, o.relief_depth = 6.0;
  o.static_light = 1;
  o.specular_exponent = 24.0;
  o.light_azimuth = 40.0, o.light_elevation = 30.0;
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < 3; k++) o.lightmap[c][k] = c == k ? 0.3f : 0.05f;
  bb_image img = render(&s.maps, &o);
  double view[3], light[3];
  bb__light_direction(300.0, 25.0, view);
  bb__light_direction(40.0, 30.0, light);
  const int pixels[][2] = {{0, 0}, {5, 7}, {23, 19}, {47, 39}, {31, 2}, {12, 33}, {40, 26}};
  int moved = 0;
  for (size_t n = 0; n < sizeof pixels / sizeof pixels[0]; n++) {
    const int i = pixels[n][0], j = pixels[n][1];
    double p[2], want[3], hit[2];
    camera(view, img.width, img.height, i, j, p);
    glsl_relief_hit(&s.height, p[0], p[1], view, 6.0, hit);
    moved += fabs(hit[0] - p[0]) + fabs(hit[1] - p[1]) > 0.5;
    glsl_shade(&s, p[0], p[1], view, 6.0, light, o.lightmap, 24.0, want);
    const float *got = bb_image_texel(&img, i, j);
    for (int c = 0; c < 3; c++)
      cr_expect(fabs(got[c] - want[c]) <= 2e-5, "pixel (%d, %d) channel %d: %.6f, the shader %.6f",
                i, j, c, (double)got[c], want[c]);
  }
  cr_expect_geq(moved, 4, "the relief moves where most pixels read (%d of 7)", moved);
  bb_image_free(&img);
  scene_free(&s);
}

/* Seen from straight above with the picture upright, the view is the plain
 * render: every map read at its own texels. */
Test(relief, overhead_view_is_the_plain_render) {
  scene s;
  scene_make(&s, 6.0f);
  bb_render_options o;
  bb__render_options_init(&o);
  o.specular_exponent = 16.0;
  bb_image plain = render(&s.maps, &o);
  o.view = 1, o.view_azimuth = 270.0, o.view_elevation = 90.0;
  bb_image seen = render(&s.maps, &o);
  cr_assert_eq(seen.width, plain.width);
  for (size_t i = 0; i < (size_t)plain.width * (size_t)plain.height * 3; i++)
    cr_assert_float_eq(seen.pixels[i], plain.pixels[i], 1e-6, "value %zu", i);
  /* a relief at its top everywhere (h = 1) moves nothing either */
  bb_image top = harness_field(s.height.width, s.height.height, 1.0f);
  o.view_elevation = 35.0;
  bb_image flat_view = render(&s.maps, &o);
  o.relief = 1, o.relief_height = &top, o.relief_depth = 6.0;
  bb_image flat_relief = render(&s.maps, &o);
  cr_expect_eq(memcmp(flat_view.pixels, flat_relief.pixels,
                      (size_t)flat_view.width * (size_t)flat_view.height * 3 * sizeof(float)),
               0);
  bb_image_free(&top), bb_image_free(&flat_view), bb_image_free(&flat_relief);
  bb_image_free(&plain), bb_image_free(&seen);
  scene_free(&s);
}

Test(relief, same_bits_on_any_thread_count_and_cropped) {
  scene s;
  scene_make(&s, 6.0f);
  bb_render_options o;
  bb__render_options_init(&o);
  o.view = 1, o.view_azimuth = 200.0, o.view_elevation = 15.0;
  o.relief = 1, o.relief_height = &s.height, o.relief_depth = 6.0;
  o.tile_x = 2;
  o.threads = 1;
  bb_image one = render(&s.maps, &o);
  cr_expect_eq(one.width, 96);
  o.threads = 3;
  bb_image three = render(&s.maps, &o);
  cr_expect_eq(memcmp(one.pixels, three.pixels, (size_t)one.width * (size_t)one.height * 3 * sizeof(float)), 0);
  o.crop_x = 10, o.crop_y = 5, o.crop_width = 20, o.crop_height = 9;
  bb_image crop = render(&s.maps, &o);
  for (int y = 0; y < 9; y++)
    cr_expect_eq(memcmp(bb_image_texel(&crop, 0, y), bb_image_texel(&one, 10, 5 + y),
                        20 * 3 * sizeof(float)),
                 0);
  char *text = bb__render_options_describe(&o);
  cr_expect(strstr(text, "view=200,15\n") && strstr(text, "relief=6\n"), "%s", text);
  free(text);
  bb_image_free(&one), bb_image_free(&three), bb_image_free(&crop);
  scene_free(&s);
}

Test(relief, refuses_what_it_cannot_draw) {
  scene s;
  scene_make(&s, 6.0f);
  bb_render_options o;
  bb__render_options_init(&o);
  bb_image out;
  bb_error err;
  o.relief = 1, o.relief_height = &s.height, o.relief_depth = 6.0;
  cr_expect_eq(bb__render(&s.maps, &o, &out, &err), BB_ERR_ARGUMENT, "relief without a view");
  o.view = 1;
  o.relief_depth = 0.0;
  cr_expect_eq(bb__render(&s.maps, &o, &out, &err), BB_ERR_ARGUMENT, "no depth");
  o.relief_depth = 6.0;
  o.relief_height = NULL;
  cr_expect_eq(bb__render(&s.maps, &o, &out, &err), BB_ERR_ARGUMENT, "no height");
  cr_expect(strstr(err.message, "relief height") != NULL, "%s", err.message);
  bb_image small = harness_field(8, 8, 0.5f);
  o.relief_height = &small;
  cr_expect_eq(bb__render(&s.maps, &o, &out, &err), BB_ERR_ARGUMENT, "a height of another size");
  o.relief_height = &s.height;
  o.view_elevation = 0.5;
  cr_expect_eq(bb__render(&s.maps, &o, &out, &err), BB_ERR_ARGUMENT, "grazing under 1 degree");
  bb_image_free(&small);
  scene_free(&s);
}
