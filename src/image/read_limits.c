/* read_limits.c: the bounds every image read applies, from the header, before
 * it allocates: the public limits (BB_MAX_DIMENSION, BB_MAX_PIXELS,
 * BB_MAX_READ_BYTES and its bytes a texel, 64 channels), the memory left,
 * and how a read is cut into bands. */
#include "image/read_limits.h"
#include "core/internal.h"
#include "image/header_probe.h"

#include <stdio.h>

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

/* The texel limits, shared by the header and the probe checks. */
static bb_status check_texels(const char *path, int width, int height, bb_error *err) {
  const double texels = (double)width * (double)height;
  if (width > BB_MAX_DIMENSION || height > BB_MAX_DIMENSION || texels > (double)BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: image %dx%d is over the maximum (%d per side, %ld texels)", path,
                    width, height, BB_MAX_DIMENSION, (long)BB_MAX_PIXELS);
  return BB_OK;
}

bb_status bb__read_check_probe(const char *path, const bb__probe *p, int reading,
                               bb_error *err) {
  if (!p->format) return BB_OK;
  if (p->corrupt[0]) return bb__fail(err, BB_ERR_FORMAT, "%s: corrupt image: %s", path, p->corrupt);
  if (p->unsafe[0])
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path, p->unsafe);
  /* Tables the file cannot hold: corrupt, whatever their size. */
  if (p->table_bytes > p->file_bytes)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: corrupt image: its header declares %.0f %s, more than the file "
                    "of %.0f bytes can list",
                    path, p->table_bytes / 8.0, p->table_entries, p->file_bytes);
  if (p->open_bytes > (double)BB_MAX_READ_BYTES)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: too large to read: a %s of %dx%d needs %.0f MiB to open (bumpbake "
                    "reads at most %ld MiB of samples)",
                    path, p->format, p->width, p->height, p->open_bytes / (double)MiB,
                    BB_MAX_READ_BYTES / MiB);
  if (p->chunk_bytes > (double)BB__MAX_CHUNK_BYTES)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: too large to read: %s blocks of %.0f MiB each (bumpbake decodes at "
                    "most %ld MiB at once)",
                    path, p->format, p->chunk_bytes / (double)MiB, BB__MAX_CHUNK_BYTES / MiB);
  if (reading && p->width > 0 && p->height > 0) {
    const bb_status st = check_texels(path, p->width, p->height, err);
    if (st != BB_OK) return st;
  }
  /* What the open allocates, and a read's floats of one channel at least
   * beside it, must fit in what this process may still allocate: a size
   * within the limits can still be more than the machine has. */
  const double texels = (double)(p->width > 0 ? p->width : 0) * (double)(p->height > 0 ? p->height : 0);
  char what[600];
  snprintf(what, sizeof what, "%s: %s a %s of %dx%d", path, reading ? "reading" : "opening",
           p->format, p->width, p->height);
  return bb__memory_check(p->open_bytes + (reading ? texels * 4.0 : 0.0), what, err);
}

bb_status bb__read_check_size(const char *path, const bb__image_header *h, int channels_read,
                              bb_error *err) {
  bb_status st = bb__read_check_shape(path, h, err);
  if (st != BB_OK) return st;
  if (h->channels > 64)
    return bb__fail(err, BB_ERR_FORMAT, "%s: %d channels (at most 64 are supported)", path,
                    h->channels);
  st = check_texels(path, h->width, h->height, err);
  if (st != BB_OK) return st;
  const double texels = (double)h->width * (double)h->height;
  if (h->tile_width > 0 && h->tile_height > 0) {
    /* A tile is decoded whole, every channel, into floats. */
    const double tile_bytes = (double)h->tile_width * (double)h->tile_height *
                              (double)h->channels * (double)(h->sample_bytes > 4 ? h->sample_bytes : 4);
    if (tile_bytes > (double)BB__MAX_CHUNK_BYTES)
      return bb__fail(err, BB_ERR_SIZE,
                      "%s: too large to read: tiles of %dx%d with %d channel%s need %.0f MiB "
                      "each (bumpbake decodes at most %ld MiB at once)",
                      path, h->tile_width, h->tile_height, h->channels, h->channels == 1 ? "" : "s",
                      tile_bytes / (double)MiB, BB__MAX_CHUNK_BYTES / MiB);
  }
  const double float_bytes = texels * channels_read * (double)sizeof(float);
  const double bytes = h->file_bytes > float_bytes ? h->file_bytes : float_bytes;
  const double per_texel = texels * BB_MAX_READ_BYTES_PER_TEXEL;
  const double limit = per_texel > (double)BB_MAX_READ_BYTES ? per_texel : (double)BB_MAX_READ_BYTES;
  if (bytes > limit)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: %dx%d with %d channels of %s needs %.0f MiB, over the limit of "
                    "%.0f MiB",
                    path, h->width, h->height, h->channels, h->format, bytes / (double)MiB,
                    limit / (double)MiB);
  /* The floats, and at most the file's own samples decoded beside them,
   * must fit in what this process may still allocate. */
  char what[600];
  snprintf(what, sizeof what, "%s: reading %dx%d with %d channels of %s", path, h->width,
           h->height, h->channels, h->format);
  return bb__memory_check(float_bytes + h->file_bytes, what, err);
}

int bb__read_band_rows(const bb__image_header *h, int channels) {
  if (h->tile_width > 0 && h->tile_height > 0) return h->tile_height;
  long row_bytes = (long)h->width * channels * (long)sizeof(float);
  long rows = (4 * MiB) / (row_bytes > 0 ? row_bytes : 1);
  return rows < 1 ? 1 : (rows > h->height ? h->height : (int)rows);
}
