/* convert.c: normal maps decoded from file values (normal2ssbump's input)
 * and basis maps turned back into normals (ssbump2normal). */

#include "trace/basis.h"
#include "core/internal.h"
#include "bake/bake_internal.h"
#include "maps/maps_internal.h"
#include <math.h>
#include <string.h>

bb_status bb_normal_map_decode(const bb_image *values, int is_float, int normal_y_up,
                               int normalize, bb_image *normals, bb_error *err) {
  if (!normals)
    return bb__fail(err, BB_ERR_ARGUMENT, "normal map decode: normals is NULL");
  memset(normals, 0, sizeof *normals);
  bb_status st = bb__check_channels(values, 3, "normal map", err);
  if (st == BB_OK)
    st = bb__check_finite(values, 3, "normal map", err);
  if (st == BB_OK)
    st = bb_image_alloc(normals, values->width, values->height, 3, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)values->width * (size_t)values->height;
  const size_t stride = (size_t)values->channels;
  for (size_t i = 0; i < n; i++) {
    const float *v = values->pixels + i * stride;
    double N[3];
    for (int k = 0; k < 3; k++)
      N[k] = is_float ? (double)v[k] : 2.0 * (double)v[k] - 1.0;
    if (normal_y_up)
      N[1] = -N[1];
    if (normalize)
      bb__normalize3(N);
    for (int k = 0; k < 3; k++)
      normals->pixels[3 * i + (size_t)k] = (float)N[k];
  }
  return BB_OK;
}

bb_status bb__ssbump_to_normal(const bb_image *ssbump, bb_map_kind kind,
                              bb_image *normals, bb_error *err) {
  if (!normals)
    return bb__fail(err, BB_ERR_ARGUMENT, "ssbump to normal: normals is NULL");
  memset(normals, 0, sizeof *normals);
  if (kind != BB_MAP_SSBUMP && kind != BB_MAP_WEIGHTS)
    return bb__fail(err, BB_ERR_ARGUMENT, "ssbump to normal: unknown kind %d", (int)kind);
  bb_status st = bb__check_channels(ssbump, 3, "ssbump", err);
  if (st == BB_OK)
    st = bb__check_hl2_map(ssbump, NULL, "ssbump", err);
  if (st == BB_OK)
    st = bb__check_finite(ssbump, 3, "ssbump", err);
  /* The three basis channels alone: bb__derive_bent_all_cores would read a fourth
   * (Valve's alpha height) as the weight of B3. */
  bb_image weights = {0};
  if (st == BB_OK)
    st = bb_image_alloc(&weights, ssbump->width, ssbump->height, 3, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)ssbump->width * (size_t)ssbump->height;
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) {
      float s = ssbump->pixels[i * (size_t)ssbump->channels + (size_t)c];
      if (kind == BB_MAP_WEIGHTS)
        s = sqrtf(s > 0.0f ? s : 0.0f);
      weights.pixels[3 * i + (size_t)c] = s;
    }
  st = bb__derive_bent_all_cores(&weights, NULL, normals, err);
  bb_image_free(&weights);
  return st;
}
