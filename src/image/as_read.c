/* as_read.c: what reading a file back gives of an image written to it, made
 * in memory: the codes an integer file stores (quantise.c) scaled as a read
 * scales them, a half file's rounding, a float file's samples as they are.
 * A golden check compares a bake's maps with goldens this way without
 * writing a file; the tests hold it to a write and a read, bit for bit. */
#include "core/internal.h"
#include "image/oiio.h"
#include "image/oiio_calls.h"
#include "image/quantise.h"
#include "texture/texture.h"

#include <stdlib.h>
#include <string.h>

bb_status bb__image_as_read(const char *path, const bb_image *img, bb_depth depth,
                            bb_range range, bb_image *out, bb_error *err) {
  memset(out, 0, sizeof *out);
  if (!img || !img->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no image", path);
  const int stored =
      bb__path_is_texture_format(path) ? -1 : bb__path_resolved_depth(path, depth);
  if (stored < 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: its samples are not made in memory", path);
  bb_status st = bb_image_alloc(out, img->width, img->height, img->channels, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  void *codes = NULL;
  if (stored == BB_DEPTH_8)
    codes = bb__quantise_8(img, range);
  else if (stored == BB_DEPTH_16)
    codes = bb__quantise_16(img, range);
  if (stored == BB_DEPTH_FLOAT) {
    memcpy(out->pixels, img->pixels, n * sizeof(float));
  } else if (stored == BB_DEPTH_HALF) {
    st = bb__oiio_samples_as_read(img->pixels, stored, n, out->pixels, err);
  } else if (!codes) {
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  } else {
    st = bb__oiio_samples_as_read(codes, stored, n, out->pixels, err);
  }
  free(codes);
  if (st != BB_OK)
    bb_image_free(out);
  return st;
}
