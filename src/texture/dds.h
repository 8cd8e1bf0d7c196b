/* dds.h: DirectX's DDS texture container, written (dds.c) and read
 * (dds_read.c): the header's flags, by Microsoft's names, and the writer. */
#ifndef BB_TEXTURE_DDS_H
#define BB_TEXTURE_DDS_H

#include "bumpbake.h"
#include "files/safe_file.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The header's flags and codes (Microsoft's DDS_HEADER, DDS_PIXELFORMAT,
 * DDS_HEADER_DXT10), as the writer sets them and the reader reads them. */
enum {
  DDSD_CAPS = 0x1,
  DDSD_HEIGHT = 0x2,
  DDSD_WIDTH = 0x4,
  DDSD_PITCH = 0x8,
  DDSD_PIXELFORMAT = 0x1000,
  DDSD_MIPMAPCOUNT = 0x20000,
  DDSD_LINEARSIZE = 0x80000,
  DDPF_ALPHAPIXELS = 0x1,
  DDPF_ALPHA = 0x2,
  DDPF_FOURCC = 0x4,
  DDPF_RGB = 0x40,
  DDPF_YUV = 0x200,
  DDPF_LUMINANCE = 0x20000,
  DDSCAPS_COMPLEX = 0x8,
  DDSCAPS_TEXTURE = 0x1000,
  DDSCAPS_MIPMAP = 0x400000,
  DDSCAPS2_VOLUME = 0x200000,
  DXGI_FORMAT_R32G32B32A32_FLOAT = 2,
  DXGI_FORMAT_R16G16B16A16_FLOAT = 10,
  D3D10_RESOURCE_DIMENSION_TEXTURE2D = 3
};
/* NVIDIA's flag for normal maps (nvtt writes it; OpenImageIO reads it as
 * "rebuild z from x and y" for BC5). */
#define DDPF_NORMAL 0x80000000u

/* Writes img as a DDS file into f (open, unfinished: the caller finishes or
 * discards it), in format (resolved by bb__texture_resolve, which has
 * accepted the request). */
/* Writes the header and levels[0..count-1], largest first, into f (open). */
bb_status bb__dds_encode(bb_staged_file *f, const bb_image *levels, int count,
                         const bb_texture_options *options, bb_texture_format format,
                         bb_error *err);

/* The name of DDS_PIXELFORMAT flag bit `bit` (0..31) without its DDPF_
 * prefix ("ALPHAPIXELS", "FOURCC", "RGB", "LUMINANCE"; bit 31 NVIDIA's
 * "NORMAL"), or NULL for an unused bit or one out of range (info's
 * report). */
const char *bb__dds_pixel_flag_name(int bit);

#ifdef __cplusplus
}
#endif

/* Reads the header of the DDS file at path, an untrusted file, with the
 * checks bb_image_read makes (every level within the file, mip count
 * within the chain). Errors: BB_ERR_IO (missing, unreadable),
 * BB_ERR_FORMAT (not a DDS, truncated, a format bumpbake does not read),
 * BB_ERR_SIZE (zero or over BB_MAX_DIMENSION a side). Nothing to free. */
bb_status bb__dds_read_info(const char *path, bb_dds_info *info, bb_error *err);

#endif /* BB_TEXTURE_DDS_H */
