/* dds_read.c: where the levels of a DDS with a DX10 header are, for the
 * pixel reads of texture_read.c. OpenImageIO 2.4 reads the legacy DDS
 * header (FourCC DXT1..5, ATI1, ATI2, and the RGB masks), which is every
 * DDS bumpbake writes but the float ones (RGBA16F, RGBA32F), which need
 * the DX10 header it refuses; those, and the other DX10 files listed in
 * DX10_TEXELS, are read here. The layout is Microsoft's (dds.c cites it):
 * "DDS ", a 124-byte header, the 20-byte DX10 header at 128, then every
 * level of array element 0, largest first. */
#include "core/input_file.h"
#include "core/internal.h"
#include "io/blocks.h"
#include "io/texture_read.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

enum { DDS_HEADER_BYTES = 148, DDSD_MIPMAPCOUNT = 0x20000, TEXTURE2D = 3 };

#define T(name, kind, block, samples, channels, s0, s1, s2, s3)                                \
  { name, kind, block, samples, channels, {s0, s1, s2, s3}, {0, 0, 0, 0} }

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

bb_status bb__dds_layout(int fd, const char *path, bb__texture_layout *layout, bb_error *err) {
  memset(layout, 0, sizeof *layout);
  layout->alpha_channel = -1;
  struct stat sb;
  unsigned char h[DDS_HEADER_BYTES];
  if (fstat(fd, &sb) != 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
  const uint64_t file_size = (uint64_t)sb.st_size;
  if (file_size < DDS_HEADER_BYTES || bb__input_read_at(fd, h, sizeof h, 0) != sizeof h ||
      memcmp(h, "DDS ", 4) != 0 || memcmp(h + 84, "DX10", 4) != 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a DDS file with a DX10 header", path);
  const uint32_t height = u32_at(h + 12), width = u32_at(h + 16), depth = u32_at(h + 24);
  const uint32_t mips = (u32_at(h + 8) & DDSD_MIPMAPCOUNT) ? u32_at(h + 28) : 1;
  const uint32_t dxgi = u32_at(h + 128), dimension = u32_at(h + 132);
  if (width == 0 || height == 0 || width > BB_MAX_DIMENSION || height > BB_MAX_DIMENSION)
    return bb__fail(err, BB_ERR_SIZE, "%s: DDS of %u x %u texels (1 to %d a side are read)",
                    path, width, height, BB_MAX_DIMENSION);
  if (dimension != TEXTURE2D || depth > 1)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: DDS resource dimension %u, depth %u: only 2D textures are read", path,
                    dimension, depth);
  const bb__texel_format *f = NULL;
  for (size_t i = 0; i < sizeof DX10_TEXELS / sizeof DX10_TEXELS[0]; i++)
    if (DX10_TEXELS[i].code == dxgi)
      f = &DX10_TEXELS[i].f;
  if (!f)
    return bb__fail(err, BB_ERR_FORMAT, "%s: DDS DXGI format %u is not read by bumpbake", path,
                    dxgi);
  int chain = 1;
  while ((width >> chain) > 0 || (height >> chain) > 0)
    chain++;
  /* A mip count of 0 is written by some tools for "no mips". */
  const uint32_t levels = mips ? mips : 1;
  if (levels > (uint32_t)chain)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: DDS of %u x %u declares %u mip levels (1 to %d are possible)", path,
                    width, height, levels, chain);
  uint64_t at = DDS_HEADER_BYTES;
  for (uint32_t k = 0; k < levels; k++) {
    const int w = (int)(width >> k > 0 ? width >> k : 1), hh = (int)(height >> k > 0 ? height >> k : 1);
    layout->offset[k] = at;
    at += bb__texels_bytes(f, w, hh);
  }
  if (at > file_size)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: truncated DDS: its levels need %llu bytes, the file has %llu", path,
                    (unsigned long long)at, (unsigned long long)file_size);
  layout->container = "dds";
  layout->format = *f;
  layout->width = (int)width;
  layout->height = (int)height;
  layout->levels = (int)levels;
  layout->alpha_channel = f->channels == 4 ? 3 : -1;
  layout->is_float = f->kind == BB__TEXELS_HALF || f->kind == BB__TEXELS_FLOAT;
  layout->bits_per_sample = f->kind == BB__TEXELS_FLOAT                                ? 32
                            : f->kind == BB__TEXELS_HALF || f->kind == BB__TEXELS_UNORM16 ? 16
                                                                                          : 8;
  return BB_OK;
}
