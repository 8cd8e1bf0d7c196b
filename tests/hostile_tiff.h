/* hostile_tiff.h: a 186-byte TIFF whose header declares an image far larger
 * than its data (8192 x 8192 x 64 channels over 52 bytes of strip): what a
 * reader must refuse, or fail on quickly, without allocating what the header
 * asks for. Shared by test_image_files.c and test_cli.c. */
#ifndef BB_TESTS_HOSTILE_TIFF_H
#define BB_TESTS_HOSTILE_TIFF_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

enum { HOSTILE_TIFF_BYTES = 186 };

static inline void hostile_put16(unsigned char *p, unsigned v) {
  p[0] = (unsigned char)(v & 0xff);
  p[1] = (unsigned char)(v >> 8);
}

static inline void hostile_put32(unsigned char *p, uint32_t v) {
  for (int i = 0; i < 4; i++)
    p[i] = (unsigned char)(v >> (8 * i));
}

/* Writes the TIFF to path (little-endian, one strip, 8-bit samples,
 * min-is-black) declaring width x height x channels; returns 0 on success. */
static inline int write_hostile_tiff(const char *path, uint32_t width, uint32_t height,
                                     unsigned channels) {
  unsigned char b[HOSTILE_TIFF_BYTES];
  memset(b, 0, sizeof b);
  memcpy(b, "II*\0", 4);
  hostile_put32(b + 4, 8); /* first IFD at offset 8 */
  const struct {
    unsigned tag, type;
    uint32_t value;
  } entries[] = {
      {256, 4, width},    /* ImageWidth */
      {257, 4, height},   /* ImageLength */
      {258, 3, 8},        /* BitsPerSample */
      {259, 3, 1},        /* Compression: none */
      {262, 3, 1},        /* Photometric: min-is-black */
      {273, 4, 134},      /* StripOffsets: just after the IFD */
      {277, 3, channels}, /* SamplesPerPixel */
      {278, 4, height},   /* RowsPerStrip: one strip */
      {279, 4, 52},       /* StripByteCounts: the 52 bytes left */
      {284, 3, 1},        /* PlanarConfig: contiguous */
  };
  const unsigned n = sizeof entries / sizeof entries[0];
  hostile_put16(b + 8, n);
  for (unsigned i = 0; i < n; i++) {
    unsigned char *e = b + 10 + 12 * i;
    hostile_put16(e, entries[i].tag);
    hostile_put16(e + 2, entries[i].type);
    hostile_put32(e + 4, 1);
    if (entries[i].type == 3)
      hostile_put16(e + 8, (unsigned)entries[i].value);
    else
      hostile_put32(e + 8, entries[i].value);
  }
  /* next-IFD offset 0 at 130, then 52 zero bytes of "strip" up to 186 */
  FILE *f = fopen(path, "wb");
  if (!f)
    return -1;
  size_t written = fwrite(b, 1, sizeof b, f);
  return (fclose(f) == 0 && written == sizeof b) ? 0 : -1;
}

#endif /* BB_TESTS_HOSTILE_TIFF_H */
