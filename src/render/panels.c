/* panels.c: pictures side by side in a labelled grid. Text goes through
 * OpenImageIO (oiio_text.cpp); the grid is drawn here. */

#include "core/internal.h"
#include "render/text.h"
#include "render/render_internal.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Row y of img, channel 0. */
static float *row_of(const bb_image *img, int y) {
  return img->pixels + (size_t)y * (size_t)img->width * (size_t)img->channels;
}

/* ----------------------------------------------------------------- grid */

void bb__panel_layout_init(bb_panel_layout *l) {
  memset(l, 0, sizeof *l);
  l->columns = 4;
  l->panel_width = 0;
  l->gap = 8;
  l->font_size = 0;
  l->font = NULL;
}

#define BACKGROUND 0.12f
#define LABEL_GREY 0.92f

/* The font labels are drawn with, into font (capacity cap), by the rule of
 * bb__panels_compose; 0 when there is none. */
static int find_font(const char *requested, char *font, size_t cap) {
  static const char *const candidates[] = {"DejaVuSans", "LiberationSans-Regular",
                                           "FreeSans", "NotoSans-Regular"};
  const char *env = getenv("BUMPBAKE_FONT");
  if (requested || env) {
    const char *only = requested ? requested : env;
    snprintf(font, cap, "%s", only);
    return only[0] && bb__font_usable(only);
  }
  for (size_t i = 0; i < sizeof candidates / sizeof candidates[0]; i++)
    if (bb__font_usable(candidates[i])) {
      snprintf(font, cap, "%s", candidates[i]);
      return 1;
    }
  return 0;
}

/* Geometry of a grid of panels. */
typedef struct grid {
  int columns, rows;
  int cell_width, cell_height; /* the panel area of a cell */
  int label_height;            /* 0 without labels */
  int font_size;               /* largest label size, pixels */
  int gap;
} grid;

static void grid_origin(const grid *g, int index, int *x, int *y) {
  *x = g->gap + (index % g->columns) * (g->cell_width + g->gap);
  *y = g->gap + (index / g->columns) * (g->cell_height + g->label_height + g->gap);
}

/* Height of panel p once scaled to the cell width. */
static int scaled_height(const bb_image *p, int cell_width) {
  long h = lround((double)p->height * cell_width / p->width);
  return h < 1 ? 1 : (h > BB_MAX_DIMENSION ? BB_MAX_DIMENSION : (int)h);
}

static bb_status check_panels(const bb_panel *panels, int count, const bb_panel_layout *l,
                              bb_error *err) {
  if (!panels || count < 1 || !l)
    return bb__fail(err, BB_ERR_ARGUMENT, "panels: nothing to lay out");
  if (l->columns < 1 || l->panel_width < 0 || l->gap < 0 || l->gap > 4096 ||
      (l->font_size != 0 && (l->font_size < 6 || l->font_size > 512)))
    return bb__fail(
        err, BB_ERR_ARGUMENT,
        "panels: bad layout (columns %d, panel width %d, gap %d, font size %d)",
        l->columns, l->panel_width, l->gap, l->font_size);
  for (int i = 0; i < count; i++) {
    const bb_image *p = panels[i].image;
    if (!p || !p->pixels || p->channels != 3 || p->width <= 0 || p->height <= 0)
      return bb__fail(err, BB_ERR_ARGUMENT, "panels: panel %d is not a 3-channel image",
                      i);
  }
  return BB_OK;
}

static int any_label(const bb_panel *panels, int count) {
  for (int i = 0; i < count; i++)
    if (panels[i].label && panels[i].label[0])
      return 1;
  return 0;
}

/* One size for every label: the planned one, made smaller until the widest
 * label fits its cell (6 pixels at least); the strip follows it. */
static void fit_labels(const bb_panel *panels, int count, const char *font, grid *g) {
  for (int i = 0; i < count; i++) {
    const char *label = panels[i].label;
    if (!label || !label[0])
      continue;
    while (g->font_size > 6 && bb__text_width(label, g->font_size, font) > g->cell_width)
      g->font_size--;
  }
  g->label_height = (g->font_size * 7 + 3) / 4;
}

static bb_status grid_plan(const bb_panel *panels, int count, const bb_panel_layout *l,
                           int labelled, const char *font, grid *g, bb_error *err) {
  memset(g, 0, sizeof *g);
  g->columns = l->columns < count ? l->columns : count;
  g->rows = (count + g->columns - 1) / g->columns;
  g->gap = l->gap;
  for (int i = 0; i < count; i++)
    if (panels[i].image->width > g->cell_width)
      g->cell_width = panels[i].image->width;
  if (l->panel_width > 0)
    g->cell_width = l->panel_width;
  for (int i = 0; i < count; i++) {
    int h = scaled_height(panels[i].image, g->cell_width);
    if (h > g->cell_height)
      g->cell_height = h;
  }
  g->font_size = l->font_size;
  if (g->font_size == 0) {
    g->font_size = g->cell_width / 16;
    g->font_size = g->font_size < 12 ? 12 : (g->font_size > 48 ? 48 : g->font_size);
  }
  g->label_height = 0;
  if (labelled)
    fit_labels(panels, count, font, g);
  long w = g->gap + (long)g->columns * (g->cell_width + g->gap);
  long h = g->gap + (long)g->rows * (g->cell_height + g->label_height + g->gap);
  if (w > BB_MAX_DIMENSION || h > BB_MAX_DIMENSION)
    return bb__fail(err, BB_ERR_SIZE, "panels: a %ldx%ld grid is over the maximum", w, h);
  return BB_OK;
}

/* Copies panel (resampled to the cell width when needed) to (x, y) of out. */
static bb_status paste_panel(const bb_image *panel, const grid *g, int x, int y,
                             bb_image *out, bb_error *err) {
  bb_image scaled = {0};
  const bb_image *src = panel;
  if (panel->width != g->cell_width) {
    bb_status st = bb__image_resample(panel, g->cell_width,
                                     scaled_height(panel, g->cell_width), &scaled, err);
    if (st != BB_OK)
      return st;
    src = &scaled;
  }
  for (int j = 0; j < src->height; j++)
    memcpy(row_of(out, y + j) + 3 * (size_t)x, row_of(src, j),
           3 * (size_t)src->width * sizeof(float));
  bb_image_free(&scaled);
  return BB_OK;
}

/* Draws label centred under a cell. */
static bb_status draw_label(const char *label, const grid *g, const char *font, int x,
                            int y, bb_image *out, bb_error *err) {
  if (!label || !label[0])
    return BB_OK;
  const float grey[3] = {LABEL_GREY, LABEL_GREY, LABEL_GREY};
  /* The strip is 1.75 font sizes tall; a baseline 2/3 down centres a line's
   * ascent (~0.75 size) and descent (~0.25) in it. */
  return bb__text_draw(out, x + g->cell_width / 2,
                       y + g->cell_height + (2 * g->label_height) / 3, label,
                       g->font_size, grey, font, err);
}

bb_status bb__panels_compose(const bb_panel *panels, int count, const bb_panel_layout *l,
                            bb_image *out, int *labels_drawn, bb_error *err) {
  if (labels_drawn)
    *labels_drawn = 0;
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "panels: out is NULL");
  memset(out, 0, sizeof *out);
  bb_status st = check_panels(panels, count, l, err);
  if (st != BB_OK)
    return st;
  char font[1024];
  const int labelled = any_label(panels, count) && find_font(l->font, font, sizeof font);
  grid g;
  st = grid_plan(panels, count, l, labelled, font, &g, err);
  if (st == BB_OK)
    st =
        bb_image_alloc(out, g.gap + g.columns * (g.cell_width + g.gap),
                       g.gap + g.rows * (g.cell_height + g.label_height + g.gap), 3, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)out->width * (size_t)out->height * 3;
  for (size_t i = 0; i < n; i++)
    out->pixels[i] = BACKGROUND;
  for (int i = 0; i < count && st == BB_OK; i++) {
    int x, y;
    grid_origin(&g, i, &x, &y);
    st = paste_panel(panels[i].image, &g, x, y, out, err);
    if (st == BB_OK && labelled)
      st = draw_label(panels[i].label, &g, font, x, y, out, err);
  }
  if (st != BB_OK) {
    bb_image_free(out);
    return st;
  }
  if (labels_drawn)
    *labels_drawn = labelled;
  return BB_OK;
}
