/* texture_read.h: VTF and DDS files read as images (texture_read.c), from
 * the layouts of texture/texture_layout.h, within the limits of
 * read_limits.h, for image_read.c. */
#ifndef BB_IMAGE_TEXTURE_READ_H
#define BB_IMAGE_TEXTURE_READ_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when path is read by bumpbake's texture readers rather than OpenImageIO: a .vtf
 * name or a file starting with "VTF\0" or "DDS ". */
int bb__texture_read_applies(const char *path);

/* bb__image_read_mip's read (channels [first, first + count), count < 0: all)
 * of a texture bb__texture_read_applies to, and its header alone. */
bb_status bb__texture_read(const char *path, int first, int count, int level, bb_image *out,
                           bb_image_info *info, int *level_count, bb_error *err);
bb_status bb__texture_read_header(const char *path, int *width, int *height, int *channels,
                                  bb_image_info *info, int *level_count, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_TEXTURE_READ_H */
