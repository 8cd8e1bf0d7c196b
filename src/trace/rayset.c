/* rayset.c: the azimuth slices every texel is integrated over, and their
 * integration tables.
 *
 * Scheme "bb-horizon-v1": A azimuth slices (A = round(sqrt(N)) for a budget
 * of N rays, or given). Slice s aims at phi_s = 2 pi (s + 1/2) / A but follows
 * the nearest lattice direction (a, b), coprime integers as small as keep it
 * within 1/20 of the slice spacing (for 16 slices: (5,1), (3,2), (2,3), (1,5)
 * and their mirrors, within 0.06 degrees). Along a lattice direction the
 * texels x + j (a, b) share one line, so one sweep per line finds all their
 * horizons (sweep.c). Slice s stands for the azimuth sector halfway to its
 * neighbours; integrate.c turns a horizon into what the sector loses.
 */

#include "trace/basis.h"
#include "trace/testing.h"
#include "core/internal.h"
#include "trace/integrate.h"
#include "trace/rayset.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int bb__slices_for_rays(int rays) {
  const long slices = lround(sqrt(rays > 1 ? (double)rays : 1.0));
  return slices < 1 ? 1 : (slices > BB_MAX_SLICES ? BB_MAX_SLICES : (int)slices);
}

void bb__rayset_release(bb_rayset *rs) {
  if (!rs) return;
  free(rs->slice_step);
  free(rs->slice_dir);
  free(rs->sector);
  free(rs->half_width);
  free(rs->table);
  memset(rs, 0, sizeof *rs);
}

void bb_rayset_free(bb_rayset *rs) {
  bb__rayset_release(rs);
  free(rs);
}

int bb_rayset_slice_count(const bb_rayset *rs) {
  return rs ? rs->slice_count : 0;
}

int bb_rayset_lobe_count(const bb_rayset *rs) {
  return rs ? rs->basis_count : 0;
}

const char *bb_rayset_id(const bb_rayset *rs) {
  return rs ? rs->id : "";
}

static bb_status allocate(bb_rayset *rs, bb_error *err) {
  const size_t a = (size_t)rs->slice_count;
  rs->slice_step = malloc(2 * a * sizeof(int));
  rs->slice_dir = malloc(2 * a * sizeof(double));
  rs->sector = malloc(2 * a * sizeof(double));
  rs->half_width = malloc(a * sizeof(double));
  rs->table = malloc(a * BB__TABLE_INTERVALS * (size_t)rs->basis_count * 4 * sizeof(double));
  if (rs->slice_step && rs->slice_dir && rs->sector && rs->half_width && rs->table)
    return BB_OK;
  bb__rayset_release(rs);
  return bb__fail(err, BB_ERR_MEMORY, "ray set: out of memory");
}

/* The smallest coprime lattice step (a, b) within tolerance of angle phi,
 * or failing that (never seen for up to 256 slices, whose steps stay under
 * 100) the closest with |a|, |b| <= BB__MAX_LATTICE_STEP. */
static void lattice_step(double phi, double tolerance, int step[2]) {
  double best = INFINITY;
  for (int q = 1; q <= BB__MAX_LATTICE_STEP; q++)
    for (int a = -q; a <= q; a++)
      for (int b = -q; b <= q; b++) {
        if ((abs(a) != q && abs(b) != q) || bb__gcd(a, b) != 1) continue;
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

/* Slice s's direction and the sector it stands for: halfway to each
 * neighbour (the whole circle for a single slice). */
static void place_slice(bb_rayset *rs, int s) {
  const double phi = slice_angle(rs, s);
  rs->slice_dir[2 * s] = cos(phi);
  rs->slice_dir[2 * s + 1] = sin(phi);
  double before = BB__PI, after = BB__PI;
  if (rs->slice_count > 1) {
    before = remainder(phi - slice_angle(rs, s - 1), 2.0 * BB__PI);
    after = remainder(slice_angle(rs, s + 1) - phi, 2.0 * BB__PI);
    if (before <= 0.0) before += 2.0 * BB__PI;
    if (after <= 0.0) after += 2.0 * BB__PI;
    before *= 0.5, after *= 0.5;
  }
  rs->sector[2 * s] = phi - before;
  rs->sector[2 * s + 1] = phi + after;
  rs->half_width[s] = 0.5 * (before + after);
}

/* The lobe tables of each slice: independent, so built on all cores. */
typedef struct table_job {
  bb_rayset *rs;
  double *share; /* basis_count per slice */
} table_job;

static void build_slice_table(void *user, int s) {
  table_job *job = user;
  bb_rayset *rs = job->rs;
  const size_t per_slice = BB__TABLE_INTERVALS * (size_t)rs->basis_count * 4;
  bb__slice_table_build(rs->sector[2 * s], rs->sector[2 * s + 1],
                        (const double(*)[3])rs->basis, rs->basis_count, rs->power,
                        rs->table + (size_t)s * per_slice,
                        job->share + (size_t)s * (size_t)rs->basis_count);
}

bb_status bb__rayset_new(int slices, double power, const bb_basis *basis, bb_rayset **out,
                         bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "ray set: out is NULL");
  *out = NULL;
  bb_rayset *rs = malloc(sizeof *rs);
  if (!rs)
    return bb__fail(err, BB_ERR_MEMORY, "ray set: out of memory");
  bb_status st = bb__rayset_make(slices, power, basis, 0, rs, err);
  if (st != BB_OK) {
    free(rs);
    return st;
  }
  *out = rs;
  return BB_OK;
}

bb_status bb__rayset_make(int slices, double power, const bb_basis *basis, int threads,
                          bb_rayset *out, bb_error *err) {
  memset(out, 0, sizeof *out);
  if (slices < 1 || slices > BB_MAX_SLICES)
    return bb__fail(err, BB_ERR_ARGUMENT, "ray set: slices must be in 1..%d (got %d)",
                    BB_MAX_SLICES, slices);
  if (!(power >= 1.0) || !isfinite(power))
    return bb__fail(err, BB_ERR_ARGUMENT, "ray set: power must be >= 1 (got %g)", power);
  bb_basis hl2;
  if (!basis) {
    bb__basis_init(&hl2);
    basis = &hl2;
  }
  bb_status st = bb__basis_check(basis, "ray set", err);
  if (st != BB_OK) return st;
  out->slice_count = slices;
  out->basis_count = basis->count;
  out->power = power;
  memcpy(out->basis, basis->vector, sizeof out->basis);
  st = allocate(out, err);
  if (st != BB_OK) return st;
  const double spacing = 2.0 * BB__PI / slices;
  for (int s = 0; s < slices; s++)
    lattice_step(spacing * (s + 0.5), spacing / 20.0, out->slice_step + 2 * s);
  for (int s = 0; s < slices; s++) place_slice(out, s);
  table_job job = {out, malloc((size_t)slices * (size_t)out->basis_count * sizeof(double))};
  if (!job.share) {
    bb__rayset_release(out);
    return bb__fail(err, BB_ERR_MEMORY, "ray set: out of memory");
  }
  st = bb__parallel_for(slices, threads, build_slice_table, &job, NULL, NULL, err);
  /* The totals, summed in slice order whatever the threads did. */
  for (int s = 0; s < slices; s++) {
    out->total[0] += out->half_width[s];
    for (int c = 0; c < out->basis_count; c++)
      out->total[1 + c] += job.share[(size_t)s * (size_t)out->basis_count + (size_t)c];
  }
  free(job.share);
  if (st != BB_OK) {
    bb__rayset_release(out);
    return st;
  }
  bb__rayset_id(slices, power, basis, out->id, sizeof out->id);
  return BB_OK;
}

void bb__rayset_id(int slices, double power, const bb_basis *basis, char *out, size_t cap) {
  /* At most 57 characters (256 slices, power 1.23457e+06, a vectors: name);
   * the larger buffer only keeps the compiler from counting wider. */
  char id[160];
  snprintf(id, sizeof id, "bb-horizon-v1:a%d:p%g:%.*s", slices, power,
           (int)sizeof basis->name, basis->name);
  snprintf(out, cap, "%.63s", id);
}

void bb__rayset_blocked(const bb_rayset *rs, int slice, double tan_horizon, double *blocked) {
  const bb__slice_integral si = bb__slice_integral_of(rs, slice);
  double t = tan_horizon > 0.0 ? tan_horizon : 0.0;
  if (t > 1e100) t = 1e100; /* keeps t^2 (1 + t) (1 + t^2) finite; the tables end at q = 1 */
  bb__slice_blocked(&si, t, blocked);
}
