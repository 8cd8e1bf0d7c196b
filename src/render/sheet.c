/* sheet.c: one labelled contact sheet of every map of a bake and one lit
 * render, for a quick look or a code-review comment. */

#include "trace/basis.h"
#include "core/internal.h"
#include "render/render_internal.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

enum { SHEET_PANEL_WIDTH = 256 };

void bb__sheet_options_init(bb_sheet_options *o) {
  memset(o, 0, sizeof *o);
  bb__panel_layout_init(&o->layout);
  o->layout.panel_width = SHEET_PANEL_WIDTH;
  bb__render_options_init(&o->lit);
}

/* The range heights are stretched over: the input's, so the filtered height
 * shows what smoothing changed on the same scale. A flat map gets a unit
 * range around its value. */
static void height_range(const bb_image *h, float *low, float *high) {
  const size_t n = (size_t)h->width * (size_t)h->height;
  float lo = h->pixels[0], hi = h->pixels[0];
  for (size_t i = 1; i < n; i++) {
    lo = fminf(lo, h->pixels[i]);
    hi = fmaxf(hi, h->pixels[i]);
  }
  if (!(hi > lo)) {
    lo -= 0.5f;
    hi = lo + 1.0f;
  }
  *low = lo;
  *high = hi;
}

static bb_status check_bake(const bb_image *height, const bb_bake_result *r,
                            bb_error *err) {
  if (!height || !height->pixels || height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "sheet: need the 1-channel height of the bake");
  if (!r || !r->filtered.pixels || !r->normal.pixels || !r->weights.pixels ||
      !r->ssbump.pixels || !r->ao.pixels || !r->bent.pixels)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "sheet: need a traced bake (ssbump, ao and bent)");
  if (r->normal.width != height->width || r->normal.height != height->height)
    return bb__fail(err, BB_ERR_ARGUMENT, "sheet: the bake is %dx%d, the height %dx%d",
                    r->normal.width, r->normal.height, height->width, height->height);
  /* Its weights, ssbump and lit panel show Half-Life 2's three directions. */
  return bb__check_hl2_map(&r->ssbump, r->basis.count ? &r->basis : NULL, "sheet: the bake",
                           err);
}

enum { SHEET_PANELS = 8 };

/* The panels' display images and labels. */
typedef struct sheet_panels {
  bb_image images[SHEET_PANELS];
  bb_panel panels[SHEET_PANELS];
  char lit_label[96];
} sheet_panels;

static void sheet_panels_free(sheet_panels *s) {
  for (int i = 0; i < SHEET_PANELS; i++)
    bb_image_free(&s->images[i]);
}

static bb_status lit_panel(const bb_bake_result *r, const bb_render_options *lit,
                           sheet_panels *s, bb_image *rgb, bb_error *err) {
  bb_render_maps maps = {&r->normal, &r->ssbump, &r->ao, &r->bent, NULL, NULL};
  bb_image render = {0};
  bb_status st = bb__render(&maps, lit, &render, err);
  if (st == BB_OK)
    st = bb__image_to_display(&render, BB_RANGE_UNIT, 0.0f, 1.0f, rgb, err);
  bb_image_free(&render);
  if (lit->dynamic_light)
    snprintf(s->lit_label, sizeof s->lit_label, "lit: %s, light %g,%g",
             bb__render_mode_name(lit->mode), lit->light_azimuth, lit->light_elevation);
  else
    snprintf(s->lit_label, sizeof s->lit_label, "lit: %s, lightmaps",
             bb__render_mode_name(lit->mode));
  return st;
}

static bb_status make_panels(const bb_image *height, const bb_bake_result *r,
                             const bb_render_options *lit, sheet_panels *s,
                             bb_error *err) {
  float low, high;
  height_range(height, &low, &high);
  const struct {
    const bb_image *map;
    bb_range range;
    float low, high;
    const char *label;
  } maps[SHEET_PANELS - 1] = {
      {height, BB_RANGE_UNIT, low, high, "height"},
      {&r->filtered, BB_RANGE_UNIT, low, high, "filtered height"},
      {&r->normal, BB_RANGE_SIGNED, 0.0f, 1.0f, "normal"},
      {&r->weights, BB_RANGE_UNIT, 0.0f, 1.0f, "weights"},
      {&r->ssbump, BB_RANGE_UNIT, 0.0f, 1.0f, "ssbump"},
      {&r->ao, BB_RANGE_UNIT, 0.0f, 1.0f, "ao"},
      {&r->bent, BB_RANGE_SIGNED, 0.0f, 1.0f, "bent normal"},
  };
  bb_status st = BB_OK;
  for (int i = 0; i < SHEET_PANELS - 1 && st == BB_OK; i++) {
    st = bb__image_to_display(maps[i].map, maps[i].range, maps[i].low, maps[i].high,
                             &s->images[i], err);
    s->panels[i] = (bb_panel){&s->images[i], maps[i].label};
  }
  if (st == BB_OK)
    st = lit_panel(r, lit, s, &s->images[SHEET_PANELS - 1], err);
  s->panels[SHEET_PANELS - 1] = (bb_panel){&s->images[SHEET_PANELS - 1], s->lit_label};
  return st;
}

bb_status bb__sheet_make(const bb_image *height, const bb_bake_result *r,
                        const bb_sheet_options *o, bb_image *out, int *labels_drawn,
                        bb_error *err) {
  if (labels_drawn)
    *labels_drawn = 0;
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "sheet: out is NULL");
  memset(out, 0, sizeof *out);
  if (!o)
    return bb__fail(err, BB_ERR_ARGUMENT, "sheet: options are NULL");
  bb_status st = check_bake(height, r, err);
  if (st != BB_OK)
    return st;
  sheet_panels s;
  memset(&s, 0, sizeof s);
  st = make_panels(height, r, &o->lit, &s, err);
  if (st == BB_OK)
    st = bb__panels_compose(s.panels, SHEET_PANELS, &o->layout, out, labels_drawn, err);
  sheet_panels_free(&s);
  return st;
}
