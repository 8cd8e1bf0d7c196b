/* maps_common.c: what the map conversions share beyond core's image checks:
 * DOOM 3's addnormals. */

#include "core/internal.h"
#include "maps/maps_internal.h"
#include <math.h>

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
