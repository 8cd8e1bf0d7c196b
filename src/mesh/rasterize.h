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
 * equal depths the first drawn stays. */
void bb__band_draw(bb__sample_band *band, const bb__raster_setup *s, int32_t id);

#endif /* BB_RASTERIZE_H */
