/* test_render.c: the lighting of baked maps (bb__render): each formula on flat
 * maps, which side of a bump is lit, the pit's self-shadowing, threads,
 * albedo, tiling and bad arguments. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "maps/maps_internal.h"
#include "render/render_internal.h"
#include "trace/basis.h"

#define SQRT3 1.7320508075688772

/* ----------------------------------------------------------------- helpers */

/* A height field of width x height from f(x, y). */
static void make_height(bb_image *h, int width, int height,
                        double (*f)(int, int, int, int)) {
  cr_assert_eq(bb_image_alloc(h, width, height, 1, NULL), BB_OK);
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
      h->pixels[(size_t)y * (size_t)width + (size_t)x] = (float)f(x, y, width, height);
}

static double flat(int x, int y, int w, int h) {
  (void)x, (void)y, (void)w, (void)h;
  return 0.5;
}

/* A round bump in the middle, 0.3 of the side in radius. */
static double bump(int x, int y, int w, int h) {
  double dx = x - w / 2, dy = y - h / 2, r = 0.3 * w;
  double d2 = (dx * dx + dy * dy) / (r * r);
  return d2 < 1.0 ? 0.5 + 0.5 * cos(3.14159265358979 * sqrt(d2)) : 0.0;
}

/* The pit fixture of tools/genheight: flat 1 with a round pit of 0 whose
 * radius is 0.3 of the side. */
static double pit(int x, int y, int w, int h) {
  double dx = x - (w - 1) / 2.0, dy = y - (h - 1) / 2.0, r = 0.3 * w;
  return dx * dx + dy * dy < r * r ? 0.0 : 1.0;
}

/* A height field baked, and its maps ready to render. */
typedef struct scene {
  bb_image height;
  bb_bake_result bake;
  bb_render_maps maps;
} scene;

static void scene_make(scene *s, int width, int height, double (*f)(int, int, int, int),
                       float scale, int rays) {
  make_height(&s->height, width, height, f);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = scale;
  o.rays = rays;
  bb_error err = {{0}};
  cr_assert_eq(bb__bake_checked(&s->height, &o, &s->bake, &err), BB_OK, "%s", err.message);
  const bb_bake_result *r = &s->bake;
  s->maps = (bb_render_maps){&r->normal, &r->ssbump, &r->ao, &r->bent, NULL, NULL};
}

static void scene_free(scene *s) {
  bb_bake_result_free(&s->bake);
  bb_image_free(&s->height);
}

/* Renders and returns the image (the caller frees it). */
static bb_image render(const bb_render_maps *m, const bb_render_options *o) {
  bb_image out;
  bb_error err = {{0}};
  cr_assert_eq(bb__render(m, o, &out, &err), BB_OK, "%s", err.message);
  cr_assert_eq(out.channels, 3);
  return out;
}

static const float *at(const bb_image *img, int x, int y) {
  return bb_image_texel(img, x, y);
}

static double grey_at(const bb_image *img, int x, int y) {
  const float *p = at(img, x, y);
  return ((double)p[0] + p[1] + p[2]) / 3.0;
}

/* Every texel of img equals rgb within tol. */
static void assert_uniform(const bb_image *img, const double rgb[3], double tol,
                           const char *what) {
  size_t n = (size_t)img->width * (size_t)img->height;
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++)
      cr_assert_float_eq(img->pixels[3 * i + (size_t)k], rgb[k], tol,
                         "%s: texel %zu channel %d is %.9g, expected %.9g", what, i, k,
                         (double)img->pixels[3 * i + (size_t)k], rgb[k]);
}

static void options(bb_render_options *o, bb_render_mode mode, double az, double el) {
  bb__render_options_init(o);
  o->mode = mode;
  o->light_azimuth = az;
  o->light_elevation = el;
}

/* --------------------------------------------------------------- names */

Test(render, mode_names_and_needs) {
  bb_render_mode m = BB_RENDER_NORMAL;
  cr_assert_eq(bb__render_mode_parse("ssbump", &m, NULL), 0);
  cr_assert_eq(m, BB_RENDER_SSBUMP);
  cr_assert_eq(bb__render_mode_parse("ao", &m, NULL), 0);
  cr_assert_eq(m, BB_RENDER_NORMAL_AO);
  cr_assert_neq(bb__render_mode_parse("phong", &m, NULL), 0);
  cr_assert_eq(m, BB_RENDER_NORMAL_AO, "a failed parse must not write");
  cr_assert_str_eq(bb__render_mode_name(BB_RENDER_NORMAL), "normal");
  cr_assert_str_eq(bb__render_mode_name((bb_render_mode)77), "unknown");
  cr_assert_eq(bb__render_mode_needs(BB_RENDER_SSBUMP), BB_RENDER_NEEDS_SSBUMP);
  cr_assert_eq(bb__render_mode_needs(BB_RENDER_NORMAL_AO),
               BB_RENDER_NEEDS_NORMAL | BB_RENDER_NEEDS_AO);
  cr_assert_eq(bb__render_mode_needs((bb_render_mode)77), 0u);
  cr_assert_eq(bb__render_mode_parse("slope", &m, NULL), 0);
  cr_assert_eq(m, BB_RENDER_SLOPE);
  cr_assert_eq(bb__render_mode_needs(BB_RENDER_SLOPE), BB_RENDER_NEEDS_SLOPE);
  bb_albedo_mode a = BB_ALBEDO_MULTIPLY;
  cr_assert_eq(bb__albedo_mode_parse("ssbump", &a, NULL), 0);
  cr_assert_eq(a, BB_ALBEDO_SSBUMP);
  cr_assert_neq(bb__albedo_mode_parse("mod4x", &a, NULL), 0);
  cr_assert_str_eq(bb__albedo_mode_name(BB_ALBEDO_MOD2X), "mod2x");
}

/* Azimuth counter-clockwise on screen from the right, +Y down: 90 degrees is
 * the top of the image, which is -y. */
Test(render, light_direction_frame) {
  double d[3];
  bb__light_direction(0, 0, d);
  cr_assert(d[0] == 1.0 && d[1] == 0.0 && d[2] == 0.0);
  bb__light_direction(90, 0, d);
  cr_assert(d[0] == 0.0 && d[1] == -1.0 && d[2] == 0.0, "90 = from the top = -y");
  bb__light_direction(270, 0, d);
  cr_assert(d[0] == 0.0 && d[1] == 1.0 && d[2] == 0.0, "270 = from the bottom = +y");
  bb__light_direction(-90, 0, d);
  cr_assert(d[1] == 1.0, "angles wrap");
  bb__light_direction(123, 90, d);
  cr_assert(d[0] == 0.0 && d[1] == 0.0 && d[2] == 1.0, "overhead is exactly +z");
  bb__light_direction(135, 45, d);
  cr_assert_float_eq(d[0], -0.5, 1e-15);
  cr_assert_float_eq(d[1], -0.5, 1e-15, "135 = from the top-left");
  cr_assert_float_eq(d[2], sqrt(0.5), 1e-15);
  /* B0 is the light from azimuth 0 at asin(1/sqrt(3)). */
  double b0[3];
  bb__basis_vector(0, b0);
  bb__light_direction(0, asin(1.0 / SQRT3) * 180.0 / 3.14159265358979323846, d);
  for (int k = 0; k < 3; k++)
    cr_assert_float_eq(d[k], b0[k], 1e-15);
}

/* ------------------------------------------------------------ flat maps */

/* A flat, unoccluded bake renders uniform, at each formula's exact value:
 * overhead, every mode gives N.L = 1; at elevation 30, sin(30) = 0.5 for the
 * ssbump too, since sum_c (1/sqrt 3)(l.B_c) = l.z. */
Test(render, flat_dynamic_light_is_lambert) {
  scene sc;
  scene_make(&sc, 12, 10, flat, 8.0f, 16);
  bb_render_maps m = sc.maps;
  const bb_render_mode modes[] = {BB_RENDER_NORMAL, BB_RENDER_NORMAL_AO,
                                  BB_RENDER_SSBUMP};
  const double elevations[] = {90.0, 30.0, 0.0};
  const double expected[] = {1.0, 0.5, 0.0};
  for (int i = 0; i < 3; i++)
    for (int e = 0; e < 3; e++) {
      bb_render_options o;
      options(&o, modes[i], 200.0, elevations[e]);
      o.light_color[0] = 1.0f, o.light_color[1] = 0.5f, o.light_color[2] = 0.25f;
      bb_image img = render(&m, &o);
      double rgb[3] = {expected[e], 0.5 * expected[e], 0.25 * expected[e]};
      assert_uniform(&img, rgb, 1e-6, bb__render_mode_name(modes[i]));
      bb_image_free(&img);
    }
  scene_free(&sc);
}

/* Static light: Source's sum_c s_c L_c = (L0 + L1 + L2) / sqrt(3) for a flat
 * ssbump; its normal-map weights give (L0 + L1 + L2) / 3. */
Test(render, flat_static_light_is_source) {
  scene sc;
  scene_make(&sc, 9, 9, flat, 4.0f, 16);
  bb_render_maps m = sc.maps;
  const float L[3][3] = {{1.0f, 0.2f, 0.0f}, {0.0f, 0.6f, 0.3f}, {0.5f, 0.0f, 0.9f}};
  double sum[3] = {0, 0, 0};
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < 3; k++)
      sum[k] += L[c][k];
  for (int i = 0; i < 3; i++) {
    bb_render_options o;
    options(&o,
            i == 0   ? BB_RENDER_SSBUMP
            : i == 1 ? BB_RENDER_NORMAL
                     : BB_RENDER_NORMAL_AO,
            0, 0);
    o.dynamic_light = 0;
    o.static_light = 1;
    memcpy(o.lightmap, L, sizeof L);
    bb_image img = render(&m, &o);
    double scale = i == 0 ? 1.0 / SQRT3 : 1.0 / 3.0;
    double rgb[3] = {sum[0] * scale, sum[1] * scale, sum[2] * scale};
    assert_uniform(&img, rgb, 1e-6, "static");
    bb_image_free(&img);
  }
  /* Both lights together add. */
  bb_render_options o;
  options(&o, BB_RENDER_SSBUMP, 45, 90);
  o.static_light = 1; /* default lightmaps: red, green, blue */
  bb_image img = render(&m, &o);
  double rgb[3] = {1.0 + 1.0 / SQRT3, 1.0 + 1.0 / SQRT3, 1.0 + 1.0 / SQRT3};
  assert_uniform(&img, rgb, 1e-6, "static + dynamic");
  bb_image_free(&img);
  scene_free(&sc);
}

/* Blinn-Phong with the viewer overhead on a flat map: N.H = cos((90 - el) / 2),
 * added to the diffuse. With the lightmaps on, each basis direction is a
 * light too: N.H_c = cos((90 - 35.26) / 2). */
Test(render, flat_specular_is_blinn_phong) {
  scene sc;
  scene_make(&sc, 8, 8, flat, 4.0f, 16);
  bb_render_maps m = sc.maps;
  const double rad = 3.14159265358979323846 / 180.0;
  for (int mode = 0; mode < 2; mode++) {
    /* --specular-strength scales the highlight only: 1 (the default),
     * 0.25 and 0 (no highlight at all). */
    const double strengths[] = {1.0, 0.25, 0.0};
    for (int k = 0; k < 3; k++) {
      bb_render_options o;
      options(&o, mode ? BB_RENDER_NORMAL : BB_RENDER_SSBUMP, 300, 30);
      o.specular_exponent = 8.0;
      if (k > 0)
        o.specular_strength = strengths[k];
      bb_image img = render(&m, &o);
      double v = 0.5 + strengths[k] * pow(cos(30.0 * rad), 8.0);
      double rgb[3] = {v, v, v};
      assert_uniform(&img, rgb, 1e-5, "specular");
      bb_image_free(&img);
    }
  }
  bb_render_options o;
  options(&o, BB_RENDER_SSBUMP, 0, 0);
  o.dynamic_light = 0;
  o.static_light = 1;
  o.specular_exponent = 4.0;
  bb_image img = render(&m, &o);
  double half = (90.0 - asin(1.0 / SQRT3) / rad) / 2.0;
  double v = 1.0 / SQRT3 + pow(cos(half * rad), 4.0);
  double rgb[3] = {v, v, v};
  assert_uniform(&img, rgb, 1e-5, "specular of the lightmaps");
  bb_image_free(&img);
  scene_free(&sc);
}

/* Albedo multiplies the diffuse, not the highlight; mod2x doubles it; an
 * ssbump detail multiplies by the grey dot(A, 2/3). */
Test(render, albedo_modes) {
  bb_image albedo, grey;
  scene sc;
  scene_make(&sc, 6, 5, flat, 4.0f, 16);
  cr_assert_eq(bb_image_alloc(&albedo, 6, 5, 3, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&grey, 6, 5, 1, NULL), BB_OK);
  for (int i = 0; i < 30; i++) {
    albedo.pixels[3 * i] = 0.5f, albedo.pixels[3 * i + 1] = 0.25f,
                      albedo.pixels[3 * i + 2] = 1;
    grey.pixels[i] = 0.25f;
  }
  bb_render_maps m = sc.maps;
  m.albedo = &albedo;
  bb_render_options o;
  options(&o, BB_RENDER_SSBUMP, 0, 90);
  bb_image img = render(&m, &o);
  assert_uniform(&img, (double[]){0.5, 0.25, 1.0}, 1e-6, "albedo");
  bb_image_free(&img);
  o.albedo_mode = BB_ALBEDO_MOD2X;
  img = render(&m, &o);
  assert_uniform(&img, (double[]){1.0, 0.5, 2.0}, 1e-6, "mod2x");
  bb_image_free(&img);
  o.albedo_mode = BB_ALBEDO_SSBUMP;
  img = render(&m, &o);
  assert_uniform(&img, (double[]){7.0 / 6.0, 7.0 / 6.0, 7.0 / 6.0}, 1e-6,
                 "(2/3)(0.5 + 0.25 + 1)");
  bb_image_free(&img);
  m.albedo = NULL;
  img = render(&m, &o);
  assert_uniform(&img, (double[]){1.0, 1.0, 1.0}, 1e-6, "no albedo: 1 in any mode");
  bb_image_free(&img);
  o.albedo_mode = BB_ALBEDO_MOD2X;
  m.albedo = &grey;
  img = render(&m, &o);
  assert_uniform(&img, (double[]){0.5, 0.5, 0.5}, 1e-6, "mod2x grey");
  bb_image_free(&img);
  o.specular_exponent = 1.0; /* overhead: N.H = 1 */
  img = render(&m, &o);
  assert_uniform(&img, (double[]){1.5, 1.5, 1.5}, 1e-6, "the highlight is not tinted");
  bb_image_free(&img);
  bb_image_free(&albedo);
  bb_image_free(&grey);
  scene_free(&sc);
}

/* ----------------------------------------------------------------- bump */

/* A bump lit from the right is brighter on its right flank, lit from below
 * (+y, azimuth 270) brighter on its lower flank: in every mode. */
Test(render, bump_is_lit_on_the_light_side) {
  scene sc;
  scene_make(&sc, 40, 40, bump, 12.0f, 64);
  bb_render_maps m = sc.maps;
  const int c = 20, d = 7;
  for (int mode = 0; mode < 4; mode++) {
    bb_render_options o;
    options(&o,
            mode == 1   ? BB_RENDER_NORMAL
            : mode == 2 ? BB_RENDER_NORMAL_AO
                        : BB_RENDER_SSBUMP,
            0, 30);
    o.specular_exponent = mode == 3 ? 16.0 : 0.0;
    bb_image right = render(&m, &o);
    cr_assert_gt(grey_at(&right, c + d, c), grey_at(&right, c - d, c) + 0.2,
                 "mode %d: lit from the right, the right flank is brighter", mode);
    bb_image_free(&right);
    o.light_azimuth = 270;
    bb_image below = render(&m, &o);
    cr_assert_gt(grey_at(&below, c, c + d), grey_at(&below, c, c - d) + 0.2,
                 "mode %d: lit from below (+y), the lower flank is brighter", mode);
    bb_image_free(&below);
  }
  scene_free(&sc);
}

/* ------------------------------------------------------------------ pit */

/* The paper's selling point: a low light from the right. The right-hand wall
 * of the pit (8 texels deep) casts its shadow over the floor beside it; the
 * plain normal map sees a flat floor there and lights it fully (N.L =
 * sin 20), the ssbump darkens it. */
Test(render, pit_floor_in_the_shadow_of_its_wall) {
  scene sc;
  scene_make(&sc, 65, 65, pit, 8.0f, 256);
  bb_render_maps m = sc.maps;
  bb_render_options o;
  options(&o, BB_RENDER_NORMAL, 0, 20);
  bb_image plain = render(&m, &o);
  o.mode = BB_RENDER_SSBUMP;
  bb_image ss = render(&m, &o);
  const double lambert = sin(20.0 * 3.14159265358979323846 / 180.0);
  /* The pit spans x = 12.5 .. 51.5 on row 32; at 20 degrees the right wall's
   * shadow reaches 8 / tan 20 = 22 texels to x = 29.5. */
  for (int x = 46; x <= 48; x++) {
    cr_assert_float_eq(grey_at(&plain, x, 32), lambert, 1e-4,
                       "x = %d: the flat floor is fully lit by N.L", x);
    cr_assert_lt(grey_at(&ss, x, 32), 0.5 * lambert,
                 "x = %d: the ssbump darkens the floor in the wall's shadow (%g vs %g)",
                 x, grey_at(&ss, x, 32), lambert);
  }
  /* Beside the left wall the floor faces the light over the whole pit. */
  cr_assert_gt(grey_at(&ss, 16, 32), 3.0 * grey_at(&ss, 48, 32),
               "the open floor near the left wall stays lit");
  bb_image_free(&plain);
  bb_image_free(&ss);
  scene_free(&sc);
}

/* -------------------------------------------------------- determinism */

Test(render, bit_identical_for_any_thread_count) {
  scene sc;
  scene_make(&sc, 37, 29, bump, 6.0f, 32);
  bb_render_maps m = sc.maps;
  bb_render_options o;
  options(&o, BB_RENDER_SSBUMP, 33, 21);
  o.static_light = 1;
  o.specular_exponent = 12;
  o.threads = 1;
  bb_image one = render(&m, &o);
  for (int t = 2; t <= 5; t++) {
    o.threads = t;
    bb_image many = render(&m, &o);
    cr_assert_eq(memcmp(one.pixels, many.pixels, sizeof(float) * 3 * 37 * 29), 0,
                 "%d threads differ from 1", t);
    bb_image_free(&many);
  }
  bb_image_free(&one);
  scene_free(&sc);
}

/* ------------------------------------------------------- bent and view */

/* Without a bent map the specular normal is the ssbump's bent normal, as
 * bb__derive_bent_all_cores makes it: the same pixels either way. */
Test(render, bent_from_the_ssbump_when_missing) {
  scene sc;
  scene_make(&sc, 24, 20, bump, 6.0f, 32);
  bb_render_maps m = sc.maps;
  bb_render_options o;
  options(&o, BB_RENDER_SSBUMP, 10, 40);
  o.specular_exponent = 20;
  bb_image with = render(&m, &o);
  m.bent = NULL;
  bb_image without = render(&m, &o);
  for (size_t i = 0; i < 3u * 24 * 20; i++)
    cr_assert_float_eq(with.pixels[i], without.pixels[i], 1e-6);
  bb_image_free(&with);
  bb_image_free(&without);
  scene_free(&sc);
}

Test(render, tile_and_crop) {
  scene sc;
  scene_make(&sc, 10, 8, bump, 4.0f, 16);
  bb_render_maps m = sc.maps;
  bb_render_options o;
  options(&o, BB_RENDER_NORMAL, 10, 40);
  bb_image base = render(&m, &o);
  o.tile_x = o.tile_y = 2;
  bb_image tiled = render(&m, &o);
  cr_assert_eq(tiled.width, 20);
  cr_assert_eq(tiled.height, 16);
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 20; x++)
      cr_assert_eq(memcmp(at(&tiled, x, y), at(&base, x % 10, y % 8), 3 * sizeof(float)),
                   0);
  o.crop_x = 7, o.crop_y = 5, o.crop_width = 6, o.crop_height = 4;
  bb_image crop = render(&m, &o);
  cr_assert_eq(crop.width, 6);
  cr_assert_eq(crop.height, 4);
  for (int y = 0; y < 4; y++)
    for (int x = 0; x < 6; x++)
      cr_assert_eq(memcmp(at(&crop, x, y), at(&tiled, 7 + x, 5 + y), 3 * sizeof(float)),
                   0);
  o.crop_x = 15; /* 15 + 6 > 20 */
  bb_image bad;
  bb_error err = {{0}};
  cr_assert_eq(bb__render(&m, &o, &bad, &err), BB_ERR_ARGUMENT);
  cr_assert_null(bad.pixels);
  bb_image_free(&base);
  bb_image_free(&tiled);
  bb_image_free(&crop);
  scene_free(&sc);
}

/* --------------------------------------------------------- bad arguments */

Test(render, bad_arguments_are_refused) {
  bb_image n3, s1, ao_small, out;
  cr_assert_eq(bb_image_alloc(&n3, 4, 4, 3, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&s1, 4, 4, 1, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&ao_small, 3, 4, 1, NULL), BB_OK);
  bb_render_options o;
  bb__render_options_init(&o);
  bb_error err = {{0}};

  bb_render_maps m = {&n3, NULL, NULL, NULL, NULL, NULL};
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "ssbump map is missing"), "%s", err.message);
  m.ssbump = &s1;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "1 channel, needs 3"), "%s", err.message);
  o.mode = BB_RENDER_NORMAL_AO;
  m.ao = &ao_small;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "ao map is 3x4, the others 4x4"), "%s", err.message);
  m.ao = &s1;
  o.light_elevation = 90.5;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "elevation"), "%s", err.message);
  o.light_elevation = 10;
  o.light_color[1] = NAN;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  o.light_color[1] = 1;
  o.specular_exponent = -1;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  o.specular_exponent = 0;
  const double bad_strengths[] = {-0.5, 1000.5, NAN};
  for (int k = 0; k < 3; k++) {
    o.specular_strength = bad_strengths[k];
    cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
    cr_assert(strstr(err.message, "specular strength must be in 0..1000"), "%s", err.message);
  }
  o.specular_strength = 1;
  o.threads = BB_MAX_THREADS + 1;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "render: threads must be in 0..4096 (got 4097)");
  o.threads = -1;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  o.threads = 0;
  o.mode = (bb_render_mode)9;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  o.mode = BB_RENDER_NORMAL;
  o.tile_x = 0;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  o.tile_x = 1;
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_OK, "%s", err.message);
  bb_image_free(&out);
  bb_image_free(&n3);
  bb_image_free(&s1);
  bb_image_free(&ao_small);
}

/* A light that passes a float's largest value is refused with what is
 * wrong: too large, said as such (not "must be >= 0"), or a picture that
 * would hold infinities (each colour a float, their highlight sum not). */
Test(render, a_light_too_bright_for_a_float_says_so) {
  scene sc;
  scene_make(&sc, 8, 8, flat, 4.0f, 16);
  bb_render_options o;
  options(&o, BB_RENDER_SSBUMP, 0, 90); /* overhead: diffuse 1, highlight 1 */
  bb_error err = {{0}};
  bb_image out;
  o.light_color[0] = o.light_color[1] = o.light_color[2] = 3.4e38f;
  o.specular_exponent = 8.0;
  cr_assert_eq(bb__render(&sc.maps, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "render: too bright: a texel passes a float's largest value "
                                "(3.40282e38); lower the light colour, lightmap or specular "
                                "strength");
  cr_assert_null(out.pixels);
  o.specular_exponent = 0.0; /* 3.4e38 alone stays finite */
  bb_image img = render(&sc.maps, &o);
  bb_image_free(&img);
  o.light_color[0] = INFINITY;
  cr_assert_eq(bb__render(&sc.maps, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "render: light colour is too large: at most 3.40282e38, a "
                                "float's largest (got inf)");
  o.light_color[0] = -1.0f;
  cr_assert_eq(bb__render(&sc.maps, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "render: light colour must be >= 0 (got -1)");
  scene_free(&sc);
}

/* ------------------------------------------------------------ describe */

Test(render, describe_names_every_option) {
  bb_render_options o;
  bb__render_options_init(&o);
  char *text = bb__render_options_describe(&o);
  cr_assert_not_null(text);
  cr_assert_str_eq(
      text, "render_mode=ssbump\nlight=135,45\nlight_color=1,1,1\n"
            "lightmap=none\nspecular=0\nspecular_strength=1\nalbedo_mode=multiply\ntile=1x1\ncrop=none\n");
  free(text);
  o.dynamic_light = 0;
  o.static_light = 1;
  o.crop_width = 3, o.crop_height = 2, o.crop_x = 1;
  text = bb__render_options_describe(&o);
  cr_assert(strstr(text, "light=none\nlightmap=1,0,0,0,1,0,0,0,1\n"), "%s", text);
  cr_assert(strstr(text, "crop=1,0,3,2\n"), "%s", text);
  free(text);
}

/* ---------------------------------------------------------- normal maps */

/* Decodes as render reads a normal map: renormalised, green_up flips y. */
static bb_status decode(const bb_image *img, int is_float, int green_up, bb_image *n) {
  return bb_normal_map_decode(img, is_float, green_up, 1, n, NULL);
}

Test(render, normals_decode) {
  bb_image img, n;
  cr_assert_eq(bb_image_alloc(&img, 3, 1, 4, NULL), BB_OK);
  const float v[12] = {0.5f, 0.5f, 1.0f, 0.7f,  /* 8-bit flat (128 rounds to ~0.502) */
                       1.0f, 0.5f, 0.5f, 0.0f,  /* +x */
                       0.5f, 0.5f, 0.5f, 1.0f}; /* zero vector */
  memcpy(img.pixels, v, sizeof v);
  cr_assert_eq(decode(&img, 0, 0, &n), BB_OK);
  cr_assert_eq(n.channels, 3);
  cr_assert(n.pixels[0] == 0.0f && n.pixels[1] == 0.0f && n.pixels[2] == 1.0f);
  cr_assert(n.pixels[3] == 1.0f && n.pixels[4] == 0.0f && n.pixels[5] == 0.0f);
  cr_assert(n.pixels[8] == 1.0f, "a zero vector becomes straight up");
  bb_image_free(&n);
  /* Float files hold N; green up flips y; lengths are renormalised. */
  const float f[12] = {0.0f, 0.6f, 0.8f, 0, 0.0f, 0.0f, 2.0f, 0, 3.0f, 0.0f, 4.0f, 0};
  memcpy(img.pixels, f, sizeof f);
  cr_assert_eq(decode(&img, 1, 1, &n), BB_OK);
  cr_assert_float_eq(n.pixels[1], -0.6f, 1e-7);
  cr_assert_float_eq(n.pixels[2], 0.8f, 1e-7);
  cr_assert_float_eq(n.pixels[5], 1.0f, 1e-7);
  cr_assert_float_eq(n.pixels[6], 0.6f, 1e-7);
  bb_image_free(&n);
  bb_image_free(&img);
  bb_image two;
  cr_assert_eq(bb_image_alloc(&two, 2, 2, 2, NULL), BB_OK);
  cr_assert_eq(decode(&two, 0, 0, &n), BB_ERR_ARGUMENT);
  bb_image_free(&two);
}

/* ------------------------------------------------------------ slope map */

/* flipcode's slope map through its table: a flat byte (0) under any light
 * gives N.L of (0, 0, 1), exactly sin(elevation); a texel whose surface rises
 * 3 texels to the right (dx = 3, the byte's low nibble) faces left, so a light
 * from the left (azimuth 180) lights it more than one from the right, and
 * the value is the table's, normalize(-3, 0, 1).l. No slope map: an error. */
Test(render, slope_map_through_the_table) {
  bb_image slope;
  cr_assert_eq(bb_image_alloc(&slope, 2, 1, 1, NULL), BB_OK);
  slope.pixels[0] = 0.0f;
  slope.pixels[1] = (float)bb__slope_encode(3, 0) / 255.0f;
  bb_render_maps m = {NULL, NULL, NULL, NULL, NULL, &slope};
  bb_render_options o;
  options(&o, BB_RENDER_SLOPE, 180.0, 30.0);
  bb_image left = render(&m, &o);
  o.light_azimuth = 0.0;
  bb_image right = render(&m, &o);
  cr_assert_float_eq(at(&left, 0, 0)[0], 0.5, 1e-6);
  cr_assert_float_eq(at(&right, 0, 0)[0], 0.5, 1e-6);
  double l[3], n[3] = {-3.0 / sqrt(10.0), 0.0, 1.0 / sqrt(10.0)};
  bb__light_direction(180.0, 30.0, l);
  cr_assert_float_eq(at(&left, 1, 0)[1], n[0] * l[0] + n[2] * l[2], 1e-6);
  cr_assert_gt(grey_at(&left, 1, 0), 0.8);
  cr_assert_eq(grey_at(&right, 1, 0), 0.0, "the right-hand light is behind the slope");
  bb_image_free(&left);
  bb_image_free(&right);
  m.slope = NULL;
  bb_image out = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb__render(&m, &o, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "slope"), "%s", err.message);
  bb_image_free(&slope);
}
