/* band.c: directional max bands, the max-mip pyramid re-cut along one
 * azimuth so the rays of a slice can skip long thin stretches of their path.
 *
 * For a direction whose major axis is A (unit cell step along x or y, with
 * the ray's sign) and minor axis B (the other, with the ray's sign), with
 * slope m = |minor/major| <= 1, band level k at cell c bounds every cell a
 * ray of that direction can touch while it is anywhere in cell c and for the
 * next 2^k - 1 cells along A:
 *   M_0(c) = max of the cells c - B, c, c + B, c + 2B (level-0 corner maxima)
 *   M_k(c) = max(M_{k-1}(c), M_{k-1}(c + hA + fB), M_{k-1}(c + hA + (f+1)B)),
 *            h = 2^(k-1), f = floor(h m).
 * A ray in cell c, h cells further along A, has moved between hm - 1 and
 * hm + 1 rows along B (it may have been anywhere in c), so it is in a cell
 * that one of the two shifted halves starts from, give or take the rows M_0
 * adds. Cell indices go through the pyramid's addressing, so bands wrap
 * (periodic) or repeat the border cells (clamp). Levels stop at a span of
 * one period along A or 2^(BB__BAND_LEVELS-1) cells, whichever is shorter.
 */
#include "internal.h"
#include "trace_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void bb__band_free(bb__band *band) {
  if (!band) return;
  for (int k = 0; k < band->levels; k++) free(band->level_max[k]);
  memset(band, 0, sizeof *band);
}

static void set_direction(bb__band *band, const bb_pyramid *p, double dx, double dy) {
  const int sx = dx < 0 ? -1 : 1, sy = dy < 0 ? -1 : 1;
  const int x_major = fabs(dx) >= fabs(dy);
  band->major_x = x_major ? sx : 0;
  band->major_y = x_major ? 0 : sy;
  band->minor_x = x_major ? 0 : sx;
  band->minor_y = x_major ? sy : 0;
  band->slope = x_major ? fabs(dy / dx) : fabs(dx / dy);
  const int period = x_major ? p->width : p->height;
  band->levels = 1;
  while ((1L << (band->levels - 1)) < period) band->levels++;
  /* Spans past 128 cells cost a full-size level each to build and, on the
   * maps measured (rock06 at scale 128), save no march steps: by then the
   * ray is high enough for the global maximum test to end it. */
  if (band->levels > BB__BAND_LEVELS) band->levels = BB__BAND_LEVELS;
}

/* out[x] = max(out[x], in[addressed(x + offset)]) for a whole row, as
 * contiguous runs the compiler can vectorise. */
static void max_run(float *out, const float *in, int n) {
  for (int i = 0; i < n; i++) out[i] = in[i] > out[i] ? in[i] : out[i];
}

static void max_fill(float *out, float v, int n) {
  for (int i = 0; i < n; i++) out[i] = v > out[i] ? v : out[i];
}

static void max_shifted_row(float *out, const float *in, int n, int offset, bb_addressing a) {
  if (a == BB_ADDRESS_PERIODIC) {
    offset = bb__wrap(offset, n);
    max_run(out, in + offset, n - offset);
    max_run(out + (n - offset), in, offset);
    return;
  }
  const int lo = bb__clampi(-offset, 0, n), hi = bb__clampi(n - offset, lo, n);
  max_fill(out, in[0], lo);
  max_run(out + lo, in + lo + offset, hi - lo);
  max_fill(out + hi, in[n - 1], n - hi);
}

/* One level: out = max over `terms` copies of `in` shifted by (dx[j], dy[j]). */
typedef struct level_job {
  const bb_pyramid *p;
  const float *in;
  float *out;
  int terms;
  int dx[4], dy[4];
} level_job;

static void level_row(void *user, int y) {
  const level_job *job = user;
  const int w = job->p->width, h = job->p->height;
  float *o = job->out + (size_t)y * (size_t)w;
  for (int x = 0; x < w; x++) o[x] = -INFINITY;
  for (int j = 0; j < job->terms; j++) {
    const int row = bb__address(y + job->dy[j], h, job->p->addressing);
    max_shifted_row(o, job->in + (size_t)row * (size_t)w, w, job->dx[j], job->p->addressing);
  }
}

/* Term j of a level: the cell offset along * A + across * B. */
static void set_term(level_job *job, const bb__band *band, int j, int along, int across) {
  job->dx[j] = along * band->major_x + across * band->minor_x;
  job->dy[j] = along * band->major_y + across * band->minor_y;
}

bb_status bb__band_build(const bb_pyramid *p, double dx, double dy, int threads,
                         bb__band *band, bb_error *err) {
  memset(band, 0, sizeof *band);
  set_direction(band, p, dx, dy);
  const size_t n = (size_t)p->width * (size_t)p->height;
  bb_status st = BB_OK;
  for (int k = 0; st == BB_OK && k < band->levels; k++) {
    if (!(band->level_max[k] = malloc(n * sizeof(float)))) {
      st = bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for bands");
      break;
    }
    level_job job = {.p = p, .out = band->level_max[k]};
    if (k == 0) { /* rows -1, 0, 1, 2 along B of the level-0 cells */
      job.in = p->level_max[0];
      job.terms = 4;
      for (int j = 0; j < 4; j++) set_term(&job, band, j, 0, j - 1);
    } else { /* itself, and the second half at offsets f and f + 1 along B */
      const int half = 1 << (k - 1), f = (int)floor((double)half * band->slope);
      job.in = band->level_max[k - 1];
      job.terms = 3;
      set_term(&job, band, 0, 0, 0);
      set_term(&job, band, 1, half, f);
      set_term(&job, band, 2, half, f + 1);
    }
    st = bb__parallel_for(p->height, threads, level_row, &job, NULL, NULL, err);
  }
  if (st != BB_OK) bb__band_free(band);
  return st;
}
