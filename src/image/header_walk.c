/* header_walk.c: the headers of OpenImageIO readers that header_probe.c
 * reads by hand (header_walk.h), at the fixed offsets of each format's
 * specification, as OpenImageIO 2.4.7's readers read them. Each section
 * says what the reader would do with the fields. Every read is a pread on
 * the descriptor the read checked. */
#include "image/header_walk.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <sys/types.h>
#include <unistd.h>

size_t bb__probe_read(int fd, void *buf, size_t n, double offset) {
  if (offset < 0 || offset > 9.0e18) return 0;
  size_t done = 0;
  while (done < n) {
    ssize_t got = pread(fd, (unsigned char *)buf + done, n - done, (off_t)offset + (off_t)done);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    done += (size_t)got;
  }
  return done;
}

uint64_t bb__walk_number(bb__walk *w, int n, int little) {
  unsigned char b[8];
  if (!w->ok || n > 8 || bb__probe_read(w->fd, b, (size_t)n, w->pos) != (size_t)n) {
    w->ok = 0;
    return 0;
  }
  w->pos += n;
  uint64_t v = 0;
  for (int i = 0; i < n; i++) v |= (uint64_t)b[little ? i : n - 1 - i] << (8 * i);
  return v;
}

void bb__probe_corrupt(bb__probe *p, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(p->corrupt, sizeof p->corrupt, fmt, ap);
  va_end(ap);
}

static unsigned big16(const unsigned char *b) { return (unsigned)b[0] << 8 | b[1]; }

/* -------------------------------------------------------------------- SGI */

/* For an RLE file, open() sizes two offset tables, 4 bytes for each row of
 * each channel, from ysize and zsize (16-bit big-endian numbers at 8 and
 * 10 of the 512-byte header; storage at 2) and zeroes them before reading
 * them from the file: a 109-byte file declaring 65292 rows of 25447
 * channels asked for 6.6 GB. The tables lie in the file, so they can be no
 * larger than it (read_limits.c). Reading a row then allocates the length
 * its table gives (an int: 0xFFFFFFFF asked for 4 GB) and reads it from
 * the start its table gives: each row the reader uses (row y of channel c
 * is entry y + c x height) must lie in the file. */
void bb__probe_sgi(int fd, const unsigned char *head, bb__probe *p) {
  p->format = "SGI";
  const unsigned dimension = big16(head + 4), ysize = big16(head + 8), zsize = big16(head + 10);
  p->width = (int)big16(head + 6);
  p->height = dimension == 1 ? 1 : (int)ysize;
  if (head[2] != 1) return;
  p->table_bytes = 8.0 * ysize * zsize;
  p->table_entries = "RLE rows";
  p->open_bytes = p->table_bytes;
  if (p->table_bytes > p->file_bytes || dimension < 1 || dimension > 3) return;
  const unsigned height = (unsigned)p->height, channels = dimension == 3 ? zsize : 1;
  const unsigned entries = ysize * zsize, used = height * channels;
  if (used > entries) {
    bb__probe_corrupt(p, "its SGI RLE tables list %u rows, not the %u of %u rows of %u channels",
                      entries, used, height, channels);
    return;
  }
  enum { CHUNK = 1024 };
  unsigned char starts[4 * CHUNK], lengths[4 * CHUNK];
  for (unsigned first = 0; first < used; first += CHUNK) {
    const unsigned n = used - first < CHUNK ? used - first : CHUNK;
    if (bb__probe_read(fd, starts, 4 * n, 512.0 + 4.0 * first) != 4 * n ||
        bb__probe_read(fd, lengths, 4 * n, 512.0 + 4.0 * entries + 4.0 * first) != 4 * n)
      return; /* the reader's read of its tables fails as well */
    for (unsigned i = 0; i < n; i++) {
      const unsigned char *s = starts + 4 * i, *l = lengths + 4 * i;
      const double start = (double)((uint32_t)big16(s) << 16 | big16(s + 2));
      const double length = (double)((uint32_t)big16(l) << 16 | big16(l + 2));
      if (length > 2147483647.0 || start + length > p->file_bytes) {
        bb__probe_corrupt(p,
                          "SGI RLE row %u of channel %u declares %.0f bytes at byte %.0f, past "
                          "the end of the file of %.0f bytes",
                          (first + i) % height, (first + i) / height, length, start,
                          p->file_bytes);
        return;
      }
    }
  }
}

/* ----------------------------------------------------------- DPX, Cineon */

/* Both readers allocate the user data the header declares (a 32-bit size,
 * 0 and 0xFFFFFFFF meaning none), zeroed, inside open(), read it from the
 * end of the 2048-byte header without looking at the result, and copy it
 * into the image's attributes twice: a 2048-byte DPX declaring 768 MiB took
 * 2.5 GB and opened (the load fuzzer's took 2.2 GB). The user data lies in
 * the file. The size's byte order is the magic number's: "SDPX" and
 * 802A5FD7 are big-endian, "XPDS" and D75F2A80 little-endian. */
static void probe_user_data(int fd, const char *format, double at, int little, bb__probe *p) {
  p->format = format;
  bb__walk w = {fd, p->file_bytes, at, 1};
  const uint64_t user = bb__walk_number(&w, 4, little);
  if (w.ok && user != 0 && user != 0xFFFFFFFFu && 2048.0 + (double)user > p->file_bytes)
    bb__probe_corrupt(p,
                      "its %s user data of %.0f bytes after the 2048-byte header runs past "
                      "the end of the file of %.0f bytes",
                      format, (double)user, p->file_bytes);
}

void bb__probe_dpx(int fd, const unsigned char *head, bb__probe *p) {
  probe_user_data(fd, "DPX", 32, head[0] == 'X', p);
}

void bb__probe_cineon(int fd, const unsigned char *head, bb__probe *p) {
  probe_user_data(fd, "Cineon", 16, head[0] == 0xD7, p);
}

/* -------------------------------------------------------------------- BMP */

/* For RLE compression (1: RLE8, 2: RLE4), open() decodes the whole image
 * into a buffer of width x height bytes, zeroed before the first RLE byte
 * is read: a 54-byte file of 40000 x 40000 took 1.7 GB. The product is an
 * int there (past INT_MAX it wraps), which BB_MAX_READ_BYTES, 1 GiB, stays
 * below. The Windows headers (40, 52, 56, 108 or 124 bytes, their size at
 * 14) hold the width and height as 32-bit little-endian numbers at 18 and
 * 22 (a negative height: rows top to bottom) and the compression at 30;
 * OS/2's 12-byte header has no compression. */
void bb__probe_bmp(int fd, bb__probe *p) {
  bb__walk w = {fd, p->file_bytes, 14, 1};
  const uint64_t size = bb__walk_number(&w, 4, 1);
  const int32_t width = (int32_t)(uint32_t)bb__walk_number(&w, 4, 1);
  const int32_t height = (int32_t)(uint32_t)bb__walk_number(&w, 4, 1);
  w.pos = 30;
  const uint64_t compression = bb__walk_number(&w, 4, 1);
  if (!w.ok || (size != 40 && size != 52 && size != 56 && size != 108 && size != 124) ||
      (compression != 1 && compression != 2))
    return;
  const double rows = height < 0 ? -(double)height : (double)height;
  if (width <= 0 || rows < 1 || rows > 2147483647.0) return; /* the reader refuses it */
  p->format = "BMP";
  p->width = width;
  p->height = (int)rows;
  p->open_bytes = (double)width * rows;
}
