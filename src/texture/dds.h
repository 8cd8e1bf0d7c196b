/* dds.h: DirectX's DDS texture container, written (dds.c). */
#ifndef BB_TEXTURE_DDS_H
#define BB_TEXTURE_DDS_H

#include "bumpbake.h"
#include "files/safe_file.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Writes img as a DDS file into f (open, unfinished: the caller finishes or
 * discards it), in format (resolved by bb__texture_resolve, which has
 * accepted the request). */
/* Writes the header and levels[0..count-1], largest first, into f (open). */
bb_status bb__dds_encode(bb_staged_file *f, const bb_image *levels, int count,
                         const bb_texture_options *options, bb_texture_format format,
                         bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_DDS_H */
