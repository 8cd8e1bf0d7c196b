/* header_walk_pic.c: a Softimage PIC file's scanlines walked as OpenImageIO
 * 2.4.7's reader decodes them (softimageinput.cpp), before it opens the
 * file. That reader is unsafe on files it cannot decode:
 * - a scanline it fails to read (the file ends early; a pure run-length
 *   packet of more than one byte a pixel, which its read always fails)
 *   closes the file and then asks the closed file for its position: a
 *   NULL FILE (SIGSEGV; the load fuzzer's find, 139 bytes);
 * - a run (pure run-length, or mixed run-length's repeated run) longer
 *   than the rest of the scanline is written past the scanline's end;
 * - a channel is written at its index (red 0 ... alpha 3) among the
 *   channels of all packets, and at the size of its own packet: a packet
 *   of alpha alone, or packets of different sizes, write past the pixel.
 * So every scanline must decode within the file and the scanline, which
 * takes reading the whole file once. The header (104 bytes, big-endian)
 * holds the width and height at 92 and 94; the channel packets follow, 4
 * bytes each (chained, bits a channel, encoding, channels: red 0x80,
 * green 0x40, blue 0x20, alpha 0x10), up to one not chained; then the
 * scanlines, each packet's data in turn. Encoding 0 is never read (the
 * reader tests `type & 0`); 1 (and 3): runs of a count byte and a pixel;
 * 2: a count byte below 128 for count + 1 literal pixels, else a repeated
 * pixel, 128 taking its count from the next 2 bytes. */
#include "image/header_walk.h"

#include <stdlib.h>

#define PIC_MAX_PACKETS 64

/* Bytes read through a buffer: the walk reads them one to a few at a time. */
typedef struct pic_reader {
  int fd;
  double size; /* the file's bytes */
  double pos;  /* of buf[0] */
  size_t at, len;
  unsigned char buf[1 << 16];
} pic_reader;

/* n bytes (n <= 2) into out; 0 at the end of the file. */
static int pic_take(pic_reader *r, unsigned char *out, size_t n) {
  for (size_t i = 0; i < n; i++) {
    if (r->at == r->len) {
      r->pos += (double)r->len;
      r->len = bb__probe_read(r->fd, r->buf, sizeof r->buf, r->pos);
      r->at = 0;
      if (r->len == 0) return 0;
    }
    out[i] = r->buf[r->at++];
  }
  return 1;
}

/* Skips n bytes; 0 when the file ends first. */
static int pic_skip(pic_reader *r, double n) {
  const double to = r->pos + (double)r->at + n;
  if (to > r->size) return 0;
  if (to <= r->pos + (double)r->len) {
    r->at = (size_t)(to - r->pos);
  } else {
    r->pos = to;
    r->at = r->len = 0;
  }
  return 1;
}

typedef struct pic_packet {
  unsigned bytes, channels, type; /* bytes a channel */
} pic_packet;

/* One packet's part of a scanline: a reason it cannot be read, or NULL. */
static const char *pic_scanline(pic_reader *r, const pic_packet *k, unsigned width) {
  const unsigned pixel = k->bytes * k->channels;
  unsigned char c[2];
  if (k->type & 1) {
    if (pixel > 1) return "a pure run-length packet of more than one byte a pixel";
    for (unsigned x = 0; x < width;) {
      if (!pic_take(r, c, 1) || !pic_skip(r, pixel)) return "it runs past the end of the file";
      if (x + c[0] > width) return "a run runs past the end of its scanline";
      x += c[0];
    }
  } else if (k->type & 2) {
    for (unsigned x = 0; x < width;) {
      if (!pic_take(r, c, 1)) return "it runs past the end of the file";
      if (c[0] < 128) {
        const unsigned n = c[0] + 1u < width - x ? c[0] + 1u : width - x;
        if (!pic_skip(r, (double)n * pixel)) return "it runs past the end of the file";
        x += n;
        continue;
      }
      unsigned n = c[0] - 127u;
      if (c[0] == 128) {
        if (!pic_take(r, c, 2)) return "it runs past the end of the file";
        n = (unsigned)c[0] << 8 | c[1];
      }
      if (!pic_skip(r, pixel)) return "it runs past the end of the file";
      if (x + n > width) return "a run runs past the end of its scanline";
      x += n;
    }
  }
  return NULL;
}

void bb__probe_softimage(int fd, const unsigned char *first, bb__probe *p) {
  (void)first;
  unsigned char head[104];
  if (bb__probe_read(fd, head, sizeof head, 0) != sizeof head) return; /* the reader fails */
  p->format = "Softimage PIC";
  const unsigned width = (unsigned)head[92] << 8 | head[93];
  const unsigned height = (unsigned)head[94] << 8 | head[95];
  pic_packet packets[PIC_MAX_PACKETS];
  unsigned count = 0, channels = 0, last_bits = 0, top = 0; /* top: the highest index + 1 */
  for (;;) {
    unsigned char k[4];
    if (bb__probe_read(fd, k, 4, 104.0 + 4.0 * count) != 4) return; /* the reader fails */
    if (count == PIC_MAX_PACKETS) {
      bb__probe_corrupt(p, "its Softimage PIC chains more than %d channel packets",
                        PIC_MAX_PACKETS);
      return;
    }
    pic_packet *pk = &packets[count++];
    pk->bytes = k[1] / 8u, pk->type = k[2], pk->channels = 0;
    for (unsigned bit = 0; bit < 4; bit++)
      if (k[3] & (0x80u >> bit)) pk->channels++, top = bit + 1 > top ? bit + 1 : top;
    channels += pk->channels;
    last_bits = k[1];
    if (!k[0]) break;
  }
  /* The reader's samples are 16 bits when the last packet's are, else 8. */
  const unsigned sample = last_bits == 16 ? 2 : 1;
  for (unsigned i = 0; i < count; i++)
    if (packets[i].channels && packets[i].bytes != sample) {
      bb__probe_corrupt(p, "its Softimage PIC channel packets differ in size (%u and %u bits)",
                        packets[i].bytes * 8, sample * 8);
      return;
    }
  if (top > channels) {
    bb__probe_corrupt(p, "its Softimage PIC packets name channel %u of %u", top, channels);
    return;
  }
  pic_reader *r = malloc(sizeof *r);
  if (!r) return; /* the reader reads it unprobed, as before */
  r->fd = fd, r->size = p->file_bytes, r->pos = 104.0 + 4.0 * count, r->at = r->len = 0;
  for (unsigned y = 0; y < height; y++)
    for (unsigned i = 0; i < count; i++) {
      const char *why = pic_scanline(r, &packets[i], width);
      if (why) {
        bb__probe_corrupt(p, "Softimage PIC scanline %u: %s", y, why);
        free(r);
        return;
      }
    }
  free(r);
}
