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
 * clipped to 0 .. count-1; *last < *first when there is none. The
 * estimates from lo * n and hi * n round, and are one off when a centre
 * lies on lo or hi (a vertex on a sample): they are stepped until the
 * centre, computed as the drawing computes it, agrees. */
static void sample_span(double lo, double hi, int n, int count, int *first, int *last) {
  double f = ceil(lo * n - 0.5), l = floor(hi * n - 0.5);
  int i = f < 0.0 ? 0 : (f > count ? count : (int)f);
  while (i > 0 && ((i - 1) + 0.5) / n >= lo)
    i--;
  while (i < count && !((i + 0.5) / n >= lo))
    i++;
  int j = l >= count ? count - 1 : (l < -1.0 ? -1 : (int)l);
  while (j < count - 1 && ((j + 1) + 0.5) / n <= hi)
    j++;
  while (j >= 0 && !((j + 0.5) / n <= hi))
    j--;
  *first = i, *last = j;
}

void bb__raster_box(const bb__sample_band *band, const bb__raster_setup *s, int *i0,
                    int *i1, int *j0, int *j1) {
  const int n = band->per_texel;
  sample_span(s->box[0], s->box[2], n, band->columns, i0, i1);
  sample_span(s->box[1], s->box[3], n, band->first_row + band->rows, j0, j1);
  if (*j0 < band->first_row)
    *j0 = band->first_row;
}

/* Narrows [*lo, *hi] to the columns where edge (a, row) is >= 0: from the
 * crossing's estimate, then stepped until the very test the drawing loop
 * makes agrees, so the run is exact and costs O(1), not a scan of the row. */
static void clip_to_edge(double a, double row, int n, int *lo, int *hi) {
  if (*lo > *hi)
    return;
  if (a == 0.0) { /* the edge runs along the row: all or nothing */
    if (!(row >= 0.0))
      *hi = *lo - 1;
    return;
  }
  /* The column whose centre is nearest the crossing u = -row / a, kept
   * within the run as a double before it becomes an int. */
  double x = (-row / a) * n - 0.5;
  int c = !(x >= *lo) ? *lo : (!(x <= *hi) ? *hi : (int)x);
  if (a > 0.0) { /* inside from the crossing rightwards: find the first inside column */
    while (c > *lo && bb__raster_edge(a, row, c - 1, n) >= 0.0)
      c--;
    while (c <= *hi && !(bb__raster_edge(a, row, c, n) >= 0.0))
      c++;
    *lo = c;
  } else { /* inside leftwards: find the last inside column */
    while (c < *hi && bb__raster_edge(a, row, c + 1, n) >= 0.0)
      c++;
    while (c >= *lo && !(bb__raster_edge(a, row, c, n) >= 0.0))
      c--;
    *hi = c;
  }
}

void bb__band_draw(bb__sample_band *band, const bb__raster_setup *s, int32_t id) {
  const int n = band->per_texel;
  int i0, i1, j0, j1;
  bb__raster_box(band, s, &i0, &i1, &j0, &j1);
  for (int j = j0; j <= j1; j++) {
    const bb__raster_row r = bb__raster_row_at(band, s, j);
    /* Only the columns the triangle covers in this row are visited: its
     * cost is what it draws plus a few tests per row, not its box. */
    int lo = i0, hi = i1;
    clip_to_edge(s->a[0], r.term[0], n, &lo, &hi);
    clip_to_edge(s->a[1], r.term[1], n, &lo, &hi);
    clip_to_edge(s->a[2], r.term[2], n, &lo, &hi);
    for (int i = lo; i <= hi; i++)
      bb__raster_sample(s, &r, i, n, id);
  }
}
