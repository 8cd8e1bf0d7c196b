/* trace_input.c: what a bake traces (the pyramid of its smoothed, scaled
 * height and its ray set), built alone, for a trace split over processes
 * whose horizons must be those of bb__bake_checked's own trace. */

#include "bake/bake_internal.h"
#include "core/internal.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"

#include <stdlib.h>

bb_status bb__bake_trace_input(const bb_image *height, const bb_bake_options *given,
                              bb_pyramid **pyramid, bb_rayset **rays, bb_error *err) {
  if (!pyramid || !rays)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: missing pyramid or ray set");
  *pyramid = NULL;
  *rays = NULL;
  if (!height || !height->pixels || height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: need a 1-channel height field");
  bb_bake_options prepared;
  const bb_bake_options *o = &prepared;
  bb_status st = bb__bake_prepare(given, &prepared, err);
  if (st == BB_OK && !(o->outputs & BB_MAPS_TRACED))
    st = bb__fail(err, BB_ERR_ARGUMENT, "bake: the outputs asked need no trace");
  if (st == BB_OK) st = bb__check_scaled_height(height, o->height_scale, err);
  if (st != BB_OK) return st;
  const int threads = bb__thread_count(o->trace.threads);
  /* bb__bake_checked's stages, with its operations: smooth, then z = scale * h in
   * float, then the pyramid of z */
  bb_image filtered = {0}, z = {0};
  st = bb__smooth_bilateral(height, height, &o->smooth, threads, NULL, &filtered, err);
  if (st == BB_OK) st = bb_image_alloc(&z, filtered.width, filtered.height, 1, err);
  if (st == BB_OK) {
    const size_t n = (size_t)z.width * (size_t)z.height;
    for (size_t i = 0; i < n; i++) z.pixels[i] = o->height_scale * filtered.pixels[i];
  }
  bb_image_free(&filtered);
  if (st == BB_OK) st = bb__pyramid_build(&z, o->smooth.addressing, threads, pyramid, err);
  bb_image_free(&z);
  bb_rayset *rs = NULL;
  if (st == BB_OK && !(rs = calloc(1, sizeof *rs)))
    st = bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  if (st == BB_OK) st = bb__rayset_make(o->slices, o->power, &o->basis, threads, rs, err);
  if (st != BB_OK) {
    free(rs);
    bb_pyramid_free(*pyramid);
    *pyramid = NULL;
    return st;
  }
  *rays = rs;
  return BB_OK;
}
