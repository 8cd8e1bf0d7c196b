/* blocks.h: 4 x 4 block compression (BC1, BC3, BC4, BC5) of images, and
 * the decoding of those and BC2: the images cut into blocks, on threads,
 * by the block codec of bc.h (bc1.c, bc4.c; blocks.c). */
#ifndef BB_TEXTURE_BLOCKS_H
#define BB_TEXTURE_BLOCKS_H

#include "bumpbake.h"

#include <pthread.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum bb__block_format {
  BB__BLOCK_BC1 = 0, /* DXT1: R, G, B (5:6:5 end points, 2-bit indices), 8 bytes */
  BB__BLOCK_BC3,     /* DXT5: BC4-style alpha + BC1 colour, 16 bytes */
  BB__BLOCK_BC4,     /* one channel (R): 2 end points, 3-bit indices, 8 bytes */
  BB__BLOCK_BC5,     /* two channels (R, G): two BC4 blocks, 16 bytes */
  BB__BLOCK_BC2 /* DXT3: 4-bit explicit alpha + BC1 colour, 16 bytes (decoded only) */
} bb__block_format;

/* How hard colour blocks (BC1, BC3's colour) are fitted; BC4 and BC5
 * blocks have one way. */
typedef enum bb__block_fit {
  BB__FIT_BEST = 0, /* every search of bc1.c */
  BB__FIT_QUICK     /* least squares and one pass of the local search
                       (bc1.c): about half the work, 0.05 to 0.08 dB less */
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

/* One image to compress: its size and format, where its texels come from,
 * and out, which holds bb__blocks_size bytes: blocks row by row, as DDS
 * and VTF store them. */
typedef struct bb__block_image {
  int width, height;
  bb__block_format format; /* BC1, BC3, BC4 or BC5 */
  bb__block_texels_fn texels;
  const void *source;
  unsigned char *out;
} bb__block_image;

/* Compresses every image of images[0..count-1] (the levels of one or
 * several textures, largest first) in one job on `threads` threads (0 =
 * all cores): the rows of blocks of all the images are handed out in
 * turn, so small levels fill the threads as large ones end. BC1 takes R,
 * G, B; BC3 R, G, B and A; BC4 R; BC5 R and G. Values are clamped to
 * [0, 1] (NaN counts as 0) and fitted as they are, not rounded to 8 bits
 * first. Sides need not be multiples of 4: the texels past an edge are
 * left out of the fit (a mip level of 2 x 2 is one block). progress (may
 * be NULL) follows the rows of blocks, from the calling thread, and may
 * cancel (BB_ERR_CANCELLED).
 *
 * Each block depends only on its texels, so the bytes are the same for any
 * thread count. Errors: BB_ERR_ARGUMENT (bad format or size),
 * BB_ERR_SIZE, BB_ERR_CANCELLED. */
bb_status bb__blocks_compress_images(const bb__block_image *images, int count,
                                     bb__block_fit fit, int threads,
                                     bb_progress_fn progress, void *progress_user,
                                     bb_error *err);

/* A watch over the block compressions a caller's threads start (the
 * job's write stage, which stages its files side by side): rows of blocks
 * done, reported to progress against total (counted by the caller
 * beforehand: bb__texture_block_rows), and the wall seconds during which
 * at least one compression ran. A compression started on a thread after
 * bb__blocks_watch_thread(w) there is counted in w; progress is called
 * under w's lock, so from one thread at a time, and a nonzero return
 * cancels that compression (BB_ERR_CANCELLED). */
typedef struct bb__blocks_watch {
  pthread_mutex_t lock;
  long done, total;
  int running; /* compressions in flight */
  double started, seconds;
  bb_progress_fn progress; /* may be NULL */
  void *progress_user;
} bb__blocks_watch;

void bb__blocks_watch_init(bb__blocks_watch *w, long total, bb_progress_fn progress,
                           void *progress_user);
void bb__blocks_watch_destroy(bb__blocks_watch *w);
/* The watch of the compressions the calling thread starts from now on
 * (NULL: none). */
void bb__blocks_watch_thread(bb__blocks_watch *w);

/* bb__blocks_compress_images of one image given as width x height texels
 * of rgba (4 floats per texel, row-major) into out. */
bb_status bb__blocks_compress(const float *rgba, int width, int height,
                              bb__block_format format, bb__block_fit fit, int threads,
                              unsigned char *out, bb_error *err);

/* Decodes width x height texels from blocks (bb__blocks_size bytes of
 * format, row by row) into rgba (4 bytes a texel, row-major) by the exact
 * rules of bc.h: BC1 (colour 3 of a 3-colour block is black with alpha
 * 0), BC2 and BC3 R, G, B, A (their colour blocks always 4-colour; BC2's
 * alpha v * 17); BC4 into R (G, B 0, A 255); BC5 into R and G (B 0, A
 * 255). Texels of the blocks past an edge are dropped. Errors:
 * BB_ERR_ARGUMENT (bad format or size). */
bb_status bb__blocks_decompress(const unsigned char *blocks, int width, int height,
                                bb__block_format format, unsigned char *rgba,
                                bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_BLOCKS_H */
