/* maps_common.c: checks and vector helpers the map conversions share. */

#include "core/internal.h"
#include "maps/maps_internal.h"
#include <math.h>

bb_status bb__check_channels(const bb_image *img, int min_channels, const char *what,
                             bb_error *err) {
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: missing or empty image", what);
  if (img->channels < min_channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s has %d channel%s, needs %d or more", what,
                    img->channels, img->channels == 1 ? "" : "s", min_channels);
  return BB_OK;
}

bb_status bb__check_finite(const bb_image *img, int channels, const char *what,
                           bb_error *err) {
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++) {
      const float *t = bb_image_texel(img, x, y);
      for (int c = 0; c < channels; c++)
        if (!isfinite(t[c]))
          return bb__fail(err, BB_ERR_VALUE, "%s: texel (%d, %d) channel %d is %s", what,
                          x, y, c, isnan(t[c]) ? "NaN" : "infinite");
    }
  return BB_OK;
}

bb_status bb__check_same_size(const bb_image *a, const char *name_a, const bb_image *b,
                              const char *name_b, bb_error *err) {
  if (a->width != b->width || a->height != b->height)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s is %dx%d but %s is %dx%d", name_a, a->width,
                    a->height, name_b, b->width, b->height);
  return BB_OK;
}

void bb__normalize3(double v[3]) {
  double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(len > 0.0) || !isfinite(len)) {
    v[0] = 0.0, v[1] = 0.0, v[2] = 1.0;
    return;
  }
  for (int k = 0; k < 3; k++)
    v[k] /= len;
}

void bb__add_normals(const double base[3], double dx, double dy, double out[3]) {
  out[0] = base[0], out[1] = base[1], out[2] = base[2];
  double len2 = out[0] * out[0] + out[1] * out[1] + out[2] * out[2];
  if (len2 < 1.0) {
    /* id's repair for maps that blend to (0, 0, 0) at their edges; the max
     * keeps a texel with x^2 + y^2 > 1 from taking the root of a negative. */
    double zz = 1.0 - out[0] * out[0] - out[1] * out[1];
    out[2] = sqrt(zz > 0.0 ? zz : 0.0);
  }
  out[0] += dx;
  out[1] += dy;
  bb__normalize3(out);
}
