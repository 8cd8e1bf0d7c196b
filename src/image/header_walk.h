/* header_walk.h: the headers header_probe.c reads by hand, for OpenImageIO
 * readers with no Debian library of their own to read them: fixed fields
 * at their offsets, and short walks over length-prefixed records, every
 * length checked against the file before it is followed (header_walk.c,
 * header_walk_psd.c for PSD, header_walk_pic.c for Softimage PIC). Each
 * fills the probe: what the open allocates, or `corrupt`, a length that
 * runs past the end of the file or what the reader cannot read safely. */
#ifndef BB_IMAGE_HEADER_WALK_H
#define BB_IMAGE_HEADER_WALK_H

#include "image/header_probe.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* pread of up to n bytes at offset, through EINTR; the bytes read (0 at
 * the end of the file or on an error, or when offset is past what off_t
 * holds). */
size_t bb__probe_read(int fd, void *buf, size_t n, double offset);

/* A cursor over the file: reads move it on; the first short read clears
 * ok (the reader's own read fails there too, so the walk stops). */
typedef struct bb__walk {
  int fd;
  double size; /* the file's bytes */
  double pos;
  int ok;
} bb__walk;

/* The next n bytes (at most 8) as a big-endian (little-endian when
 * `little`) number; 0 and ok cleared past the end. */
uint64_t bb__walk_number(bb__walk *w, int n, int little);

/* The next 4 bytes (a chunk's type, a block's signature) into tag: 1, or
 * 0 and ok cleared past the end. */
int bb__walk_tag(bb__walk *w, unsigned char tag[4]);

/* Sets the probe's `corrupt` (printf-style): the read refuses the file as
 * "corrupt image: ...". */
void bb__probe_corrupt(bb__probe *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* head: the file's first 12 bytes. */
void bb__probe_sgi(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_dpx(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_cineon(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_bmp(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_iff(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_fits(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_jpeg2000(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_webp(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_softimage(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_psd(int fd, const unsigned char *head, bb__probe *p);
void bb__probe_ico(int fd, const unsigned char *head, bb__probe *p);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_HEADER_WALK_H */
