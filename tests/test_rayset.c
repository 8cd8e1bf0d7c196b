/* test_rayset.c: the ray set's structure and that its estimators converge
 * to CONVENTIONS' integrals. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdlib.h>

#include "bumpbake.h"

Test(rayset, slices_hold_all_rays_sorted_by_elevation) {
  const int counts[] = {1, 2, 7, 250, 256, 1000};
  for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
    bb_rayset rs;
    bb_error err;
    cr_assert_eq(bb_rayset_make(counts[i], 1.0, BB_BASIS_HL2_Z, &rs, &err), BB_OK, "%s", err.message);
    cr_assert_eq(rs.slice_start[0], 0);
    cr_assert_eq(rs.slice_start[rs.slice_count], counts[i]);
    for (int s = 0; s < rs.slice_count; s++) {
      cr_assert_gt(rs.slice_start[s + 1], rs.slice_start[s], "empty slice");
      for (int r = rs.slice_start[s]; r < rs.slice_start[s + 1]; r++) {
        const double *d = rs.direction + 3 * r;
        cr_assert_float_eq(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], 1.0, 1e-12);
        cr_assert_gt(d[2], 0.0);
        cr_assert_float_eq(atan2(d[1], d[0]), atan2(rs.slice_dir[2 * s + 1], rs.slice_dir[2 * s]), 1e-9);
        if (r > rs.slice_start[s]) cr_assert_gt(rs.tan_elevation[r], rs.tan_elevation[r - 1]);
      }
    }
    bb_rayset_free(&rs);
  }
}

/* Half-space occlusion: every ray with d.x < 0 blocked. Exact answers:
 * ao = 1/2 and, for B0 = (sqrt(2/3), 0, 1/sqrt(3)) with power 1,
 * vis_0 = int_{H, x>0} max(0, w.B0) / int_H max(0, w.B0). */
static double lobe_integral(const double b[3], int half_only) {
  double sum = 0.0;
  const int n = 800;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < 2 * n; j++) {
      double z = (i + 0.5) / n, phi = 3.141592653589793 * (j + 0.5) / n;
      double r = sqrt(1 - z * z), d[3] = {r * cos(phi), r * sin(phi), z};
      double c = d[0] * b[0] + d[1] * b[1] + d[2] * b[2];
      if (c > 0 && (!half_only || d[0] > 0)) sum += c;
    }
  return sum;
}

Test(rayset, estimators_converge_on_a_half_space) {
  bb_rayset rs;
  cr_assert_eq(bb_rayset_make(4096, 1.0, BB_BASIS_HL2, &rs, NULL), BB_OK);
  double ao = 0.0, vis[3] = {0};
  for (int r = 0; r < rs.ray_count; r++) {
    if (rs.direction[3 * r] < 0) continue;
    ao += rs.weight_ao[r];
    for (int c = 0; c < 3; c++) vis[c] += rs.weight_basis[r * 3 + c];
  }
  cr_assert_float_eq(ao / rs.total_ao, 0.5, 0.01);
  for (int c = 0; c < 3; c++) {
    double b[3];
    bb_basis_vector(c, b);
    double exact = lobe_integral(b, 1) / lobe_integral(b, 0);
    cr_assert_float_eq(vis[c] / rs.total_basis[c], exact, 0.01, "channel %d", c);
  }
  bb_rayset_free(&rs);
}

Test(rayset, rejects_bad_arguments) {
  bb_rayset rs;
  bb_error err;
  cr_assert_eq(bb_rayset_make(0, 1.0, BB_BASIS_HL2, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb_rayset_make(16, 0.5, BB_BASIS_HL2, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb_rayset_make(16, NAN, BB_BASIS_HL2, &rs, &err), BB_ERR_ARGUMENT);
}

/* Slices follow lattice steps close to uniform azimuths, for every ray
 * count up to the maximum, so line sweeps can serve any bake. */
Test(rayset, slices_follow_lattice_steps_near_uniform_azimuths) {
  const int counts[] = {1, 2, 7, 256, 1000, 4096, 65536};
  for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
    bb_rayset rs;
    cr_assert_eq(bb_rayset_make(counts[i], 1.0, BB_BASIS_HL2, &rs, NULL), BB_OK);
    const double spacing = 2 * 3.141592653589793 / rs.slice_count;
    for (int s = 0; s < rs.slice_count; s++) {
      const int a = rs.slice_step[2 * s], b = rs.slice_step[2 * s + 1];
      cr_assert(abs(a) <= 128 && abs(b) <= 128 && (a || b), "%d rays, slice %d: (%d, %d)", counts[i], s, a, b);
      const double error = fabs(remainder(atan2(b, a) - spacing * (s + 0.5), 2 * 3.141592653589793));
      cr_assert_leq(error, spacing / 20 + 1e-12, "%d rays, slice %d: off by %g rad", counts[i], s, error);
      cr_assert_float_eq(atan2(rs.slice_dir[2 * s + 1], rs.slice_dir[2 * s]), atan2(b, a), 1e-12);
    }
    bb_rayset_free(&rs);
  }
}
