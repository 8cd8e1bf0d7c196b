/* test_panels.c: tiling, cropping, resampling, display encodings, labelled
 * grids (with and without a font) and the four-panel comparison. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "render/render_internal.h"

/* An image whose texel (x, y), channel k holds 100 y + 10 x + k. */
static bb_image numbered(int width, int height, int channels) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, width, height, channels, NULL), BB_OK);
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
      for (int k = 0; k < channels; k++)
        bb_image_texel(&img, x, y)[k] = (float)(100 * y + 10 * x + k);
  return img;
}

static bb_image filled(int width, int height, float r, float g, float b) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, width, height, 3, NULL), BB_OK);
  for (int i = 0; i < width * height; i++) {
    img.pixels[3 * i] = r;
    img.pixels[3 * i + 1] = g;
    img.pixels[3 * i + 2] = b;
  }
  return img;
}

Test(panels, tile_repeats) {
  bb_image in = numbered(3, 2, 2), out;
  cr_assert_eq(bb__image_tile(&in, 2, 3, &out, NULL), BB_OK);
  cr_assert_eq(out.width, 6);
  cr_assert_eq(out.height, 6);
  for (int y = 0; y < 6; y++)
    for (int x = 0; x < 6; x++)
      for (int k = 0; k < 2; k++)
        cr_assert_eq(bb_image_texel(&out, x, y)[k], bb_image_texel(&in, x % 3, y % 2)[k]);
  bb_image_free(&out);
  cr_assert_eq(bb__image_tile(&in, 0, 1, &out, NULL), BB_ERR_SIZE);
  cr_assert_eq(bb__image_tile(&in, 40000, 1, &out, NULL), BB_ERR_SIZE, "over the maximum");
  cr_assert_null(out.pixels);
  bb_image_free(&in);
}

Test(panels, crop_windows) {
  bb_image in = numbered(5, 4, 3), out;
  cr_assert_eq(bb__image_crop(&in, 1, 2, 3, 2, &out, NULL), BB_OK);
  cr_assert_eq(out.width, 3);
  cr_assert_eq(out.height, 2);
  cr_assert_eq(bb_image_texel(&out, 0, 0)[0], 210.0f);
  cr_assert_eq(bb_image_texel(&out, 2, 1)[2], 332.0f);
  bb_image_free(&out);
  bb_error err = {{0}};
  cr_assert_eq(bb__image_crop(&in, 3, 0, 3, 1, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "not inside"), "%s", err.message);
  cr_assert_eq(bb__image_crop(&in, -1, 0, 1, 1, &out, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__image_crop(&in, 0, 0, 0, 1, &out, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__image_crop(&in, 0, 0, 5, 4, &out, NULL), BB_OK, "the whole image");
  cr_assert_eq(memcmp(out.pixels, in.pixels, sizeof(float) * 60), 0);
  bb_image_free(&out);
  bb_image_free(&in);
}

/* Integer factors are box means; enlarging repeats texels; any size keeps
 * the mean of a linear ramp and a constant exactly. */
Test(panels, resample_by_area) {
  bb_image in = numbered(4, 4, 1), out;
  cr_assert_eq(bb__image_resample(&in, 2, 2, &out, NULL), BB_OK);
  cr_assert_float_eq(bb_image_texel(&out, 0, 0)[0], (0 + 10 + 100 + 110) / 4.0, 1e-4);
  cr_assert_float_eq(bb_image_texel(&out, 1, 1)[0], (220 + 230 + 320 + 330) / 4.0, 1e-4);
  bb_image_free(&out);
  cr_assert_eq(bb__image_resample(&in, 8, 8, &out, NULL), BB_OK);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++)
      cr_assert_float_eq(bb_image_texel(&out, x, y)[0],
                         bb_image_texel(&in, x / 2, y / 2)[0], 1e-4,
                         "enlarging by 2 repeats texels");
  bb_image_free(&out);
  cr_assert_eq(bb__image_resample(&in, 3, 1, &out, NULL), BB_OK);
  /* Column means of the ramp: rows average to 150; x covers thirds of 4. */
  double sum = 0;
  for (int x = 0; x < 3; x++)
    sum += bb_image_texel(&out, x, 0)[0];
  cr_assert_float_eq(sum / 3.0, 150.0 + 15.0, 1e-3, "the mean is kept");
  /* Output 0 covers x in [0, 4/3): x = 0 whole, x = 1 a third: 10 x
   * averages (0 + 10 / 3) / (4 / 3) = 2.5; output 2 mirrors it. */
  cr_assert_float_eq(bb_image_texel(&out, 0, 0)[0], 152.5, 1e-3);
  cr_assert_float_eq(bb_image_texel(&out, 2, 0)[0], 177.5, 1e-3);
  bb_image_free(&out);
  bb_image_free(&in);
  bb_image c = filled(7, 5, 0.25f, 0.5f, 0.75f);
  cr_assert_eq(bb__image_resample(&c, 3, 11, &out, NULL), BB_OK);
  for (int i = 0; i < 33; i++)
    cr_assert_float_eq(out.pixels[3 * i + 1], 0.5f, 1e-6);
  bb_image_free(&out);
  bb_image_free(&c);
}

Test(panels, display_encodings) {
  bb_image signed3, grey, rgb;
  cr_assert_eq(bb_image_alloc(&signed3, 2, 1, 3, NULL), BB_OK);
  const float n[6] = {0.0f, 0.0f, 1.0f, -1.0f, 0.5f, 2.0f};
  memcpy(signed3.pixels, n, sizeof n);
  cr_assert_eq(bb__image_to_display(&signed3, BB_RANGE_SIGNED, 0, 1, &rgb, NULL), BB_OK);
  const float expect[6] = {0.5f, 0.5f, 1.0f, 0.0f, 0.75f, 1.0f};
  for (int i = 0; i < 6; i++)
    cr_assert_float_eq(rgb.pixels[i], expect[i], 1e-7, "0.5 + 0.5 N, clamped");
  bb_image_free(&rgb);
  cr_assert_eq(bb_image_alloc(&grey, 3, 1, 1, NULL), BB_OK);
  grey.pixels[0] = 2.0f, grey.pixels[1] = 3.0f, grey.pixels[2] = 7.0f;
  cr_assert_eq(bb__image_to_display(&grey, BB_RANGE_UNIT, 2.0f, 4.0f, &rgb, NULL), BB_OK);
  cr_assert_eq(rgb.channels, 3);
  const float g[9] = {0, 0, 0, 0.5f, 0.5f, 0.5f, 1, 1, 1};
  for (int i = 0; i < 9; i++)
    cr_assert_float_eq(rgb.pixels[i], g[i], 1e-7, "grey, stretched and clamped");
  bb_image_free(&rgb);
  cr_assert_eq(bb__image_to_display(&grey, BB_RANGE_UNIT, 1.0f, 1.0f, &rgb, NULL),
               BB_ERR_ARGUMENT);
  bb_image_free(&grey);
  bb_image_free(&signed3);
}

/* Grid geometry: gap + columns x (cell + gap) wide; each row a cell, a label
 * strip when labelled, a gap. */
static void assert_grid(const bb_image *out, int columns, int rows, int cell_w,
                        int cell_h, int label_h, int gap) {
  cr_assert_eq(out->width, gap + columns * (cell_w + gap));
  cr_assert_eq(out->height, gap + rows * (cell_h + label_h + gap));
}

/* The label strip of a labelled grid, from its height: 1.75 font sizes for
 * a font of 6..max_font pixels (labels shrink to fit narrow panels). */
static int label_strip(const bb_image *out, int rows, int cell_h, int gap, int max_font) {
  int strip = (out->height - gap - rows * (cell_h + gap)) / rows;
  int found = 0;
  for (int size = 6; size <= max_font; size++)
    found |= strip == (size * 7 + 3) / 4;
  cr_assert(found, "a %d-pixel label strip fits no font of 6..%d pixels", strip,
            max_font);
  return strip;
}

/* Largest channel value in a window, to find drawn text. */
static float window_max(const bb_image *img, int x0, int y0, int w, int h) {
  float m = 0;
  for (int y = y0; y < y0 + h; y++)
    for (int x = x0; x < x0 + w; x++)
      for (int k = 0; k < 3; k++)
        m = fmaxf(m, bb_image_texel(img, x, y)[k]);
  return m;
}

Test(panels, compose_with_labels) {
  bb_image a = filled(32, 16, 1, 0, 0), b = filled(128, 64, 0, 1, 0),
           c = filled(64, 64, 0, 0, 1);
  bb_panel p[3] = {{&a, "red"}, {&b, "green"}, {&c, NULL}};
  bb_panel_layout l;
  bb__panel_layout_init(&l);
  l.columns = 2;
  l.panel_width = 64;
  l.gap = 4;
  l.font_size = 12;
  bb_image out;
  int labels = -1;
  bb_error err = {{0}};
  cr_assert_eq(bb__panels_compose(p, 3, &l, &out, &labels, &err), BB_OK, "%s",
               err.message);
  cr_assert_eq(labels, 1, "fonts-dejavu-core is a build dependency");
  const int label_h = (12 * 7 + 3) / 4; /* both labels fit 64 pixels at 12 */
  assert_grid(&out, 2, 2, 64, 64, label_h, 4);
  /* Panel a enlarged to 64 x 32 at (4, 4), top-aligned in its 64-high cell;
   * b reduced to 64 x 32 at (72, 4); c at (4, 4 + 64 + label_h + 4). */
  cr_assert_eq(bb_image_texel(&out, 4, 4)[0], 1.0f);
  cr_assert_eq(bb_image_texel(&out, 67, 35)[0], 1.0f);
  cr_assert_eq(bb_image_texel(&out, 4, 36)[0], 0.12f, "below a short panel: background");
  cr_assert_eq(bb_image_texel(&out, 72, 4)[1], 1.0f);
  cr_assert_eq(bb_image_texel(&out, 135, 35)[1], 1.0f);
  cr_assert_eq(bb_image_texel(&out, 4, 72 + label_h)[2], 1.0f);
  cr_assert_eq(bb_image_texel(&out, 2, 2)[0], 0.12f, "the gap is background");
  /* Labels are light text in the strip under each labelled panel. */
  cr_assert_gt(window_max(&out, 4, 68, 64, label_h), 0.5f,
               "a label is drawn under 'red'");
  cr_assert_gt(window_max(&out, 72, 68, 64, label_h), 0.5f);
  cr_assert_lt(window_max(&out, 4, 136 + label_h, 64, label_h), 0.13f,
               "no label under an unlabelled panel");
  bb_image_free(&out);
  /* Narrow panels: one smaller size for every label, a thinner strip. */
  l.panel_width = 16;
  cr_assert_eq(bb__panels_compose(p, 3, &l, &out, &labels, &err), BB_OK, "%s",
               err.message);
  cr_assert_lt(label_strip(&out, 2, 16, 4, 12), label_h, "'green' does not fit 16 at 12");
  bb_image_free(&out);
  bb_image_free(&a);
  bb_image_free(&b);
  bb_image_free(&c);
}

/* With no usable font the grid loses its label strips and says so. */
Test(panels, compose_without_a_font) {
  bb_image a = filled(48, 16, 0.5f, 0.5f, 0.5f);
  bb_panel p[2] = {{&a, "one"}, {&a, "two"}};
  bb_panel_layout l;
  bb__panel_layout_init(&l);
  l.gap = 2;
  bb_image out;
  int labels = -1;
  cr_assert_eq(setenv("BUMPBAKE_FONT", "/nonexistent/font.ttf", 1), 0);
  cr_assert_eq(bb__panels_compose(p, 2, &l, &out, &labels, NULL), BB_OK);
  cr_assert_eq(labels, 0);
  assert_grid(&out, 2, 1, 48, 16, 0, 2);
  bb_image_free(&out);
  cr_assert_eq(setenv("BUMPBAKE_FONT", "", 1), 0);
  cr_assert_eq(bb__panels_compose(p, 2, &l, &out, &labels, NULL), BB_OK);
  cr_assert_eq(labels, 0, "an empty BUMPBAKE_FONT means no labels");
  bb_image_free(&out);
  unsetenv("BUMPBAKE_FONT");
  cr_assert_eq(bb__panels_compose(p, 2, &l, &out, &labels, NULL), BB_OK);
  cr_assert_eq(labels, 1);
  assert_grid(&out, 2, 1, 48, 16, (12 * 7 + 3) / 4, 2);
  bb_image_free(&out);
  bb_image_free(&a);
}

Test(panels, compose_refuses_bad_panels) {
  bb_image one;
  cr_assert_eq(bb_image_alloc(&one, 4, 4, 1, NULL), BB_OK);
  bb_panel p = {&one, "x"};
  bb_panel_layout l;
  bb__panel_layout_init(&l);
  bb_image out;
  cr_assert_eq(bb__panels_compose(&p, 1, &l, &out, NULL, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__panels_compose(&p, 0, &l, &out, NULL, NULL), BB_ERR_ARGUMENT);
  l.columns = 0;
  cr_assert_eq(bb__panels_compose(&p, 1, &l, &out, NULL, NULL), BB_ERR_ARGUMENT);
  bb_image_free(&one);
}

/* The comparison: four renders in a row, each the render of its mode. */
Test(panels, compare_is_four_renders) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 24, 20, 1, NULL), BB_OK);
  for (int i = 0; i < 24 * 20; i++)
    h.pixels[i] = (float)(0.5 + 0.4 * sin(i * 0.37) * cos(i * 0.11));
  bb_bake_options bo;
  bb__bake_options_init(&bo);
  bo.height_scale = 4;
  bo.rays = 16;
  bb_bake_result r;
  cr_assert_eq(bb__bake_checked(&h, &bo, &r, NULL), BB_OK);
  bb_render_maps m = {&r.normal, &r.ssbump, &r.ao, &r.bent, NULL, NULL};
  bb_render_options o;
  bb__render_options_init(&o);
  bb_panel_layout l;
  bb__panel_layout_init(&l);
  bb_image out;
  int labels = 0;
  cr_assert_eq(bb__render_compare(&m, &o, &l, &out, &labels, NULL), BB_OK);
  cr_assert_eq(labels, 1);
  assert_grid(&out, 4, 1, 24, 20, label_strip(&out, 1, 20, 8, 12), 8);
  const bb_render_mode modes[4] = {BB_RENDER_NORMAL, BB_RENDER_SSBUMP, BB_RENDER_SSBUMP,
                                   BB_RENDER_NORMAL_AO};
  for (int i = 0; i < 4; i++) {
    o.mode = modes[i];
    o.specular_exponent = i == 2 ? BB_COMPARE_SPECULAR_EXPONENT : 0.0;
    bb_image one;
    cr_assert_eq(bb__render(&m, &o, &one, NULL), BB_OK);
    for (int y = 0; y < 20; y++)
      cr_assert_eq(memcmp(bb_image_texel(&out, 8 + i * 32, 8 + y),
                          bb_image_texel(&one, 0, y), sizeof(float) * 3 * 24),
                   0, "panel %d row %d", i, y);
    bb_image_free(&one);
  }
  bb_image_free(&out);
  m.ao = NULL;
  cr_assert_eq(bb__render_compare(&m, &o, &l, &out, &labels, NULL), BB_ERR_ARGUMENT,
               "the ao panel needs ao");
  bb_bake_result_free(&r);
  bb_image_free(&h);
}
