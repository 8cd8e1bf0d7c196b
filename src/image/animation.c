/* animation.c: the public GIF animation writer (bumpbake.h "animation"):
 * its arguments checked here, the frames encoded by OpenImageIO
 * (oiio_gif.cpp). */
#include "core/internal.h"
#include "image/formats.h"
#include "image/oiio_calls.h"
#include "image/oiio.h"

#include <stddef.h>

bb_status bb__animation_open(const char *path, int width, int height, double frames_per_second,
                            bb_animation **out, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__animation_open: out is NULL");
  *out = NULL;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "animation: path is NULL");
  if (!bb__path_has_extension(path, "gif"))
    return bb__fail(err, BB_ERR_FORMAT, "%s: animations are written as .gif files", path);
  if (width <= 0 || height <= 0 || width > 65535 || height > 65535)
    return bb__fail(err, BB_ERR_SIZE, "%s: a GIF frame cannot be %dx%d", path, width, height);
  if (!(frames_per_second >= 1.0 && frames_per_second <= 100.0))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: frames per second must be in 1..100 (got %g)",
                    path, frames_per_second);
  return bb__oiio_gif_open(path, width, height, frames_per_second, out, err);
}

bb_status bb__animation_add_frame(bb_animation *a, const bb_image *frame, bb_error *err) {
  return bb__oiio_gif_add(a, frame, err);
}

bb_status bb__animation_close(bb_animation *a, bb_error *err) {
  if (!a) return bb__fail(err, BB_ERR_ARGUMENT, "bb__animation_close: NULL animation");
  return bb__oiio_gif_close(a, err);
}

void bb__animation_abort(bb_animation *a) { bb__oiio_gif_abort(a); }
