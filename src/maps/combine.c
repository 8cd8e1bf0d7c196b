/* combine.c: blending two maps and overlaying a detail map, for ssbumps,
 * weights, ao and normal maps (docs/commands/combine.md defines the operators).
 *
 * Invariant: an identity input gives the base back bit for bit. A blend
 * factor of exactly 0 (or 1) copies a (or b); a detail texel equal to the
 * detail's flat texel (within FLAT_TOLERANCE) copies the base texel. Every other texel is computed
 * in double from its own inputs only. */

#include "bake/bake_internal.h"
#include "trace/basis.h"
#include "core/internal.h"
#include "maps/maps_internal.h"
#include <math.h>
#include <string.h>
#include <strings.h>

/* The channels combine's operators act on (bb_map_kind_info.file_channels:
 * 3, or 1 for ao), 0 for a kind combine does not work on. */
static int combine_channels(bb_map_kind kind) {
  switch (kind) {
  case BB_MAP_SSBUMP:
  case BB_MAP_WEIGHTS:
  case BB_MAP_AO:
  case BB_MAP_NORMAL:
    return bb_map_kind_get(kind)->file_channels;
  default:
    return 0;
  }
}

static bb_status check_kind(bb_map_kind kind, const char *what, bb_error *err) {
  if (combine_channels(kind))
    return BB_OK;
  return bb__fail(err, BB_ERR_ARGUMENT, "%s: map kind %s is not one of ssbump, weights, ao, normal",
                  what, bb__map_kind_name(kind));
}

/* The exact flat value of channel c, encoded as a file stores it (normals
 * as 0.5 + 0.5 N). */
static double flat_encoded(bb_map_kind kind, int c) {
  switch (kind) {
  case BB_MAP_SSBUMP:
    return 1.0 / sqrt(3.0);
  case BB_MAP_WEIGHTS:
    return 1.0 / 3.0;
  case BB_MAP_AO:
    return 1.0;
  case BB_MAP_NORMAL:
    return c == 2 ? 1.0 : 0.5;
  default:
    return 0.0;
  }
}

/* v as a half float holds it: 11 significant bits (values here are normal
 * halves, between 2^-14 and 65504). */
static double round_to_half(double v) {
  int e;
  double m = frexp(v, &e);
  return ldexp(floor(m * 2048.0 + 0.5) / 2048.0, e);
}

void bb__map_flat_texel(bb_map_kind kind, int bits_per_sample, int is_float,
                       float texel[3]) {
  for (int c = 0; c < combine_channels(kind); c++) {
    double v = flat_encoded(kind, c);
    if (is_float) {
      /* Float files store normals raw: N = 2 v - 1 of the encoded flat. */
      if (kind == BB_MAP_NORMAL)
        v = 2.0 * v - 1.0;
      v = bits_per_sample == 16 && v != 0.0 ? round_to_half(v) : (double)(float)v;
    } else {
      /* bb__image_write's rule (round half up), read back as code / max. */
      int bits = bits_per_sample >= 1 && bits_per_sample <= 32 ? bits_per_sample : 8;
      double max_code = ldexp(1.0, bits) - 1.0;
      v = floor(v * max_code + 0.5) / max_code;
      if (kind == BB_MAP_NORMAL)
        v = 2.0 * v - 1.0;
    }
    texel[c] = (float)v;
  }
}


const bb__range bb__range_mix = {"blend factor", 0.0, 1.0, 0, 0};

/* ------------------------------------------------------------------ blend */

static bb_status check_blend(const bb_image *a, const bb_image *b, const bb_image *mask,
                             float mix, bb_map_kind kind, bb_error *err) {
  const int need = combine_channels(kind);
  bb_status st = check_kind(kind, "blend", err);
  if (st == BB_OK)
    st = bb__check_channels(a, need, "first map", err);
  if (st == BB_OK)
    st = bb__check_channels(b, need, "second map", err);
  if (st == BB_OK)
    st = bb__check_same_size(a, "the first map", b, "the second map", err);
  if (st == BB_OK && kind != BB_MAP_NORMAL && a->channels != b->channels)
    st = bb__fail(err, BB_ERR_ARGUMENT,
                  "the first map has %d channels but the second has %d", a->channels,
                  b->channels);
  if (st == BB_OK && mask) {
    st = bb__check_channels(mask, 1, "mask", err);
    if (st == BB_OK)
      st = bb__check_same_size(a, "the first map", mask, "the mask", err);
    if (st == BB_OK)
      st = bb__check_finite(mask, 1, "mask", err);
  }
  if (st == BB_OK && !mask)
    st = bb__range_check(&bb__range_mix, (double)mix, NULL, err);
  if (st == BB_OK)
    st = bb__check_finite(a, a->channels, "first map", err);
  if (st == BB_OK)
    st = bb__check_finite(b, b->channels, "second map", err);
  return st;
}

static double blend_factor(const bb_image *mask, float mix, size_t i) {
  if (!mask)
    return (double)mix;
  double m = (double)mask->pixels[i * (size_t)mask->channels];
  return m < 0.0 ? 0.0 : (m > 1.0 ? 1.0 : m);
}

static void blend_linear_texel(const float *a, const float *b, double m, int channels,
                               float *out) {
  for (int c = 0; c < channels; c++)
    out[c] = (float)((1.0 - m) * (double)a[c] + m * (double)b[c]);
}

static void blend_normal_texel(const float *a, const float *b, double m, float *out) {
  if (m == 0.0 || m == 1.0) {
    memcpy(out, m == 0.0 ? a : b, 3 * sizeof(float));
    return;
  }
  double t[3];
  for (int k = 0; k < 3; k++)
    t[k] = (1.0 - m) * (double)a[k] + m * (double)b[k];
  bb__normalize3(t);
  for (int k = 0; k < 3; k++)
    out[k] = (float)t[k];
}

bb_status bb__combine_blend(const bb_image *a, const bb_image *b, const bb_image *mask,
                           float mix, bb_map_kind kind, bb_image *out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "blend: out is NULL");
  memset(out, 0, sizeof *out);
  bb_status st = check_blend(a, b, mask, mix, kind, err);
  const int channels = kind == BB_MAP_NORMAL ? 3 : a->channels;
  if (st == BB_OK)
    st = bb_image_alloc(out, a->width, a->height, channels, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)a->width * (size_t)a->height;
  for (size_t i = 0; i < n; i++) {
    const float *ta = a->pixels + i * (size_t)a->channels;
    const float *tb = b->pixels + i * (size_t)b->channels;
    float *to = out->pixels + i * (size_t)channels;
    double m = blend_factor(mask, mix, i);
    if (kind == BB_MAP_NORMAL)
      blend_normal_texel(ta, tb, m, to);
    else
      blend_linear_texel(ta, tb, m, channels, to);
  }
  return BB_OK;
}

/* ----------------------------------------------------------------- detail */

/* How close a detail texel must be to flat to count as flat: far below one
 * 16-bit code (1.5e-5), far above the float rounding by which two ways of
 * turning the same code into a float may differ. */
#define FLAT_TOLERANCE 1e-6

static bb_status check_detail(const bb_image *base, const bb_image *detail,
                              bb_map_kind kind, const float *flat, bb_error *err) {
  const int need = combine_channels(kind);
  bb_status st = check_kind(kind, "detail", err);
  if (st == BB_OK)
    st = bb__check_channels(base, need, "base", err);
  if (st == BB_OK)
    st = bb__check_channels(detail, need, "detail", err);
  if (st == BB_OK)
    st = bb__check_same_size(base, "the base", detail, "the detail", err);
  /* Only the kind's 3 channels are scaled and the rest copied, which would
   * leave a basis of more directions half overlaid. */
  if (st == BB_OK && need == 3 && kind != BB_MAP_NORMAL)
    st = bb__check_hl2_map(base, NULL, "detail: the base", err);
  if (st == BB_OK && need == 3 && kind != BB_MAP_NORMAL)
    st = bb__check_hl2_map(detail, NULL, "detail: the detail", err);
  if (st == BB_OK)
    st = bb__check_finite(base, base->channels, "base", err);
  if (st == BB_OK)
    st = bb__check_finite(detail, need, "detail", err);
  if (st == BB_OK && flat && kind != BB_MAP_NORMAL)
    for (int c = 0; c < need; c++)
      if (!(flat[c] > 0.0f) || !isfinite(flat[c]))
        return bb__fail(err, BB_ERR_ARGUMENT,
                        "detail: flat value %g of channel %d is not > 0", (double)flat[c],
                        c);
  return st;
}

static void detail_linear_texel(const float *base, const float *detail, const float *flat,
                                int kind_channels, int channels, float *out) {
  memcpy(out, base, (size_t)channels * sizeof(float));
  for (int c = 0; c < kind_channels; c++) {
    double ratio = (double)detail[c] / (double)flat[c];
    if (fabs(ratio - 1.0) <= FLAT_TOLERANCE)
      continue; /* a flat detail texel: the base's value stays as it is */
    out[c] = (float)((double)base[c] * ratio);
  }
}

static void detail_normal_texel(const float *base, const float *detail, const float *flat,
                                int channels, float *out) {
  memcpy(out, base, (size_t)channels * sizeof(float));
  double dx = (double)detail[0] - (double)flat[0];
  double dy = (double)detail[1] - (double)flat[1];
  if (fabs(dx) <= FLAT_TOLERANCE && fabs(dy) <= FLAT_TOLERANCE)
    return; /* adding nothing leaves the base as it is */
  double n[3] = {base[0], base[1], base[2]}, sum[3];
  bb__add_normals(n, dx, dy, sum);
  for (int k = 0; k < 3; k++)
    out[k] = (float)sum[k];
}

bb_status bb__combine_detail(const bb_image *base, const bb_image *detail,
                            bb_map_kind kind, const float *flat, bb_image *out,
                            bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "detail: out is NULL");
  memset(out, 0, sizeof *out);
  bb_status st = check_detail(base, detail, kind, flat, err);
  if (st == BB_OK)
    st = bb_image_alloc(out, base->width, base->height, base->channels, err);
  if (st != BB_OK)
    return st;
  float exact[3];
  bb__map_flat_texel(kind, 32, 1, exact);
  if (!flat)
    flat = exact;
  const int need = combine_channels(kind), channels = base->channels;
  const size_t n = (size_t)base->width * (size_t)base->height;
  for (size_t i = 0; i < n; i++) {
    const float *tb = base->pixels + i * (size_t)channels;
    const float *td = detail->pixels + i * (size_t)detail->channels;
    float *to = out->pixels + i * (size_t)channels;
    if (kind == BB_MAP_NORMAL)
      detail_normal_texel(tb, td, flat, channels, to);
    else
      detail_linear_texel(tb, td, flat, need, channels, to);
  }
  return BB_OK;
}

/* --------------------------------------------------------- brightness */

bb_status bb__combine_brightness(const bb_image *map, const bb_image *brightness,
                                bb_map_kind kind, bb_image *out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "brightness: out is NULL");
  memset(out, 0, sizeof *out);
  if (kind == BB_MAP_NORMAL)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "brightness: a normal map has no room for a brightness (unit vectors); "
                    "give it to the ssbump or the weights");
  if (!combine_channels(kind))
    return check_kind(kind, "brightness", err);
  const int need = combine_channels(kind);
  bb_status st = bb__check_channels(map, need, "brightness: the map", err);
  if (st == BB_OK && need == 3) st = bb__check_hl2_map(map, NULL, "brightness: the map", err);
  if (st == BB_OK) st = bb__check_finite(map, map->channels, "brightness: the map", err);
  if (st == BB_OK && (!brightness || !brightness->pixels))
    st = bb__fail(err, BB_ERR_ARGUMENT, "brightness: missing brightness map");
  if (st == BB_OK)
    st = bb__derive_brightness(map, need, brightness, "brightness", 0, out, err);
  return st;
}
