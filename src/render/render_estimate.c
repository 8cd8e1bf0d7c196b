/* render_estimate.c: what a render will make and take, from sizes alone,
 * before anything is read or allocated: the picture (the maps' size times
 * the tiles, then the crop) checked against the limits, and its memory at
 * the peak checked against what is available, as bakes are. A 59 KB normal
 * map of 4096 x 4096 tiled 8 times is a 32768 x 32768 picture of 12 GiB
 * before it is encoded. */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "image/formats.h"
#include "render/render_internal.h"

#include <stdio.h>

/* Bytes of one 3-float texel of a picture. */
#define PICTURE_TEXEL 12.0

bb_status bb__render_estimate(int width, int height, const bb_render_options *o, int compare,
                             const char *output, bb_depth depth, int *picture_width,
                             int *picture_height, double *bytes, bb_error *err) {
  if (picture_width)
    *picture_width = 0;
  if (picture_height)
    *picture_height = 0;
  if (bytes)
    *bytes = 0.0;
  if (!o || width <= 0 || height <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "render estimate: bad arguments");
  const int tx = o->tile_x > 1 ? o->tile_x : 1, ty = o->tile_y > 1 ? o->tile_y : 1;
  const long long w = (long long)width * tx, h = (long long)height * ty;
  if (w > BB_MAX_DIMENSION || h > BB_MAX_DIMENSION || w * h > BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_SIZE,
                    "tiles %dx%d make a %lldx%lld picture, over the maximum (%ld texels)", tx,
                    ty, w, h, (long)BB_MAX_PIXELS);
  if (o->crop_width > 0 && (o->crop_x < 0 || o->crop_y < 0 ||
                            (long long)o->crop_x + o->crop_width > w ||
                            (long long)o->crop_y + o->crop_height > h))
    return bb__fail(err, BB_ERR_ARGUMENT, "the crop %d,%d,%d,%d is not inside the %lldx%lld picture",
                    o->crop_x, o->crop_y, o->crop_width, o->crop_height, w, h);
  const double maps = (double)width * height, tiled = (double)w * (double)h;
  const double final = o->crop_width > 0 ? (double)o->crop_width * o->crop_height : tiled;
  /* One picture: straight down it is rendered at the maps' size, then tiled
   * (both alive), then cropped (both alive); with a view it is rendered at
   * the tiled size, then cropped. */
  double one;
  if (o->view)
    one = tiled + (o->crop_width > 0 ? final : 0.0);
  else {
    const double tiling = tx * ty > 1 ? maps + tiled : maps;
    const double cropping = (tx * ty > 1 ? tiled : maps) + (o->crop_width > 0 ? final : 0.0);
    one = tiling > cropping ? tiling : cropping;
  }
  /* The comparison: its four pictures, then their grid (a little more than
   * four pictures, with gaps and labels) and a panel resampled into it. */
  double written = final, during = one;
  if (compare) {
    written = 4.5 * final;
    const double all = 3.0 * final + one, grid = 4.0 * final + written + final;
    during = all > grid ? all : grid;
  }
  /* The encoder's copy of what is written, at the output's sample size
   * (none without an output: the picture alone, as bb__render makes it). */
  const double sample = output ? bb__encoded_sample_bytes(output, depth) : 0.0;
  const double encode = written * PICTURE_TEXEL + written * 3.0 * sample;
  const double peak = during * PICTURE_TEXEL > encode ? during * PICTURE_TEXEL : encode;
  if (picture_width)
    *picture_width = (int)(o->crop_width > 0 ? o->crop_width : w);
  if (picture_height)
    *picture_height = (int)(o->crop_width > 0 ? o->crop_height : h);
  if (bytes)
    *bytes = peak;
  return BB_OK;
}

/* Bytes a map file read for a render holds (its samples as floats, and a
 * normal or bent map's decoded copy while it is made) and keeps. */
static void map_bytes(double texels, int channels, int decoded, double *peak, double *kept) {
  const double raw = texels * channels * 4.0, vectors = texels * 3 * 4.0;
  /* the file's own samples (up to 4 bytes each) while they are converted */
  const double reading = raw + texels * channels * 4.0;
  *peak = decoded ? (reading > raw + vectors ? reading : raw + vectors) : reading;
  *kept = decoded ? vectors : raw;
}

/* A header over the read's own limits (BB_MAX_PIXELS, BB_MAX_READ_BYTES):
 * the read refuses it as a file too large, not a lack of memory. */
static int over_read_limits(double texels, int channels) {
  const double cap = BB_MAX_READ_BYTES > BB_MAX_READ_BYTES_PER_TEXEL * texels
                         ? (double)BB_MAX_READ_BYTES
                         : BB_MAX_READ_BYTES_PER_TEXEL * texels;
  return texels > (double)BB_MAX_PIXELS || channels * 4.0 * texels > cap;
}

bb_status bb__render_files_need(const bb_render_sources *files,
                                const bb_bake_options *bake, const bb_render_options *o,
                                int compare, const char *output, bb_depth depth,
                                int *width, int *height, double *need, const char **named,
                                char *what, size_t what_cap, bb_error *err) {
  *need = 0.0;
  *named = NULL;
  if (what_cap)
    what[0] = '\0';
  if (width)
    *width = 0;
  if (height)
    *height = 0;
  if (!files || !o)
    return bb__fail(err, BB_ERR_ARGUMENT, "render files check: bad arguments");
  int w = 0, h = 0;
  const char *first = NULL;
  double kept = 0.0, reading = 0.0;
  /* Each file's header, in the order they are read; every map of one size. */
  for (int m = 0; m <= BB_MAP_KIND_COUNT; m++) {
    const char *path = m < BB_MAP_KIND_COUNT ? files->maps[m] : files->height;
    if (!path)
      continue;
    int fw = 0, fh = 0, channels = 0;
    bb_status st = bb_image_read_info(path, &fw, &fh, &channels, NULL, err);
    if (st != BB_OK)
      return st;
    if (first && (fw != w || fh != h))
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: %dx%d, but the other maps are %dx%d", path,
                      fw, fh, w, h);
    if (!first) {
      first = path, w = fw, h = fh;
      if (width)
        *width = w;
      if (height)
        *height = h;
    }
    const double texels = (double)fw * fh;
    if (over_read_limits(texels, channels))
      return BB_OK; /* the read refuses it, as a file too large */
    double peak, keeps;
    if (m == BB_MAP_KIND_COUNT) {
      /* a height baked first: its read (the channels its rule needs, then
       * the height), then the bake, whose result the picture is lit from */
      const double read = ((channels < 4 ? channels : 4) + 1) * 4.0 * texels;
      double maps = 0.0;
      const double baked = bake ? bb__bake_memory(fw, fh, bake, 0, 4.0 * texels, &maps) : 0.0;
      peak = read > baked ? read : baked;
      keeps = 4.0 * texels + maps; /* the height, and the maps the picture is lit from */
    } else {
      map_bytes(texels, channels, bb_map_kind_get((bb_map_kind)m)->unit_vectors, &peak,
                &keeps);
    }
    if (kept + peak > reading)
      reading = kept + peak;
    kept += keeps;
  }
  if (!first)
    return bb__fail(err, BB_ERR_ARGUMENT, "render files check: no map or height to read");
  if (files->albedo) {
    int aw = 0, ah = 0, channels = 0;
    bb_status st = bb_image_read_info(files->albedo, &aw, &ah, &channels, NULL, err);
    if (st != BB_OK)
      return st;
    if (over_read_limits((double)aw * ah, channels))
      return BB_OK;
    double peak, keeps;
    map_bytes((double)aw * ah, channels, 0, &peak, &keeps);
    if (kept + peak > reading)
      reading = kept + peak;
    kept += keeps;
  }
  int pw = 0, ph = 0;
  double picture = 0.0;
  bb_status st = bb__render_estimate(w, h, o, compare, output, depth, &pw, &ph, &picture, err);
  if (st != BB_OK)
    return st;
  *need =
      (reading > kept + picture ? reading : kept + picture) * 1.05 + 32.0 * 1024 * 1024;
  *named = output ? output : first;
  snprintf(what, what_cap, "a %d x %d render", pw, ph);
  return BB_OK;
}

bb_status bb__render_files_check(const bb_render_sources *files,
                                const bb_bake_options *bake, const bb_render_options *o,
                                int compare, const char *output, bb_depth depth,
                                int *width, int *height, bb_error *err) {
  double need = 0.0;
  const char *path = NULL;
  char what[128], named[4200];
  bb_status st = bb__render_files_need(files, bake, o, compare, output, depth, width,
                                       height, &need, &path, what, sizeof what, err);
  if (st != BB_OK || need <= 0.0)
    return st;
  snprintf(named, sizeof named, "%s: %s", path, what);
  return bb__memory_check(need, named, err);
}
