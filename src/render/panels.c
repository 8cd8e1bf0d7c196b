/* panels.c: pictures of maps side by side: tiling, cropping, resampling,
 * display encodings, labelled grids and the paper's four-panel comparison.
 * Text goes through OpenImageIO (io_oiio.cpp); the grid is drawn here. */
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bb_status check_input(const bb_image *in, const bb_image *out, const char *what,
                             bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: out is NULL", what);
  if (!in || !in->pixels || in->width <= 0 || in->height <= 0 || in->channels <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: missing or empty image", what);
  if (in == out)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the output must be a separate image",
                    what);
  return BB_OK;
}

/* Row y of img, channel 0. */
static float *row_of(const bb_image *img, int y) {
  return img->pixels + (size_t)y * (size_t)img->width * (size_t)img->channels;
}

bb_status bb_image_tile(const bb_image *in, int nx, int ny, bb_image *out,
                        bb_error *err) {
  bb_status st = check_input(in, out, "tile", err);
  if (st != BB_OK)
    return st;
  memset(out, 0, sizeof *out);
  if (nx < 1 || ny < 1 || nx > BB_MAX_DIMENSION / in->width ||
      ny > BB_MAX_DIMENSION / in->height)
    return bb__fail(err, BB_ERR_SIZE, "tile: %dx%d copies of %dx%d is too large or empty",
                    nx, ny, in->width, in->height);
  st = bb_image_alloc(out, in->width * nx, in->height * ny, in->channels, err);
  if (st != BB_OK)
    return st;
  const size_t row_floats = (size_t)in->width * (size_t)in->channels;
  for (int y = 0; y < out->height; y++) {
    const float *src = row_of(in, y % in->height);
    float *dst = row_of(out, y);
    for (int i = 0; i < nx; i++)
      memcpy(dst + (size_t)i * row_floats, src, row_floats * sizeof(float));
  }
  return BB_OK;
}

bb_status bb_image_crop(const bb_image *in, int x, int y, int width, int height,
                        bb_image *out, bb_error *err) {
  bb_status st = check_input(in, out, "crop", err);
  if (st != BB_OK)
    return st;
  memset(out, 0, sizeof *out);
  if (x < 0 || y < 0 || width <= 0 || height <= 0 || width > in->width - x ||
      height > in->height - y)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "crop: window %d,%d %dx%d is not inside the %dx%d image", x, y, width,
                    height, in->width, in->height);
  st = bb_image_alloc(out, width, height, in->channels, err);
  if (st != BB_OK)
    return st;
  const size_t c = (size_t)in->channels;
  for (int j = 0; j < height; j++)
    memcpy(row_of(out, j), row_of(in, y + j) + (size_t)x * c,
           (size_t)width * c * sizeof(float));
  return BB_OK;
}

/* ------------------------------------------------------------- resample */

/* The input texels output texel i covers, [n_in * i / n_out, n_in * (i + 1)
 * / n_out), and the share of each: first index and weights. */
typedef struct footprint {
  int *first, *count;
  double *weight; /* count[i] weights per output texel, at offset[i] */
  size_t *offset;
} footprint;

static void footprint_free(footprint *f) {
  free(f->first);
  free(f->count);
  free(f->weight);
  free(f->offset);
  memset(f, 0, sizeof *f);
}

static bb_status footprint_make(int n_in, int n_out, footprint *f, bb_error *err) {
  memset(f, 0, sizeof *f);
  /* Each output texel touches at most ceil(n_in / n_out) + 1 inputs. */
  size_t per = (size_t)(n_in / n_out) + 2;
  f->first = malloc((size_t)n_out * sizeof *f->first);
  f->count = malloc((size_t)n_out * sizeof *f->count);
  f->offset = malloc((size_t)n_out * sizeof *f->offset);
  f->weight = malloc((size_t)n_out * per * sizeof *f->weight);
  if (!f->first || !f->count || !f->offset || !f->weight) {
    footprint_free(f);
    return bb__fail(err, BB_ERR_MEMORY, "resample: out of memory");
  }
  const double step = (double)n_in / (double)n_out;
  for (int i = 0; i < n_out; i++) {
    double x0 = step * i, x1 = i + 1 == n_out ? (double)n_in : step * (i + 1);
    int j0 = (int)floor(x0), j1 = (int)ceil(x1);
    if (j1 > n_in)
      j1 = n_in;
    f->first[i] = j0;
    f->count[i] = 0;
    f->offset[i] = (size_t)i * per;
    for (int j = j0; j < j1; j++) {
      double overlap = fmin(x1, j + 1.0) - fmax(x0, (double)j);
      if (overlap > 0.0)
        f->weight[f->offset[i] + (size_t)f->count[i]++] = overlap / (x1 - x0);
      else if (f->count[i] == 0)
        f->first[i] = j + 1;
    }
  }
  return BB_OK;
}

/* Resamples along x (horizontal = 1) or y of in into out (already sized). */
static void resample_axis(const bb_image *in, const footprint *f, int horizontal,
                          bb_image *out) {
  const size_t c = (size_t)in->channels;
  for (int y = 0; y < out->height; y++)
    for (int x = 0; x < out->width; x++) {
      const int i = horizontal ? x : y;
      float *dst = row_of(out, y) + (size_t)x * c;
      for (size_t k = 0; k < c; k++) {
        double sum = 0.0;
        for (int t = 0; t < f->count[i]; t++) {
          int j = f->first[i] + t;
          const float *src =
              horizontal ? row_of(in, y) + (size_t)j * c : row_of(in, j) + (size_t)x * c;
          sum += f->weight[f->offset[i] + (size_t)t] * (double)src[k];
        }
        dst[k] = (float)sum;
      }
    }
}

bb_status bb_image_resample(const bb_image *in, int width, int height, bb_image *out,
                            bb_error *err) {
  bb_status st = check_input(in, out, "resample", err);
  if (st != BB_OK)
    return st;
  memset(out, 0, sizeof *out);
  bb_image wide = {0};
  footprint fx = {0}, fy = {0};
  st = bb_image_alloc(&wide, width, in->height, in->channels, err);
  if (st == BB_OK)
    st = bb_image_alloc(out, width, height, in->channels, err);
  if (st == BB_OK)
    st = footprint_make(in->width, width, &fx, err);
  if (st == BB_OK)
    st = footprint_make(in->height, height, &fy, err);
  if (st == BB_OK) {
    resample_axis(in, &fx, 1, &wide);
    resample_axis(&wide, &fy, 0, out);
  } else {
    bb_image_free(out);
  }
  footprint_free(&fx);
  footprint_free(&fy);
  bb_image_free(&wide);
  return st;
}

/* -------------------------------------------------------------- display */

static float clamp01(double v) {
  return (float)(v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0);
}

bb_status bb_image_to_display(const bb_image *map, bb_range range, float low, float high,
                              bb_image *rgb, bb_error *err) {
  bb_status st = check_input(map, rgb, "display", err);
  if (st != BB_OK)
    return st;
  memset(rgb, 0, sizeof *rgb);
  if (!(high > low) || !isfinite(low) || !isfinite(high))
    return bb__fail(err, BB_ERR_ARGUMENT, "display: range %g..%g is empty", (double)low,
                    (double)high);
  st = bb_image_alloc(rgb, map->width, map->height, 3, err);
  if (st != BB_OK)
    return st;
  const size_t count = (size_t)map->width * (size_t)map->height,
               c = (size_t)map->channels;
  const int grey = map->channels < 3;
  for (size_t i = 0; i < count; i++)
    for (int k = 0; k < 3; k++) {
      double v = (double)map->pixels[i * c + (grey ? 0 : (size_t)k)];
      v = range == BB_RANGE_SIGNED ? 0.5 + 0.5 * v : (v - low) / ((double)high - low);
      rgb->pixels[3 * i + (size_t)k] = clamp01(v);
    }
  return BB_OK;
}

/* ----------------------------------------------------------------- grid */

void bb_panel_layout_init(bb_panel_layout *l) {
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
 * bb_panels_compose; 0 when there is none. */
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
    bb_status st = bb_image_resample(panel, g->cell_width,
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

bb_status bb_panels_compose(const bb_panel *panels, int count, const bb_panel_layout *l,
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

/* ----------------------------------------------------------- comparison */

bb_status bb_render_compare(const bb_render_maps *maps, const bb_render_options *o,
                            const bb_panel_layout *l, bb_image *out, int *labels_drawn,
                            bb_error *err) {
  if (labels_drawn)
    *labels_drawn = 0;
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: out is NULL");
  memset(out, 0, sizeof *out);
  if (!o || !l)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: options are NULL");
  static const struct {
    bb_render_mode mode;
    int specular;
    const char *label;
  } kinds[] = {
      {BB_RENDER_NORMAL, 0, "normal-mapped"},
      {BB_RENDER_SSBUMP, 0, "ssbump"},
      {BB_RENDER_SSBUMP, 1, "ssbump + specular"},
      {BB_RENDER_NORMAL_AO, 0, "ao"},
  };
  enum { KINDS = sizeof kinds / sizeof kinds[0] };
  bb_image renders[KINDS];
  bb_panel panels[KINDS];
  memset(renders, 0, sizeof renders);
  bb_status st = BB_OK;
  for (int i = 0; i < KINDS && st == BB_OK; i++) {
    bb_render_options po = *o;
    po.mode = kinds[i].mode;
    po.specular_exponent = !kinds[i].specular           ? 0.0
                           : o->specular_exponent > 0.0 ? o->specular_exponent
                                                        : BB_COMPARE_SPECULAR_EXPONENT;
    st = bb_render(maps, &po, &renders[i], err);
    panels[i] = (bb_panel){&renders[i], kinds[i].label};
  }
  if (st == BB_OK)
    st = bb_panels_compose(panels, KINDS, l, out, labels_drawn, err);
  for (int i = 0; i < KINDS; i++)
    bb_image_free(&renders[i]);
  return st;
}
