/* oiio_calls.h: the OpenImageIO calls of the image family, by job, as C
 * functions for the family's C files (image_read.c, image_write.c,
 * animation.c). Each is defined in an oiio_*.cpp file and runs behind the
 * one exception guard (oiio_guard.h): none throws. The rules around them
 * (formats, limits, descriptions, codes) are C and live elsewhere. */
#ifndef BB_IMAGE_OIIO_CALLS_H
#define BB_IMAGE_OIIO_CALLS_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------- reads (oiio_read.cpp) */

/* Reads channels [first, first + count) (count < 0: all) of mip level
 * `level` of subimage 0 of path as float into out, with the bounds of
 * read_limits.h; info (may be NULL) is filled; level_count (may be NULL)
 * receives the file's number of mip levels, and a level past the last is
 * BB_ERR_ARGUMENT. On failure the caller frees out and info. */
bb_status bb__oiio_read(const char *path, int first, int count, int level, bb_image *out,
                        bb_image_info *info, int *level_count, bb_error *err);

/* The header of path: size, channels and info, no pixel decoded. */
bb_status bb__oiio_read_header(const char *path, int *width, int *height, int *channels,
                               bb_image_info *info, bb_error *err);

/* Mip levels of subimage 0, and subimages (frames), of path, from headers. */
bb_status bb__oiio_level_count(const char *path, int *levels, bb_error *err);
bb_status bb__oiio_frame_count(const char *path, int *frames, bb_error *err);

/* The n floats a read hands back of samples stored at depth: samples are
 * codes (uint8_t for BB_DEPTH_8, uint16_t for BB_DEPTH_16) scaled as a read
 * of an integer file scales them, or floats (BB_DEPTH_HALF) rounded to half
 * as a write rounds them and widened again. */
bb_status bb__oiio_samples_as_read(const void *samples, int depth, size_t n, float *out,
                                   bb_error *err);

/* OpenImageIO's "extension_list" ("tiff:tif,tiff;png:png;..."), malloc'd,
 * or NULL. */
char *bb__oiio_extension_list(void);

/* -------------------------------------------------- writes (oiio_write.cpp) */

/* Encodes img at depth (resolved, checked by bb__write_check) into a
 * finished temporary for path (f: see safe_file.h), for the caller to
 * commit or discard; an OpenEXR file's chunks are compressed on up to
 * `threads` threads (0 = all cores; exr_pool.h), with exr_compression
 * (OpenImageIO's name: "piz", "zip:1"...) or, when NULL, the library's
 * rule (bb__exr_compression); tools/exr_compression.c measures the others. */
bb_status bb__oiio_write_image(const char *path, const bb_image *img, bb_depth depth,
                               bb_range range, const char *description, int threads,
                               const char *exr_compression, bb_staged_file *f, bb_error *err);

/* ----------------------------------------------- mip chains (oiio_mips.cpp) */

/* Encodes the chain (checked by bb__write_mips_check) as one tiled,
 * mip-mapped file into a finished temporary for path (threads as above). */
bb_status bb__oiio_write_mips(const char *path, const bb_image *levels, int count,
                              bb_depth depth, bb_range range, const char *description,
                              int threads, bb_staged_file *f, bb_error *err);

/* ------------------------------------------------ animations (oiio_gif.cpp) */

/* A GIF being written (checked by animation.c); see bb__animation_open. */
bb_status bb__oiio_gif_open(const char *path, int width, int height, double frames_per_second,
                            bb_animation **out, bb_error *err);
bb_status bb__oiio_gif_add(bb_animation *a, const bb_image *frame, bb_error *err);
/* Closes, checks and commits the file; a is freed whatever the outcome. */
bb_status bb__oiio_gif_close(bb_animation *a, bb_error *err);
/* Frees a and removes what it staged. */
void bb__oiio_gif_abort(bb_animation *a);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_OIIO_CALLS_H */
