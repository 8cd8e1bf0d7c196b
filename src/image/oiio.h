/* oiio.h: what the rest of the library asks of the image family beyond the
 * public reads and writes: file headers, bounded channel reads, resizing.
 * (The family reaches OpenImageIO only in its oiio_*.cpp files.) */
#ifndef BB_IMAGE_OIIO_H
#define BB_IMAGE_OIIO_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Image headers for bb_output_check: the depth bb_image_write stores for
 * `depth` in path's format (BB_DEPTH_DEFAULT resolved), or -1 for an
 * unknown extension (formats.c); and the number of mip levels of subimage 0
 * of the file at path, from its headers (image_read.c). */
int bb__path_resolved_depth(const char *path, bb_depth depth);

/* A depth as messages say it: "8-bit", "16-bit", "half float", "float",
 * "default", or "unknown" for anything else (depth.c; bb_depth_name is
 * the word --depth takes). */
const char *bb__depth_words(int depth);
bb_status bb__image_level_count(const char *path, int *levels, bb_error *err);


/* Reads channels [first_channel, first_channel + channel_count) of path as
 * float (the bounds of bb_image_read apply: the bytes of the whole file's
 * samples and of what is read). info may be NULL. Messages name the file.
 * (image_read.c) */
bb_status bb__image_read_channels(const char *path, int first_channel, int channel_count,
                                  bb_image *out, bb_image_info *info, bb_error *err);


/* What bb_image_read of path gives back of img written there at depth
 * (BB_DEPTH_DEFAULT: the format's) with range, bit for bit, made in memory
 * (as_read.c): the top level, a mip chain's too. Allocates out.
 * BB_ERR_FORMAT for an engine texture (.vtf, .dds: its blocks are made by
 * writing it) or an unknown extension. */
bb_status bb__image_as_read(const char *path, const bb_image *img, bb_depth depth,
                            bb_range range, bb_image *out, bb_error *err);

/* The filter of a map's mip chain (mips.c): a normal map's levels
 * renormalised, any other's averaged. */
bb_mip_filter bb__mip_filter(int normal_map);

/* in, box-filtered by OpenImageIO's ImageBufAlgo::resize to width x height
 * (oiio_mips.cpp). Allocates out. */
bb_status bb__image_resize_box(const bb_image *in, int width, int height, bb_image *out,
                               bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_OIIO_H */
