/* image.c: the bb_image type, status names and errors shared by every stage. */
#include "core/internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *bb_status_name(bb_status status) {
  switch (status) {
  case BB_OK: return "ok";
  case BB_ERR_ARGUMENT: return "bad argument";
  case BB_ERR_IO: return "i/o error";
  case BB_ERR_FORMAT: return "bad image format";
  case BB_ERR_SIZE: return "bad image size";
  case BB_ERR_VALUE: return "bad value";
  case BB_ERR_MEMORY: return "out of memory";
  case BB_ERR_CANCELLED: return "cancelled";
  }
  return "unknown status";
}

/* A message is one line, safe to show, whatever a name in it holds: a
 * control character (a newline in a path, an escape sequence), a
 * bidirectional control or bytes that are not UTF-8 are written as \xNN,
 * as the command line prints text (bb_text_printable), so every client
 * shows the same single line. */
bb_status bb__fail(bb_error *err, bb_status status, const char *fmt, ...) {
  if (err) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    char shown[4 * sizeof err->message];
    bb_text_printable(err->message, shown, sizeof shown);
    size_t n = strlen(shown);
    if (n >= sizeof err->message)
      n = sizeof err->message - 1;
    memcpy(err->message, shown, n);
    err->message[n] = '\0';
  }
  return status;
}

size_t bb__message_names(const char *message, const char *path) {
  char shown[4 * sizeof(((bb_error *)0)->message)];
  bb_text_printable(path, shown, sizeof shown);
  const size_t n = strlen(shown);
  return strncmp(message, shown, n) == 0 && message[n] == ':' ? n : 0;
}

bb_status bb__fail_at(bb_error *err, bb_status st, const char *path, const bb_error *e) {
  const char *why = e && e->message[0] ? e->message : bb_status_name(st);
  if (bb__message_names(why, path))
    return bb__fail(err, st, "%s", why);
  return bb__fail(err, st, "%s: %s", path, why);
}

bb_status bb_image_size_check(int width, int height, int channels, bb_error *err) {
  if (width <= 0 || height <= 0)
    return bb__fail(err, BB_ERR_SIZE, "zero or negative image size %dx%d", width, height);
  if (width > BB_MAX_DIMENSION || height > BB_MAX_DIMENSION ||
      (long long)width * height > BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_SIZE,
                    "image %dx%d is over the maximum (%d per side, %ld texels)", width,
                    height, BB_MAX_DIMENSION, (long)BB_MAX_PIXELS);
  if (channels < 1 || channels > 64)
    return bb__fail(err, BB_ERR_ARGUMENT, "unsupported channel count %d", channels);
  return BB_OK;
}

bb_status bb_image_alloc(bb_image *img, int width, int height, int channels,
                         bb_error *err) {
  memset(img, 0, sizeof *img);
  bb_status st = bb_image_size_check(width, height, channels, err);
  if (st != BB_OK)
    return st;
  /* width*height <= 2^26 and channels <= 64, so the product fits in size_t. */
  size_t count = (size_t)width * (size_t)height * (size_t)channels;
  img->pixels = calloc(count, sizeof(float));
  if (!img->pixels)
    return bb__fail(err, BB_ERR_MEMORY, "cannot allocate a %dx%dx%d image", width,
                    height, channels);
  img->width = width;
  img->height = height;
  img->channels = channels;
  return BB_OK;
}

void bb_image_free(bb_image *img) {
  if (!img) return;
  free(img->pixels);
  memset(img, 0, sizeof *img);
}

float *bb_image_texel(const bb_image *img, int x, int y) {
  assert(x >= 0 && x < img->width && y >= 0 && y < img->height);
  return img->pixels + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels;
}

void bb__image_flip_green(bb_image *img) {
  assert(img->channels >= 2);
  size_t n = (size_t)img->width * (size_t)img->height;
  for (size_t i = 0; i < n; i++) img->pixels[i * (size_t)img->channels + 1] *= -1.0f;
}
