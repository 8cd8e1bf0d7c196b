/* image_write.h: bb__image_write_staged_all_cores and bb__image_write_mips_staged_all_cores with
 * the thread count of the job writing them (image_write.c): an OpenEXR
 * file's chunks are compressed on up to `threads` threads (0 = all cores,
 * what the public calls use; image/exr_pool.h); the bytes are the same on any
 * count. */
#ifndef BB_IO_IMAGE_WRITE_H
#define BB_IO_IMAGE_WRITE_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How a file is written: its depth, range, provenance text and texture
 * settings (once in bumpbake.h, issue 41: no public function takes it). */
typedef struct bb_write_options {
  bb_depth depth;
  bb_range range;
  const char *description; /* provenance text stored in the file, or NULL.
                              TGA holds 4 rows of 80 characters: provenance
                              is fitted with whole key=value lines, keys that
                              affect pixels first, and what does not fit is
                              left out (see bb_provenance_class) */
  const struct bb_texture_options *texture; /* .vtf and .dds only: format, mip
                              chain, flags (see "engine textures"); NULL: the
                              defaults, the map NORMAL for BB_RANGE_SIGNED and
                              PLAIN otherwise. description overrides its own */
} bb_write_options;

bb_status bb__image_write_staged(const char *path, const bb_image *img,
                                 const bb_write_options *options, int threads,
                                 bb_staged_file **staged, bb_error *err);

bb_status bb__image_write_mips_staged(const char *path, const bb_image *levels, int count,
                                      const bb_write_options *options, int threads,
                                      bb_staged_file **staged, bb_error *err);


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Writes img to path; the format comes from the extension (.png .tga .tif
 * .tiff .exr, and the engine textures .vtf and .dds, written by
 * bb__texture_write with options->texture: depth must then be
 * BB_DEPTH_DEFAULT, the texture format sets it; with a description, the
 * texture's settings are added to it as bb__texture_provenance's lines).
 * Integer formats clamp to the code range and round to nearest.
 * Channels are R, G, B, A for up to 4; an image of more (a basis map with
 * more than 4 directions) has them named B0, B1, ... instead, zero-padded
 * to one width (B00..B15 for 16) because OpenEXR keeps channels sorted by
 * name, and none is alpha.
 * The file is written to a temporary file in the destination directory,
 * every write checked, then flushed, fsynced and closed (checked) and only
 * then renamed into place, so a failure (a full disk included) leaves no
 * partial file and nothing at path. Errors: BB_ERR_FORMAT (unknown
 * extension, depth not supported by the format), BB_ERR_IO (cannot write:
 * the message gives the system's reason, e.g. "No space left on device"). */
bb_status bb__image_write(const char *path, const bb_image *img,
                         const bb_write_options *options, bb_error *err);

/* bb__image_write up to, not including, the rename: on success *staged
 * receives the handle; on failure it is NULL and nothing is left on disk.
 * The handle must be passed to bb__staged_file_commit or _discard. */
bb_status bb__image_write_staged_all_cores(const char *path, const bb_image *img,
                                const bb_write_options *options,
                                bb_staged_file **staged, bb_error *err);

/* Writes a mip chain (levels[0] the largest, each the halved size of the one
 * before, as bb_mip_chain makes it) as one tiled, mip-mapped TIFF or
 * OpenEXR file, every level encoded as bb__image_write encodes an image, and
 * written to a temporary name and renamed as it does; or as a .vtf or .dds
 * texture holding these levels (options->texture's mips is then ignored).
 * Errors as bb__image_write's; BB_ERR_FORMAT for a format without mip maps. */
bb_status bb__image_write_mips(const char *path, const bb_image *levels, int count,
                              const bb_write_options *options, bb_error *err);

/* bb__image_write_mips up to, not including, the rename, as
 * bb__image_write_staged_all_cores: commit or discard *staged. */
bb_status bb__image_write_mips_staged_all_cores(const char *path, const bb_image *levels, int count,
                                     const bb_write_options *options,
                                     bb_staged_file **staged, bb_error *err);

/* Writes img to path as a VTF or DDS texture (by extension), after
 * bb__texture_check; options may be NULL (the defaults). The mip chain is
 * made here (options->mips).
 *
 * VTF (Valve's layout: VTFLib's VTFFormat.h and the Valve Developer
 * Community's "Valve Texture Format" page): an 80-byte header (7.3 and up:
 * followed by a resource dictionary of 8-byte entries), reflectivity the
 * mean of (code / 255)^2.2 per channel over the 8-bit top level (as vtex and
 * VTFLib compute it), bump scale 1, one frame, depth 1, the low-resolution
 * image as DXT1 at the first mip size of at most 16 x 16, then every level,
 * smallest first. Flags: the map's, BB_VTF_FLAG_NOMIP | NOLOD without mips,
 * EIGHTBITALPHA for a 4-channel image in a format with alpha, and
 * options->vtf_flags.
 *
 * DDS: "DDS " and the 124-byte header, levels largest first. BC1 and BC3
 * carry FourCC DXT1 and DXT5; BC4 and BC5 ATI1 and ATI2 (the oldest codes,
 * which every DDS reader knows, OpenImageIO's included); a BC5 normal map
 * also carries the DDPF_NORMAL flag (0x80000000, NVIDIA's), which tells
 * readers that know it (OpenImageIO) to rebuild z. RGBA8 is a 32-bit RGB +
 * alpha pixel format with masks; RGBA16F and RGBA32F need, and get, the
 * DX10 header (DXGI_FORMAT_R16G16B16A16_FLOAT and _R32G32B32A32_FLOAT).
 * OpenImageIO 2.4 reads every DDS written here except those two float ones.
 *
 * The file is written as bb__image_write writes, through a temporary renamed
 * into place. Errors: as bb__texture_check; BB_ERR_VALUE (NaN or infinite
 * texels); BB_ERR_MEMORY; BB_ERR_IO. */
bb_status bb__texture_write(const char *path, const bb_image *img,
                           const bb_texture_options *options, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_IO_IMAGE_WRITE_H */
