/* header_probe.h: what opening a file will make OpenImageIO's reader
 * allocate, learnt from the file's header before that reader sees it
 * (header_probe.c). */
#ifndef BB_IMAGE_HEADER_PROBE_H
#define BB_IMAGE_HEADER_PROBE_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a header declares that costs memory at open, for the formats whose
 * readers allocate from the header inside open(), before any ImageSpec
 * reaches bumpbake. format is NULL when no probe applies (another format,
 * or a header the format's library cannot read: the reader then fails on
 * its own, allocating nothing large). */
typedef struct bb__probe {
  const char *format;  /* "JPEG", "GIF", "OpenEXR", "SGI", ... or NULL */
  int width, height;   /* the declared image (subimage 0), 0 when unknown */
  double open_bytes;   /* what the reader allocates in open() */
  double chunk_bytes;  /* OpenEXR: the largest chunk (tile or scanline block) decoded */
  double table_bytes;  /* OpenEXR, SGI: the offset tables read whole in open(), 8 bytes an
                        * entry (a chunk; an RLE row of one channel) */
  const char *table_entries; /* what an entry is, for messages: "chunks", "RLE rows" */
  double file_bytes;   /* the file's size */
  char corrupt[240];   /* set when the header declares what the file cannot hold (a length
                        * running past its end): why, after "corrupt image: " */
  char unsafe[240];    /* set for a valid file OpenImageIO's reader mishandles (writes
                        * past its buffer): why, after "not a readable image: " */
} bb__probe;

/* Reads the header of the regular file open at fd (path names it in
 * messages), through pread only, with the format's own Debian library
 * (libjpeg's jpeg_read_header, OpenEXRCore's exr_start_read) or, for GIF
 * and the formats of header_walk.h (SGI, DPX, Cineon, BMP, PSD, IFF, FITS,
 * JPEG 2000, WebP), by hand: sizes at their fixed offsets, and lengths
 * walked within the file. BB_ERR_FORMAT when OpenEXRCore refuses the
 * header (an attribute larger than the file, say), which OpenImageIO's
 * reader would first have allocated, and for any DDS, which bumpbake reads
 * itself (texture_read.h). */
bb_status bb__probe_header(int fd, const char *path, bb__probe *probe, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_HEADER_PROBE_H */
