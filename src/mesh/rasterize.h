/* rasterize.h: the front-most triangle at each sample of a band of image
 * rows, for the flat render bump (internal to bumpbake). */
#ifndef BB_RASTERIZE_H
#define BB_RASTERIZE_H

#include <stdint.h>

/* A triangle in image space: u to the right and v down, in texels; d is the
 * height towards the viewer (larger is nearer), in any unit. */
typedef struct bb__raster_tri {
  double u[3], v[3], d[3];
} bb__raster_tri;

/* A triangle ready to draw: edge k (the one opposite vertex k) is
 * e_k(u, v) = a[k] u + b[k] v + c[k], >= 0 on the triangle's side, and
 * e_k / (e_0 + e_1 + e_2) is vertex k's barycentric weight. */
typedef struct bb__raster_setup {
  double a[3], b[3], c[3];
  double inv_area; /* 1 / (twice the area), in 1/texel^2 */
  double d[3];
  double box[4]; /* u_min, v_min, u_max, v_max */
} bb__raster_setup;

/* Sets s up from t. Each edge's coefficients are computed from its
 * lexicographically smaller endpoint, so the two triangles sharing an edge
 * get exactly opposite values at every sample and no sample falls between
 * them. Returns 0 (s unusable) when t has zero area. */
int bb__raster_setup_make(const bb__raster_tri *t, bb__raster_setup *s);

/* Barycentric weights of the point (u, v) in s (summing to 1 up to
 * rounding), by the edge functions the inside test uses. */
void bb__raster_weights(const bb__raster_setup *s, double u, double v, double w[3]);

/* The samples of `rows` sample rows starting at sample row `first_row`, each
 * `columns` samples wide, on a regular grid of `per_texel` x `per_texel`
 * samples per texel: sample (i, j) sits at u = (i + 0.5) / per_texel,
 * v = (j + 0.5) / per_texel. winner holds the id of the front-most triangle
 * drawn so far, or -1; depth its d there. */
typedef struct bb__sample_band {
  int columns, rows, first_row, per_texel;
  double *depth;   /* columns * rows */
  int32_t *winner; /* columns * rows */
} bb__sample_band;

/* Draws s with id into the band: every sample inside (edges included) whose
 * interpolated d is strictly greater than the winner's takes id, so among
 * equal depths the first drawn stays. It visits only the columns each row's
 * edges leave, and draws them by bb__raster_sample. */
void bb__band_draw(bb__sample_band *band, const bb__raster_setup *s, int32_t id);

/* The parts of bb__band_draw every way of visiting the samples shares (its
 * test draws each triangle's whole box with them, sample for sample). */

/* The samples s's box covers in the band: columns *i0 .. *i1 and sample
 * rows *j0 .. *j1 (counted from the image's top, within the band); none
 * when *i1 < *i0 or *j1 < *j0. */
void bb__raster_box(const bb__sample_band *band, const bb__raster_setup *s, int *i0,
                    int *i1, int *j0, int *j1);

/* Sample row j of a band being drawn: each edge's term of the row,
 * b[k] v + c[k] at the row's centre v, and the row's cells. */
typedef struct bb__raster_row {
  double term[3];
  double *depth;
  int32_t *winner;
} bb__raster_row;

static inline bb__raster_row bb__raster_row_at(const bb__sample_band *band,
                                               const bb__raster_setup *s, int j) {
  const double v = (j + 0.5) / band->per_texel;
  const long at = (long)(j - band->first_row) * band->columns;
  bb__raster_row r = {
      {s->b[0] * v + s->c[0], s->b[1] * v + s->c[1], s->b[2] * v + s->c[2]},
      band->depth + at,
      band->winner + at};
  return r;
}

/* Edge (a, row) at sample column i, n samples per texel: the one
 * expression every inside test uses. fl(a u + row) never decreases in u
 * when a > 0 and never increases when a < 0 (rounding is monotone), so the
 * columns where it is >= 0 are one run reaching an end of the row. */
static inline double bb__raster_edge(double a, double row, int i, int n) {
  const double u = (i + 0.5) / n;
  return a * u + row;
}

/* Draws sample i of row r: inside (every edge >= 0) and strictly nearer
 * than the winner so far, it takes id and its depth. */
static inline void bb__raster_sample(const bb__raster_setup *s, const bb__raster_row *r,
                                     int i, int n, int32_t id) {
  const double e0 = bb__raster_edge(s->a[0], r->term[0], i, n),
               e1 = bb__raster_edge(s->a[1], r->term[1], i, n),
               e2 = bb__raster_edge(s->a[2], r->term[2], i, n);
  if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0)
    return;
  const double d = (e0 * s->d[0] + e1 * s->d[1] + e2 * s->d[2]) * s->inv_area;
  if (r->winner[i] < 0 || d > r->depth[i]) {
    r->winner[i] = id;
    r->depth[i] = d;
  }
}

#endif /* BB_RASTERIZE_H */
