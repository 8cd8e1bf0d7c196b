/* blocks.c: images cut into 4 x 4 blocks and compressed on threads, one
 * row of blocks an item, by the block codec (bc.h); and blocks decoded
 * back into texels (see blocks.h). */
#include "texture/blocks.h"
#include "core/internal.h"
#include "texture/bc.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

size_t bb__block_bytes(bb__block_format format) {
  return format == BB__BLOCK_BC1 || format == BB__BLOCK_BC4 ? 8 : 16;
}

size_t bb__blocks_size(bb__block_format format, int width, int height) {
  if (width <= 0 || height <= 0)
    return 0;
  return (size_t)((width + 3) / 4) * (size_t)((height + 3) / 4) * bb__block_bytes(format);
}

/* ------------------------------------------------------------- encoding */

typedef struct job {
  const bb__block_image *images;
  int *first_row; /* block row where each image starts; one more at the end */
  int quick;
} job;

/* One block of format from its texels (those of mask). */
static void encode_block(bb__block_format format, const float rgba[64], int mask,
                         int quick, unsigned char *out) {
  switch (format) {
  case BB__BLOCK_BC1:
    bb__bc1_encode(rgba, mask, 1, quick, out);
    return;
  case BB__BLOCK_BC3:
    bb__bc4_encode(rgba, 3, mask, out);
    bb__bc1_encode(rgba, mask, 0, quick, out + 8);
    return;
  case BB__BLOCK_BC4:
    bb__bc4_encode(rgba, 0, mask, out);
    return;
  case BB__BLOCK_BC5:
    bb__bc4_encode(rgba, 0, mask, out);
    bb__bc4_encode(rgba, 1, mask, out + 8);
    return;
  case BB__BLOCK_BC2:
    return; /* refused before any work */
  }
}

/* One row of blocks of one image: gathers each block's texels (those
 * inside the image set in the mask) and encodes it. */
static void compress_row(void *user, int item) {
  const job *j = user;
  int k = 0;
  while (item >= j->first_row[k + 1])
    k++;
  const bb__block_image *img = &j->images[k];
  const int block_row = item - j->first_row[k];
  const int blocks_wide = (img->width + 3) / 4;
  const int y0 = block_row * 4, h = img->height - y0 < 4 ? img->height - y0 : 4;
  const size_t bytes = bb__block_bytes(img->format);
  unsigned char *row = img->out + (size_t)block_row * (size_t)blocks_wide * bytes;
  for (int bx = 0; bx < blocks_wide; bx++) {
    const int x0 = bx * 4, w = img->width - x0 < 4 ? img->width - x0 : 4;
    float rgba[64] = {0};
    img->texels(img->source, x0, y0, w, h, rgba);
    int mask = 0;
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++)
        mask |= 1 << (4 * y + x);
    encode_block(img->format, rgba, mask, j->quick, row + (size_t)bx * bytes);
  }
}

/* ---------------------------------------------------------------- watch */

/* The calling thread's watch (bb__blocks_watch_thread). */
static _Thread_local bb__blocks_watch *watched;

void bb__blocks_watch_init(bb__blocks_watch *w, long total, bb_progress_fn progress,
                           void *progress_user) {
  memset(w, 0, sizeof *w);
  pthread_mutex_init(&w->lock, NULL);
  w->total = total;
  w->progress = progress;
  w->progress_user = progress_user;
}

void bb__blocks_watch_destroy(bb__blocks_watch *w) {
  pthread_mutex_destroy(&w->lock);
}

void bb__blocks_watch_thread(bb__blocks_watch *w) {
  watched = w;
}

/* One compression's progress under a watch: its rows done so far. */
typedef struct watched_run {
  bb__blocks_watch *w;
  long reported; /* this run's rows already added to w->done */
} watched_run;

/* Adds the run's rows done since the last call to the watch's and tells
 * the watch's progress (done clamped to the total counted beforehand). */
static int watch_progress(void *user, long done, long total) {
  (void)total;
  watched_run *run = user;
  bb__blocks_watch *w = run->w;
  pthread_mutex_lock(&w->lock);
  w->done += done - run->reported;
  run->reported = done;
  const long shown = w->done < w->total ? w->done : w->total;
  const int stop = w->progress ? w->progress(w->progress_user, shown, w->total) : 0;
  pthread_mutex_unlock(&w->lock);
  return stop;
}

static void watch_begin(bb__blocks_watch *w) {
  pthread_mutex_lock(&w->lock);
  if (w->running++ == 0)
    w->started = bb__now_seconds();
  pthread_mutex_unlock(&w->lock);
}

static void watch_end(watched_run *run, long rows) {
  bb__blocks_watch *w = run->w;
  pthread_mutex_lock(&w->lock);
  w->done += rows - run->reported;
  if (--w->running == 0)
    w->seconds += bb__now_seconds() - w->started;
  pthread_mutex_unlock(&w->lock);
}

/* ------------------------------------------------------------ compressing */

bb_status bb__blocks_compress_images(const bb__block_image *images, int count,
                                     bb__block_fit fit, int threads,
                                     bb_progress_fn progress, void *progress_user,
                                     bb_error *err) {
  if (fit != BB__FIT_BEST && fit != BB__FIT_QUICK)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: unknown fit %d", (int)fit);
  if (count < 0 || (count > 0 && !images))
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no images");
  for (int k = 0; k < count; k++) {
    const bb__block_image *img = &images[k];
    if (img->format < BB__BLOCK_BC1 || img->format > BB__BLOCK_BC5)
      return bb__fail(err, BB_ERR_ARGUMENT, "block compression: unknown block format %d",
                      (int)img->format);
    if (!img->texels || !img->out || img->width <= 0 || img->height <= 0)
      return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no image (%d x %d)",
                      img->width, img->height);
  }
  job j = {images, malloc(((size_t)count + 1) * sizeof(int)), fit == BB__FIT_QUICK};
  if (!j.first_row)
    return bb__fail(err, BB_ERR_MEMORY, "block compression: out of memory");
  j.first_row[0] = 0;
  bb_status st = BB_OK;
  for (int k = 0; k < count && st == BB_OK; k++) {
    const int rows = (images[k].height + 3) / 4;
    if (j.first_row[k] > INT_MAX - rows)
      st = bb__fail(err, BB_ERR_SIZE, "block compression: too many rows of blocks");
    else
      j.first_row[k + 1] = j.first_row[k] + rows;
  }
  /* Under a watch (and no progress of the caller's own), the rows count in
   * the watch's stage. */
  watched_run run = {watched, 0};
  if (run.w && !progress) {
    progress = watch_progress;
    progress_user = &run;
  } else {
    run.w = NULL;
  }
  if (st == BB_OK && count > 0) {
    if (run.w)
      watch_begin(run.w);
    st = bb__parallel_for(j.first_row[count], threads, compress_row, &j, progress,
                          progress_user, err);
    if (run.w)
      watch_end(&run, st == BB_OK ? j.first_row[count] : run.reported);
  }
  free(j.first_row);
  return st;
}

/* bb__blocks_compress's source: rows of 4 floats a texel. */
typedef struct float_image {
  const float *rgba;
  int width;
} float_image;

static void float_texels(const void *source, int x0, int y0, int w, int h,
                         float rgba[64]) {
  const float_image *f = source;
  for (int y = 0; y < h; y++)
    memcpy(rgba + 16 * y,
           f->rgba + ((size_t)(y0 + y) * (size_t)f->width + (size_t)x0) * 4,
           (size_t)w * 4 * sizeof(float));
}

bb_status bb__blocks_compress(const float *rgba, int width, int height,
                              bb__block_format format, bb__block_fit fit, int threads,
                              unsigned char *out, bb_error *err) {
  if (!rgba)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no image (%d x %d)", width,
                    height);
  const float_image source = {rgba, width};
  const bb__block_image image = {width, height, format, float_texels, &source, out};
  return bb__blocks_compress_images(&image, 1, fit, threads, NULL, NULL, err);
}

/* ------------------------------------------------------------- decoding */

/* One block of format into 16 RGBA texels. */
static void decode_block(const unsigned char *b, bb__block_format format,
                         unsigned char texels[64]) {
  switch (format) {
  case BB__BLOCK_BC1:
    bb__bc1_decode(b, 0, texels);
    return;
  case BB__BLOCK_BC2:
    bb__bc1_decode(b + 8, 1, texels);
    for (int i = 0; i < 16; i++)
      texels[4 * i + 3] = (unsigned char)(17 * ((b[i / 2] >> (4 * (i % 2))) & 15));
    return;
  case BB__BLOCK_BC3:
    bb__bc1_decode(b + 8, 1, texels);
    bb__bc4_decode(b, texels + 3, 4);
    return;
  case BB__BLOCK_BC4:
  case BB__BLOCK_BC5:
    for (int i = 0; i < 16; i++) {
      texels[4 * i + 0] = texels[4 * i + 1] = texels[4 * i + 2] = 0;
      texels[4 * i + 3] = 255;
    }
    bb__bc4_decode(b, texels, 4);
    if (format == BB__BLOCK_BC5)
      bb__bc4_decode(b + 8, texels + 1, 4);
    return;
  }
}

bb_status bb__blocks_decompress(const unsigned char *blocks, int width, int height,
                                bb__block_format format, unsigned char *rgba,
                                bb_error *err) {
  if (format < BB__BLOCK_BC1 || format > BB__BLOCK_BC2)
    return bb__fail(err, BB_ERR_ARGUMENT, "block decoding: unknown block format %d",
                    (int)format);
  if (!blocks || !rgba || width <= 0 || height <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "block decoding: no image (%d x %d)", width,
                    height);
  const size_t block_bytes = bb__block_bytes(format);
  const int blocks_wide = (width + 3) / 4;
  unsigned char texels[64];
  for (int by = 0; by < (height + 3) / 4; by++)
    for (int bx = 0; bx < blocks_wide; bx++) {
      decode_block(blocks + ((size_t)by * (size_t)blocks_wide + (size_t)bx) * block_bytes,
                   format, texels);
      for (int py = 0; py < 4 && by * 4 + py < height; py++)
        for (int px = 0; px < 4 && bx * 4 + px < width; px++)
          memcpy(rgba +
                     ((size_t)(by * 4 + py) * (size_t)width + (size_t)(bx * 4 + px)) * 4,
                 texels + (py * 4 + px) * 4, 4);
    }
  return BB_OK;
}
