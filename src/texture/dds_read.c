/* dds_read.c: where a DDS file's levels are and how its texels are stored,
 * for the pixel reads of texture_read.c. bumpbake reads DDS itself, though
 * OpenImageIO 2.4.7 has a reader: that reader divides by zero on a DXT2 or
 * DXT4 FourCC (a crash), loops for ever on an RGB format with a zero mask,
 * takes minutes on a mip count of 65029 (it walks every level before the
 * one it seeks), and refuses the DX10 header that bumpbake's float DDS
 * need; the fuzzer found the first three within minutes of its first DDS
 * seeds. The layout is Microsoft's (dds.c cites it): "DDS ", the 124-byte
 * header (the pixel format at 76), the 20-byte DX10 header at 128 when the
 * FourCC is "DX10", then every level of the first face or array element,
 * largest first.
 *
 * Channels, as OpenImageIO's reader gave them where bumpbake's files rely
 * on it: BC1 is R, G, B (A too when the header's DDPF_ALPHAPIXELS says it
 * has alpha), BC2 and BC3 R, G, B, A, BC4 one channel, BC5 R, G and, for a
 * normal map (NVIDIA's DDPF_NORMAL flag, which bumpbake writes), z rebuilt
 * from them; masked formats the channels their masks name. */
#include "core/input_file.h"
#include "core/internal.h"
#include "texture/blocks.h"
#include "texture/dds.h"
#include "texture/texture_layout.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { DDS_HEADER_BYTES = 148 };

#define T(name, kind, block, samples, channels, s0, s1, s2, s3)                                \
  { name, kind, block, samples, channels, {s0, s1, s2, s3}, {0, 0, 0, 0}, 0 }

/* The DXGI_FORMAT codes read (dxgiformat.h). */
static const struct {
  unsigned code;
  bb__texel_format f;
} DX10_TEXELS[] = {
    {2, T("R32G32B32A32_FLOAT", BB__TEXELS_FLOAT, 0, 4, 4, 0, 1, 2, 3)},
    {6, T("R32G32B32_FLOAT", BB__TEXELS_FLOAT, 0, 3, 3, 0, 1, 2, 0)},
    {10, T("R16G16B16A16_FLOAT", BB__TEXELS_HALF, 0, 4, 4, 0, 1, 2, 3)},
    {11, T("R16G16B16A16_UNORM", BB__TEXELS_UNORM16, 0, 4, 4, 0, 1, 2, 3)},
    {28, T("R8G8B8A8_UNORM", BB__TEXELS_UNORM8, 0, 4, 4, 0, 1, 2, 3)},
    {29, T("R8G8B8A8_UNORM_SRGB", BB__TEXELS_UNORM8, 0, 4, 4, 0, 1, 2, 3)},
    {41, T("R32_FLOAT", BB__TEXELS_FLOAT, 0, 1, 1, 0, 0, 0, 0)},
    {54, T("R16_FLOAT", BB__TEXELS_HALF, 0, 1, 1, 0, 0, 0, 0)},
    {56, T("R16_UNORM", BB__TEXELS_UNORM16, 0, 1, 1, 0, 0, 0, 0)},
    {61, T("R8_UNORM", BB__TEXELS_UNORM8, 0, 1, 1, 0, 0, 0, 0)},
    {71, T("BC1_UNORM", BB__TEXELS_BLOCKS, BB__BLOCK_BC1, 0, 4, 0, 1, 2, 3)},
    {72, T("BC1_UNORM_SRGB", BB__TEXELS_BLOCKS, BB__BLOCK_BC1, 0, 4, 0, 1, 2, 3)},
    {74, T("BC2_UNORM", BB__TEXELS_BLOCKS, BB__BLOCK_BC2, 0, 4, 0, 1, 2, 3)},
    {75, T("BC2_UNORM_SRGB", BB__TEXELS_BLOCKS, BB__BLOCK_BC2, 0, 4, 0, 1, 2, 3)},
    {77, T("BC3_UNORM", BB__TEXELS_BLOCKS, BB__BLOCK_BC3, 0, 4, 0, 1, 2, 3)},
    {78, T("BC3_UNORM_SRGB", BB__TEXELS_BLOCKS, BB__BLOCK_BC3, 0, 4, 0, 1, 2, 3)},
    {80, T("BC4_UNORM", BB__TEXELS_BLOCKS, BB__BLOCK_BC4, 0, 1, 0, 0, 0, 0)},
    {83, T("BC5_UNORM", BB__TEXELS_BLOCKS, BB__BLOCK_BC5, 0, 2, 0, 1, 0, 0)},
    {87, T("B8G8R8A8_UNORM", BB__TEXELS_UNORM8, 0, 4, 4, 2, 1, 0, 3)},
};

static uint32_t u32_at(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}


static int fourcc_is(const unsigned char *p, const char *code) { return !memcmp(p, code, 4); }

/* A legacy FourCC's block format; NULL when it is not one read. */
static const bb__texel_format *fourcc_format(const unsigned char *pf, uint32_t pf_flags) {
  static const bb__texel_format BC1_RGB = T("DXT1", BB__TEXELS_BLOCKS, BB__BLOCK_BC1, 0, 3, 0, 1, 2, 0);
  static const bb__texel_format BC1_RGBA = T("DXT1", BB__TEXELS_BLOCKS, BB__BLOCK_BC1, 0, 4, 0, 1, 2, 3);
  static const bb__texel_format BC2 = T("DXT3", BB__TEXELS_BLOCKS, BB__BLOCK_BC2, 0, 4, 0, 1, 2, 3);
  static const bb__texel_format BC3 = T("DXT5", BB__TEXELS_BLOCKS, BB__BLOCK_BC3, 0, 4, 0, 1, 2, 3);
  static const bb__texel_format BC4 = T("BC4", BB__TEXELS_BLOCKS, BB__BLOCK_BC4, 0, 1, 0, 0, 0, 0);
  static const bb__texel_format BC5 = T("BC5", BB__TEXELS_BLOCKS, BB__BLOCK_BC5, 0, 2, 0, 1, 0, 0);
  static const bb__texel_format BC5_NORMAL = {"BC5", BB__TEXELS_BLOCKS, BB__BLOCK_BC5, 0, 3,
                                              {0, 1, 2, 0}, {0, 0, 0, 0}, 1};
  const unsigned char *code = pf + 8;
  if (fourcc_is(code, "DXT1")) return pf_flags & DDPF_ALPHAPIXELS ? &BC1_RGBA : &BC1_RGB;
  /* DXT2 and DXT4 are DXT3 and DXT5 with colour premultiplied by alpha:
   * read as stored, as bumpbake reads alpha (never divided out). */
  if (fourcc_is(code, "DXT2") || fourcc_is(code, "DXT3")) return &BC2;
  if (fourcc_is(code, "DXT4") || fourcc_is(code, "DXT5")) return &BC3;
  if (fourcc_is(code, "ATI1") || fourcc_is(code, "BC4U")) return &BC4;
  if (fourcc_is(code, "ATI2") || fourcc_is(code, "BC5U"))
    return pf_flags & DDPF_NORMAL ? &BC5_NORMAL : &BC5;
  return NULL;
}

/* Channel c of a masked format from its mask: shift and width; 0 when the
 * mask is empty or not one run of bits. */
static int mask_channel(uint32_t mask, bb__texel_format *f, int c) {
  if (!mask) return 0;
  int shift = 0, bits = 0;
  while (!(mask & 1u)) mask >>= 1, shift++;
  while (mask & 1u) mask >>= 1, bits++;
  if (mask) return 0; /* bits after a gap */
  f->source[c] = (signed char)shift;
  f->bits[c] = (unsigned char)bits;
  return 1;
}

/* A legacy uncompressed format from its bit count and masks (R, G, B, A at
 * pf + 16..28): RGB, luminance or alpha alone, with alpha when
 * DDPF_ALPHAPIXELS says so. 0 when it is not one read. */
static int masked_format(const unsigned char *pf, uint32_t pf_flags, bb__texel_format *f) {
  const uint32_t bits = u32_at(pf + 12);
  if (bits != 8 && bits != 16 && bits != 24 && bits != 32) return 0;
  memset(f, 0, sizeof *f);
  f->kind = BB__TEXELS_PACKED;
  f->samples = (int)bits / 8;
  int channels = 0;
  if (pf_flags & DDPF_RGB) {
    f->name = "RGB";
    for (int c = 0; c < 3; c++)
      if (!mask_channel(u32_at(pf + 16 + 4 * c), f, channels++)) return 0;
  } else if (pf_flags & DDPF_LUMINANCE) {
    f->name = "luminance";
    if (!mask_channel(u32_at(pf + 16), f, channels++)) return 0;
  } else if (!(pf_flags & DDPF_ALPHA)) {
    return 0;
  } else {
    f->name = "alpha";
  }
  if (pf_flags & (DDPF_ALPHAPIXELS | DDPF_ALPHA))
    if (!mask_channel(u32_at(pf + 28), f, channels++)) return 0;
  f->channels = channels;
  return channels > 0;
}

bb_status bb__dds_layout(int fd, const char *path, bb__texture_layout *layout, bb_error *err) {
  memset(layout, 0, sizeof *layout);
  layout->alpha_channel = -1;
  struct stat sb;
  unsigned char h[DDS_HEADER_BYTES];
  memset(h, 0, sizeof h);
  if (fstat(fd, &sb) != 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
  const uint64_t file_size = (uint64_t)sb.st_size;
  const size_t got = bb__input_read_at(fd, h, sizeof h, 0);
  if (got < 128 || memcmp(h, "DDS ", 4) != 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a DDS file (or cut short in its header)", path);
  const unsigned char *pf = h + 76;
  const uint32_t pf_flags = u32_at(pf + 4);
  const int dx10 = (pf_flags & DDPF_FOURCC) && fourcc_is(pf + 8, "DX10");
  if (dx10 && got < DDS_HEADER_BYTES)
    return bb__fail(err, BB_ERR_FORMAT, "%s: DDS cut short in its DX10 header", path);
  const uint32_t height = u32_at(h + 12), width = u32_at(h + 16), depth = u32_at(h + 24);
  const uint32_t mips =
      (u32_at(h + 8) & DDSD_MIPMAPCOUNT) && u32_at(h + 28) > 0 ? u32_at(h + 28) : 1;
  if (width == 0 || height == 0 || width > BB_MAX_DIMENSION || height > BB_MAX_DIMENSION)
    return bb__fail(err, BB_ERR_SIZE, "%s: DDS of %u x %u texels (1 to %d a side are read)",
                    path, width, height, BB_MAX_DIMENSION);
  bb__texel_format f;
  if (dx10) {
    const uint32_t dxgi = u32_at(h + 128), dimension = u32_at(h + 132);
    if (dimension != D3D10_RESOURCE_DIMENSION_TEXTURE2D || depth > 1)
      return bb__fail(err, BB_ERR_FORMAT,
                      "%s: DDS resource dimension %u, depth %u: only 2D textures are read", path,
                      dimension, depth);
    const bb__texel_format *known = NULL;
    for (size_t i = 0; i < sizeof DX10_TEXELS / sizeof DX10_TEXELS[0]; i++)
      if (DX10_TEXELS[i].code == dxgi) known = &DX10_TEXELS[i].f;
    if (!known)
      return bb__fail(err, BB_ERR_FORMAT, "%s: DDS DXGI format %u is not read by bumpbake",
                      path, dxgi);
    f = *known;
  } else {
    if ((u32_at(h + 112) & DDSCAPS2_VOLUME) && depth > 1)
      return bb__fail(err, BB_ERR_FORMAT, "%s: volume DDS (depth %u) is not read", path, depth);
    const bb__texel_format *known = (pf_flags & DDPF_FOURCC) ? fourcc_format(pf, pf_flags) : NULL;
    if (known) {
      f = *known;
    } else if ((pf_flags & DDPF_FOURCC) || !masked_format(pf, pf_flags, &f)) {
      char code[5];
      for (int k = 0; k < 4; k++)
        code[k] = pf[8 + k] >= 0x20 && pf[8 + k] < 0x7f ? (char)pf[8 + k] : '?';
      code[4] = '\0';
      return (pf_flags & DDPF_FOURCC)
                 ? bb__fail(err, BB_ERR_FORMAT, "%s: DDS FourCC '%s' is not read by bumpbake",
                            path, code)
                 : bb__fail(err, BB_ERR_FORMAT,
                            "%s: DDS pixel format (flags 0x%x, %u bits, masks %08x %08x %08x "
                            "%08x) is not read by bumpbake",
                            path, pf_flags, u32_at(pf + 12), u32_at(pf + 16), u32_at(pf + 20),
                            u32_at(pf + 24), u32_at(pf + 28));
    }
  }
  int chain = 1;
  while ((width >> chain) > 0 || (height >> chain) > 0)
    chain++;
  if (mips > (uint32_t)chain)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: DDS of %u x %u declares %u mip levels (1 to %d are possible)", path,
                    width, height, mips, chain);
  uint64_t at = dx10 ? DDS_HEADER_BYTES : 128;
  for (uint32_t k = 0; k < mips; k++) {
    const int w = (int)(width >> k > 0 ? width >> k : 1), hh = (int)(height >> k > 0 ? height >> k : 1);
    layout->offset[k] = at;
    at += bb__texels_bytes(&f, w, hh);
  }
  if (at > file_size)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: truncated DDS: its levels need %llu bytes, the file has %llu", path,
                    (unsigned long long)at, (unsigned long long)file_size);
  layout->container = "dds";
  layout->format = f;
  layout->width = (int)width;
  layout->height = (int)height;
  layout->levels = (int)mips;
  layout->alpha_channel = f.channels == 4 ? 3 : -1;
  if (!dx10 && f.kind == BB__TEXELS_PACKED && (pf_flags & (DDPF_ALPHAPIXELS | DDPF_ALPHA)))
    layout->alpha_channel = f.channels - 1;
  layout->is_float = f.kind == BB__TEXELS_HALF || f.kind == BB__TEXELS_FLOAT;
  layout->bits_per_sample = f.kind == BB__TEXELS_FLOAT                               ? 32
                            : f.kind == BB__TEXELS_HALF || f.kind == BB__TEXELS_UNORM16 ? 16
                                                                                        : 8;
  if (f.kind == BB__TEXELS_PACKED) {
    int widest = 0;
    for (int c = 0; c < f.channels; c++)
      widest = f.bits[c] > widest ? f.bits[c] : widest;
    layout->bits_per_sample = widest;
  }
  return BB_OK;
}

/* ------------------------------------------------------------------ info */

/* A masked format's name from its channels' widths: "R5G6B5", "L8A8". */
static void masked_name(const bb__texel_format *f, const char *letters, char *out, size_t cap) {
  size_t n = 0;
  out[0] = '\0';
  for (int c = 0; c < f->channels && c < 4 && n < cap; c++) {
    const int w = snprintf(out + n, cap - n, "%c%d", letters[c], f->bits[c]);
    n += w > 0 ? (size_t)w : 0;
  }
}

bb_status bb__dds_read_info(const char *path, bb_dds_info *info, bb_error *err) {
  if (!info)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__dds_read_info: info is NULL");
  memset(info, 0, sizeof *info);
  if (!path)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__dds_read_info: path is NULL");
  int fd;
  bb_status st = bb__input_open(path, &fd, err);
  if (st != BB_OK)
    return st;
  bb__texture_layout layout;
  unsigned char h[DDS_HEADER_BYTES];
  memset(h, 0, sizeof h);
  st = bb__dds_layout(fd, path, &layout, err);
  if (st == BB_OK && bb__input_read_at(fd, h, sizeof h, 0) < 128)
    st = bb__fail(err, BB_ERR_IO, "%s: cannot read its header again", path);
  close(fd);
  if (st != BB_OK)
    return st;
  const unsigned char *pf = h + 76;
  const bb__texel_format *f = &layout.format;
  info->width = layout.width;
  info->height = layout.height;
  info->mip_count = layout.levels;
  info->pixel_flags = u32_at(pf + 4);
  info->caps2 = u32_at(h + 112);
  if (info->pixel_flags & DDPF_FOURCC) {
    for (int k = 0; k < 4; k++) /* read formats only: printable */
      info->fourcc[k] = (char)pf[8 + k];
    if (fourcc_is(pf + 8, "DX10"))
      info->dxgi_format = (int)u32_at(h + 128);
  }
  if (f->kind == BB__TEXELS_PACKED)
    masked_name(f,
                (info->pixel_flags & DDPF_RGB)         ? "RGBA"
                : (info->pixel_flags & DDPF_LUMINANCE) ? "LA"
                                                       : "A",
                info->format_name, sizeof info->format_name);
  else
    snprintf(info->format_name, sizeof info->format_name, "%s", f->name);
  static const char *const blocks[] = {[BB__BLOCK_BC1] = "BC1", [BB__BLOCK_BC2] = "BC2",
                                       [BB__BLOCK_BC3] = "BC3", [BB__BLOCK_BC4] = "BC4",
                                       [BB__BLOCK_BC5] = "BC5"};
  snprintf(info->compression, sizeof info->compression, "%s",
           f->kind == BB__TEXELS_BLOCKS ? blocks[f->block] : "none");
  return BB_OK;
}

const char *bb__dds_pixel_flag_name(int bit) {
  static const struct {
    uint32_t flag;
    const char *name;
  } names[] = {{DDPF_ALPHAPIXELS, "ALPHAPIXELS"}, {DDPF_ALPHA, "ALPHA"},
               {DDPF_FOURCC, "FOURCC"},           {DDPF_RGB, "RGB"},
               {DDPF_YUV, "YUV"},                 {DDPF_LUMINANCE, "LUMINANCE"},
               {DDPF_NORMAL, "NORMAL"}};
  for (size_t i = 0; bit >= 0 && bit < 32 && i < sizeof names / sizeof names[0]; i++)
    if (names[i].flag == 1u << bit)
      return names[i].name;
  return NULL;
}
