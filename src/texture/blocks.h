/* blocks.h: 4 x 4 block compression (BC1, BC3, BC4, BC5) of RGBA images,
 * the one door to the block codec (squish.cpp, over Debian's libsquish). */
#ifndef BB_TEXTURE_BLOCKS_H
#define BB_TEXTURE_BLOCKS_H

#include "bumpbake.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum bb__block_format {
  BB__BLOCK_BC1 = 0, /* DXT1: R, G, B (5:6:5 end points, 2-bit indices), 8 bytes */
  BB__BLOCK_BC3,     /* DXT5: BC1 colour + BC4-style alpha, 16 bytes */
  BB__BLOCK_BC4,     /* one channel (R): 2 end points, 3-bit indices, 8 bytes */
  BB__BLOCK_BC5,     /* two channels (R, G): two BC4 blocks, 16 bytes */
  BB__BLOCK_BC2      /* DXT3: BC1 colour + 4-bit explicit alpha, 16 bytes (decoded only) */
} bb__block_format;

/* Bytes of one 4 x 4 block of format: 8 or 16. */
size_t bb__block_bytes(bb__block_format format);

/* Bytes of a width x height image in format: ceil(w/4) x ceil(h/4) blocks. */
size_t bb__blocks_size(bb__block_format format, int width, int height);

/* Compresses width x height texels of rgba (4 floats per texel, row-major,
 * values in [0, 1]; outside is clamped, NaN counts as 0) into out, which
 * holds bb__blocks_size bytes: blocks row by row, as DDS and VTF store
 * them. Each value is first rounded to 8 bits (round half up), as the codec
 * works on bytes. BC1 takes R, G, B; BC3 R, G, B, A; BC4 R; BC5 R and G.
 * Sides need not be multiples of 4: the texels past an edge are left out
 * of the fit (a mip level of 2 x 2 is one block). fast selects the codec's
 * range fit (about 40 times faster, about 1.7 dB lower PSNR on colour
 * blocks) instead of its cluster fit; BC4 and BC5 blocks are the same
 * either way. Blocks are compressed on `threads` threads (0 = all cores);
 * each block depends only on its texels, so out is the same for any count.
 * Errors: BB_ERR_ARGUMENT (bad format or size), BB_ERR_MEMORY, and any
 * exception of the codec, turned into a message. */
bb_status bb__blocks_compress(const float *rgba, int width, int height,
                              bb__block_format format, int fast, int threads,
                              unsigned char *out, bb_error *err);

/* Decodes width x height texels from blocks (bb__blocks_size bytes of
 * format, row by row) into rgba (4 bytes a texel, row-major) through the
 * codec's decoder: BC1 (index 3 of a 3-colour block is black with alpha 0),
 * BC2 and BC3 R, G, B, A; BC4 into R (G, B 0, A 255); BC5 into R and G (B
 * 0, A 255). Texels of the blocks past an edge are dropped. Errors:
 * BB_ERR_ARGUMENT (bad format or size) and any exception of the codec. */
bb_status bb__blocks_decompress(const unsigned char *blocks, int width, int height,
                                bb__block_format format, unsigned char *rgba, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_BLOCKS_H */
