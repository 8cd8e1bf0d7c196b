/* read_limits.h: what a read may cost, decided from an image's header
 * before anything is allocated (read_limits.c). */
#ifndef BB_IMAGE_READ_LIMITS_H
#define BB_IMAGE_READ_LIMITS_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a reader's header declares, as OpenImageIO's ImageSpec says it. */
typedef struct bb__image_header {
  int width, height, channels;
  int depth;                  /* volume depth; 1 for a flat image */
  int deep;                   /* 1 for deep (several samples per texel) data */
  int tile_width, tile_height; /* 0 for scanline files */
  double file_bytes;          /* the samples of the whole image, in the file's own types */
  int sample_bytes;           /* bytes of the file's widest sample type */
  const char *format;         /* the sample type's name, for messages ("uint8") */
} bb__image_header;

/* A size a reader can be given at all: positive, flat, not deep. */
bb_status bb__read_check_shape(const char *path, const bb__image_header *h, bb_error *err);

/* Everything a read of channels_read channels would allocate, checked
 * against the header before any allocation: the texel count, the channel
 * count, the bytes of the file's own samples (some readers decode the whole
 * image natively first) and the bytes of the floats handed back. */
bb_status bb__read_check_size(const char *path, const bb__image_header *h, int channels_read,
                              bb_error *err);

/* Most bytes one decode unit (a tile, or a block of scanlines) may take as
 * floats of every channel: a reader allocates it whole however small the
 * image (a 1 x 1 TIFF declaring 16384 x 16384 tiles took 8.5 GB). */
#define BB__MAX_CHUNK_BYTES (64L << 20)

/* What a header makes a reader allocate in open() (header_probe.h), checked
 * before the reader sees the file: the open itself within BB_MAX_READ_BYTES,
 * an OpenEXR chunk within BB__MAX_CHUNK_BYTES and its chunk tables within
 * the file, and when `reading` pixels, the declared size within the limits
 * of bb__read_check_size. */
struct bb__probe;
bb_status bb__read_check_probe(const char *path, const struct bb__probe *probe, int reading,
                               bb_error *err);

/* Rows decoded per call: whole tile rows for tiled files, else about 4 MiB
 * of floats. Reading in bands lets a file whose data stops early (a header
 * promising 8192 rows over 52 bytes) fail at its first band instead of
 * decoding, and touching, the whole image. */
int bb__read_band_rows(const bb__image_header *h, int channels);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_READ_LIMITS_H */
