/* vtf.h: Valve's texture container, written and its header read (vtf.c);
 * its pixels are laid out by vtf_read.c (texture_layout.h). */
#ifndef BB_TEXTURE_VTF_H
#define BB_TEXTURE_VTF_H

#include "bumpbake.h"
#include "files/safe_file.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Valve's IMAGE_FORMAT_* codes the writer uses. */
enum {
  BB__VTF_BGR888 = 3,
  BB__VTF_BGRA8888 = 12,
  BB__VTF_DXT1 = 13,
  BB__VTF_DXT5 = 15,
  BB__VTF_RGBA16161616F = 24
};

/* Writes img as a VTF file into f (open, unfinished: the caller finishes or
 * discards it), in format (resolved by bb__texture_resolve, which has
 * accepted the request). */
/* Writes the header, the low-resolution image (low, at most 16 x 16, as
 * DXT1), the provenance resource and levels[0..count-1], smallest first,
 * into f (open). */
bb_status bb__vtf_encode(bb_staged_file *f, const bb_image *levels, int count,
                         const bb_image *low, const bb_texture_options *options,
                         bb_texture_format format, bb_error *err);

/* bb__vtf_read_info on the file open at fd (path names it in messages; fd
 * is left open): every size and offset checked against the file's length.
 * *image_offset (may be NULL) receives where the image data starts (every
 * level, smallest first). */
bb_status bb__vtf_read_header(int fd, const char *path, bb_vtf_info *info,
                              uint64_t *image_offset, bb_error *err);

/* Valve's name of the TEXTUREFLAGS_* bit `bit` (0..31) as Source SDK 2013
 * spells it without the prefix ("CLAMPS", "NORMAL", "SSBUMP"), or NULL for
 * an unused bit or one out of range (info's report). */
const char *bb__vtf_flag_name(int bit);

#ifdef __cplusplus
}
#endif

/* Reads the header (and resource dictionary) of the VTF file at path, an
 * untrusted file: every size and offset is checked against the file's
 * length. Errors: BB_ERR_IO (missing, unreadable), BB_ERR_FORMAT (not a
 * VTF, a version other than 7.0..7.5, a header, resource or image data
 * that runs past the end of the file). Free with bb__vtf_info_free. */
bb_status bb__vtf_read_info(const char *path, bb_vtf_info *info, bb_error *err);

/* Frees info->description and clears it; safe on a zeroed struct. */
void bb__vtf_info_free(bb_vtf_info *info);

#endif /* BB_TEXTURE_VTF_H */
