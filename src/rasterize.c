/* rasterize.c: a depth-tested, edge-function rasteriser of triangles into a
 * band of samples, the CPU stand-in for DOOM 3's OpenGL pass.
 *
 * Invariant: a sample's result depends only on the triangles drawn into its
 * band and their order, never on how rows are split into bands or threads.
 * Every sample is tested on its own (no incremental stepping), in double,
 * with edge functions that give bit-exact opposite values for the two
 * triangles sharing an edge, so watertight meshes leave no cracks.
 */
#include "rasterize.h"

#include <math.h>

/* The edge function of the directed edge a -> b at p: twice the signed area
 * of (a, b, p), whose sign says which side of the line ab p lies on. It is
 * always computed from the lexicographically smaller endpoint, so the two
 * directions of an edge give exactly opposite values. */
static double edge(double ua, double va, double ub, double vb, double pu, double pv) {
  if (ua > ub || (ua == ub && va > vb))
    return -((ua - ub) * (pv - vb) - (va - vb) * (pu - ub));
  return (ub - ua) * (pv - va) - (vb - va) * (pu - ua);
}

/* Twice the signed area of t, by the same edge function (edge 0 -> 1 seen
 * from vertex 2), so the weights below sum to one up to rounding. */
static double area2(const bb__raster_tri *t) {
  return edge(t->u[0], t->v[0], t->u[1], t->v[1], t->u[2], t->v[2]);
}

/* The three edge functions at (u, v), each opposite its vertex and scaled by
 * the sign of the area, so all three are >= 0 inside. */
static void edges_at(const bb__raster_tri *t, double sign, double u, double v, double e[3]) {
  e[0] = sign * edge(t->u[1], t->v[1], t->u[2], t->v[2], u, v);
  e[1] = sign * edge(t->u[2], t->v[2], t->u[0], t->v[0], u, v);
  e[2] = sign * edge(t->u[0], t->v[0], t->u[1], t->v[1], u, v);
}

int bb__raster_weights(const bb__raster_tri *t, double u, double v, double w[3]) {
  double a = area2(t);
  if (a == 0.0 || !isfinite(a))
    return 0;
  double e[3];
  edges_at(t, 1.0, u, v, e);
  for (int k = 0; k < 3; k++)
    w[k] = e[k] / a;
  return 1;
}

static double min3(const double x[3]) {
  return fmin(x[0], fmin(x[1], x[2]));
}

static double max3(const double x[3]) {
  return fmax(x[0], fmax(x[1], x[2]));
}

/* First and last sample index i whose centre (i + 0.5) / n lies in [lo, hi],
 * clipped to 0 .. count-1; *last < *first when there is none. */
static void sample_span(double lo, double hi, int n, int count, int *first, int *last) {
  double f = ceil(lo * n - 0.5), l = floor(hi * n - 0.5);
  *first = f < 0.0 ? 0 : (f > count ? count : (int)f);
  *last = l >= count ? count - 1 : (l < -1.0 ? -1 : (int)l);
}

void bb__band_draw(bb__sample_band *band, const bb__raster_tri *t, int32_t id) {
  const double a = area2(t);
  if (a == 0.0 || !isfinite(a))
    return;
  const double sign = a > 0.0 ? 1.0 : -1.0, abs_area = fabs(a);
  const int n = band->per_texel;
  int i0, i1, j0, j1;
  sample_span(min3(t->u), max3(t->u), n, band->columns, &i0, &i1);
  sample_span(min3(t->v), max3(t->v), n, band->first_row + band->rows, &j0, &j1);
  if (j0 < band->first_row)
    j0 = band->first_row;
  for (int j = j0; j <= j1; j++) {
    const double v = (j + 0.5) / n;
    const long row = (long)(j - band->first_row) * band->columns;
    for (int i = i0; i <= i1; i++) {
      const double u = (i + 0.5) / n;
      double e[3];
      edges_at(t, sign, u, v, e);
      if (e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0)
        continue;
      const double d = (e[0] * t->d[0] + e[1] * t->d[1] + e[2] * t->d[2]) / abs_area;
      const long k = row + i;
      if (band->winner[k] < 0 || d > band->depth[k]) {
        band->winner[k] = id;
        band->depth[k] = d;
      }
    }
  }
}
