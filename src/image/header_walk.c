/* header_walk.c: the headers of OpenImageIO readers that header_probe.c
 * reads by hand (header_walk.h), at the fixed offsets of each format's
 * specification, as OpenImageIO 2.4.7's readers read them. Each section
 * says what the reader would do with the fields. Every read is a pread on
 * the descriptor the read checked. */
#include "image/header_walk.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

int bb__walk_tag(bb__walk *w, unsigned char tag[4]) {
  if (!w->ok || bb__probe_read(w->fd, tag, 4, w->pos) != 4) return w->ok = 0;
  w->pos += 4;
  return 1;
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
    bb__probe_corrupt(p, "its SGI RLE tables list %u rows, fewer than its %u rows of %u channels",
                      entries, height, channels);
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
void bb__probe_bmp(int fd, const unsigned char *head, bb__probe *p) {
  (void)head;
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

/* -------------------------------------------------------------------- ICO */

/* ICO: OpenImageIO 2.4.7's reader fills a bitmap icon's 1-bit
 * transparency mask 8 texels at a time (icoinput.cpp readimg), so in an
 * icon of fewer than 32 bits a texel whose width (the directory entry's
 * byte) is not a multiple of 8 has the mask's padding bits written into
 * the next row's first alpha bytes and, in its top row, up to 28 bytes
 * past the reader's buffer (valgrind: an invalid write reading a valid
 * 1 x 3 icon; the load fuzzer's heap overflow). Nothing of the reader's
 * catches it, and the file is valid: refused, saying why. A PNG icon is
 * read by libpng. Every entry is looked at, since every frame can be
 * read; an entry or bitmap header past the end of the file fails the
 * reader's own read. */
void bb__probe_ico(int fd, const unsigned char *head, bb__probe *p) {
  const int count = (int16_t)(uint16_t)(head[4] | head[5] << 8);
  for (int i = 0; i < count; i++) {
    bb__walk w = {fd, p->file_bytes, 6.0 + 16.0 * i, 1};
    const unsigned width = (unsigned)bb__walk_number(&w, 1, 1);
    w.pos += 11; /* height, colours, reserved, planes, bits, size */
    const double at = (double)bb__walk_number(&w, 4, 1);
    if (!w.ok) return;
    unsigned char dib[16];
    if (bb__probe_read(fd, dib, sizeof dib, at) != sizeof dib) continue;
    if (dib[1] == 'P' && dib[2] == 'N' && dib[3] == 'G') continue;
    const int bits = (int16_t)(uint16_t)(dib[14] | dib[15] << 8);
    if ((bits == 1 || bits == 4 || bits == 8 || bits == 24) && width % 8 != 0) {
      snprintf(p->unsafe, sizeof p->unsafe,
               "icon %d is a %d-bit bitmap %u texel%s wide, which OpenImageIO 2.4's ICO "
               "reader writes past its buffer (a width not a multiple of 8); save it as a "
               "32-bit or PNG icon",
               i, bits, width, width == 1 ? "" : "s");
      p->format = "ICO";
      return;
    }
  }
}

/* -------------------------------------------------------------------- IFF */

/* Maya IFF, walked as open() walks it (iffinput.cpp read_header): chunks
 * of a 4-byte type and a 32-bit big-endian size (rounded up to 4 bytes)
 * up to FOR4 CIMG's TBHD, the table header, then AUTH, DATE and other
 * chunks up to FOR4 TBMP. open() allocates an AUTH or DATE chunk's size,
 * zeroed, before reading it (a 52-byte file declaring 1.5 GiB took 1.7
 * GB; a size that rounds up past 32 bits reads 4 GiB through an empty
 * buffer): it must lie in the file. And it asserts on two flag combinations of
 * TBHD, which Debian's build keeps: RGB or alpha with "black" (0x10), and
 * a Z buffer (0x04, without RGB or alpha) with a non-zero byte count,
 * which abort() the process. Each step reads 8 bytes or more, so the walk
 * ends at the end of the file. The first read of a tile then allocates
 * every tile's RGBA chunk (its size less 8, zeroed; a size below 8 wraps
 * to 4 GiB): each must lie in the file. */
static int is_type(const unsigned char *t, const char *name) { return memcmp(t, name, 4) == 0; }

/* The flags of TBHD's table header at w->pos, and its tile count: 0 when
 * the probe is corrupt. */
static int check_tbhd(bb__walk *w, uint32_t size, unsigned *tile_count, bb__probe *p) {
  if (size != 24 && size != 32) return 1; /* the reader refuses it */
  w->pos += 12;                           /* width, height, aspect ratio */
  const uint32_t flags = (uint32_t)bb__walk_number(w, 4, 0);
  const uint64_t bytes = bb__walk_number(w, 2, 0), tiles = bb__walk_number(w, 2, 0);
  const uint64_t compression = bb__walk_number(w, 4, 0);
  if (!w->ok || tiles == 0 || compression > 1) return 1; /* the reader refuses it */
  if ((flags & 0x3) && (flags & 0x10)) {
    bb__probe_corrupt(p, "IFF table header flags 0x%x set RGB or alpha with black", flags);
    return 0;
  }
  if (!(flags & 0x3) && (flags & 0x4) && bytes != 0) {
    bb__probe_corrupt(p, "IFF table header flags a Z buffer with a byte count of %u, not 0",
                      (unsigned)bytes);
    return 0;
  }
  w->pos += size - 24; /* x and y when the header is 32 bytes */
  *tile_count = (unsigned)tiles;
  return 1;
}

/* TBMP's tiles: the first read allocates each RGBA chunk's size less 8
 * (its tile's corners), zeroed, before reading it. */
static void check_tiles(bb__walk *w, unsigned tiles, bb__probe *p) {
  unsigned char type[4];
  for (unsigned t = 0; t < tiles && bb__walk_tag(w, type);) {
    const uint32_t size = (uint32_t)bb__walk_number(w, 4, 0);
    const uint32_t chunk = (size + 3u) & ~3u;
    if (!w->ok) return;
    if (is_type(type, "RGBA")) {
      if (chunk < 8 || w->pos + (double)size > p->file_bytes || w->pos + chunk > p->file_bytes) {
        bb__probe_corrupt(p,
                          "IFF tile %u's RGBA chunk of %u bytes at byte %.0f runs past the "
                          "end of the file of %.0f bytes",
                          t, size, w->pos, p->file_bytes);
        return;
      }
      t++;
    }
    w->pos += chunk;
  }
}

void bb__probe_iff(int fd, const unsigned char *head, bb__probe *p) {
  (void)head;
  p->format = "IFF";
  bb__walk w = {fd, p->file_bytes, 0, 1};
  int in_cimg = 0, past_tbhd = 0;
  unsigned tiles = 0;
  unsigned char type[4];
  while (bb__walk_tag(&w, type)) {
    const uint32_t size = (uint32_t)bb__walk_number(&w, 4, 0);
    const uint32_t chunk = (size + 3u) & ~3u;
    if (!w.ok) return;
    if (!in_cimg && is_type(type, "FOR4")) {
      if (!bb__walk_tag(&w, type)) return;
      if (is_type(type, "CIMG")) {
        in_cimg = 1;
        continue;
      }
    } else if (in_cimg && !past_tbhd && is_type(type, "TBHD")) {
      if (!check_tbhd(&w, size, &tiles, p) || !w.ok || tiles == 0) return;
      past_tbhd = 1;
      continue;
    } else if (past_tbhd && (is_type(type, "AUTH") || is_type(type, "DATE"))) {
      if (w.pos + (double)size > p->file_bytes || w.pos + chunk > p->file_bytes) {
        bb__probe_corrupt(p,
                          "IFF %.4s chunk of %u bytes at byte %.0f runs past the end of the "
                          "file of %.0f bytes",
                          (const char *)type, size, w.pos, p->file_bytes);
        return;
      }
    } else if (past_tbhd && is_type(type, "FOR4")) {
      if (!bb__walk_tag(&w, type)) return;
      if (is_type(type, "TBMP")) { /* the header ends: the tiles follow */
        check_tiles(&w, tiles, p);
        return;
      }
    }
    w.pos += chunk;
  }
}

/* ------------------------------------------------------------------- FITS */

/* FITS headers are 2880-byte blocks of 36 cards of 80 characters, up to
 * one holding the END card. Every block that starts "SIMPLE" or
 * "XTENSION= 'IMAGE   '" starts an image (OpenImageIO's reader looks at
 * every block of the file for them in open()), whose header the reader
 * reads when the image is opened:
 * - it sizes a vector of ints by the NAXIS card's value, zeroed, before it
 *   checks it (a 2880-byte file of NAXIS = 400000000 took 1.7 GB; a
 *   negative one throws): the FITS standard allows 0 to 999 axes;
 * - it reads a block, then calls itself for the next until END, a stack
 *   frame a block: 11000 blocks of spaces (32 MB, which compresses to
 *   almost nothing) overflowed the 8 MB main stack (SIGSEGV). A header is
 *   refused when no END comes within FITS_MAX_HEADER_BLOCKS blocks of its
 *   start: 1000 blocks are 36000 cards (real headers take a few blocks,
 *   long histories a few dozen), and take well under 1 MB of stack. */
#define FITS_BLOCK 2880
#define FITS_MAX_HEADER_BLOCKS 1000

/* A card's keyword: its first 8 characters, blanks stripped at both ends
 * (as OpenImageIO's Strutil::strip). */
static int fits_keyword_is(const unsigned char *card, const char *word) {
  size_t from = 0, to = 8;
  while (from < to && isspace(card[from])) from++;
  while (to > from && isspace(card[to - 1])) to--;
  return to - from == strlen(word) && memcmp(card + from, word, to - from) == 0;
}

/* The value of a NAXIS card from its 11th character, read as OpenImageIO's
 * Strutil::stoi reads it (blanks, a sign, decimal digits; past an int it
 * saturates). */
static double fits_integer(const unsigned char *card) {
  size_t i = 10;
  while (i < 80 && isspace(card[i])) i++;
  const int negative = i < 80 && card[i] == '-';
  if (i < 80 && (card[i] == '-' || card[i] == '+')) i++;
  double value = 0;
  for (; i < 80 && isdigit(card[i]) && value < 1e10; i++) value = value * 10 + (card[i] - '0');
  return negative ? -value : value;
}

void bb__probe_fits(int fd, const unsigned char *head, bb__probe *p) {
  (void)head;
  p->format = "FITS";
  enum { BATCH = 32 };
  unsigned char *blocks = malloc((size_t)BATCH * FITS_BLOCK);
  if (!blocks) return; /* the reader reads it unprobed, as before */
  double header = -1; /* the block the header without END so far starts at, or -1 */
  double index = 0;
  for (;;) {
    const size_t got = bb__probe_read(fd, blocks, (size_t)BATCH * FITS_BLOCK, index * FITS_BLOCK);
    const size_t whole = got / FITS_BLOCK;
    for (size_t b = 0; b < whole; b++, index++) {
      const unsigned char *block = blocks + b * FITS_BLOCK;
      if (header < 0 && (memcmp(block, "SIMPLE", 6) == 0 ||
                         memcmp(block, "XTENSION= 'IMAGE   '", 20) == 0))
        header = index;
      if (header < 0) continue;
      for (int c = 0; c < FITS_BLOCK / 80; c++) {
        const unsigned char *card = block + 80 * c;
        if (fits_keyword_is(card, "END")) {
          header = -1;
          break;
        }
        const double axes = fits_keyword_is(card, "NAXIS") ? fits_integer(card) : 0;
        if (axes < 0 || axes > 999) {
          bb__probe_corrupt(p, "FITS header declares %.0f axes (NAXIS is 0 to 999)", axes);
          free(blocks);
          return;
        }
      }
      if (header >= 0 && index - header + 1 >= FITS_MAX_HEADER_BLOCKS) {
        bb__probe_corrupt(p, "FITS header at byte %.0f has no END card in its first %d blocks",
                          header * FITS_BLOCK, FITS_MAX_HEADER_BLOCKS);
        free(blocks);
        return;
      }
    }
    if (whole < BATCH) break;
  }
  free(blocks);
}

/* --------------------------------------------------------------- JPEG 2000 */

/* open() decodes the whole image (OpenJPEG's opj_decode), into 4 bytes a
 * sample of every component, whatever the file holds: an 82-byte
 * codestream declaring 12000 x 12000 took 707 MB and opened (empty code
 * blocks decode to zeros). OpenJPEG's own header reader (opj_read_header)
 * is not among bumpbake's build dependencies (libopenjp2-7-dev), so this
 * reads the SIZ marker segment's fixed fields, which follow the
 * codestream's first marker (SOC, FF4F) in every JPEG 2000 codestream:
 * Xsiz, Ysiz, XOsiz, YOsiz (32-bit big-endian at 6, 10, 14 and 18 of
 * SIZ), Csiz at 38, then each component's subsampling XRsiz, YRsiz. A raw
 * codestream starts with it; a JP2 file holds it in its jp2c box, found
 * by walking the top-level boxes (a length, a type; length 1: a 64-bit
 * length follows; 0: the box runs to the end of the file). */
#define JP2_MAX_BOXES 1000

static void probe_codestream(int fd, double at, bb__probe *p) {
  bb__walk w = {fd, p->file_bytes, at, 1};
  if (bb__walk_number(&w, 2, 0) != 0xFF4F || bb__walk_number(&w, 2, 0) != 0xFF51) return;
  w.pos += 4; /* Lsiz, Rsiz */
  const double xsiz = (double)bb__walk_number(&w, 4, 0), ysiz = (double)bb__walk_number(&w, 4, 0);
  const double x0 = (double)bb__walk_number(&w, 4, 0), y0 = (double)bb__walk_number(&w, 4, 0);
  w.pos += 16; /* the tiles */
  const unsigned components = (unsigned)bb__walk_number(&w, 2, 0);
  if (!w.ok || xsiz <= x0 || ysiz <= y0 || components == 0) return; /* OpenJPEG refuses it */
  double samples = 0;
  for (unsigned c = 0; c < components && w.ok; c++) {
    w.pos += 1; /* Ssiz: the sample's bits */
    const double dx = (double)bb__walk_number(&w, 1, 0), dy = (double)bb__walk_number(&w, 1, 0);
    if (!w.ok || dx == 0 || dy == 0) return; /* OpenJPEG refuses it */
    samples += (ceil(xsiz / dx) - ceil(x0 / dx)) * (ceil(ysiz / dy) - ceil(y0 / dy));
  }
  if (!w.ok) return;
  p->format = "JPEG 2000";
  p->width = xsiz - x0 > 2147483647.0 ? 2147483647 : (int)(xsiz - x0);
  p->height = ysiz - y0 > 2147483647.0 ? 2147483647 : (int)(ysiz - y0);
  p->open_bytes = 4.0 * samples;
}

void bb__probe_jpeg2000(int fd, const unsigned char *head, bb__probe *p) {
  if (head[0] == 0xFF) {
    probe_codestream(fd, 0, p);
    return;
  }
  bb__walk w = {fd, p->file_bytes, 0, 1};
  for (int box = 0; box < JP2_MAX_BOXES && w.ok && w.pos < p->file_bytes; box++) {
    const double start = w.pos;
    double length = (double)bb__walk_number(&w, 4, 0);
    unsigned char type[4];
    if (!bb__walk_tag(&w, type)) return;
    if (length == 1) length = (double)bb__walk_number(&w, 8, 0);
    if (!w.ok) return;
    if (is_type(type, "jp2c")) {
      probe_codestream(fd, w.pos, p);
      return;
    }
    if (length < 8) return; /* to the end of the file, or not a box: no codestream */
    w.pos = start + length;
  }
}

/* ------------------------------------------------------------------- WebP */

/* open() allocates the canvas, width x height x 3 bytes (4 with alpha),
 * uninitialised, before decoding any frame: the extended format's VP8X
 * chunk declares it, up to 2^24 a side (24-bit little-endian numbers less
 * one at 24 and 27, the alpha flag 0x10 at 20), whatever the frames hold.
 * It takes no memory until written, but counts against a process's
 * address space limit, and it is the size of every frame read. */
void bb__probe_webp(int fd, const unsigned char *head, bb__probe *p) {
  (void)head;
  unsigned char h[30];
  if (bb__probe_read(fd, h, sizeof h, 0) != sizeof h || memcmp(h + 12, "VP8X", 4) != 0) return;
  const double width = 1.0 + (h[24] | h[25] << 8 | h[26] << 16);
  const double height = 1.0 + (h[27] | h[28] << 8 | h[29] << 16);
  p->format = "WebP";
  p->width = (int)width;
  p->height = (int)height;
  p->open_bytes = width * height * ((h[20] & 0x10) ? 4.0 : 3.0);
}
