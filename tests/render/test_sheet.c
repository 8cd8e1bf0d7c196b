/* test_sheet.c: the contact sheet of a bake: its eight panels, their
 * encodings and labels, and bakes it cannot show. */
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "render/render_internal.h"

static void bake_small(bb_image *h, bb_bake_result *r, int trace) {
  cr_assert_eq(bb_image_alloc(h, 32, 24, 1, NULL), BB_OK);
  for (int y = 0; y < 24; y++)
    for (int x = 0; x < 32; x++)
      h->pixels[y * 32 + x] = (float)(0.3 + 0.2 * sin(x * 0.39) * cos(y * 0.52));
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 6;
  o.rays = 16;
  o.outputs = trace ? BB_MAPS_BAKED : BB_MAPS_BAKED & ~BB_MAPS_TRACED;
  cr_assert_eq(bb__bake_checked(h, &o, r, NULL), BB_OK);
}

/* Texel (x, y) of panel i of a 4-column sheet of 32-wide panels (24 high),
 * gap 8, label strips of label_h. */
static const float *panel_texel(const bb_image *sheet, int i, int x, int y, int label_h) {
  int px = 8 + (i % 4) * (32 + 8), py = 8 + (i / 4) * (24 + label_h + 8);
  return bb_image_texel(sheet, px + x, py + y);
}

Test(sheet, eight_labelled_panels) {
  bb_image h, sheet;
  bb_bake_result r;
  bake_small(&h, &r, 1);
  bb_sheet_options o;
  bb__sheet_options_init(&o);
  cr_assert_eq(o.layout.panel_width, 256);
  o.layout.panel_width = 32;
  int labels = 0;
  bb_error err = {{0}};
  cr_assert_eq(bb__sheet_make(&h, &r, &o, &sheet, &labels, &err), BB_OK, "%s",
               err.message);
  cr_assert_eq(labels, 1);
  /* Labels shrink to fit 32-pixel panels: a strip of 1.75 x 6..12 pixels. */
  const int label_h = (sheet.height - 8 - 2 * (24 + 8)) / 2;
  cr_assert_eq(sheet.width, 8 + 4 * 40);
  cr_assert_eq(sheet.height, 8 + 2 * (24 + label_h + 8));
  cr_assert(label_h >= (6 * 7 + 3) / 4 && label_h <= (12 * 7 + 3) / 4, "strip %d",
            label_h);
  /* The height is stretched over its own range: its lowest texel is black. */
  float lo = h.pixels[0], hi = h.pixels[0];
  int lowest = 0;
  for (int i = 1; i < 32 * 24; i++) {
    if (h.pixels[i] < lo)
      lo = h.pixels[i], lowest = i;
    hi = fmaxf(hi, h.pixels[i]);
  }
  cr_assert_eq(panel_texel(&sheet, 0, lowest % 32, lowest / 32, label_h)[0], 0.0f);
  float mid = (bb_image_texel(&h, 5, 7)[0] - lo) / (hi - lo);
  cr_assert_float_eq(panel_texel(&sheet, 0, 5, 7, label_h)[1], mid, 1e-6);
  /* Normal (panel 2) as 0.5 + 0.5 N, ssbump (4) raw, ao (5) grey. */
  for (int k = 0; k < 3; k++) {
    cr_assert_float_eq(panel_texel(&sheet, 2, 9, 3, label_h)[k],
                       0.5f + 0.5f * bb_image_texel(&r.normal, 9, 3)[k], 1e-6);
    cr_assert_float_eq(panel_texel(&sheet, 4, 9, 3, label_h)[k],
                       bb_image_texel(&r.ssbump, 9, 3)[k], 1e-6);
    cr_assert_float_eq(panel_texel(&sheet, 5, 9, 3, label_h)[k],
                       bb_image_texel(&r.ao, 9, 3)[0], 1e-6);
  }
  /* The lit panel (7) is the render of o.lit, clamped to [0, 1]. */
  bb_render_maps m = {&r.normal, &r.ssbump, &r.ao, &r.bent, NULL, NULL};
  bb_image lit;
  cr_assert_eq(bb__render(&m, &o.lit, &lit, NULL), BB_OK);
  for (int k = 0; k < 3; k++)
    cr_assert_float_eq(panel_texel(&sheet, 7, 20, 11, label_h)[k],
                       fminf(1.0f, bb_image_texel(&lit, 20, 11)[k]), 1e-6);
  bb_image_free(&lit);
  bb_image_free(&sheet);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

Test(sheet, needs_a_traced_bake) {
  bb_image h, sheet;
  bb_bake_result r;
  bake_small(&h, &r, 0);
  bb_sheet_options o;
  bb__sheet_options_init(&o);
  bb_error err = {{0}};
  cr_assert_eq(bb__sheet_make(&h, &r, &o, &sheet, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "traced"), "%s", err.message);
  cr_assert_null(sheet.pixels);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}
