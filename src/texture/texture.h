/* texture.h: what the VTF and DDS writers share (texture.c): the table of
 * formats, the checks of a request against a container, the mip chain and
 * the encoding of one level into a format's bytes. */
#ifndef BB_TEXTURE_TEXTURE_H
#define BB_TEXTURE_TEXTURE_H

#include "bumpbake.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum bb__container {
  BB__CONTAINER_NONE = 0,
  BB__CONTAINER_VTF,
  BB__CONTAINER_DDS
} bb__container;

/* The container path's extension names (any case). */
bb__container bb__texture_container(const char *path);

/* bb_texture_check's rules; on success *format is the format to write
 * (BB_TEXTURE_FORMAT_DEFAULT resolved). Messages start with path. */
bb_status bb__texture_resolve(const char *path, int width, int height, int channels,
                              const bb_texture_options *options, bb_texture_format *format,
                              bb_error *err);

/* Encodes levels[0] (given 0: its chain is made here by the map's rule and
 * written when options->mips) or the caller's chain levels[0..count-1]
 * (given 1: checked, written as it is) into f, opened here and finished on
 * success, discarded on failure. f must be bb__safe_init'ed. */
bb_status bb__texture_stage(const char *path, const bb_image *levels, int count, int given,
                            const bb_texture_options *options, struct bb_staged_file *f,
                            bb_error *err);

/* Rows of 4 x 4 blocks the texture file path of a width x height image of
 * `channels` channels, written with options, compresses: every level
 * written (and a VTF's low-resolution image); 0 for a texel format or a
 * request bb__texture_resolve refuses. */
long bb__texture_block_rows(const char *path, int width, int height, int channels,
                            const bb_texture_options *options);

/* Bytes of a width x height level in format. */
size_t bb__texture_level_bytes(bb_texture_format format, int width, int height);

/* 1 when format stores an alpha channel. */
int bb__texture_format_has_alpha(bb_texture_format format);

/* Texels i..i+n-1 of img as the engine samples them (see bumpbake.h): R,
 * G, B, A each into rgba (4 n floats), unit vectors
 * (bb_map_kind_info.unit_vectors) mapped to 0.5 + 0.5 v; not clamped. The
 * channel count's case is chosen once a call: a block codec reads a row of
 * a block at a time. */
void bb__texture_texels(const bb_image *img, int unit_vectors, size_t i, size_t n,
                        float *rgba);

/* Encodes levels[0..count-1] into out[k], bb__texture_level_bytes(format,
 * levels[k]) bytes each, little-endian. Block formats compress all the
 * levels in one job on `threads` threads (0 = all cores), the same bytes on
 * any count; fast: the codec's quick fit (BB__FIT_QUICK), else BB__FIT_BEST (blocks.h). Pass the largest
 * level first: its rows are handed out first, the small levels' fill in. */
bb_status bb__texture_encode_levels(const bb_image *levels, int count, bb_map_kind map,
                                    bb_texture_format format, int fast, int threads,
                                    unsigned char *const *out, bb_error *err);

/* bb__texture_encode_levels of one level. */
bb_status bb__texture_encode(const bb_image *level, bb_map_kind map,
                             bb_texture_format format, int fast, int threads,
                             unsigned char *out, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_TEXTURE_H */
