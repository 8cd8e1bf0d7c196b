/* texels.c: a texture level's stored texels decoded into floats: 4 x 4
 * blocks through the block codec (blocks.h), 8- and 16-bit
 * normalised samples as v / 255 and v / 65535 (as OpenImageIO reads 8- and
 * 16-bit files), half floats through Imath's C conversion, packed texels
 * (DDS's bit masks; 5:6:5, 5:5:5:1, 4:4:4:4) channel by channel. */
#include "texture/texture_layout.h"
#include "core/internal.h"
#include "texture/blocks.h"

/* Imath's C half conversion, header only (as texture.c uses it): no lookup
 * table, so nothing to link. */
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

uint64_t bb__texels_bytes(const bb__texel_format *f, int width, int height) {
  const uint64_t w = (uint64_t)width, h = (uint64_t)height;
  switch (f->kind) {
  case BB__TEXELS_BLOCKS:
    return (w + 3) / 4 * ((h + 3) / 4) * (uint64_t)bb__block_bytes((bb__block_format)f->block);
  case BB__TEXELS_UNORM8: return w * h * (uint64_t)f->samples;
  case BB__TEXELS_UNORM16:
  case BB__TEXELS_HALF: return w * h * 2 * (uint64_t)f->samples;
  case BB__TEXELS_FLOAT: return w * h * 4 * (uint64_t)f->samples;
  case BB__TEXELS_PACKED: return w * h * (uint64_t)f->samples;
  }
  return 0;
}

uint64_t bb__texels_scratch_bytes(const bb__texel_format *f, int width, int height) {
  /* Blocks are decoded into 8-bit RGBA first. */
  return f->kind == BB__TEXELS_BLOCKS ? (uint64_t)width * (uint64_t)height * 4 : 0;
}

static unsigned u16_at(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }

static float f32_at(const unsigned char *p) {
  const uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                     (uint32_t)p[3] << 24;
  float v;
  memcpy(&v, &u, sizeof v);
  return v;
}

/* Sample s of the texel at p. */
static float sample(const bb__texel_format *f, const unsigned char *p, int s) {
  switch (f->kind) {
  case BB__TEXELS_UNORM8: return (float)p[s] / 255.0f;
  case BB__TEXELS_UNORM16: return (float)u16_at(p + 2 * s) / 65535.0f;
  case BB__TEXELS_HALF: return imath_half_to_float((imath_half_bits_t)u16_at(p + 2 * s));
  case BB__TEXELS_FLOAT: return f32_at(p + 4 * s);
  case BB__TEXELS_BLOCKS:
  case BB__TEXELS_PACKED: break;
  }
  return 0.0f;
}

/* z of the unit normal whose x and y a BC5 texel holds, as 0.5 + 0.5 z
 * (what OpenImageIO's DDS reader gave for NVIDIA's DDPF_NORMAL). */
static float rebuilt_z(const unsigned char *rgba) {
  const double x = rgba[0] / 127.5 - 1.0, y = rgba[1] / 127.5 - 1.0;
  const double zz = 1.0 - x * x - y * y;
  return (float)(0.5 + 0.5 * (zz > 0.0 ? sqrt(zz) : 0.0));
}

bb_status bb__texels_decode(const bb__texel_format *f, const unsigned char *data, int width,
                            int height, int first, int count, float *out, bb_error *err) {
  if (first < 0 || count < 1 || first + count > f->channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "channels %d..%d asked of a %d-channel texture",
                    first, first + count - 1, f->channels);
  const size_t n = (size_t)width * (size_t)height;
  if (f->kind == BB__TEXELS_BLOCKS) {
    unsigned char *rgba = malloc(n * 4);
    if (!rgba)
      return bb__fail(err, BB_ERR_MEMORY, "out of memory decoding %s blocks", f->name);
    bb_status st =
        bb__blocks_decompress(data, width, height, (bb__block_format)f->block, rgba, err);
    if (st == BB_OK)
      for (size_t i = 0; i < n; i++)
        for (int c = 0; c < count; c++)
          out[i * (size_t)count + (size_t)c] =
              f->rebuild_z && first + c == 2
                  ? rebuilt_z(rgba + 4 * i)
                  : (float)rgba[4 * i + (size_t)f->source[first + c]] / 255.0f;
    free(rgba);
    return st;
  }
  if (f->kind == BB__TEXELS_PACKED) {
    for (size_t i = 0; i < n; i++) {
      uint32_t v = 0;
      for (int b = 0; b < f->samples; b++)
        v |= (uint32_t)data[i * (size_t)f->samples + (size_t)b] << (8 * b);
      for (int c = 0; c < count; c++) {
        const unsigned bits = f->bits[first + c];
        const uint64_t max = (1ull << bits) - 1u;
        out[i * (size_t)count + (size_t)c] =
            (float)((double)(((uint64_t)v >> f->source[first + c]) & max) / (double)max);
      }
    }
    return BB_OK;
  }
  const size_t stride = (size_t)(bb__texels_bytes(f, 1, 1));
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < count; c++)
      out[i * (size_t)count + (size_t)c] = sample(f, data + i * stride, f->source[first + c]);
  return BB_OK;
}
