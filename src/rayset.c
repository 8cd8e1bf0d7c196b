/* rayset.c: the set of directions traced from every texel, and its weights.
 *
 * Scheme ("lattice slices", id "bb-latslices-v1"): A = round(sqrt(N)) azimuth
 * slices. Slice s aims at phi_s = 2 pi (s + 1/2) / A but follows the nearest
 * lattice direction (a, b), coprime integers as small as keep it within
 * 1/20 of the slice spacing (for 16 slices: (5,1), (3,2), (2,3), (1,5) and
 * their mirrors, within 0.06 degrees). Along a lattice direction the texels
 * x + j (a, b) share one line, so one sweep per line answers all of them
 * (sweep.c). Slice s holds E_s = floor(N (s+1)/A) - floor(N s/A) rays and
 * stands for the azimuth sector halfway to its neighbours, of width dphi_s.
 * In a slice the cosine-weighted measure sin^2(elevation) is split into E_s
 * equal strata and each ray sits at its stratum's midpoint: z_e =
 * sqrt((e + 1/2) / E_s). Each ray stands for a share dphi_s / (2 pi E_s) of
 * the cosine-weighted hemisphere. The estimators are ratios of weighted sums:
 *   ao    = sum_unblocked w_ao / sum_all w_ao,       w_ao = share
 *   vis_c = sum_unblocked w_c  / sum_all w_c,        w_c  = max(0, d.B_c)^P / z * share
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
  free(rs->slice_step);
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
  rs->slice_step = malloc(2 * a * sizeof(int));
  rs->tan_elevation = malloc(n * sizeof(double));
  rs->direction = malloc(3 * n * sizeof(double));
  rs->weight_ao = malloc(n * sizeof(double));
  rs->weight_basis = malloc(n * (size_t)rs->basis_count * sizeof(double));
  if (rs->slice_start && rs->slice_dir && rs->slice_step && rs->tan_elevation && rs->direction &&
      rs->weight_ao && rs->weight_basis)
    return BB_OK;
  bb_rayset_free(rs);
  return bb__fail(err, BB_ERR_MEMORY, "ray set: out of memory");
}

static int gcd(int a, int b) {
  a = a < 0 ? -a : a;
  b = b < 0 ? -b : b;
  while (b) {
    int r = a % b;
    a = b;
    b = r;
  }
  return a;
}

/* The smallest coprime lattice step (a, b) within tolerance of angle phi,
 * or failing that (never seen for up to 65536 rays, whose steps stay under
 * 100) the closest with |a|, |b| <= BB__MAX_LATTICE_STEP. */
static void lattice_step(double phi, double tolerance, int step[2]) {
  double best = INFINITY;
  for (int q = 1; q <= BB__MAX_LATTICE_STEP; q++)
    for (int a = -q; a <= q; a++)
      for (int b = -q; b <= q; b++) {
        if ((abs(a) != q && abs(b) != q) || gcd(a, b) != 1) continue;
        const double error = fabs(remainder(atan2(b, a) - phi, 2.0 * BB__PI));
        if (error < best) {
          best = error;
          step[0] = a;
          step[1] = b;
        }
        if (error <= tolerance) return;
      }
}

static double slice_angle(const bb_rayset *rs, int s) {
  s = bb__wrap(s, rs->slice_count);
  return atan2(rs->slice_step[2 * s + 1], rs->slice_step[2 * s]);
}

/* The azimuth sector slice s stands for: halfway to each neighbour. */
static double sector_width(const bb_rayset *rs, int s) {
  if (rs->slice_count == 1) return 2.0 * BB__PI;
  double before = remainder(slice_angle(rs, s) - slice_angle(rs, s - 1), 2.0 * BB__PI);
  double after = remainder(slice_angle(rs, s + 1) - slice_angle(rs, s), 2.0 * BB__PI);
  if (before <= 0.0) before += 2.0 * BB__PI;
  if (after <= 0.0) after += 2.0 * BB__PI;
  return 0.5 * (before + after);
}

static void fill_slice(bb_rayset *rs, int s, double power) {
  const int start = rs->slice_start[s], count = rs->slice_start[s + 1] - start;
  const double phi = slice_angle(rs, s);
  const double cx = cos(phi), cy = sin(phi);
  rs->slice_dir[2 * s] = cx;
  rs->slice_dir[2 * s + 1] = cy;
  const double share = sector_width(rs, s) / (2.0 * BB__PI * (double)count);
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
  const double spacing = 2.0 * BB__PI / out->slice_count;
  for (int s = 0; s < out->slice_count; s++)
    lattice_step(spacing * (s + 0.5), spacing / 20.0, out->slice_step + 2 * s);
  for (int s = 0; s < out->slice_count; s++) fill_slice(out, s, power);
  out->total_ao = 0.0;
  for (int c = 0; c < out->basis_count; c++) out->total_basis[c] = 0.0;
  for (int i = 0; i < rays; i++) {
    out->total_ao += out->weight_ao[i];
    for (int c = 0; c < out->basis_count; c++)
      out->total_basis[c] += out->weight_basis[(size_t)i * (size_t)out->basis_count + (size_t)c];
  }
  snprintf(out->id, sizeof out->id, "bb-latslices-v1:n%d:a%d:p%g:%s", rays,
           out->slice_count, power, bb_basis_name(basis));
  return BB_OK;
}
