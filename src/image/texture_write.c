/* texture_write.c: bb__texture_write and the texture branch of
 * bb__image_write: a VTF or DDS file by extension, from one image (its mip
 * chain made here) or from a caller's chain, staged and committed as every
 * file the library writes. */

#include "core/internal.h"
#include "image/oiio.h"
#include "texture/dds.h"
#include "files/safe_file.h"
#include "texture/texture.h"
#include "texture/vtf.h"
#include "image/image_write.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The levels to write: bb_mip_chain of img by the map's rule (it also
 * rejects NaN and infinite texels), img itself its top level (freed by
 * bb__mip_chain_borrowed_free). */
static bb_status texture_chain(const bb_image *img, bb_map_kind map, int threads,
                               bb_image **levels, int *count, bb_error *err) {
  return bb__mip_chain_borrowed(img, bb__mip_filter(bb_map_kind_get(map)->unit_vectors), threads,
                                levels, count, err);
}

/* A caller's chain must be one bb_mip_chain could have made (each level
 * half the one before, floored, at least 1; the same channels) and finite. */
static bb_status check_given_chain(const char *path, const bb_image *levels, int count,
                                   bb_error *err) {
  for (int k = 0; k < count; k++) {
    const bb_image *b = &levels[k];
    if (!b->pixels || b->width <= 0 || b->height <= 0 || b->channels <= 0)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: mip level %d is empty", path, k);
    if (k > 0) {
      const bb_image *a = &levels[k - 1];
      const int w = a->width / 2 > 1 ? a->width / 2 : 1, h = a->height / 2 > 1 ? a->height / 2 : 1;
      if (b->width != w || b->height != h || b->channels != a->channels)
        return bb__fail(err, BB_ERR_ARGUMENT,
                        "%s: mip level %d is %dx%dx%d, not %dx%dx%d (half of the level before)",
                        path, k, b->width, b->height, b->channels, w, h, a->channels);
    }
    const size_t n = (size_t)b->width * (size_t)b->height * (size_t)b->channels;
    for (size_t i = 0; i < n; i++)
      if (!isfinite(b->pixels[i]))
        return bb__fail(err, BB_ERR_VALUE, "%s: mip level %d has a NaN or infinite value",
                        path, k);
  }
  return BB_OK;
}

bb_status bb__texture_stage(const char *path, const bb_image *levels, int count, int given,
                            const bb_texture_options *options, bb_staged_file *f,
                            bb_error *err) {
  bb_texture_options effective;
  if (options)
    effective = *options;
  else
    bb_texture_options_init(&effective);
  /* A caller's chain is written as it is: mip-mapped when it has levels. */
  if (given)
    effective.mips = count > 1;
  const bb_texture_options *o = &effective;
  if (!levels || count < 1 || !levels[0].pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no image", path ? path : "texture");
  bb_texture_format format;
  bb_status st = bb__texture_resolve(path, levels[0].width, levels[0].height,
                                     levels[0].channels, o, &format, err);
  if (st == BB_OK && given)
    st = check_given_chain(path, levels, count, err);
  if (st != BB_OK)
    return st;
  /* The levels: the caller's, or the chain of the one image by the map's rule. */
  bb_image *made = NULL, *extra = NULL;
  int made_count = 0, extra_count = 0;
  const bb_image *chain = levels;
  int chain_count = count, write = count;
  if (!given) {
    st = texture_chain(&levels[0], o->map, o->threads, &made, &made_count, err);
    chain = made;
    chain_count = made_count;
    write = o->mips ? made_count : 1;
  }
  /* A VTF's low-resolution image is the first level of at most 16 x 16;
   * a caller's chain that stops above it is carried on from its last. */
  const bb_image *low = NULL;
  for (int k = 0; st == BB_OK && k < chain_count && !low; k++)
    if (chain[k].width <= 16 && chain[k].height <= 16)
      low = &chain[k];
  if (st == BB_OK && !low && bb__texture_container(path) == BB__CONTAINER_VTF) {
    st = texture_chain(&chain[chain_count - 1], o->map, o->threads, &extra, &extra_count, err);
    for (int k = 0; st == BB_OK && k < extra_count && !low; k++)
      if (extra[k].width <= 16 && extra[k].height <= 16)
        low = &extra[k];
  }
  if (st == BB_OK)
    st = bb__safe_open(f, path, err);
  if (st == BB_OK) {
    st = bb__texture_container(path) == BB__CONTAINER_VTF
             ? bb__vtf_encode(f, chain, write, low, o, format, err)
             : bb__dds_encode(f, chain, write, o, format, err);
    if (st != BB_OK)
      bb__safe_discard(f);
    else
      st = bb__safe_finish(f, err);
  }
  bb__mip_chain_borrowed_free(made, made_count);
  bb__mip_chain_borrowed_free(extra, extra_count);
  return st;
}

bb_status bb__texture_write(const char *path, const bb_image *img,
                           const bb_texture_options *options, bb_error *err) {
  bb_staged_file f;
  bb__safe_init(&f);
  bb_status st = bb__texture_stage(path, img, 1, 0, options, &f, err);
  return st == BB_OK ? bb__safe_commit(&f, err) : st;
}
