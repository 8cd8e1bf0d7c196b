/* valve.c: the RGBA files of Valve's height2ssbump (docs/conventions.md "Valve
 * compatibility"): RGB = ssbump or the encoded normal map, A = the filtered
 * height or ao, and the detail variant's colour factor. */

#include "trace/basis.h"
#include "core/internal.h"
#include "bake/bake_internal.h"
#include "maps/maps_internal.h"
#include <math.h>
#include <string.h>

void bb__valve_options_init(bb_valve_options *o) {
  memset(o, 0, sizeof *o);
}

static int same_size(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height;
}

/* An input the packing needs: made (pixels) and with enough channels. */
static bb_status check_part(const bb_image *img, const char *what, int channels,
                            bb_error *err) {
  if (!img->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "valve pack: the bake has no %s (ssbump and ao need a traced bake)",
                    what);
  if (img->channels < channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "valve pack: %s has %d channel%s, needs %d",
                    what, img->channels, img->channels == 1 ? "" : "s", channels);
  return BB_OK;
}

bb_status bb__valve_pack(const bb_bake_result *result, const bb_valve_options *o,
                        bb_image *out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "valve pack: out is NULL");
  memset(out, 0, sizeof *out);
  if (!result || !o)
    return bb__fail(err, BB_ERR_ARGUMENT, "valve pack: result or options is NULL");
  const bb_image *rgb = o->normal_map ? &result->normal : &result->ssbump;
  const bb_image *alpha = o->ao_in_alpha ? &result->ao : &result->filtered;
  bb_status st = check_part(rgb, o->normal_map ? "normal map" : "ssbump", 3, err);
  if (st == BB_OK && !o->normal_map) /* a hand-made result has a zeroed basis */
    st = bb__check_hl2_map(rgb, result->basis.count ? &result->basis : NULL,
                           "valve pack: the ssbump", err);
  if (st == BB_OK)
    st = check_part(alpha, o->ao_in_alpha ? "ao" : "filtered height", 1, err);
  if (st != BB_OK)
    return st;
  if (!same_size(rgb, alpha))
    return bb__fail(err, BB_ERR_SIZE, "valve pack: RGB is %dx%d, alpha %dx%d", rgb->width,
                    rgb->height, alpha->width, alpha->height);
  st = bb_image_alloc(out, rgb->width, rgb->height, 4, err);
  if (st != BB_OK)
    return st;
  const size_t texels = (size_t)rgb->width * (size_t)rgb->height;
  for (size_t i = 0; i < texels; i++) {
    const float *src = rgb->pixels + i * (size_t)rgb->channels;
    float *dst = out->pixels + i * 4;
    /* The normal shares a unit-range file with a height in alpha, so it is
     * encoded here rather than by BB_RANGE_SIGNED (which would encode the
     * alpha too). */
    for (int c = 0; c < 3; c++)
      dst[c] = o->normal_map ? 0.5f + 0.5f * src[c] : src[c];
    dst[3] = alpha->pixels[i * (size_t)alpha->channels];
  }
  return BB_OK;
}

/* The RGB of colour (grey replicated, alpha dropped), as a 3-channel image. */
static bb_status colour_rgb(const bb_image *colour, bb_image *rgb, bb_error *err) {
  bb_status st = bb_image_alloc(rgb, colour->width, colour->height, 3, err);
  if (st != BB_OK)
    return st;
  /* With 3+ channels R, G, B are the first three; with 1 or 2 (grey,
   * grey + alpha) grey is channel 0. */
  const int colour_channels = colour->channels >= 3 ? 3 : 1;
  const size_t texels = (size_t)colour->width * (size_t)colour->height;
  for (size_t i = 0; i < texels; i++)
    for (int c = 0; c < 3; c++)
      rgb->pixels[i * 3 + (size_t)c] =
          colour->pixels[i * (size_t)colour->channels +
                         (size_t)(c < colour_channels ? c : 0)];
  return BB_OK;
}

static bb_status check_detail_inputs(const bb_image *rgba, const bb_image *colour,
                                     const bb_image *height,
                                     const bb_smooth_options *smooth, bb_error *err) {
  if (!rgba || !colour || !height || !smooth || !rgba->pixels || !colour->pixels ||
      !height->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "valve detail: an image or the options is NULL");
  if (rgba->channels != 4 || height->channels != 1 || colour->channels < 1)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "valve detail: needs 4-channel RGBA and a 1-channel height (got %d "
                    "and %d)",
                    rgba->channels, height->channels);
  if (!same_size(rgba, colour) || !same_size(rgba, height))
    return bb__fail(err, BB_ERR_SIZE,
                    "valve detail: sizes differ: RGBA %dx%d, colour %dx%d, height %dx%d",
                    rgba->width, rgba->height, colour->width, colour->height,
                    height->width, height->height);
  return BB_OK;
}

bb_status bb__valve_detail(bb_image *rgba, const bb_image *colour, const bb_image *height,
                          const bb_smooth_options *smooth, bb_error *err) {
  bb_status st = check_detail_inputs(rgba, colour, height, smooth, err);
  if (st != BB_OK)
    return st;
  bb_image rgb = {0}, smoothed = {0};
  st = colour_rgb(colour, &rgb, err);
  if (st == BB_OK)
    st = bb__smooth_bilateral_all_cores(&rgb, height, smooth, &smoothed, err);
  if (st == BB_OK) {
    const size_t texels = (size_t)rgba->width * (size_t)rgba->height;
    const float inv_sqrt3 = (float)(1.0 / sqrt(3.0));
    for (size_t i = 0; i < texels; i++) {
      const float *c = smoothed.pixels + i * 3;
      const float factor = (c[0] + c[1] + c[2]) * inv_sqrt3;
      for (int k = 0; k < 3; k++)
        rgba->pixels[i * 4 + (size_t)k] *= factor;
    }
  }
  bb_image_free(&rgb);
  bb_image_free(&smoothed);
  return st;
}
