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

/* bb__texture_check's rules; on success *format is the format to write
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

/* A sample as an 8-bit code: rounded half up to 0..255, NaN to 0 (as
 * 8-bit image files are written). Inline, so a loop over samples runs in
 * lanes. */
static inline unsigned char bb__texture_byte(float v) {
  double u = v > 0.0f ? (double)v : 0.0;
  u = u < 1.0 ? u : 1.0;
  return (unsigned char)(u * 255.0 + 0.5);
}

/* bb__texture_byte of n samples, of 0.5f + 0.5f v when unit_vectors (a
 * normal map's texels as the codec sees them): the same codes, four
 * samples at a time where the compiler has SSE2. */
void bb__texture_bytes(const float *v, size_t n, int unit_vectors, unsigned char *out);

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


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* True (1) when path's extension (any case) is .vtf or .dds, the containers
 * bb__texture_write writes. */
int bb__path_is_texture_format(const char *path);

/* Checks, before any work, that a width x height image of `channels`
 * channels can go to path (.vtf or .dds) with options, so a caller can
 * refuse a bad request before a long bake. BB_ERR_ARGUMENT with the reason
 * for: another extension; a format the container does not have (VTF: bc1,
 * bc3, bgr888, bgra8888, rgba16f; DDS: bc1, bc3, bc4, bc5, rgba8, rgba16f,
 * rgba32f); a format that cannot hold the channels (bc1 and bgr888 take at
 * most 3, the others 4; bc4 exactly 1; bc5 2, or a normal map's 3); a
 * normal map of fewer than 3 channels; a VTF side that is not a power of
 * two or over 32768 (Source); a block format (bc*) whose width or height is
 * not a multiple of 4; a VTF version outside 2..5 or the ENVMAP flag; an
 * unknown format or map. */
bb_status bb__texture_check(const char *path, int width, int height, int channels,
                           const bb_texture_options *options, bb_error *err);

/* Sets options->map for a file of an output kind (a kind string as
 * bb_output_file's: NAME or NAME+EXTRA, a NAME map with EXTRA in its last
 * channel, "ssbump+height") holding values of range: the kind NAME names
 * (bb_map_kind_info.name, or "detail-ssbump", an ssbump), whose facts then
 * decide its mip rule, DDS default and VTF flags; except that a normal or
 * bent map not of BB_RANGE_SIGNED was packed into [0, 1] already ("normal+ao",
 * height2ssbump -n's): PLAIN, with the kind's BB_VTF_FLAG_NORMAL added to
 * options->vtf_flags. Any other kind ("height", "colour", "render", ...):
 * NORMAL for BB_RANGE_SIGNED values, else PLAIN. bb_outputs_write applies
 * it to every .vtf and .dds it writes, bb_outputs_check to every one it
 * checks. */
void bb__texture_options_for(bb_texture_options *options, const char *kind, bb_range range);

/* The "key=value" lines bb__image_write adds to a texture's provenance, so
 * an up-to-date check sees a changed texture setting: texture (vtf or
 * dds), texture_format, texture_mips, texture_fit (cluster or range), and
 * for VTF vtf_version and vtf_flags (hex). options may be NULL (the
 * defaults). malloc'd; NULL for another extension or out of memory. */
char *bb__texture_provenance(const char *path, const bb_texture_options *options);

/* The text bb_vmt_write writes, malloc'd into *text (*size bytes), for a
 * caller that writes it with other files (bb_outputs_write). Errors as
 * bb_vmt_write's, without BB_ERR_IO. */
bb_status bb__vmt_text(const char *path, const bb_vmt_options *options, char **text,
                      size_t *size, bb_error *err);

/* Once in bumpbake.h beside the functions that stay public there. */
/* The first name of format ("bc1", ...), "default", or "unknown". */
const char *bb__texture_format_name(bb_texture_format format);

/* Once public (bumpbake.h); a client parses these as options do
 * (bb_option_parse on --texture-format, --vtf-version, --vtf-flags). */
/* Parses a format name above (any case); "default" is BB_TEXTURE_FORMAT_DEFAULT. */
bb_status bb__texture_format_parse(const char *name, bb_texture_format *out, bb_error *err);
/* Parses a VTF version as --vtf-version takes it: "7.2" to "7.5", or the
 * minor number alone ("2" to "5"); *minor receives 2..5. */
bb_status bb__vtf_version_parse(const char *text, int *minor, bb_error *err);
/* Parses VTF flags as --vtf-flags takes them: a 32-bit number, decimal,
 * 0x hexadecimal or 0 octal (strtoul's base 0), no sign. */
bb_status bb__vtf_flags_parse(const char *text, uint32_t *flags, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_TEXTURE_H */
