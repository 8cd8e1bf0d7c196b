/* rasterize.c: a depth-tested, edge-function rasteriser of triangles into a
 * band of samples, the CPU stand-in for DOOM 3's OpenGL pass.
 *
 * Invariant: a sample's result depends only on the triangles drawn into its
 * band and their order, never on how rows are split into bands or threads.
 * Every sample's edge values are evaluated from the same per-edge
 * coefficients and per-row terms, whatever triangle or box it is reached
 * from (no stepping that accumulates), in double; shared edges give exactly
 * opposite values, so watertight meshes leave no cracks.
 */
#include "mesh/rasterize.h"

#include <math.h>

/* Coefficients of the edge function of the directed edge p -> q,
 * e(u, v) = (uq - up)(v - vp) - (vq - vp)(u - up), written a u + b v + c.
 * They are computed for the lexicographically smaller endpoint first and
 * negated (exactly) for the other direction. */
static void edge_coefficients(double up, double vp, double uq, double vq, double abc[3]) {
  int swap = up > uq || (up == uq && vp > vq);
  if (swap) {
    double t = up;
    up = uq, uq = t;
    t = vp;
    vp = vq, vq = t;
  }
  abc[0] = vp - vq;
  abc[1] = uq - up;
  abc[2] = (vq - vp) * up - (uq - up) * vp;
  if (swap)
    for (int k = 0; k < 3; k++)
      abc[k] = -abc[k];
}

int bb__raster_setup_make(const bb__raster_tri *t, bb__raster_setup *s) {
  for (int k = 0; k < 3; k++) {
    /* edge k runs between the two other vertices, k+1 -> k+2 */
    int p = (k + 1) % 3, q = (k + 2) % 3;
    double abc[3];
    edge_coefficients(t->u[p], t->v[p], t->u[q], t->v[q], abc);
    s->a[k] = abc[0], s->b[k] = abc[1], s->c[k] = abc[2];
  }
  /* Edge 0 at vertex 0 is twice the signed area. */
  double area2 = s->a[0] * t->u[0] + s->b[0] * t->v[0] + s->c[0];
  if (area2 == 0.0 || !isfinite(area2))
    return 0;
  if (area2 < 0.0) {
    area2 = -area2;
    for (int k = 0; k < 3; k++)
      s->a[k] = -s->a[k], s->b[k] = -s->b[k], s->c[k] = -s->c[k];
  }
  s->inv_area = 1.0 / area2;
  for (int k = 0; k < 3; k++)
    s->d[k] = t->d[k];
  s->box[0] = fmin(t->u[0], fmin(t->u[1], t->u[2]));
  s->box[1] = fmin(t->v[0], fmin(t->v[1], t->v[2]));
  s->box[2] = fmax(t->u[0], fmax(t->u[1], t->u[2]));
  s->box[3] = fmax(t->v[0], fmax(t->v[1], t->v[2]));
  return 1;
}

void bb__raster_weights(const bb__raster_setup *s, double u, double v, double w[3]) {
  for (int k = 0; k < 3; k++)
    w[k] = (s->a[k] * u + (s->b[k] * v + s->c[k])) * s->inv_area;
}

/* First and last sample index i whose centre (i + 0.5) / n lies in [lo, hi],
 * clipped to 0 .. count-1; *last < *first when there is none. */
static void sample_span(double lo, double hi, int n, int count, int *first, int *last) {
  double f = ceil(lo * n - 0.5), l = floor(hi * n - 0.5);
  *first = f < 0.0 ? 0 : (f > count ? count : (int)f);
  *last = l >= count ? count - 1 : (l < -1.0 ? -1 : (int)l);
}

void bb__band_draw(bb__sample_band *band, const bb__raster_setup *s, int32_t id) {
  const int n = band->per_texel;
  int i0, i1, j0, j1;
  sample_span(s->box[0], s->box[2], n, band->columns, &i0, &i1);
  sample_span(s->box[1], s->box[3], n, band->first_row + band->rows, &j0, &j1);
  if (j0 < band->first_row)
    j0 = band->first_row;
  for (int j = j0; j <= j1; j++) {
    const double v = (j + 0.5) / n;
    const double row0 = s->b[0] * v + s->c[0], row1 = s->b[1] * v + s->c[1],
                 row2 = s->b[2] * v + s->c[2];
    double *depth = band->depth + (long)(j - band->first_row) * band->columns;
    int32_t *winner = band->winner + (long)(j - band->first_row) * band->columns;
    for (int i = i0; i <= i1; i++) {
      const double u = (i + 0.5) / n;
      const double e0 = s->a[0] * u + row0, e1 = s->a[1] * u + row1, e2 = s->a[2] * u + row2;
      if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0)
        continue;
      const double d = (e0 * s->d[0] + e1 * s->d[1] + e2 * s->d[2]) * s->inv_area;
      if (winner[i] < 0 || d > depth[i]) {
        winner[i] = id;
        depth[i] = d;
      }
    }
  }
}
