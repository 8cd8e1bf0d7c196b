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

bb_mip_filter bb__mip_filter(int normal_map) {
  return normal_map ? BB_MIP_RENORMALIZE : BB_MIP_AVERAGE;
}

void bb_mip_chain_free(bb_image *levels, int count) {
  if (!levels)
    return;
  for (int k = 0; k < count; k++)
    bb_image_free(&levels[k]);
  free(levels);
}

bb_status bb_mip_chain(const bb_image *img, bb_mip_filter filter, bb_image **levels,
                       int *count, bb_error *err) {
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
  st = bb_image_alloc(&chain[0], img->width, img->height, img->channels, err);
  if (st == BB_OK)
    memcpy(chain[0].pixels, img->pixels,
           (size_t)img->width * (size_t)img->height * (size_t)img->channels *
               sizeof(float));
  for (int k = 1; k < n && st == BB_OK; k++) {
    const bb_image *up = &chain[k - 1];
    st =
        bb__image_resize_box(up, half_of(up->width), half_of(up->height), &chain[k], err);
    if (st == BB_OK && filter == BB_MIP_RENORMALIZE)
      renormalize(&chain[k]);
  }
  if (st != BB_OK) {
    bb_mip_chain_free(chain, n);
    return st;
  }
  *levels = chain;
  *count = n;
  return BB_OK;
}
