/* image_write.h: bb_image_write_staged and bb_image_write_mips_staged with
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

bb_status bb__image_write_staged(const char *path, const bb_image *img,
                                 const bb_write_options *options, int threads,
                                 bb_staged_file **staged, bb_error *err);

bb_status bb__image_write_mips_staged(const char *path, const bb_image *levels, int count,
                                      const bb_write_options *options, int threads,
                                      bb_staged_file **staged, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_IO_IMAGE_WRITE_H */
