/* oiio.h: what the rest of the library asks of the image family beyond the
 * public reads and writes: file headers, bounded channel reads, resizing.
 * (The family reaches OpenImageIO only in its oiio_*.cpp files.) */
#ifndef BB_IMAGE_OIIO_H
#define BB_IMAGE_OIIO_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Image headers for bb__output_check: the depth bb__image_write stores for
 * `depth` in path's format (BB_DEPTH_DEFAULT resolved), or -1 for an
 * unknown extension (formats.c); and the number of mip levels of subimage 0
 * of the file at path, from its headers (image_read.c). */
int bb__path_resolved_depth(const char *path, bb_depth depth);

/* A depth as messages say it: "8-bit", "16-bit", "half float", "float",
 * "default", or "unknown" for anything else (depth.c; bb__depth_name is
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

/* bb_mip_chain of img whose levels[0] is *img itself: its pixels are not
 * copied (a 1024 x 1024 RGB map's 12 MB, cleared by calloc then copied:
 * 18 M instructions and 3,000 page faults of a texture write), so img
 * must outlive the chain. Its halvings run on threads (0: all cores; the
 * same bits on any count). Freed by bb__mip_chain_borrowed_free, which
 * leaves level 0 alone (mips.c). */
bb_status bb__mip_chain_borrowed(const bb_image *img, bb_mip_filter filter, int threads,
                                 bb_image **levels, int *count, bb_error *err);
void bb__mip_chain_borrowed_free(bb_image *levels, int count);

/* in, box-filtered by OpenImageIO's ImageBufAlgo::resize to width x height
 * (oiio_mips.cpp). Allocates out. */
bb_status bb__image_resize_box(const bb_image *in, int width, int height, bb_image *out,
                               bb_error *err);


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Number of subimages (frames) in an image file (1 for a VTF or DDS: the
 * frame read). */
bb_status bb__image_frame_count(const char *path, int *frames, bb_error *err);

/* True (1) when the extension of path (any case) is one OpenImageIO has a
 * reader for (png, tga, tif, exr, jpg, ...: its "extension_list"), so a
 * caller can pick the images out of a directory without opening each file.
 * It says nothing of the file's contents. */
int bb__path_is_readable_format(const char *path);

/* Starts path (extension .gif) for frames of width x height, shown at
 * frames_per_second (1..100). Errors: BB_ERR_FORMAT (not .gif), BB_ERR_IO. */
bb_status bb__animation_open(const char *path, int width, int height, double frames_per_second,
                            bb_animation **out, bb_error *err);

/* Appends a frame: 3 channels, the open size, values in [0, 1]. On failure
 * the animation stays open; bb__animation_abort it. */
bb_status bb__animation_add_frame(bb_animation *a, const bb_image *frame, bb_error *err);

/* Finishes the file, reads it back to check its frame count, renames it into
 * place and frees a, also on failure (then no file is left). */
bb_status bb__animation_close(bb_animation *a, bb_error *err);

/* Removes the temporary file and frees a; safe on NULL. */
void bb__animation_abort(bb_animation *a);

/* Parses "8", "16", "half", "float" (exact case), the words of --depth. */
bb_status bb__depth_parse(const char *name, bb_depth *out, bb_error *err);

/* Once public (bumpbake.h); no client read a level of its own. */
/* Reads mip level `level` (0 = full size) of subimage 0, as bb_image_read
 * reads level 0. level_count (may be NULL) receives the file's number of
 * levels; a level past the last is BB_ERR_ARGUMENT. */
bb_status bb__image_read_mip(const char *path, int level, bb_image *out,
                            bb_image_info *info, int *level_count, bb_error *err);

/* Once in bumpbake.h beside the functions that stay public there. */
/* The word bb__depth_parse accepts; "default" for BB_DEPTH_DEFAULT, "unknown"
 * for values outside the enum. */
const char *bb__depth_name(bb_depth depth);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_OIIO_H */
