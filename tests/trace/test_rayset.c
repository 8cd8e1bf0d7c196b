/* test_rayset.c: the slices' structure: lattice steps near uniform
 * azimuths, directions and sectors that agree with them, and the id. */
#include "trace/rayset.h"
#include "trace/testing.h"
#include <criterion/criterion.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bumpbake.h"
#include "trace/basis.h"

static const double PI = 3.14159265358979323846;

/* Slices follow lattice steps close to uniform azimuths, for every slice
 * count up to the maximum, so line sweeps can serve any bake; each slice's
 * direction is its step's and lies inside its sector. */
Test(rayset, slices_follow_lattice_steps_near_uniform_azimuths) {
  const int counts[] = {1, 2, 3, 7, 16, 32, 64, 100, 256};
  for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
    bb_rayset rs;
    cr_assert_eq(bb__rayset_make(counts[i], 1.0, NULL, 0, &rs, NULL), BB_OK);
    const double spacing = 2 * PI / rs.slice_count;
    for (int s = 0; s < rs.slice_count; s++) {
      const int a = rs.slice_step[2 * s], b = rs.slice_step[2 * s + 1];
      cr_assert(abs(a) <= 128 && abs(b) <= 128 && (a || b), "%d slices, slice %d: (%d, %d)",
                counts[i], s, a, b);
      const double error = fabs(remainder(atan2(b, a) - spacing * (s + 0.5), 2 * PI));
      cr_assert_leq(error, spacing / 20 + 1e-12, "%d slices, slice %d: off by %g rad", counts[i], s,
                    error);
      const double phi = atan2(rs.slice_dir[2 * s + 1], rs.slice_dir[2 * s]);
      cr_assert_float_eq(phi, atan2(b, a), 1e-12);
      cr_assert_float_eq(hypot(rs.slice_dir[2 * s], rs.slice_dir[2 * s + 1]), 1.0, 1e-15);
      const double lo = rs.sector[2 * s], hi = rs.sector[2 * s + 1];
      cr_assert((remainder(phi - lo, 2 * PI) > 0 && remainder(hi - phi, 2 * PI) > 0) ||
                    rs.slice_count == 1,
                "%d slices, slice %d outside its sector", counts[i], s);
      cr_assert_float_eq(rs.half_width[s], 0.5 * (hi - lo), 1e-15);
    }
    bb__rayset_release(&rs);
  }
}

Test(rayset, id_names_the_scheme_and_its_parameters) {
  bb_rayset rs;
  bb_basis hl2z;
  cr_assert_eq(bb__basis_parse("hl2+z", &hl2z, NULL), BB_OK);
  cr_assert_eq(bb__rayset_make(16, 2.0, &hl2z, 0, &rs, NULL), BB_OK);
  cr_assert_str_eq(rs.id, "bb-horizon-v1:a16:p2:hl2+z");
  cr_assert_eq(rs.basis_count, 4);
  cr_assert_eq(rs.power, 2.0);
  bb__rayset_release(&rs);
}

/* The public loss function: nothing below the plane, the whole share for a
 * vertical wall, and more loss for a higher horizon. */
Test(rayset, blocked_rises_with_the_horizon) {
  bb_rayset rs;
  cr_assert_eq(bb__rayset_make(16, 1.0, NULL, 0, &rs, NULL), BB_OK);
  double last[4] = {0};
  for (double t = -1.0; t < 1e4; t = t < 0 ? 0.001 : t * 2) {
    double blocked[4];
    bb__rayset_blocked(&rs, 3, t, blocked);
    for (int c = 0; c < 4; c++) {
      if (t <= 0) cr_assert_eq(blocked[c], 0.0);
      cr_assert_geq(blocked[c], last[c], "channel %d at t %g", c, t);
      last[c] = blocked[c];
    }
  }
  double wall[4];
  bb__rayset_blocked(&rs, 3, INFINITY, wall);
  cr_assert_float_eq(wall[0], rs.half_width[3], 1e-12);
  bb__rayset_release(&rs);
}

/* The public handle: made, read through its accessors, freed. */
Test(rayset, public_handle) {
  bb_rayset *rs = NULL;
  bb_error err;
  cr_assert_eq(bb__rayset_new(16, 2.0, NULL, &rs, &err), BB_OK, "%s", err.message);
  cr_assert_not_null(rs);
  cr_assert_eq(bb_rayset_slice_count(rs), 16);
  cr_assert_eq(bb_rayset_lobe_count(rs), 3);
  cr_assert_str_eq(bb_rayset_id(rs), "bb-horizon-v1:a16:p2:hl2");
  bb_rayset_free(rs);
  cr_assert_eq(bb__rayset_new(0, 1.0, NULL, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_null(rs);
  bb_rayset_free(NULL);
}
