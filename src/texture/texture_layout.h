/* texture_layout.h: engine textures as a reader sees them: Valve's VTF
 * (OpenImageIO has no reader) and DDS (OpenImageIO 2.4.7's reader crashes
 * or hangs on hostile headers: see dds_read.c) laid out by their own
 * readers (vtf_read.c, dds_read.c), every offset checked against the
 * file, and a level's stored texels decoded into floats (texels.c, blocks
 * through the block codec). image/texture_read.c reads them as images. */
#ifndef BB_TEXTURE_TEXTURE_LAYOUT_H
#define BB_TEXTURE_TEXTURE_LAYOUT_H

#include "bumpbake.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* How a format stores its texels. */
typedef enum bb__texel_kind {
  BB__TEXELS_BLOCKS,  /* 4 x 4 blocks (block: a bb__block_format) */
  BB__TEXELS_UNORM8,  /* `samples` bytes a texel, v / 255 */
  BB__TEXELS_UNORM16, /* `samples` little-endian u16 a texel, v / 65535 */
  BB__TEXELS_HALF,    /* `samples` binary16 a texel */
  BB__TEXELS_FLOAT,   /* `samples` binary32 a texel */
  BB__TEXELS_PACKED   /* one little-endian word of `samples` bytes (1 to 4)
                         a texel, channel c in bits [source[c], source[c] +
                         bits[c]), v / (2^bits - 1) (DDS's masks, VTF's
                         565, 5551, 4444) */
} bb__texel_kind;

typedef struct bb__texel_format {
  const char *name;          /* "DXT1", "BGR888", "R16G16B16A16_FLOAT"... */
  bb__texel_kind kind;
  int block;                 /* BLOCKS: the bb__block_format */
  int samples;               /* samples stored a texel (UNORM8..FLOAT; PACKED:
                                bytes of its word) */
  int channels;              /* channels handed back, 1 to 4 */
  signed char source[4];     /* channel c: sample source[c] (BLOCKS: of the
                                decoded R, G, B, A; PACKED: bit shift) */
  unsigned char bits[4];     /* PACKED: bits of channel c */
  int rebuild_z;             /* BLOCKS, 3 channels from BC5's two: channel 2
                                is z = sqrt(1 - x^2 - y^2) of the normal
                                (x, y) = 2 (R, G) - 1, stored as 0.5 + 0.5 z */
} bb__texel_format;

/* Bytes a width x height level of f takes in the file. */
uint64_t bb__texels_bytes(const bb__texel_format *f, int width, int height);

/* Bytes decoding a width x height level allocates beside its floats. */
uint64_t bb__texels_scratch_bytes(const bb__texel_format *f, int width, int height);

/* Decodes a width x height level (bb__texels_bytes of data) into out:
 * channels [first, first + count) of f's, as floats, row-major. */
bb_status bb__texels_decode(const bb__texel_format *f, const unsigned char *data, int width,
                            int height, int first, int count, float *out, bb_error *err);

enum { BB__TEXTURE_MAX_LEVELS = 17 }; /* 65536 texels a side: 17 levels */

/* Where a texture's levels are, as its container's reader found them:
 * every offset and size checked against the file's length. */
typedef struct bb__texture_layout {
  const char *container;     /* "vtf" or "dds" */
  bb__texel_format format;
  int width, height;         /* level 0 */
  int levels;                /* 1 to BB__TEXTURE_MAX_LEVELS */
  uint64_t offset[BB__TEXTURE_MAX_LEVELS]; /* level k's first byte (frame 0, face 0) */
  int alpha_channel;         /* -1 for none */
  int bits_per_sample, is_float;
  char *description;         /* provenance (VTF 7.3+ KVD), malloc'd, or NULL */
} bb__texture_layout;

/* The layout of the VTF (vtf_read.c) or DDS (dds_read.c) open at fd.
 * On failure nothing is left allocated. */
bb_status bb__vtf_layout(int fd, const char *path, bb__texture_layout *layout, bb_error *err);
bb_status bb__dds_layout(int fd, const char *path, bb__texture_layout *layout, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_TEXTURE_LAYOUT_H */
