/* texture_oracle.h: the tests' own reading of VTF and DDS files, written
 * from the formats' specifications and independent of src/texture/: a BC1..BC5
 * block decoder and the offsets of a VTF's levels. A test oracle (and the
 * quality tool's VTF decoder), not product code.
 *
 * Block decoding follows the BCn rules of the Direct3D 10 functional
 * specification (Microsoft's "Block Compression" page), in exact arithmetic:
 * 5:6:5 end points as v / 31 and v / 63; BC1 colour 2 = (2 c0 + c1) / 3 and
 * colour 3 = (c0 + 2 c1) / 3 when c0 > c1 (always in BC3), else
 * (c0 + c1) / 2 and black; BC4 values a0, a1 and 6 steps between (a0 > a1)
 * or 4 steps plus 0 and 255; each rounded to the nearest 8-bit code at the
 * end. Decoders in use round on the way (libsquish truncates, OpenImageIO's
 * bcdec adds 1 before dividing, GPUs differ again): they stay within one
 * code of this. */
#ifndef BB_TESTS_TEXTURE_ORACLE_H
#define BB_TESTS_TEXTURE_ORACLE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* The nearest 8-bit code of x in [0, 1], exact halves up. 3-colour BC1's
 * halfway colour has halves (green end points summing to 21: 255 x 21 /
 * 126 = 42.5), which x * 255 in doubles may land a last bit under; the
 * values here are multiples of 1/378, so 1e-9 moves nothing else. */
static inline int oracle_code(double x) {
  return (int)(x * 255.0 + 0.5 + 1e-9);
}

/* One BC1 colour block into 16 RGBA texels (out[4 * i + c], i = 4 y + x).
 * four: BC3's colour block, always in 4-colour mode. */
static inline void oracle_colour(const unsigned char *b, unsigned char out[64], int four) {
  const unsigned c0 = (unsigned)b[0] | (unsigned)b[1] << 8;
  const unsigned c1 = (unsigned)b[2] | (unsigned)b[3] << 8;
  double e[2][3];
  for (int j = 0; j < 2; j++) {
    const unsigned v = j ? c1 : c0;
    e[j][0] = (double)((v >> 11) & 31) / 31.0;
    e[j][1] = (double)((v >> 5) & 63) / 63.0;
    e[j][2] = (double)(v & 31) / 31.0;
  }
  int p[4][4];
  for (int k = 0; k < 3; k++) {
    p[0][k] = oracle_code(e[0][k]);
    p[1][k] = oracle_code(e[1][k]);
    if (c0 > c1 || four) {
      p[2][k] = oracle_code((2.0 * e[0][k] + e[1][k]) / 3.0);
      p[3][k] = oracle_code((e[0][k] + 2.0 * e[1][k]) / 3.0);
    } else {
      p[2][k] = oracle_code((e[0][k] + e[1][k]) / 2.0);
      p[3][k] = 0;
    }
  }
  p[0][3] = p[1][3] = p[2][3] = 255;
  p[3][3] = c0 > c1 || four ? 255 : 0;
  const uint32_t idx = (uint32_t)b[4] | (uint32_t)b[5] << 8 | (uint32_t)b[6] << 16 |
                       (uint32_t)b[7] << 24;
  for (int i = 0; i < 16; i++)
    for (int k = 0; k < 4; k++)
      out[4 * i + k] = (unsigned char)p[(idx >> (2 * i)) & 3][k];
}

/* One BC4 (DXT5 alpha) block into out[stride * i], i = 0..15. */
static inline void oracle_bc4(const unsigned char *b, unsigned char *out, int stride) {
  const double a0 = b[0] / 255.0, a1 = b[1] / 255.0;
  int v[8] = {b[0], b[1]};
  if (b[0] > b[1]) {
    for (int i = 1; i < 7; i++)
      v[i + 1] = oracle_code(((7 - i) * a0 + i * a1) / 7.0);
  } else {
    for (int i = 1; i < 5; i++)
      v[i + 1] = oracle_code(((5 - i) * a0 + i * a1) / 5.0);
    v[6] = 0;
    v[7] = 255;
  }
  uint64_t bits = 0;
  for (int i = 0; i < 6; i++)
    bits |= (uint64_t)b[2 + i] << (8 * i);
  for (int i = 0; i < 16; i++)
    out[stride * i] = (unsigned char)v[(bits >> (3 * i)) & 7];
}

enum { ORACLE_BC1 = 1, ORACLE_BC3 = 3, ORACLE_BC4 = 4, ORACLE_BC5 = 5 };

static inline size_t oracle_block_bytes(int bc) {
  return bc == ORACLE_BC1 || bc == ORACLE_BC4 ? 8 : 16;
}

/* Decodes w x h texels of blocks (row by row) into rgba (4 bytes a texel):
 * BC1 R, G, B, A; BC3 R, G, B and A; BC4 R (G = B = R, A = 255); BC5 R, G
 * (B = 0, A = 255). */
static inline void oracle_decode(int bc, const unsigned char *blocks, int w, int h,
                                 unsigned char *rgba) {
  const int bw = (w + 3) / 4, bh = (h + 3) / 4;
  for (int by = 0; by < bh; by++)
    for (int bx = 0; bx < bw; bx++) {
      const unsigned char *b = blocks + ((size_t)by * (size_t)bw + (size_t)bx) * oracle_block_bytes(bc);
      unsigned char t[64];
      memset(t, 255, sizeof t);
      if (bc == ORACLE_BC1) {
        oracle_colour(b, t, 0);
      } else if (bc == ORACLE_BC3) {
        oracle_colour(b + 8, t, 1);
        oracle_bc4(b, t + 3, 4);
      } else if (bc == ORACLE_BC4) {
        oracle_bc4(b, t, 4);
        for (int i = 0; i < 16; i++)
          t[4 * i + 1] = t[4 * i + 2] = t[4 * i];
      } else {
        oracle_bc4(b, t, 4);
        oracle_bc4(b + 8, t + 1, 4);
        for (int i = 0; i < 16; i++)
          t[4 * i + 2] = 0;
      }
      for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
          const int px = bx * 4 + x, py = by * 4 + y;
          if (px < w && py < h)
            memcpy(rgba + ((size_t)py * (size_t)w + (size_t)px) * 4, t + 4 * (4 * y + x), 4);
        }
    }
}

/* ------------------------------------------------------------ VTF files */

static inline uint32_t oracle_u32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline unsigned oracle_u16(const unsigned char *p) {
  return (unsigned)p[0] | (unsigned)p[1] << 8;
}

/* Bytes of a w x h level of a VTF format the writer uses (DXT1 13, DXT5 15,
 * BGR888 3, BGRA8888 12, RGBA16161616F 24); 0 for others. */
static inline size_t oracle_vtf_level_bytes(int code, int w, int h) {
  const size_t blocks = (size_t)((w + 3) / 4) * (size_t)((h + 3) / 4);
  switch (code) {
  case 13: return blocks * 8;
  case 15: return blocks * 16;
  case 3: return (size_t)w * (size_t)h * 3;
  case 12: return (size_t)w * (size_t)h * 4;
  case 24: return (size_t)w * (size_t)h * 8;
  default: return 0;
  }
}

/* Where level `level` (0 = full size) of a one-frame, one-face VTF starts,
 * from the header alone, by the layout (7.2: low-res image right after
 * the header, then the levels smallest first; 7.3+: the image resource's
 * offset); 0 when the file is not one such. *w, *h receive its size. */
static inline size_t oracle_vtf_level_offset(const unsigned char *file, size_t size, int level,
                                             int *w, int *h) {
  if (size < 80 || memcmp(file, "VTF\0", 4) != 0)
    return 0;
  const uint32_t minor = oracle_u32(file + 8), header = oracle_u32(file + 12);
  const int W = (int)oracle_u16(file + 16), H = (int)oracle_u16(file + 18);
  const int code = (int)oracle_u32(file + 52), mips = file[56];
  if (level >= mips)
    return 0;
  size_t image_at;
  if (minor >= 3) {
    const uint32_t n = oracle_u32(file + 68);
    image_at = 0;
    for (uint32_t r = 0; r < n && 80 + 8 * (size_t)r + 8 <= size; r++)
      if ((oracle_u32(file + 80 + 8 * r) & 0xffffff) == 0x30)
        image_at = oracle_u32(file + 80 + 8 * r + 4);
  } else {
    image_at = header + oracle_vtf_level_bytes(13, file[61], file[62]);
  }
  size_t at = image_at;
  for (int k = mips - 1; k > level; k--) {
    const int lw = W >> k > 0 ? W >> k : 1, lh = H >> k > 0 ? H >> k : 1;
    at += oracle_vtf_level_bytes(code, lw, lh);
  }
  *w = W >> level > 0 ? W >> level : 1;
  *h = H >> level > 0 ? H >> level : 1;
  return at + oracle_vtf_level_bytes(code, *w, *h) <= size ? at : 0;
}

#endif /* BB_TESTS_TEXTURE_ORACLE_H */
