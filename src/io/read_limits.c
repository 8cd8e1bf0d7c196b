/* read_limits.c: the bounds every image read applies, from the header, before
 * it allocates: the public limits (BB_MAX_DIMENSION, BB_MAX_PIXELS,
 * BB_MAX_READ_BYTES, 64 channels) and how a read is cut into bands. */
#include "io/read_limits.h"
#include "core/internal.h"

#define MiB (1L << 20)

bb_status bb__read_check_shape(const char *path, const bb__image_header *h, bb_error *err) {
  if (h->width <= 0 || h->height <= 0 || h->channels <= 0)
    return bb__fail(err, BB_ERR_SIZE, "%s: zero or negative image size %dx%d, %d channels",
                    path, h->width, h->height, h->channels);
  if (h->depth > 1)
    return bb__fail(err, BB_ERR_FORMAT, "%s: volume images (depth %d) are not supported",
                    path, h->depth);
  if (h->deep) return bb__fail(err, BB_ERR_FORMAT, "%s: deep images are not supported", path);
  return BB_OK;
}

bb_status bb__read_check_size(const char *path, const bb__image_header *h, int channels_read,
                              bb_error *err) {
  bb_status st = bb__read_check_shape(path, h, err);
  if (st != BB_OK) return st;
  if (h->channels > 64)
    return bb__fail(err, BB_ERR_FORMAT, "%s: %d channels (at most 64 are supported)", path,
                    h->channels);
  const double texels = (double)h->width * (double)h->height;
  if (h->width > BB_MAX_DIMENSION || h->height > BB_MAX_DIMENSION ||
      texels > (double)BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: image %dx%d is over the maximum (%d per side, %ld texels)", path,
                    h->width, h->height, BB_MAX_DIMENSION, (long)BB_MAX_PIXELS);
  const double float_bytes = texels * channels_read * (double)sizeof(float);
  const double bytes = h->file_bytes > float_bytes ? h->file_bytes : float_bytes;
  if (bytes > (double)BB_MAX_READ_BYTES)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: %dx%d with %d channels of %s needs %.0f MiB, over the limit of "
                    "%ld MiB",
                    path, h->width, h->height, h->channels, h->format, bytes / (double)MiB,
                    BB_MAX_READ_BYTES / MiB);
  return BB_OK;
}

int bb__read_band_rows(const bb__image_header *h, int channels) {
  if (h->tile_width > 0 && h->tile_height > 0) return h->tile_height;
  long row_bytes = (long)h->width * channels * (long)sizeof(float);
  long rows = (4 * MiB) / (row_bytes > 0 ? row_bytes : 1);
  return rows < 1 ? 1 : (rows > h->height ? h->height : (int)rows);
}
