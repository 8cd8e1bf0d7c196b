/* formats.h: the formats bumpbake writes and what each can hold (depths,
 * channels, mip levels), and the checks a write makes before OpenImageIO
 * sees a byte (formats.c). */
#ifndef BB_IMAGE_FORMATS_H
#define BB_IMAGE_FORMATS_H

#include "bumpbake.h"
#include "core/file_names.h" /* bb__path_has_extension */
#include "image/image_write.h" /* bb_write_options */

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The extension of path's last component, lower-cased, with its dot
 * ("" when it has none), into out (cap bytes, cut to fit). */
void bb__extension_of(const char *path, char *out, size_t cap);

/* Bytes a sample of path's format takes at depth (BB_DEPTH_DEFAULT: the
 * format's own) in the copy its encoder makes: 1, 2 or 4; 4 for an engine
 * texture (its float mip chain) or an unknown format. */
double bb__encoded_sample_bytes(const char *path, bb_depth depth);

/* 1 when path's format can hold a mip chain (.tif, .tiff, .exr, .vtf, .dds). */
int bb__path_holds_mips(const char *path);

/* Everything bb__image_write checks before encoding: the image (not empty),
 * the options (known enums), the format (known extension) and that it holds
 * the depth and the channel count. *depth receives the depth to write. */
bb_status bb__write_check(const char *path, const bb_image *img, const bb_write_options *options,
                          bb_depth *depth, bb_error *err);

/* The same for a mip chain: every level half the one before (floored, at
 * least 1) with the same channels, as bb_mip_chain makes them, and a
 * format that holds mip levels. */
bb_status bb__write_mips_check(const char *path, const bb_image *levels, int count,
                               const bb_write_options *options, bb_depth *depth,
                               bb_error *err);

/* The lossless compression an OpenEXR file of depth is written with, as
 * OpenImageIO names it: "piz" for half, "none" for float. Chosen by
 * measuring every map (docs/performance.md, "EXR compression"): on half
 * maps PIZ is the fastest compressor and the smallest file or within 5% of
 * it; float maps' mantissas leave the compressors 4 to 13% to take, for 12
 * to 25 times the time of writing them as they are. */
const char *bb__exr_compression(bb_depth depth);

/* The texture options a write of a .vtf or .dds uses: options->texture's
 * (or the defaults, with the map NORMAL for BB_RANGE_SIGNED), with
 * options->description when it has one. */
void bb__texture_options_of(const bb_write_options *options, bb_texture_options *out);

/* The name of channel c of an image of `count` channels: NULL when count <=
 * 4 (OpenImageIO's R, G, B, A stay), else "B" and c zero-padded to the
 * width of count - 1 (B00..B15): OpenEXR keeps channels sorted by name and
 * reads them back in that order. out holds at least 8 bytes. */
const char *bb__basis_channel_name(int c, int count, char out[8]);


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* True (1) when the extension of path names a format bb__image_write knows
 * (.vtf and .dds included). */
int bb__path_is_writable_format(const char *path);

/* True (1) when bb__image_write can store depth in the format path's extension
 * names (BB_DEPTH_DEFAULT fits every known format), so a caller can refuse a
 * bad combination before a long bake rather than after it. */
int bb__path_supports_depth(const char *path, bb_depth depth);

/* Most channels bb__image_write can store in the format path's extension
 * names: 4 for .png, .tga, .vtf and .dds, 64 for .tif, .tiff and .exr; 0 for an unknown
 * extension. So a caller can refuse a basis with more directions than the
 * file can hold before the bake. */
int bb__path_max_channels(const char *path);

/* True (1) when path's format can hold a mip chain (.tif, .tiff, .exr; .vtf
 * and .dds, which have one unless bb_texture_options.mips is 0). */
int bb__path_supports_mips(const char *path);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_FORMATS_H */
