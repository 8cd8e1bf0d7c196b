/* vector.c: unit vectors, for normals (core/internal.h). */

#include "core/internal.h"

#include <math.h>

void bb__normalize3(double v[3]) {
  double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(len > 0.0) || !isfinite(len)) {
    v[0] = 0.0, v[1] = 0.0, v[2] = 1.0;
    return;
  }
  for (int k = 0; k < 3; k++)
    v[k] /= len;
}
