/* scaled_height.c: the check every bake makes of its height before a stage
 * runs: height scale times height stays well inside the float range. */

#include "bake/bake_internal.h"
#include "core/internal.h"

#include <math.h>

bb_status bb__check_scaled_height(const bb_image *height, float height_scale,
                                  bb_error *err) {
  for (int y = 0; y < height->height; y++) {
    const float *row = bb_image_texel(height, 0, y);
    for (int x = 0; x < height->width; x++) {
      double h = (double)row[(size_t)x * (size_t)height->channels];
      double z = (double)height_scale * h;
      if (!(fabs(z) <= BB_MAX_HEIGHT_TEXELS))
        return bb__fail(err, BB_ERR_VALUE,
                        "height scale %g times the height %g at texel (%d, %d) is %g "
                        "texels, over the limit of %g (scaled heights must stay well "
                        "inside the float range)",
                        (double)height_scale, h, x, y, z, BB_MAX_HEIGHT_TEXELS);
    }
  }
  return BB_OK;
}
