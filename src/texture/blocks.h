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

/* How colour blocks (BC1, BC3's colour) are fitted; BC4 and BC5 have one way. */
typedef enum bb__block_fit {
  BB__FIT_BEST = 0, /* cluster fit, or range fit where a level gains (below) */
  BB__FIT_RANGE,    /* range fit alone: --fast-compression */
  BB__FIT_CLUSTER   /* cluster fit alone: for tests and measurements */
} bb__block_fit;

/* Bytes of one 4 x 4 block of format: 8 or 16. */
size_t bb__block_bytes(bb__block_format format);

/* Bytes of a width x height image in format: ceil(w/4) x ceil(h/4) blocks. */
size_t bb__blocks_size(bb__block_format format, int width, int height);

/* Writes the texels x0..x0+w-1, y0..y0+h-1 (w, h at most 4, all inside the
 * image) of source as RGBA floats in [0, 1] into rgba[4 * (4 * y + x) + c],
 * y and x counted from y0 and x0. Called from any of the worker threads. */
typedef void (*bb__block_texels_fn)(const void *source, int x0, int y0, int w, int h,
                                    float rgba[64]);

/* One image to compress: its size, where its texels come from, and out,
 * which holds bb__blocks_size bytes: blocks row by row, as DDS and VTF
 * store them. */
typedef struct bb__block_image {
  int width, height;
  bb__block_texels_fn texels;
  const void *source;
  unsigned char *out;
} bb__block_image;

/* Compresses every image of images[0..count-1] (a texture's mip levels,
 * largest first) in one job on `threads` threads (0 = all cores): the rows
 * of blocks of all the images are handed out in turn, so small levels fill
 * the threads as the large one ends. Each value is first rounded to 8 bits
 * (round half up; outside [0, 1] clamped, NaN counts as 0), as the codec
 * works on bytes. BC1 takes R, G, B; BC3 R, G, B, A; BC4 R; BC5 R and G.
 * Sides need not be multiples of 4: the texels past an edge are left out
 * of the fit (a mip level of 2 x 2 is one block).
 *
 * BB__FIT_BEST fits each image's colour blocks (BC1, BC3's colour) by the
 * codec's cluster fit and by its range fit, and keeps the range fit's
 * blocks for an image where their squared error (8-bit codes, R, G, B, the
 * codec's own decoder, against the rounded texels) is under 90% of cluster
 * fit's: never worse than cluster fit alone on a level, and a gain under
 * any decoder's rounding (squish.cpp says why per level and 10%).
 * BB__FIT_RANGE takes the range fit alone (about 30 times faster, about
 * 1.8 dB lower PSNR). BC4 and BC5 blocks are the same whatever the fit.
 *
 * Each block depends only on its texels, so the bytes are the same for any
 * thread count. Errors: BB_ERR_ARGUMENT (bad format or size),
 * BB_ERR_MEMORY, and any exception of the codec, turned into a message. */
bb_status bb__blocks_compress_images(const bb__block_image *images, int count,
                                     bb__block_format format, bb__block_fit fit, int threads,
                                     bb_error *err);

/* bb__blocks_compress_images of one image given as width x height texels
 * of rgba (4 floats per texel, row-major) into out. */
bb_status bb__blocks_compress(const float *rgba, int width, int height,
                              bb__block_format format, bb__block_fit fit, int threads,
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
