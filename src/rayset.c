/* rayset.c: the set of directions traced from every texel, and its weights.
 *
 * Scheme ("cosine slices", id "bb-cosslices-v1"): A = round(sqrt(N)) azimuth
 * slices at phi_s = 2 pi (s + 1/2) / A; slice s holds E_s = floor(N (s+1)/A)
 * - floor(N s/A) rays (so the N rays are spread as evenly as N allows). In a
 * slice, the cosine-weighted measure sin^2(elevation) is split into E_s equal
 * strata and each ray sits at its stratum's midpoint: z_e = sqrt((e + 1/2) /
 * E_s). Each ray therefore stands for an equal share of the cosine-weighted
 * hemisphere, 1 / (A E_s). The estimators are ratios of weighted sums:
 *   ao    = sum_unblocked w_ao / sum_all w_ao,       w_ao = 1 / (A E_s)
 *   vis_c = sum_unblocked w_c  / sum_all w_c,        w_c  = max(0, d.B_c)^P / (z A E_s)
 * (the 1/z undoes the cosine density), which converge to CONVENTIONS' ao and
 * vis_c as N grows. Cosine weighting keeps the lowest ray at z = sqrt(1/(2E)),
 * about 10 degrees for 256 rays, which spares the march the near-horizontal
 * rays whose weight in ao is near zero anyway.
 */
#include "internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void bb_rayset_free(bb_rayset *rs) {
  if (!rs) return;
  free(rs->slice_start);
  free(rs->slice_dir);
  free(rs->tan_elevation);
  free(rs->direction);
  free(rs->weight_ao);
  free(rs->weight_basis);
  memset(rs, 0, sizeof *rs);
}

static bb_status allocate(bb_rayset *rs, bb_error *err) {
  const size_t n = (size_t)rs->ray_count, a = (size_t)rs->slice_count;
  rs->slice_start = malloc((a + 1) * sizeof(int));
  rs->slice_dir = malloc(2 * a * sizeof(double));
  rs->tan_elevation = malloc(n * sizeof(double));
  rs->direction = malloc(3 * n * sizeof(double));
  rs->weight_ao = malloc(n * sizeof(double));
  rs->weight_basis = malloc(n * (size_t)rs->basis_count * sizeof(double));
  if (rs->slice_start && rs->slice_dir && rs->tan_elevation && rs->direction &&
      rs->weight_ao && rs->weight_basis)
    return BB_OK;
  bb_rayset_free(rs);
  return bb__fail(err, BB_ERR_MEMORY, "ray set: out of memory");
}

static void fill_slice(bb_rayset *rs, int s, double power) {
  const int start = rs->slice_start[s], count = rs->slice_start[s + 1] - start;
  const double phi = 2.0 * BB__PI * (s + 0.5) / rs->slice_count;
  const double cx = cos(phi), cy = sin(phi);
  rs->slice_dir[2 * s] = cx;
  rs->slice_dir[2 * s + 1] = cy;
  const double share = 1.0 / ((double)rs->slice_count * (double)count);
  for (int e = 0; e < count; e++) {
    const int i = start + e;
    const double z = sqrt((e + 0.5) / count), horizontal = sqrt(1.0 - z * z);
    double *d = rs->direction + 3 * (size_t)i;
    d[0] = horizontal * cx;
    d[1] = horizontal * cy;
    d[2] = z;
    rs->tan_elevation[i] = z / horizontal;
    rs->weight_ao[i] = share;
    for (int c = 0; c < rs->basis_count; c++) {
      double b[3];
      bb_basis_vector(c, b);
      const double cosine = d[0] * b[0] + d[1] * b[1] + d[2] * b[2];
      rs->weight_basis[(size_t)i * (size_t)rs->basis_count + (size_t)c] =
          cosine > 0.0 ? pow(cosine, power) / z * share : 0.0;
    }
  }
}

bb_status bb_rayset_make(int rays, double power, bb_basis basis, bb_rayset *out,
                         bb_error *err) {
  memset(out, 0, sizeof *out);
  if (rays < 1 || rays > 65536)
    return bb__fail(err, BB_ERR_ARGUMENT, "ray set: rays must be in 1..65536 (got %d)", rays);
  if (!(power >= 1.0) || !isfinite(power))
    return bb__fail(err, BB_ERR_ARGUMENT, "ray set: power must be >= 1 (got %g)", power);
  out->ray_count = rays;
  out->slice_count = (int)lround(sqrt((double)rays));
  out->basis_count = bb_basis_count(basis);
  bb_status st = allocate(out, err);
  if (st != BB_OK) return st;
  for (int s = 0; s <= out->slice_count; s++)
    out->slice_start[s] = (int)((long)rays * s / out->slice_count);
  for (int s = 0; s < out->slice_count; s++) fill_slice(out, s, power);
  out->total_ao = 0.0;
  for (int c = 0; c < out->basis_count; c++) out->total_basis[c] = 0.0;
  for (int i = 0; i < rays; i++) {
    out->total_ao += out->weight_ao[i];
    for (int c = 0; c < out->basis_count; c++)
      out->total_basis[c] += out->weight_basis[(size_t)i * (size_t)out->basis_count + (size_t)c];
  }
  snprintf(out->id, sizeof out->id, "bb-cosslices-v1:n%d:a%d:p%g:%s", rays,
           out->slice_count, power, bb_basis_name(basis));
  return BB_OK;
}
