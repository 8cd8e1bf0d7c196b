/* vtf_read.c: where a VTF's levels are and how its texels are stored, from
 * the header vtf.c reads (bb__vtf_read_header, the one VTF parser), for the
 * pixel reads of texture_read.c.
 *
 * The image data is every mip level, smallest first; each level holds every
 * frame, then every face, then every slice (VTFLib's VTFFile.cpp,
 * ComputeDataOffset). The reader hands back level k of frame 0, face 0 of a
 * flat texture: volume textures (depth > 1) are refused. Alpha is read when
 * the header's flags say the texture has it (EIGHTBITALPHA or ONEBITALPHA,
 * as vtex and bumpbake set them), so a 3-channel map written as BGRA8888 or
 * RGBA16161616F comes back with its 3 channels. */
#include "core/internal.h"
#include "texture/blocks.h"
#include "texture/texture_layout.h"
#include "texture/vtf.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#define T(name, kind, block, samples, channels, s0, s1, s2, s3)                                \
  { name, kind, block, samples, channels, {s0, s1, s2, s3}, {0, 0, 0, 0}, 0 }
#define P(name, channels, s0, b0, s1, b1, s2, b2, s3, b3)                                      \
  { name, BB__TEXELS_PACKED, 0, 2, channels, {s0, s1, s2, s3}, {b0, b1, b2, b3}, 0 }

/* Valve's IMAGE_FORMAT_* codes (Source SDK 2013, public/bitmap/imageformat.h),
 * as read; channels with alpha when the flags allow it (4), else one less.
 * A name NULL: not read (palettes, signed du/dv formats, depth buffers). */
static const bb__texel_format VTF_TEXELS[] = {
    T("RGBA8888", BB__TEXELS_UNORM8, 0, 4, 4, 0, 1, 2, 3),
    T("ABGR8888", BB__TEXELS_UNORM8, 0, 4, 4, 3, 2, 1, 0),
    T("RGB888", BB__TEXELS_UNORM8, 0, 3, 3, 0, 1, 2, 0),
    T("BGR888", BB__TEXELS_UNORM8, 0, 3, 3, 2, 1, 0, 0),
    P("RGB565", 3, 0, 5, 5, 6, 11, 5, 0, 0),
    T("I8", BB__TEXELS_UNORM8, 0, 1, 1, 0, 0, 0, 0),
    T("IA88", BB__TEXELS_UNORM8, 0, 2, 2, 0, 1, 0, 0),
    T(NULL, BB__TEXELS_UNORM8, 0, 1, 1, 0, 0, 0, 0), /* P8 */
    T("A8", BB__TEXELS_UNORM8, 0, 1, 1, 0, 0, 0, 0),
    T("RGB888_BLUESCREEN", BB__TEXELS_UNORM8, 0, 3, 3, 0, 1, 2, 0),
    T("BGR888_BLUESCREEN", BB__TEXELS_UNORM8, 0, 3, 3, 2, 1, 0, 0),
    T("ARGB8888", BB__TEXELS_UNORM8, 0, 4, 4, 1, 2, 3, 0),
    T("BGRA8888", BB__TEXELS_UNORM8, 0, 4, 4, 2, 1, 0, 3),
    T("DXT1", BB__TEXELS_BLOCKS, BB__BLOCK_BC1, 0, 3, 0, 1, 2, 3),
    T("DXT3", BB__TEXELS_BLOCKS, BB__BLOCK_BC2, 0, 4, 0, 1, 2, 3),
    T("DXT5", BB__TEXELS_BLOCKS, BB__BLOCK_BC3, 0, 4, 0, 1, 2, 3),
    T("BGRX8888", BB__TEXELS_UNORM8, 0, 4, 3, 2, 1, 0, 0),
    P("BGR565", 3, 11, 5, 5, 6, 0, 5, 0, 0),
    P("BGRX5551", 3, 10, 5, 5, 5, 0, 5, 0, 0),
    P("BGRA4444", 4, 8, 4, 4, 4, 0, 4, 12, 4),
    T("DXT1_ONEBITALPHA", BB__TEXELS_BLOCKS, BB__BLOCK_BC1, 0, 4, 0, 1, 2, 3),
    P("BGRA5551", 4, 10, 5, 5, 5, 0, 5, 15, 1),
    T(NULL, BB__TEXELS_UNORM8, 0, 2, 2, 0, 1, 0, 0), /* UV88 (signed) */
    T(NULL, BB__TEXELS_UNORM8, 0, 4, 4, 0, 1, 2, 3), /* UVWQ8888 (signed) */
    T("RGBA16161616F", BB__TEXELS_HALF, 0, 4, 4, 0, 1, 2, 3),
    T("RGBA16161616", BB__TEXELS_UNORM16, 0, 4, 4, 0, 1, 2, 3),
    T(NULL, BB__TEXELS_UNORM8, 0, 4, 4, 0, 1, 2, 3), /* UVLX8888 (signed) */
    T("R32F", BB__TEXELS_FLOAT, 0, 1, 1, 0, 0, 0, 0),
    T("RGB323232F", BB__TEXELS_FLOAT, 0, 3, 3, 0, 1, 2, 0),
    T("RGBA32323232F", BB__TEXELS_FLOAT, 0, 4, 4, 0, 1, 2, 3),
    /* 30..36: depth buffer formats, not images */
    T(NULL, 0, 0, 1, 1, 0, 0, 0, 0), T(NULL, 0, 0, 1, 1, 0, 0, 0, 0),
    T(NULL, 0, 0, 1, 1, 0, 0, 0, 0), T(NULL, 0, 0, 1, 1, 0, 0, 0, 0),
    T(NULL, 0, 0, 1, 1, 0, 0, 0, 0), T(NULL, 0, 0, 1, 1, 0, 0, 0, 0),
    T(NULL, 0, 0, 1, 1, 0, 0, 0, 0),
    T("ATI2N", BB__TEXELS_BLOCKS, BB__BLOCK_BC5, 0, 2, 0, 1, 0, 0),
    T("ATI1N", BB__TEXELS_BLOCKS, BB__BLOCK_BC4, 0, 1, 0, 0, 0, 0),
};
enum { VTF_TEXEL_COUNT = (int)(sizeof VTF_TEXELS / sizeof VTF_TEXELS[0]) };

/* 1 when the format's fourth channel is alpha that the flags may drop. */
static int has_droppable_alpha(int code) {
  switch (code) {
  case 0: case 1: case 11: case 12: case 14: case 15: case 19: case 21: case 24: case 25:
  case 29:
    return 1;
  default:
    return 0;
  }
}

bb_status bb__vtf_layout(int fd, const char *path, bb__texture_layout *layout, bb_error *err) {
  memset(layout, 0, sizeof *layout);
  layout->alpha_channel = -1;
  bb_vtf_info v;
  uint64_t image_at = 0;
  bb_status st = bb__vtf_read_header(fd, path, &v, &image_at, err);
  if (st != BB_OK)
    return st;
  struct stat sb;
  const uint64_t file_size = fstat(fd, &sb) == 0 ? (uint64_t)sb.st_size : 0;
  if (v.format < 0 || v.format >= VTF_TEXEL_COUNT || !VTF_TEXELS[v.format].name)
    st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF image format %s (%d) is not read by bumpbake",
                  path, v.format_name, v.format);
  else if (v.depth > 1)
    st = bb__fail(err, BB_ERR_FORMAT, "%s: volume textures (VTF depth %d) are not supported",
                  path, v.depth);
  if (st != BB_OK) {
    bb__vtf_info_free(&v);
    return st;
  }
  /* A chain longer than the halvings down to 1 x 1 is not a VTF Valve's
   * loader accepts (its mip count is computed the same way). */
  int chain = 1;
  while ((v.width >> chain) > 0 || (v.height >> chain) > 0)
    chain++;
  if (v.mip_count < 1 || v.mip_count > chain) {
    st = bb__fail(err, BB_ERR_FORMAT,
                  "%s: VTF of %d x %d declares %d mip levels (1 to %d are possible)", path,
                  v.width, v.height, v.mip_count, chain);
    bb__vtf_info_free(&v);
    return st;
  }
  bb__texel_format f = VTF_TEXELS[v.format];
  if (v.format == BB__VTF_DXT1 && (v.flags & BB_VTF_FLAG_ONEBITALPHA))
    f.channels = 4; /* DXT1 with its 1-bit alpha in use */
  if (has_droppable_alpha(v.format) &&
      !(v.flags & (BB_VTF_FLAG_EIGHTBITALPHA | BB_VTF_FLAG_ONEBITALPHA)))
    f.channels = 3;
  /* Each level holds every frame and face; frame 0, face 0 comes first. */
  const int faces = (v.flags & BB_VTF_FLAG_ENVMAP) ? (v.version_minor < 5 && v.first_frame != 0xffff ? 7 : 6) : 1;
  const uint64_t copies = (uint64_t)(v.frames > 0 ? v.frames : 1) * (uint64_t)faces;
  uint64_t at = image_at;
  for (int k = v.mip_count - 1; k >= 0; k--) {
    const int w = v.width >> k > 0 ? v.width >> k : 1, h = v.height >> k > 0 ? v.height >> k : 1;
    layout->offset[k] = at;
    at += bb__texels_bytes(&f, w, h) * copies;
  }
  if (at > file_size) {
    st = bb__fail(err, BB_ERR_FORMAT,
                  "%s: truncated VTF: its levels need %llu bytes, the file has %llu", path,
                  (unsigned long long)at, (unsigned long long)file_size);
    bb__vtf_info_free(&v);
    return st;
  }
  layout->container = "vtf";
  layout->format = f;
  layout->width = v.width;
  layout->height = v.height;
  layout->levels = v.mip_count;
  layout->alpha_channel = f.channels == 4 ? 3 : f.channels == 2 && v.format == 6 ? 1 : -1;
  layout->is_float = f.kind == BB__TEXELS_HALF || f.kind == BB__TEXELS_FLOAT;
  layout->bits_per_sample = f.kind == BB__TEXELS_FLOAT ? 32
                            : f.kind == BB__TEXELS_HALF || f.kind == BB__TEXELS_UNORM16 ? 16
                                                                                      : 8;
  layout->description = v.description;
  v.description = NULL;
  bb__vtf_info_free(&v);
  return BB_OK;
}
