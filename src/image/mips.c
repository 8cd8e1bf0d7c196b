/* mips.c: mip chains: each level box-filtered from the one above by
 * OpenImageIO (bb__image_resize_box), normal maps renormalised per level. */

#include "core/internal.h"
#include "image/oiio.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int half_of(int n) {
  return n / 2 > 1 ? n / 2 : 1;
}

static int level_count(int width, int height) {
  int count = 1;
  for (int w = width, h = height; w > 1 || h > 1; w = half_of(w), h = half_of(h))
    count++;
  return count;
}

/* Unit length on channels 0..2 of every texel, in place. */
static void renormalize(bb_image *img) {
  const size_t n = (size_t)img->width * (size_t)img->height;
  for (size_t i = 0; i < n; i++) {
    float *t = img->pixels + i * (size_t)img->channels;
    double v[3] = {t[0], t[1], t[2]};
    bb__normalize3(v);
    for (int k = 0; k < 3; k++)
      t[k] = (float)v[k];
  }
}

/* The level below up when both its sides are even: each texel the mean
 * of the 2 x 2 above it, summed row by row and scaled, (((a + b) + c) +
 * d) / 4, which is what OpenImageIO's box resize gives at exactly half
 * (the same bits: tools' checks on rock06's maps, and the output matrix),
 * at a small part of its cost (its resize was 430 M instructions of a
 * 1024 x 1024 VTF write, about a whole PNG write). Bands of rows on
 * threads (each texel its own sum: the same bits on any count). */
typedef struct halving {
  const bb_image *up;
  bb_image *out;
} halving;

enum { HALVING_BAND = 32 }; /* rows of the level below an item */

static void halve_band(void *user, int item) {
  const halving *hv = user;
  const bb_image *up = hv->up;
  const int w = hv->out->width, h = hv->out->height;
  const size_t ch = (size_t)up->channels, row = (size_t)up->width * ch;
  const int y1 = (item + 1) * HALVING_BAND < h ? (item + 1) * HALVING_BAND : h;
  for (int y = item * HALVING_BAND; y < y1; y++) {
    const float *p = up->pixels + (size_t)(2 * y) * row, *q = p + row;
    float *o = hv->out->pixels + (size_t)y * (size_t)w * ch;
    for (size_t x = 0; x < (size_t)w; x++)
      for (size_t c = 0; c < ch; c++) {
        const size_t i = 2 * x * ch + c;
        o[x * ch + c] = (((p[i] + p[i + ch]) + q[i]) + q[i + ch]) / 4.0f;
      }
  }
}

static bb_status halve_even(const bb_image *up, bb_image *out, int threads, bb_error *err) {
  bb_status st = bb_image_alloc(out, up->width / 2, up->height / 2, up->channels, err);
  if (st != BB_OK)
    return st;
  halving hv = {up, out};
  return bb__parallel_for((out->height + HALVING_BAND - 1) / HALVING_BAND, threads, halve_band,
                          &hv, NULL, NULL, err);
}

bb_mip_filter bb__mip_filter(int normal_map) {
  return normal_map ? BB_MIP_RENORMALIZE : BB_MIP_AVERAGE;
}

/* Frees levels[first..count) and the array. */
static void free_from(bb_image *levels, int first, int count) {
  if (!levels)
    return;
  for (int k = first; k < count; k++)
    bb_image_free(&levels[k]);
  free(levels);
}

void bb_mip_chain_free(bb_image *levels, int count) {
  free_from(levels, 0, count);
}

/* bb_mip_chain's work; borrow: levels[0] is *img itself (its pixels
 * not copied, and not the chain's to free); even halvings on threads (0:
 * all cores). */
static bb_status make_chain(const bb_image *img, bb_mip_filter filter, int borrow,
                            int threads, bb_image **levels, int *count, bb_error *err) {
  if (!levels || !count)
    return bb__fail(err, BB_ERR_ARGUMENT, "mip chain: levels and count are required");
  *levels = NULL;
  *count = 0;
  if (filter != BB_MIP_AVERAGE && filter != BB_MIP_RENORMALIZE)
    return bb__fail(err, BB_ERR_ARGUMENT, "mip chain: unknown filter %d", (int)filter);
  bb_status st =
      bb__check_channels(img, filter == BB_MIP_RENORMALIZE ? 3 : 1, "mip chain", err);
  if (st == BB_OK)
    st = bb__check_finite(img, img->channels, "mip chain", err);
  if (st != BB_OK)
    return st;
  const int n = level_count(img->width, img->height);
  bb_image *chain = calloc((size_t)n, sizeof *chain);
  if (!chain)
    return bb__fail(err, BB_ERR_MEMORY, "mip chain: out of memory");
  if (borrow)
    chain[0] = *img;
  else
    st = bb_image_alloc(&chain[0], img->width, img->height, img->channels, err);
  if (st == BB_OK && !borrow)
    memcpy(chain[0].pixels, img->pixels,
           (size_t)img->width * (size_t)img->height * (size_t)img->channels *
               sizeof(float));
  for (int k = 1; k < n && st == BB_OK; k++) {
    const bb_image *up = &chain[k - 1];
    st = up->width % 2 == 0 && up->height % 2 == 0
             ? halve_even(up, &chain[k], threads, err)
             : bb__image_resize_box(up, half_of(up->width), half_of(up->height), &chain[k],
                                    err);
    if (st == BB_OK && filter == BB_MIP_RENORMALIZE)
      renormalize(&chain[k]);
  }
  if (st != BB_OK) {
    if (borrow)
      bb__mip_chain_borrowed_free(chain, n);
    else
      bb_mip_chain_free(chain, n);
    return st;
  }
  *levels = chain;
  *count = n;
  return BB_OK;
}

bb_status bb_mip_chain(const bb_image *img, bb_mip_filter filter, bb_image **levels,
                       int *count, bb_error *err) {
  return make_chain(img, filter, 0, 1, levels, count, err);
}

bb_status bb__mip_chain_borrowed(const bb_image *img, bb_mip_filter filter, int threads,
                                 bb_image **levels, int *count, bb_error *err) {
  return make_chain(img, filter, 1, threads, levels, count, err);
}

void bb__mip_chain_borrowed_free(bb_image *levels, int count) {
  free_from(levels, 1, count);
}
