/* dds.c: DirectDraw Surface files: one 2D texture and its mip chain.
 *
 * No Debian library writes this container with what we need: OpenImageIO
 * 2.4 reads DDS only; NVIDIA Texture Tools 2.0.8 writes the legacy header
 * (no DX10 header, no float formats) and only around its own compressor and
 * mip maps. The bytes follow Microsoft's "DDS_HEADER structure",
 * "DDS_PIXELFORMAT" and "DDS_HEADER_DXT10" pages (Programming Guide for
 * DDS), all little-endian:
 *
 *   0  "DDS "
 *   4  u32 size 124, flags, height, width, pitch or linear size, depth,
 *      mip count, u32 reserved[11]
 *  76  pixel format: u32 size 32, flags, FourCC, RGB bit count, R, G, B, A masks
 * 108  u32 caps, caps2, caps3, caps4, reserved
 * 128  DX10 header (when FourCC is "DX10"): u32 DXGI format, resource
 *      dimension (3: 2D), misc flag, array size (1), misc flags 2
 *
 * then every level, largest first. */

#include "core/internal.h"
#include "texture/dds.h"
#include "texture/texture.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static uint32_t fourcc(const char c[4]) {
  return (uint32_t)(unsigned char)c[0] | (uint32_t)(unsigned char)c[1] << 8 |
         (uint32_t)(unsigned char)c[2] << 16 | (uint32_t)(unsigned char)c[3] << 24;
}

static void put_u32(unsigned char *p, uint32_t v) {
  for (int k = 0; k < 4; k++)
    p[k] = (unsigned char)((v >> (8 * k)) & 0xff);
}

bb_status bb__dds_encode(bb_staged_file *f, const bb_image *chain, int levels,
                         const bb_texture_options *o, bb_texture_format format,
                         bb_error *err) {
  const char *path = f->path;
  const bb_image *img = &chain[0];
  bb_status st = BB_OK;
  const int mips = o->mips != 0;
  const int block = format == BB_TEXTURE_FORMAT_BC1 || format == BB_TEXTURE_FORMAT_BC3 ||
                    format == BB_TEXTURE_FORMAT_BC4 || format == BB_TEXTURE_FORMAT_BC5;
  const int dx10 = format == BB_TEXTURE_FORMAT_RGBA16F || format == BB_TEXTURE_FORMAT_RGBA32F;
  const size_t top_bytes = bb__texture_level_bytes(format, img->width, img->height);

  unsigned char h[148];
  memset(h, 0, sizeof h);
  memcpy(h, "DDS ", 4);
  put_u32(h + 4, 124);
  uint32_t flags = DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PIXELFORMAT;
  flags |= block ? DDSD_LINEARSIZE : DDSD_PITCH;
  if (mips)
    flags |= DDSD_MIPMAPCOUNT;
  put_u32(h + 8, flags);
  put_u32(h + 12, (uint32_t)img->height);
  put_u32(h + 16, (uint32_t)img->width);
  /* Block formats: bytes of the top level; others: bytes of a row. */
  put_u32(h + 20, block ? (uint32_t)top_bytes : (uint32_t)(top_bytes / (size_t)img->height));
  put_u32(h + 28, mips ? (uint32_t)levels : 0);
  put_u32(h + 76, 32);
  uint32_t pf_flags = DDPF_FOURCC;
  switch (format) {
  case BB_TEXTURE_FORMAT_BC1: put_u32(h + 84, fourcc("DXT1")); break;
  case BB_TEXTURE_FORMAT_BC3: put_u32(h + 84, fourcc("DXT5")); break;
  case BB_TEXTURE_FORMAT_BC4: put_u32(h + 84, fourcc("ATI1")); break;
  case BB_TEXTURE_FORMAT_BC5:
    put_u32(h + 84, fourcc("ATI2"));
    if (bb_map_kind_get(o->map)->unit_vectors)
      pf_flags |= DDPF_NORMAL;
    break;
  case BB_TEXTURE_FORMAT_RGBA8:
    /* R, G, B, A in byte order: DXGI's R8G8B8A8_UNORM. */
    pf_flags = DDPF_RGB | DDPF_ALPHAPIXELS;
    put_u32(h + 88, 32);
    put_u32(h + 92, 0x000000ffu);
    put_u32(h + 96, 0x0000ff00u);
    put_u32(h + 100, 0x00ff0000u);
    put_u32(h + 104, 0xff000000u);
    break;
  case BB_TEXTURE_FORMAT_RGBA16F:
  case BB_TEXTURE_FORMAT_RGBA32F:
    put_u32(h + 84, fourcc("DX10"));
    put_u32(h + 128, format == BB_TEXTURE_FORMAT_RGBA16F ? DXGI_FORMAT_R16G16B16A16_FLOAT
                                                         : DXGI_FORMAT_R32G32B32A32_FLOAT);
    put_u32(h + 132, D3D10_RESOURCE_DIMENSION_TEXTURE2D);
    put_u32(h + 140, 1); /* array size */
    break;
  default:
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: DDS has no format %s", path,
                    bb__texture_format_name(format));
  }
  put_u32(h + 80, pf_flags);
  put_u32(h + 108, DDSCAPS_TEXTURE | (mips ? DDSCAPS_COMPLEX | DDSCAPS_MIPMAP : 0));

  /* Every level, largest first as the file holds them, compressed in one job. */
  size_t data_bytes = 0;
  for (int k = 0; k < levels; k++)
    data_bytes += bb__texture_level_bytes(format, chain[k].width, chain[k].height);
  unsigned char *data = malloc(data_bytes ? data_bytes : 1);
  unsigned char **at = malloc((size_t)levels * sizeof *at);
  if (!data || !at)
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  for (size_t offset = 0, k = 0; st == BB_OK && k < (size_t)levels; k++) {
    at[k] = data + offset;
    offset += bb__texture_level_bytes(format, chain[k].width, chain[k].height);
  }
  if (st == BB_OK)
    st = bb__texture_encode_levels(chain, levels, o->map, format, o->fast, o->threads, at, err);
  if (st == BB_OK) {
    bb__safe_write(f, h, dx10 ? 148 : 128);
    bb__safe_write(f, data, data_bytes);
  }
  /* Write errors are kept by f and reported when the caller finishes it. */
  free(at);
  free(data);
  return st;
}
