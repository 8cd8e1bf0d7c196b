/* hostile_headers.h: small files whose headers declare what their readers
 * would allocate before any size check of bumpbake's, made
 * here so no binary is committed. Each writer returns 0 on success.
 * Little-endian helpers come from hostile_tiff.h. */
#ifndef BB_TESTS_HOSTILE_HEADERS_H
#define BB_TESTS_HOSTILE_HEADERS_H

#include "hostile_tiff.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

static inline int hostile_write(const char *path, const unsigned char *bytes, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  size_t written = fwrite(bytes, 1, n, f);
  return (fclose(f) == 0 && written == n) ? 0 : -1;
}

/* Appends a PNG chunk at out: length, type, data, CRC-32 of type and data.
 * Returns its bytes. */
static inline size_t hostile_png_chunk(unsigned char *out, const char *type,
                                       const unsigned char *data, unsigned length) {
  out[0] = (unsigned char)(length >> 24), out[1] = (unsigned char)(length >> 16);
  out[2] = (unsigned char)(length >> 8), out[3] = (unsigned char)length;
  memcpy(out + 4, type, 4);
  if (length) memcpy(out + 8, data, length);
  unsigned long crc = 0xffffffffUL;
  for (unsigned i = 4; i < 8 + length; i++) {
    crc ^= out[i];
    for (int k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xedb88320UL & (0UL - (crc & 1)));
  }
  crc ^= 0xffffffffUL;
  for (unsigned i = 0; i < 4; i++) out[8 + length + i] = (unsigned char)(crc >> (24 - 8 * i));
  return 12 + length;
}

/* A PNG of width x height, 8-bit RGB, whose image data is empty (57
 * bytes): its header reads, its pixels do not. */
static inline int write_png_header(const char *path, uint32_t width, uint32_t height) {
  unsigned char b[128] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  unsigned char ihdr[13] = {0};
  for (int i = 0; i < 4; i++) {
    ihdr[i] = (unsigned char)(width >> (24 - 8 * i));
    ihdr[4 + i] = (unsigned char)(height >> (24 - 8 * i));
  }
  ihdr[8] = 8, ihdr[9] = 2; /* 8-bit RGB */
  size_t n = 8;
  n += hostile_png_chunk(b + n, "IHDR", ihdr, sizeof ihdr);
  n += hostile_png_chunk(b + n, "IDAT", NULL, 0);
  n += hostile_png_chunk(b + n, "IEND", NULL, 0);
  return hostile_write(path, b, n);
}

/* A DDS of width x height, 32-bit RGBA, with no data (128 bytes). */
static inline int write_dds_header(const char *path, uint32_t width, uint32_t height) {
  unsigned char b[128];
  memset(b, 0, sizeof b);
  memcpy(b, "DDS ", 4);
  hostile_put32(b + 4, 124);        /* dwSize */
  hostile_put32(b + 8, 0x100F);     /* CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT */
  hostile_put32(b + 12, height);
  hostile_put32(b + 16, width);
  hostile_put32(b + 20, width * 4); /* pitch */
  hostile_put32(b + 76, 32);        /* the pixel format: its size, */
  hostile_put32(b + 80, 0x41);      /* RGB | ALPHAPIXELS, */
  hostile_put32(b + 88, 32);        /* 32 bits, and the masks */
  hostile_put32(b + 92, 0x00FF0000);
  hostile_put32(b + 96, 0x0000FF00);
  hostile_put32(b + 100, 0x000000FF);
  hostile_put32(b + 104, 0xFF000000);
  hostile_put32(b + 108, 0x1000);   /* caps: a texture */
  return hostile_write(path, b, sizeof b);
}

/* A DDS of width x height in DX10's R32G32B32A32_FLOAT (a 148-byte
 * header), its file made as long as its samples by a hole (sparse: it
 * costs no disk), so every read accepts it: 4 GiB for 16384 x 16384. */
static inline int write_dds_float_header(const char *path, uint32_t width,
                                         uint32_t height) {
  unsigned char b[148];
  memset(b, 0, sizeof b);
  memcpy(b, "DDS ", 4);
  hostile_put32(b + 4, 124);    /* dwSize */
  hostile_put32(b + 8, 0x100F); /* CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT */
  hostile_put32(b + 12, height);
  hostile_put32(b + 16, width);
  hostile_put32(b + 20, width * 16); /* pitch */
  hostile_put32(b + 28, 1);          /* mip levels */
  hostile_put32(b + 76, 32);         /* the pixel format: its size, */
  hostile_put32(b + 80, 0x4);        /* FOURCC, */
  memcpy(b + 84, "DX10", 4);
  hostile_put32(b + 108, 0x1000); /* caps: a texture */
  hostile_put32(b + 128, 2);      /* DXGI_FORMAT_R32G32B32A32_FLOAT */
  hostile_put32(b + 132, 3);      /* a 2D texture */
  hostile_put32(b + 140, 1);      /* one in the array */
  FILE *f = fopen(path, "wb");
  if (!f)
    return -1;
  int ok = fwrite(b, 1, sizeof b, f) == sizeof b &&
           fseeko(f, (off_t)sizeof b + (off_t)width * height * 16 - 1, SEEK_SET) == 0 &&
           fputc(0, f) == 0;
  return fclose(f) == 0 && ok ? 0 : -1;
}

/* A progressive JPEG (SOF2) of one component declaring width x height: a
 * quantisation table, a one-code Huffman table and a DC scan of 8 zero
 * bytes (126 bytes). libjpeg buffers a progressive image whole, 2 bytes a
 * texel: 8 GiB for 65500 x 65500. */
static inline int write_progressive_jpeg(const char *path, unsigned width, unsigned height) {
  unsigned char b[160];
  size_t n = 0;
  b[n++] = 0xFF, b[n++] = 0xD8;                        /* SOI */
  b[n++] = 0xFF, b[n++] = 0xDB, b[n++] = 0, b[n++] = 67; /* DQT */
  b[n++] = 0;
  for (int i = 0; i < 64; i++) b[n++] = 1;
  b[n++] = 0xFF, b[n++] = 0xC2, b[n++] = 0, b[n++] = 11; /* SOF2: progressive */
  b[n++] = 8;
  b[n++] = (unsigned char)(height >> 8), b[n++] = (unsigned char)height;
  b[n++] = (unsigned char)(width >> 8), b[n++] = (unsigned char)width;
  b[n++] = 1, b[n++] = 1, b[n++] = 0x11, b[n++] = 0;   /* one component, 1x1 sampling */
  b[n++] = 0xFF, b[n++] = 0xC4, b[n++] = 0, b[n++] = 20; /* DHT: DC table 0, one code */
  b[n++] = 0x00, b[n++] = 1;
  for (int i = 1; i < 16; i++) b[n++] = 0;
  b[n++] = 0;
  b[n++] = 0xFF, b[n++] = 0xDA, b[n++] = 0, b[n++] = 8;  /* SOS: the DC scan */
  b[n++] = 1, b[n++] = 1, b[n++] = 0x00, b[n++] = 0, b[n++] = 0, b[n++] = 0;
  for (int i = 0; i < 8; i++) b[n++] = 0;
  b[n++] = 0xFF, b[n++] = 0xD9;                        /* EOI */
  return hostile_write(path, b, n);
}

/* A tiled TIFF of width x height, one 8-bit channel, declaring tiles of
 * tile_w x tile_h (16 bytes of data follow): libtiff and OpenImageIO
 * decode a whole tile at a time, however small the image. */
static inline int write_tiled_tiff(const char *path, uint32_t width, uint32_t height,
                                   uint32_t tile_w, uint32_t tile_h) {
  const struct {
    unsigned tag, type;
    uint32_t value;
  } entries[] = {
      {256, 4, width},  {257, 4, height}, {258, 3, 8},      {259, 3, 1},
      {262, 3, 1},      {277, 3, 1},      {284, 3, 1},      {322, 4, tile_w},
      {323, 4, tile_h}, {324, 4, 0},      {325, 4, 16},
  };
  enum { N = sizeof entries / sizeof entries[0] };
  unsigned char b[8 + 2 + 12 * N + 4 + 16];
  memset(b, 0, sizeof b);
  memcpy(b, "II*\0", 4);
  hostile_put32(b + 4, 8);
  hostile_put16(b + 8, N);
  const uint32_t data = 8 + 2 + 12 * N + 4;
  for (unsigned i = 0; i < N; i++) {
    unsigned char *e = b + 10 + 12 * i;
    uint32_t value = entries[i].tag == 324 ? data : entries[i].value; /* TileOffsets */
    hostile_put16(e, entries[i].tag);
    hostile_put16(e + 2, entries[i].type);
    hostile_put32(e + 4, 1);
    if (entries[i].type == 3)
      hostile_put16(e + 8, (unsigned)value);
    else
      hostile_put32(e + 8, value);
  }
  return hostile_write(path, b, sizeof b);
}

/* An OpenEXR file whose first attribute, a string "comment", declares
 * `declared` bytes and holds 64 (91 bytes): OpenEXR's C++ reader
 * allocates the declared size before it reads a byte of it. */
static inline int write_exr_with_huge_attribute(const char *path, uint32_t declared) {
  unsigned char b[91];
  size_t n = 0;
  const unsigned char magic[] = {0x76, 0x2F, 0x31, 0x01, 2, 0, 0, 0};
  memcpy(b, magic, sizeof magic), n += sizeof magic;
  memcpy(b + n, "comment\0string\0", 15), n += 15;
  hostile_put32(b + n, declared), n += 4;
  memset(b + n, 'x', sizeof b - n);
  return hostile_write(path, b, sizeof b);
}

/* An OpenEXR file whose first attribute has no type name and declares
 * `declared` bytes (the load fuzzer's first find): OpenEXR's C++ reader
 * takes it for an opaque attribute and allocates the declared size;
 * OpenEXRCore reports it and skips it. */
static inline int write_exr_with_untyped_attribute(const char *path, uint32_t declared) {
  unsigned char b[86];
  size_t n = 0;
  const unsigned char magic[] = {0x76, 0x2F, 0x31, 0x01, 2, 0, 0, 0};
  memcpy(b, magic, sizeof magic), n += sizeof magic;
  memcpy(b + n, "junk\0\0", 6), n += 6; /* name "junk", type "" */
  hostile_put32(b + n, declared), n += 4;
  memset(b + n, 'x', sizeof b - n);
  return hostile_write(path, b, sizeof b);
}

/* A GIF whose logical screen and one image are width x height, with a
 * two-colour table and an LZW stream that ends at once (35 bytes):
 * OpenImageIO allocates a canvas of width x height x 4 bytes to open it. */
static inline int write_gif_screen(const char *path, unsigned width, unsigned height) {
  unsigned char b[35];
  size_t n = 0;
  memcpy(b, "GIF89a", 6), n = 6;
  hostile_put16(b + n, width), hostile_put16(b + n + 2, height), n += 4;
  b[n++] = 0x80, b[n++] = 0, b[n++] = 0;          /* global table of 2 colours */
  b[n++] = 0, b[n++] = 0, b[n++] = 0, b[n++] = 0xFF, b[n++] = 0xFF, b[n++] = 0xFF;
  b[n++] = 0x2C;                                  /* image descriptor */
  hostile_put16(b + n, 0), hostile_put16(b + n + 2, 0), n += 4;
  hostile_put16(b + n, width), hostile_put16(b + n + 2, height), n += 4;
  b[n++] = 0;
  b[n++] = 2, b[n++] = 2, b[n++] = 0x44, b[n++] = 0x01, b[n++] = 0; /* LZW data */
  b[n++] = 0x3B;                                  /* trailer */
  return hostile_write(path, b, n);
}

/* An 8-bit RLE SGI of 2 x 2 texels, one channel, whose header declares
 * `rows` rows of `channels` channels (2 and 1 make it a valid file of 544
 * bytes): OpenImageIO zeroes offset tables of 8 bytes a row and channel
 * to open it. Its second row's length is `second_row_length` (4 is the
 * row's; reading a row allocates its length). SGI's numbers are
 * big-endian; the header is 512 bytes. */
static inline void hostile_put_be(unsigned char *p, unsigned v, int bytes) {
  for (int i = 0; i < bytes; i++) p[i] = (unsigned char)(v >> (8 * (bytes - 1 - i)));
}

static inline int write_sgi_rle_rows(const char *path, unsigned rows, unsigned channels,
                                     unsigned second_row_length) {
  unsigned char b[544] = {0};
  hostile_put_be(b, 0x01DA, 2);    /* magic */
  b[2] = 1, b[3] = 1;              /* RLE, one byte a sample */
  hostile_put_be(b + 4, 2, 2);     /* dimension: rows of one channel */
  hostile_put_be(b + 6, 2, 2);     /* xsize */
  hostile_put_be(b + 8, rows, 2);  /* ysize */
  hostile_put_be(b + 10, channels, 2); /* zsize */
  hostile_put_be(b + 16, 255, 4);  /* pixmax */
  /* The row starts, the row lengths, then two rows of 4 bytes each: a
   * run of two literal samples, then the end. */
  hostile_put_be(b + 512, 528, 4), hostile_put_be(b + 516, 532, 4);
  hostile_put_be(b + 520, 4, 4), hostile_put_be(b + 524, second_row_length, 4);
  const unsigned char rows_rle[8] = {0x82, 10, 200, 0, 0x82, 90, 30, 0};
  memcpy(b + 528, rows_rle, sizeof rows_rle);
  return hostile_write(path, b, sizeof b);
}

static inline int write_sgi_rle(const char *path, unsigned rows, unsigned channels) {
  return write_sgi_rle_rows(path, rows, channels, 4);
}

/* A DPX of 1 x 1 RGB texel, 8 bits (4 bytes of data after the 2048-byte
 * header and `user_bytes` bytes of user data), whose header declares
 * `user_size` bytes of user data (user_bytes makes it a valid file),
 * big-endian ("SDPX") or little-endian ("XPDS"): OpenImageIO's reader
 * allocates the declared size, zeroed, in open(). */
static inline void hostile_put_order(unsigned char *p, unsigned v, int bytes, int little) {
  for (int i = 0; i < bytes; i++)
    p[i] = (unsigned char)(v >> (8 * (little ? i : bytes - 1 - i)));
}

static inline int write_dpx_user(const char *path, uint32_t user_size, unsigned user_bytes,
                                 int little) {
  unsigned char b[2048 + 64 + 4];
  if (user_bytes > 64) return -1;
  const unsigned data = 2048 + user_bytes, total = data + 4;
  memset(b, 0, sizeof b);
  memcpy(b, little ? "XPDS" : "SDPX", 4);
  hostile_put_order(b + 4, data, 4, little);   /* image data offset */
  memcpy(b + 8, "V2.0", 4);
  hostile_put_order(b + 16, total, 4, little); /* file size */
  hostile_put_order(b + 24, 1664, 4, little);  /* generic header */
  hostile_put_order(b + 28, 384, 4, little);   /* industry header */
  hostile_put_order(b + 32, user_size, 4, little);
  hostile_put_order(b + 770, 1, 2, little);    /* one element */
  hostile_put_order(b + 772, 1, 4, little);    /* 1 pixel a line */
  hostile_put_order(b + 776, 1, 4, little);    /* 1 line */
  b[800] = 50, b[803] = 8;                     /* RGB, 8 bits */
  hostile_put_order(b + 808, data, 4, little); /* the element's data */
  memset(b + 2048, 'u', user_bytes);
  b[data] = 200, b[data + 1] = 100, b[data + 2] = 50;
  return hostile_write(path, b, total);
}

/* A Cineon file of 1 x 1 texel, one 8-bit channel, laid out as
 * write_dpx_user's (the user data size at 16, big-endian). */
static inline int write_cineon_user(const char *path, uint32_t user_size, unsigned user_bytes) {
  unsigned char b[2048 + 64 + 4];
  if (user_bytes > 64) return -1;
  const unsigned data = 2048 + user_bytes, total = data + 4;
  memset(b, 0, sizeof b);
  hostile_put_be(b, 0x802A5FD7u, 4);
  hostile_put_be(b + 4, data, 4);   /* image data offset */
  hostile_put_be(b + 8, 1024, 4);   /* generic header */
  hostile_put_be(b + 12, 1024, 4);  /* industry header */
  hostile_put_be(b + 16, user_size, 4);
  hostile_put_be(b + 20, total, 4); /* file size */
  b[193] = 1;                       /* one element: */
  b[198] = 8;                       /* 8 bits, */
  hostile_put_be(b + 200, 1, 4);    /* 1 pixel a line, */
  hostile_put_be(b + 204, 1, 4);    /* 1 line */
  memset(b + 2048, 'u', user_bytes);
  b[data] = 200;
  return hostile_write(path, b, total);
}

/* An RLE8 BMP (Windows' 40-byte header) declaring width x height (a
 * negative height: rows top to bottom), two palette colours (black and
 * white), and for its first two rows from the bottom: two white texels,
 * then two black (76 bytes; 2 x 2 makes it a valid file). OpenImageIO
 * decodes an RLE BMP into width x height bytes, zeroed first, in open(). */
static inline int write_bmp_rle8(const char *path, int32_t width, int32_t height) {
  unsigned char b[76];
  memset(b, 0, sizeof b);
  memcpy(b, "BM", 2);
  hostile_put32(b + 2, sizeof b);
  hostile_put32(b + 10, 14 + 40 + 8); /* the pixels' offset */
  hostile_put32(b + 14, 40);
  hostile_put32(b + 18, (uint32_t)width);
  hostile_put32(b + 22, (uint32_t)height);
  hostile_put16(b + 26, 1);           /* planes */
  hostile_put16(b + 28, 8);           /* bits a texel */
  hostile_put32(b + 30, 1);           /* RLE8 */
  hostile_put32(b + 34, 14);          /* the RLE bytes */
  hostile_put32(b + 46, 2);           /* colours used */
  memset(b + 58, 0xFF, 3);            /* colour 1: white */
  const unsigned char rle[8] = {2, 1, 0, 0, 2, 0, 0, 1}; /* rows, then the end */
  memcpy(b + 62, rle, sizeof rle);
  return hostile_write(path, b, sizeof b);
}

/* A 2 x 2 grayscale PSD, 8 bits, of one layer (one channel, raw): its
 * colour mode data declares `colour_length` bytes (none are there), its
 * one image resource `resource_id` declares `resource_length` bytes (2
 * are there: a name of `name_length` bytes, then "A"), and its layer runs
 * from row 0 to `layer_bottom` (0, `id`, 2, 1, 2 make it a valid file of
 * 126 bytes; resource 1006 holds alpha channel names). Its layer's texels
 * are 10, 20, 30, 40; the merged image's 50, 60, 70, 80. OpenImageIO
 * allocates each length, and a table of 8 bytes for each of a layer
 * channel's rows, zeroed, in open(). PSD's numbers are big-endian. */
static inline int write_psd(const char *path, uint32_t colour_length, unsigned resource_id,
                            uint32_t resource_length, unsigned name_length,
                            uint32_t layer_bottom) {
  unsigned char b[256];
  size_t n = 0;
  memset(b, 0, sizeof b);
  memcpy(b, "8BPS", 4), n = 4;
  hostile_put_be(b + n, 1, 2), n += 2 + 6;       /* version 1, reserved */
  hostile_put_be(b + n, 1, 2), n += 2;           /* one channel */
  hostile_put_be(b + n, 2, 4), n += 4;           /* height */
  hostile_put_be(b + n, 2, 4), n += 4;           /* width */
  hostile_put_be(b + n, 8, 2), n += 2;           /* bits */
  hostile_put_be(b + n, 1, 2), n += 2;           /* grayscale */
  hostile_put_be(b + n, colour_length, 4), n += 4;
  hostile_put_be(b + n, 14, 4), n += 4;          /* the image resources: */
  memcpy(b + n, "8BIM", 4), n += 4;
  hostile_put_be(b + n, resource_id, 2), n += 2;
  n += 2;                                        /* no name, padded */
  hostile_put_be(b + n, resource_length, 4), n += 4;
  b[n++] = (unsigned char)name_length, b[n++] = 'A';
  hostile_put_be(b + n, 68, 4), n += 4;          /* layer and mask information */
  hostile_put_be(b + n, 60, 4), n += 4;          /* layer information */
  hostile_put_be(b + n, 1, 2), n += 2;           /* one layer */
  hostile_put_be(b + n, 0, 4), hostile_put_be(b + n + 4, 0, 4), n += 8; /* top, left */
  hostile_put_be(b + n, layer_bottom, 4), hostile_put_be(b + n + 4, 2, 4), n += 8;
  hostile_put_be(b + n, 1, 2), n += 2;           /* one channel: */
  hostile_put_be(b + n, 0, 2), hostile_put_be(b + n + 2, 6, 4), n += 6; /* 0, 6 bytes */
  memcpy(b + n, "8BIMnorm", 8), n += 8;          /* blend mode */
  b[n] = 255, n += 4;                            /* opacity, clipping, flags, filler */
  hostile_put_be(b + n, 12, 4), n += 4;          /* extra data: */
  n += 4 + 4 + 4;                                /* no mask, no ranges, no name */
  n += 2;                                        /* the channel: raw, */
  const unsigned char layer[4] = {10, 20, 30, 40}, merged[4] = {50, 60, 70, 80};
  memcpy(b + n, layer, 4), n += 4;
  n += 4;                                        /* no global mask */
  n += 2;                                        /* the merged image: raw */
  memcpy(b + n, merged, 4), n += 4;
  return hostile_write(path, b, n);
}

/* A Maya IFF of 2 x 2 RGB texels, 8 bits, in one uncompressed tile, all
 * (200, 100, 50): FOR4 CIMG, its table header TBHD with `flags` and
 * `bytes`, an AUTH chunk declaring `auth_size` bytes (4 are there), then
 * FOR4 TBMP and the tile's RGBA chunk declaring `rgba_size` bytes (1, 0, 2
 * and 20 make it a valid file of 96 bytes). OpenImageIO allocates the
 * AUTH chunk's size in open(), the RGBA chunk's less 8 at the first read,
 * and asserts (abort()) on some flags. IFF's numbers are big-endian. */
static inline int write_iff(const char *path, uint32_t flags, unsigned bytes,
                            uint32_t auth_size, uint32_t rgba_size) {
  unsigned char b[96];
  size_t n = 0;
  memset(b, 0, sizeof b);
  memcpy(b, "FOR4", 4), hostile_put_be(b + 4, 88, 4), memcpy(b + 8, "CIMG", 4), n = 12;
  memcpy(b + n, "TBHD", 4), hostile_put_be(b + n + 4, 24, 4), n += 8;
  hostile_put_be(b + n, 2, 4), hostile_put_be(b + n + 4, 2, 4), n += 8; /* width, height */
  hostile_put_be(b + n, 1, 2), hostile_put_be(b + n + 2, 1, 2), n += 4; /* aspect ratio */
  hostile_put_be(b + n, flags, 4), n += 4;
  hostile_put_be(b + n, bytes, 2), hostile_put_be(b + n + 2, 1, 2), n += 4; /* one tile */
  n += 4;                                                                 /* uncompressed */
  memcpy(b + n, "AUTH", 4), hostile_put_be(b + n + 4, auth_size, 4), memcpy(b + n + 8, "bb", 2);
  n += 12;
  memcpy(b + n, "FOR4", 4), hostile_put_be(b + n + 4, 32, 4), memcpy(b + n + 8, "TBMP", 4);
  n += 12;
  memcpy(b + n, "RGBA", 4), hostile_put_be(b + n + 4, rgba_size, 4), n += 8;
  hostile_put_be(b + n + 4, 1, 2), hostile_put_be(b + n + 6, 1, 2), n += 8; /* 0, 0 to 1, 1 */
  for (int i = 0; i < 4; i++) /* blue, green, red */
    b[n++] = 50, b[n++] = 100, b[n++] = 200;
  return hostile_write(path, b, n);
}

/* A FITS image of 2 x 2 8-bit texels, all 200, whose NAXIS card reads
 * `naxis` ("2" makes it a valid file of two 2880-byte blocks), its END
 * card after `blank_blocks` blocks of blank cards (negative: no END at
 * all, and that many blocks). OpenImageIO's reader sizes a vector by
 * NAXIS in open() and calls itself for each block up to END. */
static inline int write_fits(const char *path, const char *naxis, int blank_blocks) {
  const int blocks = blank_blocks < 0 ? -blank_blocks : blank_blocks + 2;
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  char block[2880];
  int ok = 1;
  for (int i = 0; i < blocks && ok; i++) {
    memset(block, ' ', sizeof block);
    if (i == 0) {
      char cards[5][81];
      snprintf(cards[0], 81, "%-80s", "SIMPLE  =                    T");
      snprintf(cards[1], 81, "%-80s", "BITPIX  =                    8");
      snprintf(cards[2], 81, "NAXIS   = %20s%50s", naxis, "");
      snprintf(cards[3], 81, "%-80s", "NAXIS1  =                    2");
      snprintf(cards[4], 81, "%-80s", "NAXIS2  =                    2");
      for (int c = 0; c < 5; c++) memcpy(block + 80 * c, cards[c], 80);
    }
    if (blank_blocks >= 0 && i == blank_blocks) memcpy(block + (i == 0 ? 400 : 0), "END", 3);
    if (blank_blocks >= 0 && i == blocks - 1) memset(block, 200, sizeof block); /* the data */
    ok = fwrite(block, 1, sizeof block, f) == sizeof block;
  }
  return fclose(f) == 0 && ok ? 0 : -1;
}

/* A JPEG 2000 codestream of one 8-bit component declaring width x height
 * in one tile, whose one tile holds nothing (82 bytes: SOC, SIZ, COD, QCD,
 * SOT, SOD, a zero byte, EOC; 4 x 4 makes it a valid file), raw or, with
 * `jp2`, in a JP2 file's boxes (signature, ftyp, jp2h with ihdr and colr,
 * jp2c). OpenImageIO's reader decodes the whole image, 4 bytes a sample,
 * in open(). */
static inline int write_jpeg2000(const char *path, uint32_t width, uint32_t height, int jp2) {
  unsigned char b[256];
  size_t n = 0;
  memset(b, 0, sizeof b);
  if (jp2) {
    const unsigned char signature[12] = {0, 0, 0, 12, 'j', 'P', ' ', ' ', 0x0D, 0x0A, 0x87, 0x0A};
    memcpy(b, signature, 12), n = 12;
    hostile_put_be(b + n, 20, 4), memcpy(b + n + 4, "ftypjp2 ", 8), n += 16;
    memcpy(b + n, "jp2 ", 4), n += 4;
    hostile_put_be(b + n, 8 + 22 + 15, 4), memcpy(b + n + 4, "jp2h", 4), n += 8;
    hostile_put_be(b + n, 22, 4), memcpy(b + n + 4, "ihdr", 4), n += 8;
    hostile_put_be(b + n, height, 4), hostile_put_be(b + n + 4, width, 4), n += 8;
    hostile_put_be(b + n, 1, 2), b[n + 2] = 7, b[n + 3] = 7, n += 6; /* 1 component, 8 bits */
    hostile_put_be(b + n, 15, 4), memcpy(b + n + 4, "colr", 4), n += 8;
    b[n] = 1, hostile_put_be(b + n + 3, 17, 4), n += 7; /* enumerated: greyscale */
    hostile_put_be(b + n, 8 + 82, 4), memcpy(b + n + 4, "jp2c", 4), n += 8;
  }
  const unsigned char soc_siz[4] = {0xFF, 0x4F, 0xFF, 0x51};
  memcpy(b + n, soc_siz, 4), n += 4;
  hostile_put_be(b + n, 41, 2), n += 4;                                  /* Lsiz, Rsiz */
  hostile_put_be(b + n, width, 4), hostile_put_be(b + n + 4, height, 4), n += 8;
  n += 8;                                                                /* the origin */
  hostile_put_be(b + n, width, 4), hostile_put_be(b + n + 4, height, 4), n += 8; /* tiles */
  n += 8;                                                                /* their origin */
  hostile_put_be(b + n, 1, 2), b[n + 2] = 7, b[n + 3] = 1, b[n + 4] = 1, n += 5;
  const unsigned char rest[] = {
      0xFF, 0x52, 0, 12, 0, 0, 0, 1, 0, 0, 4, 4, 0, 1, /* COD: no levels, 5-3 wavelet */
      0xFF, 0x5C, 0, 4, 0, 0x40,                       /* QCD: no quantisation */
      0xFF, 0x90, 0, 10, 0, 0, 0, 0, 0, 15, 0, 1,            /* SOT: tile 0, 15 bytes */
      0xFF, 0x93, 0,                                         /* SOD, an empty packet */
      0xFF, 0xD9};                                           /* EOC */
  memcpy(b + n, rest, sizeof rest), n += sizeof rest;
  return hostile_write(path, b, n);
}

/* An animated WebP (the extended format: VP8X, ANIM, one ANMF frame)
 * whose canvas is width x height and whose one frame, at its top left, is
 * 2 x 2 texels of (204, 103, 50) in lossless VP8L (88 bytes; 2 x 2 makes
 * it a valid file). OpenImageIO allocates the canvas, 3 bytes a texel, in
 * open(). */
static inline void hostile_put_le(unsigned char *p, uint32_t v, int bytes) {
  for (int i = 0; i < bytes; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static inline int write_webp_canvas(const char *path, uint32_t width, uint32_t height) {
  static const unsigned char vp8l[12] = {0x2f, 0x01, 0x40, 0x00, 0x00, 0xe8,
                                         0x59, 0x99, 0x2b, 0xd3, 0xff, 0x00};
  unsigned char b[88];
  memset(b, 0, sizeof b);
  memcpy(b, "RIFF", 4), hostile_put_le(b + 4, 80, 4), memcpy(b + 8, "WEBP", 4);
  memcpy(b + 12, "VP8X", 4), hostile_put_le(b + 16, 10, 4);
  b[20] = 0x02;                                   /* animated */
  hostile_put_le(b + 24, width - 1, 3), hostile_put_le(b + 27, height - 1, 3);
  memcpy(b + 30, "ANIM", 4), hostile_put_le(b + 34, 6, 4); /* no background, no loops */
  memcpy(b + 44, "ANMF", 4), hostile_put_le(b + 48, 36, 4);
  hostile_put_le(b + 58, 1, 3), hostile_put_le(b + 61, 1, 3); /* at 0, 0, 2 x 2 */
  hostile_put_le(b + 64, 100, 3);                 /* 100 ms */
  memcpy(b + 68, "VP8L", 4), hostile_put_le(b + 72, sizeof vp8l, 4);
  memcpy(b + 76, vp8l, sizeof vp8l);
  return hostile_write(path, b, sizeof b);
}

/* A Softimage PIC of 2 x 2 texels, all (200, 100, 50): one channel packet
 * of 8 bits a channel, encoding `type` (2: mixed run-length) and channels
 * `code` (0xE0: red, green, blue), each scanline one repeated run of
 * `run` - 127 pixels (129: the scanline's 2); `cut` bytes short of its
 * end (2, 0xE0, 129, 0 make it a valid file of 116 bytes). OpenImageIO's
 * reader writes runs and channels where they say, and a scanline it
 * cannot read makes it use the FILE it closed. Big-endian. */
static inline int write_softimage(const char *path, unsigned type, unsigned code, unsigned run,
                                  unsigned cut) {
  unsigned char b[116];
  memset(b, 0, sizeof b);
  hostile_put_be(b, 0x5380F634u, 4);
  hostile_put_be(b + 4, 0x406D70A4u, 4); /* version 3.71 */
  memcpy(b + 88, "PICT", 4);
  hostile_put_be(b + 92, 2, 2), hostile_put_be(b + 94, 2, 2);
  hostile_put_be(b + 96, 0x3F800000u, 4); /* aspect ratio 1 */
  hostile_put_be(b + 100, 3, 2);          /* every scanline */
  b[104] = 0, b[105] = 8, b[106] = (unsigned char)type, b[107] = (unsigned char)code;
  for (int y = 0; y < 2; y++) {
    unsigned char *row = b + 108 + 4 * y;
    row[0] = (unsigned char)run, row[1] = 200, row[2] = 100, row[3] = 50;
  }
  return hostile_write(path, b, sizeof b - cut);
}

/* A one-icon ICO holding a 24-bit bitmap of width x height (at most 16 x
 * 4) of one colour (B, G, R = 50, 100, 200), opaque: rows of 3 bytes a
 * texel and a 1-bit mask, each row padded to 4 bytes, bottom up, after a
 * 40-byte bitmap header that counts both (height twice). */
static inline int write_ico_bitmap(const char *path, unsigned width, unsigned height) {
  unsigned char b[512] = {0};
  const unsigned row = (width * 3 + 3) / 4 * 4, mask = ((width + 7) / 8 + 3) / 4 * 4;
  const unsigned bitmap = 40 + height * (row + mask);
  hostile_put16(b + 2, 1), hostile_put16(b + 4, 1); /* an icon; one image */
  b[6] = (unsigned char)width, b[7] = (unsigned char)height;
  hostile_put16(b + 10, 1), hostile_put16(b + 12, 24); /* planes, bits */
  hostile_put32(b + 14, bitmap), hostile_put32(b + 18, 22); /* its size, where */
  unsigned char *h = b + 22;
  hostile_put32(h, 40), hostile_put32(h + 4, width), hostile_put32(h + 8, 2 * height);
  hostile_put16(h + 12, 1), hostile_put16(h + 14, 24);
  for (unsigned y = 0; y < height; y++)
    for (unsigned x = 0; x < width; x++) {
      unsigned char *t = h + 40 + y * row + 3 * x;
      t[0] = 50, t[1] = 100, t[2] = 200;
    }
  return hostile_write(path, b, 22 + bitmap);
}

#endif /* BB_TESTS_HOSTILE_HEADERS_H */
