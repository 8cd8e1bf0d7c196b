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

/* Draws t with id into the band: every sample inside t (edges included)
 * whose interpolated d is strictly greater than the winner's takes id, so
 * among equal depths the first drawn stays. A shared edge of two triangles
 * is evaluated from the same two endpoints in the same order for both, so
 * no sample falls between them. Triangles of zero area draw nothing. */
void bb__band_draw(bb__sample_band *band, const bb__raster_tri *t, int32_t id);

/* Barycentric weights of the point (u, v) in t (they sum to 1 up to
 * rounding); the same edge functions the inside test uses. Returns 0 when
 * t has zero area (w untouched), else 1. */
int bb__raster_weights(const bb__raster_tri *t, double u, double v, double w[3]);

#endif /* BB_RASTERIZE_H */
