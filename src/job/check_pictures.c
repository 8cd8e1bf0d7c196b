/* check_pictures.c: the HTML report's pictures of a golden check. Every
 * case gets a thumbnail, packed 256 to an atlas image (one file, and one
 * sync, per 256 cases rather than per case); a case that does not pass gets
 * one strip image: golden, new and the heat map of their difference side
 * by side, which the page shows as three pictures, a flip and a slider.
 *
 * Maps are shown as a person would look at them: unit vectors stored raw
 * (float files of normal maps) as 0.5 + 0.5 N, values clamped to [0, 1],
 * a NaN magenta. The heat map keeps the largest difference of each block it
 * shrinks (a one-texel regression stays visible in a big map), on a square
 * root scale whose white is the largest finite difference. */
#include "core/internal.h"
#include "job/check.h"
#include "image/image_write.h"

#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum {
  THUMB = BB__CHECK_THUMB,
  ATLAS_SIDE = BB__CHECK_ATLAS_SIDE,
  STRIP_MAX = 512 /* a strip's part is shrunk to fit this */
};

struct bb__check_atlas {
  bb_image image;     /* ATLAS_SIDE x ATLAS_SIDE cells, RGB */
  char name[32];      /* "img/t-HASH.png", relative to the report */
  char dir[PATH_MAX]; /* the report's directory */
  int used;
};

static uint64_t name_hash(const char *prefix, const char *name) {
  uint64_t h = BB__FNV64_OFFSET;
  for (const char *s = prefix; *s; s++)
    h = (h ^ (unsigned char)*s) * 0x100000001b3ULL;
  for (const char *s = name; *s; s++)
    h = (h ^ (unsigned char)*s) * 0x100000001b3ULL;
  return h;
}

/* ------------------------------------------------------------- colours */

/* The colour of texel (x, y) of img as shown. */
static void shown(const bb_image *img, int signed_raw, int x, int y, float rgb[3]) {
  const float *p =
      img->pixels + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels;
  for (int c = 0; c < 3; c++) {
    const float v = img->channels >= 3   ? p[c]
                    : img->channels == 2 ? (c < 2 ? p[c] : 0)
                                         : p[0];
    if (isnan(v)) {
      rgb[0] = 1, rgb[1] = 0, rgb[2] = 1;
      return;
    }
    const float u = signed_raw ? 0.5f + 0.5f * v : v;
    rgb[c] = u < 0 ? 0 : u > 1 ? 1 : u;
  }
}

/* The largest difference of any channel at texel i: a NaN against a number
 * is infinite, two NaNs equal (as bb__compare_images counts them). */
static double texel_difference(const bb_image *a, const bb_image *b, size_t i) {
  double worst = 0;
  for (int c = 0; c < a->channels; c++) {
    const float x = a->pixels[i * (size_t)a->channels + (size_t)c];
    const float y = b->pixels[i * (size_t)b->channels + (size_t)c];
    double d = (x == y || (isnan(x) && isnan(y))) ? 0
               : (isnan(x) || isnan(y))           ? INFINITY
                                                  : fabs((double)x - (double)y);
    if (d > worst)
      worst = d;
  }
  return worst;
}

/* A heat colour of t in [0, 1]: black, blue, magenta, orange, yellow,
 * white. */
static void heat(double t, float rgb[3]) {
  static const float stops[6][3] = {{0, 0, 0},          {0.1f, 0.1f, 0.6f},
                                    {0.7f, 0.1f, 0.6f}, {1, 0.45f, 0.1f},
                                    {1, 0.9f, 0.2f},    {1, 1, 1}};
  const double u = (t < 0 ? 0 : t > 1 ? 1 : t) * 5;
  const int i = u >= 5 ? 4 : (int)u;
  const float f = (float)(u - i);
  for (int c = 0; c < 3; c++)
    rgb[c] = stops[i][c] + f * (stops[i + 1][c] - stops[i][c]);
}

/* ---------------------------------------------------------- shrinking */

/* The size w x h fits in a box of side `box`, kept in proportion (at least
 * 1 x 1). */
static void fit(int w, int h, int box, int *fw, int *fh) {
  const double s = fmin((double)box / w, (double)box / h);
  *fw = s >= 1 ? w : (int)fmax(1, floor(w * s));
  *fh = s >= 1 ? h : (int)fmax(1, floor(h * s));
}

/* The end of the block of source texels (of `side`) target texel i of
 * `target` covers, from start: at least one texel. */
static int span_end(int i, int start, int side, int target) {
  const int end = (int)((long)(i + 1) * side / target);
  return end > start ? end : start + 1;
}

/* Draws img shrunk (a mean per block) to fw x fh at (ox, oy) of out. */
static void draw(bb_image *out, int ox, int oy, const bb_image *img, int signed_raw,
                 int fw, int fh) {
  for (int y = 0; y < fh; y++) {
    const int y0 = (int)((long)y * img->height / fh);
    const int y1 = span_end(y, y0, img->height, fh);
    for (int x = 0; x < fw; x++) {
      const int x0 = (int)((long)x * img->width / fw);
      const int x1 = span_end(x, x0, img->width, fw);
      double sum[3] = {0, 0, 0};
      for (int sy = y0; sy < y1; sy++)
        for (int sx = x0; sx < x1; sx++) {
          float rgb[3];
          shown(img, signed_raw, sx, sy, rgb);
          for (int c = 0; c < 3; c++)
            sum[c] += rgb[c];
        }
      float *o =
          out->pixels + ((size_t)(oy + y) * (size_t)out->width + (size_t)(ox + x)) * 3;
      const double n = (double)(y1 - y0) * (x1 - x0);
      for (int c = 0; c < 3; c++)
        o[c] = (float)(sum[c] / n);
    }
  }
}

/* Draws the heat map of |a - b| shrunk (the largest per block) to fw x fh
 * at (ox, oy) of out; the largest finite difference. */
static double draw_heat(bb_image *out, int ox, int oy, const bb_image *a,
                        const bb_image *b, int fw, int fh) {
  const size_t n = (size_t)a->width * (size_t)a->height;
  double max = 0;
  for (size_t i = 0; i < n; i++) {
    const double d = texel_difference(a, b, i);
    if (isfinite(d) && d > max)
      max = d;
  }
  for (int y = 0; y < fh; y++) {
    const int y0 = (int)((long)y * a->height / fh);
    const int y1 = span_end(y, y0, a->height, fh);
    for (int x = 0; x < fw; x++) {
      const int x0 = (int)((long)x * a->width / fw);
      const int x1 = span_end(x, x0, a->width, fw);
      double worst = 0;
      for (int sy = y0; sy < y1; sy++)
        for (int sx = x0; sx < x1; sx++) {
          const double d =
              texel_difference(a, b, (size_t)sy * (size_t)a->width + (size_t)sx);
          if (d > worst)
            worst = d;
        }
      const double t = !isfinite(worst) ? 1 : max > 0 ? sqrt(worst / max) : 0;
      heat(t,
           out->pixels + ((size_t)(oy + y) * (size_t)out->width + (size_t)(ox + x)) * 3);
    }
  }
  return max;
}

static bb_status write_png(const char *dir, const char *name, const bb_image *img,
                           bb_error *err) {
  char path[PATH_MAX];
  if ((size_t)snprintf(path, sizeof path, "%s/%s", dir, name) >= sizeof path)
    return bb__fail(err, BB_ERR_IO, "%s: the path is too long", dir);
  const bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT, NULL, NULL};
  return bb__image_write(path, img, &wo, err);
}

/* ---------------------------------------------------------- thumbnails */

static bb_status atlas_flush(bb__check_atlas *a, bb_error *err) {
  if (!a || !a->used)
    return BB_OK;
  /* only the rows used: a last atlas of a few cases stays small */
  const int rows = (a->used + ATLAS_SIDE - 1) / ATLAS_SIDE;
  bb_image used = a->image;
  used.height = rows * THUMB;
  bb_status st = write_png(a->dir, a->name, &used, err);
  a->used = 0;
  return st;
}

bb_status bb__check_pictures_flush(bb__check_atlas **atlas, bb_error *err) {
  return atlas && *atlas ? atlas_flush(*atlas, err) : BB_OK;
}

void bb__check_atlas_free(bb__check_atlas *a) {
  if (!a)
    return;
  bb_image_free(&a->image);
  free(a);
}

static bb_status thumbnail(bb__check_atlas **atlas, const char *dir, bb__check_case *k,
                           const bb_image *img, int signed_raw, bb_error *err) {
  bb__check_atlas *a = *atlas;
  if (!a) {
    if (!(a = calloc(1, sizeof *a)))
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    bb_status st =
        bb_image_alloc(&a->image, ATLAS_SIDE * THUMB, ATLAS_SIDE * THUMB, 3, err);
    if (st != BB_OK) {
      free(a);
      return st;
    }
    *atlas = a;
  }
  if (a->used == ATLAS_SIDE * ATLAS_SIDE) {
    bb_status st = atlas_flush(a, err);
    if (st != BB_OK)
      return st;
  }
  if (!a->used) {
    snprintf(a->dir, sizeof a->dir, "%s", dir);
    snprintf(a->name, sizeof a->name, "img/t-%016llx.png",
             (unsigned long long)name_hash("thumbs:", k->name));
    const size_t n = (size_t)a->image.width * (size_t)a->image.height * 3;
    for (size_t i = 0; i < n; i++)
      a->image.pixels[i] = 0.13f;
  }
  const int cell = a->used++;
  int fw, fh;
  fit(img->width, img->height, THUMB, &fw, &fh);
  draw(&a->image, cell % ATLAS_SIDE * THUMB, cell / ATLAS_SIDE * THUMB, img, signed_raw,
       fw, fh);
  free(k->thumbs);
  if (!(k->thumbs = strdup(a->name)))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  k->thumb_cell = cell;
  k->thumb_width = fw;
  k->thumb_height = fh;
  return BB_OK;
}

/* ---------------------------------------------------------------- strips */

static bb_status strip(const char *dir, bb__check_case *k, const bb__check_sides *s,
                       bb_error *err) {
  const bb_image *parts[2] = {s->golden, s->fresh};
  const int signs[2] = {s->golden_signed, s->fresh_signed};
  const int both = s->golden && s->fresh;
  const int diff = both && s->golden->width == s->fresh->width &&
                   s->golden->height == s->fresh->height &&
                   s->golden->channels == s->fresh->channels;
  int pw = 0, ph = 0;
  for (int i = 0; i < 2; i++)
    if (parts[i]) {
      int fw, fh;
      fit(parts[i]->width, parts[i]->height, STRIP_MAX, &fw, &fh);
      pw = fw > pw ? fw : pw;
      ph = fh > ph ? fh : ph;
    }
  const int count = 2 + diff;
  bb_image out;
  bb_status st = bb_image_alloc(&out, pw * count, ph, 3, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)out.width * (size_t)out.height * 3;
  for (size_t i = 0; i < n; i++)
    out.pixels[i] = 0.13f;
  for (int i = 0; i < 2; i++)
    if (parts[i]) {
      int fw, fh;
      fit(parts[i]->width, parts[i]->height, STRIP_MAX, &fw, &fh);
      draw(&out, i * pw, 0, parts[i], signs[i], fw, fh);
    }
  if (diff)
    k->heat_max = draw_heat(&out, 2 * pw, 0, s->golden, s->fresh, pw, ph);
  char name[32];
  snprintf(name, sizeof name, "img/c-%016llx.png",
           (unsigned long long)name_hash("case:", k->name));
  st = write_png(dir, name, &out, err);
  bb_image_free(&out);
  if (st == BB_OK) {
    free(k->strip);
    if (!(k->strip = strdup(name)))
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    k->strip_width = pw;
    k->strip_height = ph;
    k->strip_parts = count;
  }
  return st;
}

bb_status bb__check_pictures(bb__check_atlas **atlas, const char *dir, bb__check_case *k,
                             const bb__check_sides *s, bb_error *err) {
  const bb_image *shown_img = s->fresh ? s->fresh : s->golden;
  if (!shown_img)
    return BB_OK;
  bb_status st = thumbnail(atlas, dir, k, shown_img,
                           s->fresh ? s->fresh_signed : s->golden_signed, err);
  if (st == BB_OK && k->pub.status != BB_CHECK_PASS)
    st = strip(dir, k, s, err);
  return st;
}

/* 1 for the names this file gives pictures: "t-" or "c-", 16 hex digits,
 * ".png". */
static int is_picture_name(const char *name) {
  if (strlen(name) != 22 || (name[0] != 't' && name[0] != 'c') || name[1] != '-' ||
      strcmp(name + 18, ".png") != 0)
    return 0;
  for (int i = 2; i < 18; i++)
    if (!strchr("0123456789abcdef", name[i]))
      return 0;
  return 1;
}

int bb__check_picture_path(const char *relative) {
  return relative && strncmp(relative, "img/", 4) == 0 && is_picture_name(relative + 4);
}

static int by_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

void bb__check_pictures_prune(const char *dir, bb__check_case *const *cases, int count) {
  const char **shown_names = malloc(((size_t)count * 2 + 1) * sizeof *shown_names);
  if (!shown_names)
    return; /* stale pictures stay: nothing is lost */
  size_t n = 0;
  for (int i = 0; i < count; i++) {
    if (cases[i]->thumbs)
      shown_names[n++] = cases[i]->thumbs + 4;
    if (cases[i]->strip)
      shown_names[n++] = cases[i]->strip + 4;
  }
  qsort(shown_names, n, sizeof *shown_names, by_name);
  char img[PATH_MAX];
  snprintf(img, sizeof img, "%s/img", dir);
  DIR *d = opendir(img);
  for (struct dirent *e; d && (e = readdir(d));) {
    const char *name = e->d_name;
    if (is_picture_name(name) &&
        !bsearch(&name, shown_names, n, sizeof *shown_names, by_name)) {
      char path[PATH_MAX + 32];
      snprintf(path, sizeof path, "%s/%s", img, name);
      unlink(path);
    }
  }
  if (d)
    closedir(d);
  free(shown_names);
}
