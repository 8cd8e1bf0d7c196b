/* image_ops.c: whole-image operations for pictures: tiling, cropping,
 * area resampling and the display encodings of maps. */
#include "core/internal.h"
#include "render/render_internal.h"

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

bb_status bb__image_tile(const bb_image *in, int nx, int ny, bb_image *out,
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

bb_status bb__image_crop(const bb_image *in, int x, int y, int width, int height,
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

bb_status bb__image_resample(const bb_image *in, int width, int height, bb_image *out,
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

bb_status bb__image_to_display(const bb_image *map, bb_range range, float low, float high,
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
