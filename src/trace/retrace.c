/* retrace.c: the horizons of every slice found again where a change of
 * heights can have moved them (retrace.h says which and why).
 *
 * Per pair of opposite slices (one sweep of the whole trace), the lines
 * whose breakpoints read a changed vertex are found from the texels of the
 * changed rectangle widened by the step's reach, each line once (by the
 * texel its sweep starts from). Each is walked once round: its "moved"
 * steps (those reading a changed vertex, with the heights of their
 * breakpoints) and, for every texel and side, the moved steps ahead of it
 * along (a, b) and behind it along (-a, -b). A texel then either keeps
 * its horizon (every moved point, old or new, clearly below it), or takes
 * the moved points' (now clearly above it), or is found again by a sweep:
 * those become stretches of the line (runs of them, profiled with enough
 * look-ahead that the sweep can vouch for them, or marched from there
 * where it cannot), or the whole line when that costs less. Where a
 * horizon found differs from the kept one, it is written and its texel
 * marked. Lines, and so texels, are disjoint within a sweep, so the work
 * runs on all threads and any count gives the same bits. */
#include "trace/retrace.h"
#include "core/internal.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/sweep.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The relative margin by which a changed breakpoint must stay below a
 * horizon for the horizon to stand: far beyond the rounding of a slope and
 * of the float a horizon is kept in. */
#define KEEP_MARGIN 1e-6

/* Least and most look-ahead of a stretch, in steps. */
#define MIN_LOOKAHEAD 8
#define MAX_LOOKAHEAD 128

/* Flags of a line's positions: its step reads a changed vertex; its texel
 * changed; its horizon along (a, b) (ahead) or (-a, -b) (behind) must be
 * found again. */
enum { MOVED = 1, CHANGED = 2, FAIL_AHEAD = 4, FAIL_BEHIND = 8 };
#define FAILED (FAIL_AHEAD | FAIL_BEHIND)

/* A line's texel 0 as its sweep starts it, and its texels. */
typedef struct seed {
  int x, y, len;
} seed;

/* What one line asks of the sweeps: stretches (their `want` point into
 * want), or the whole line. */
typedef struct line_out {
  bb__stretch *stretch;
  int count;
  unsigned char *want;
  int round;       /* the whole line, swept round */
  int failed;      /* out of memory */
  long found_here; /* horizons the tests found themselves */
} line_out;

/* One pair of opposite slices. */
typedef struct pair_job {
  const bb__retrace *r;
  int a, b;
  int slice[2]; /* along (a, b), and along (-a, -b); -1 when not traced */
  bb__template_extent ext;
  bb__template_point *points; /* the step's breakpoints (bb__sweep_template) */
  int point_count;
  double inverse_length;
  long period, long_line; /* periodic: the lines' steps, and the longest swept round */
  /* periodic: the texels whose steps read a changed vertex, a rectangle
   * (wrapping; a side of the image's length holds every texel) */
  int move_x0, move_y0, move_w, move_h;
  seed *seeds;
  int seed_count;
  line_out *out;
} pair_job;

static inline int imin(int a, int b) {
  return a < b ? a : b;
}

static inline int imax(int a, int b) {
  return a > b ? a : b;
}

static inline int periodic(const bb_pyramid *p) {
  return p->addressing == BB_ADDRESS_PERIODIC;
}

/* Is v in the interval first .. first+count-1 of an axis of n, which may
 * wrap (v and first in [0, n))? */
static inline int in_wrapped(int v, int first, int count, int n) {
  int d = v - first;
  if (d < 0)
    d += n;
  return d < count;
}

/* Is texel (x, y) (inside the image) one whose height changed? */
static inline int changed_texel(const bb__retrace *r, int x, int y) {
  const bb_pyramid *p = r->p;
  if (periodic(p))
    return in_wrapped(x, r->x0, r->width, p->width) &&
           in_wrapped(y, r->y0, r->height, p->height);
  return x >= r->x0 && x < r->x0 + r->width && y >= r->y0 && y < r->y0 + r->height;
}

/* Does the step from position (x, y) read a changed vertex? Its vertices
 * lie within the template's extent of it (conservative: the extent's whole
 * rectangle). Periodic positions are inside the image; clamped ones
 * anywhere, their vertices clamped to it. */
static inline int moved_step(const pair_job *job, long x, long y) {
  const bb__retrace *r = job->r;
  const bb_pyramid *p = r->p;
  if (periodic(p))
    return in_wrapped((int)x, job->move_x0, job->move_w, p->width) &&
           in_wrapped((int)y, job->move_y0, job->move_h, p->height);
  const bb__template_extent *e = &job->ext;
  const long lx = x + e->min_dx, hx = x + e->max_dx, ly = y + e->min_dy,
             hy = y + e->max_dy;
  const long cx0 = lx < 0 ? 0 : (lx > p->width - 1 ? p->width - 1 : lx);
  const long cx1 = hx < 0 ? 0 : (hx > p->width - 1 ? p->width - 1 : hx);
  const long cy0 = ly < 0 ? 0 : (ly > p->height - 1 ? p->height - 1 : ly);
  const long cy1 = hy < 0 ? 0 : (hy > p->height - 1 ? p->height - 1 : hy);
  return cx0 <= r->x0 + r->width - 1 && cx1 >= r->x0 && cy0 <= r->y0 + r->height - 1 &&
         cy1 >= r->y0;
}

/* Does a texel of horizon h (kept) keep it, when from its origin the
 * moved breakpoints (old and new) rise at most `slope` per step? A horizon
 * the moved points stay clearly below was found at a point that did not
 * move, which is still there and still the highest; a horizon of 0 stays
 * 0 while nothing moved rises above the origin. */
static inline int keeps(const pair_job *job, float h, double slope) {
  if (slope <= 0.0)
    return 1;
  return h > 0.0f && slope * job->inverse_length < (double)h * (1.0 - KEEP_MARGIN);
}

/* The steps a stretch must reach past a texel whose horizon was h
 * (texels of rise per texel), from an origin at oz, for the sweep to vouch
 * for it (a point beyond, at most the global max high, cannot beat it),
 * with a quarter to spare; at most MAX_LOOKAHEAD (or the line's `most`):
 * past that, a texel the stretch cannot vouch for is marched from its
 * horizon so far (bb__slice_horizon_above), which costs less than
 * profiling the far end of the line for it (rock06: a low texel's
 * horizon can come from half a line away). */
static int lookahead_for(const pair_job *job, float h, double oz, int most) {
  const int cap = most < MAX_LOOKAHEAD ? most : MAX_LOOKAHEAD;
  const double rise = (double)job->r->p->global_max - oz;
  if (rise <= 0.0)
    return 0;
  if (!(h > 0.0f))
    return cap;
  const double steps = rise / ((double)h / job->inverse_length) * 1.25 + 4.0;
  return steps >= (double)cap ? cap : (int)steps;
}

/* A line's positions (periodic: 0 .. len-1, going round; clamped: -before
 * .. len+after-1, the steps the whole trace profiles) and, for each texel,
 * the steps its horizon along each side asks past it (need). */
typedef struct line_walk {
  int len, before, after;
  size_t *texel;        /* texel j's image index */
  unsigned char *flags; /* position j at flags[j + before] */
  int *need[2];         /* texel j's, when it failed on that side */
  int most;             /* the most any asks: past it, the whole line */
  /* the moved steps: their positions, in order, and the highest vertex
   * each reads, old or new; and the highest of those */
  int *moved;
  double *moved_z;
  double *point_z;   /* each moved step's breakpoints' heights, template order */
  double *point_top; /* and the highest of them */
  int moved_count;
  double moved_top;
  long found_here; /* horizons found by the tests themselves */
} line_walk;

/* The steepest rise per step from an origin at oz of texel j to any moved
 * breakpoint along side k: each moved step's highest vertex at the
 * nearest distance its points can lie (along (a, b) past the step's start,
 * the first at first_frac; along (-a, -b) the step just behind reaches up
 * to its last point before the texel, a further one up to its end
 * vertex). Periodic lines go round. */
static double steepest(const pair_job *job, const line_walk *lw, int j, int k,
                       double oz) {
  double best = -INFINITY;
  const int L = lw->len, round = periodic(job->r->p);
  for (int q = 0; q < lw->moved_count; q++) {
    const int m = lw->moved[q];
    long steps = k == 0 ? (long)m - j : (long)j - 1 - m;
    if (steps < 0) {
      if (!round)
        continue;
      steps += L;
    }
    const double distance =
        k == 0 ? (double)steps + job->ext.first_frac
               : (steps >= 1 ? (double)steps : 1.0 - job->ext.last_inner_frac);
    const double slope = (lw->moved_z[q] - oz) / distance;
    if (slope > best)
      best = slope;
  }
  return best;
}

/* The largest slope per step from an origin at oz of texel j to a moved
 * breakpoint along side k, each computed as every path of the trace
 * computes it (march.h: from the crossing's integers). A moved step whose
 * highest vertex cannot beat the best so far is skipped. The origin vertex
 * itself (the end of the step just behind, along (-a, -b)) never counts. */
static double moved_slope(const pair_job *job, const line_walk *lw, int j, int k,
                          double oz) {
  const int L = lw->len, round = periodic(job->r->p), count = job->point_count;
  double best = -INFINITY;
  for (int q = 0; q < lw->moved_count; q++) {
    const int m = lw->moved[q];
    long steps = k == 0 ? (long)m - j : (long)j - m; /* whole steps from j to the step */
    if (steps < 0 || (k == 1 && steps == 0)) {
      if (!round)
        continue;
      steps += L;
    }
    /* the nearest any of its points can be, and so its steepest */
    const double near =
        k == 0 ? (double)steps + job->ext.first_frac
               : (steps > 1 ? (double)(steps - 1) : 1.0 - job->ext.last_inner_frac);
    if ((lw->point_top[q] - oz) / near <= best)
      continue;
    const double *z = lw->point_z + (size_t)q * (size_t)count;
    for (int e = 0; e < count; e++) {
      const bb__template_point *t = &job->points[e];
      const long n = k == 0 ? steps * t->m + t->i : steps * t->m - t->i;
      if (n <= 0)
        continue; /* the origin vertex */
      const double slope = (z[e] - oz) / bb__lattice_distance(n, t->inverse_m);
      if (slope > best)
        best = slope;
    }
  }
  return best;
}

/* Tests texel j (not changed) on side k, the nearest moved step `steps`
 * whole steps from it (-1: none): against the line's highest moved vertex
 * there, then against each moved step's. When those cannot tell, and the
 * moved breakpoints now rise clearly above the old horizon, the new one is
 * theirs: the points that did not move are no higher than the old horizon
 * (a tall new peak's shadow, found without a sweep). Otherwise the texel
 * is found again by a sweep. */
static inline void test_texel(const pair_job *job, line_walk *lw, int j, int k,
                              long steps) {
  if (steps < 0)
    return;
  const bb__retrace *r = job->r;
  const size_t t = lw->texel[j];
  const double oz = (double)r->p->z[t] + r->bias;
  float *kept = &r->horizons[job->slice[k]][t];
  const float h = *kept;
  const double distance =
      k == 0 ? (double)steps + job->ext.first_frac
             : (steps >= 1 ? (double)steps : 1.0 - job->ext.last_inner_frac);
  const double rise = lw->moved_top - oz;
  if (keeps(job, h, rise <= 0.0 ? rise : rise / distance))
    return;
  if (keeps(job, h, steepest(job, lw, j, k, oz)))
    return;
  const double top = moved_slope(job, lw, j, k, oz);
  if (top > 0.0 && top * job->inverse_length > (double)h * (1.0 + KEEP_MARGIN)) {
    const float found = bb__lattice_horizon(top, job->inverse_length);
    if (memcmp(&found, kept, sizeof found) != 0) {
      *kept = found;
      r->dirty[t] |= 1;
    }
    lw->found_here++;
    return;
  }
  lw->flags[j + lw->before] |= (unsigned char)(k == 0 ? FAIL_AHEAD : FAIL_BEHIND);
  lw->need[k][j] = lookahead_for(job, h, oz, lw->most);
}

/* A changed texel: both sides are found again. */
static void fail_changed(const pair_job *job, line_walk *lw, int j) {
  const bb__retrace *r = job->r;
  const size_t t = lw->texel[j];
  const double oz = (double)r->p->z[t] + r->bias;
  for (int k = 0; k < 2; k++)
    if (job->slice[k] >= 0) {
      lw->flags[j + lw->before] |= (unsigned char)(k == 0 ? FAIL_AHEAD : FAIL_BEHIND);
      lw->need[k][j] = lookahead_for(job, r->horizons[job->slice[k]][t], oz, lw->most);
    }
}

/* The tests of a periodic line of len texels (round: position j + len is
 * j), from a moved position p0. */
static void test_round(const pair_job *job, line_walk *lw, int p0) {
  const int L = lw->len;
  const unsigned char *f = lw->flags;
  if (job->slice[0] >= 0) { /* backwards from p0: the nearest moved step ahead */
    int next = p0, ahead = 0;
    for (int i = 0, j = p0; i < L; i++, j = j == 0 ? L - 1 : j - 1, ahead++) {
      if (f[j] & MOVED)
        next = j, ahead = 0;
      if (!(f[j] & CHANGED))
        test_texel(job, lw, j, 0, ahead);
    }
    (void)next;
  }
  if (job->slice[1] >= 0) { /* forwards from p0: the nearest moved step behind */
    int behind = -1;        /* steps from the last moved one, less one */
    for (int i = 1, j = p0 + 1 == L ? 0 : p0 + 1; i <= L;
         i++, j = j + 1 == L ? 0 : j + 1) {
      behind++;
      if (!(f[j] & CHANGED))
        test_texel(job, lw, j, 1, behind);
      if (f[j] & MOVED)
        behind = -1;
    }
  }
  for (int j = 0; j < L; j++)
    if (f[j] & CHANGED)
      fail_changed(job, lw, j);
}

/* The tests of a clamped line: positions -before .. len+after-1. */
static void test_ends(const pair_job *job, line_walk *lw) {
  const int L = lw->len, B = lw->before;
  const unsigned char *f = lw->flags + B;
  if (job->slice[0] >= 0) {
    long ahead = -1; /* steps to the nearest moved one; -1: none */
    for (int j = L + lw->after - 1; j >= 0; j--) {
      if (ahead >= 0)
        ahead++;
      if (f[j] & MOVED)
        ahead = 0;
      if (j < L && !(f[j] & CHANGED))
        test_texel(job, lw, j, 0, ahead);
    }
  }
  if (job->slice[1] >= 0) {
    long behind = -2; /* steps from the last moved one, less one; -2: none */
    for (int j = -B; j < L; j++) {
      if (behind >= -1)
        behind++;
      if (j >= 0 && !(f[j] & CHANGED))
        test_texel(job, lw, j, 1, behind < 0 ? -1 : behind);
      if (f[j] & MOVED)
        behind = -1;
    }
  }
  for (int j = 0; j < L; j++)
    if (f[j] & CHANGED)
      fail_changed(job, lw, j);
}

/* Texel j of the line whose texel 0 is (x, y): its coordinates. */
static void texel_at(const pair_job *job, const seed *sd, long j, int *x, int *y) {
  const bb_pyramid *p = job->r->p;
  long px = (long)sd->x + j * job->a, py = (long)sd->y + j * job->b;
  if (periodic(p))
    px = ((px % p->width) + p->width) % p->width,
    py = ((py % p->height) + p->height) % p->height;
  *x = (int)px, *y = (int)py;
}

/* A run of failed texels of a line, i0 .. i1 in the order from `start`. */
typedef struct run {
  int i0, i1;
  int ahead, behind; /* steps its profile must reach past i1, before i0 */
} run;

/* The failed texels of a line as stretches: a run goes on while the next
 * failed texel lies within the steps its profile reaches ahead anyway;
 * the steps a stretch reaches each way are the most its texels ask, for
 * the side they failed on (the others are not wanted). The whole line,
 * swept round, when the stretches would profile as many steps as it. */
static void stretches_of(const pair_job *job, const seed *sd, line_walk *lw,
                         line_out *out) {
  const bb_pyramid *p = job->r->p;
  const int L = lw->len, B = lw->before, round_line = periodic(p);
  const unsigned char *f = lw->flags + B;
  int start = 0; /* a periodic line's runs, from the end of its longest gap */
  int count = 0;
  if (round_line) {
    int first = -1, last = -1, best_gap = -1;
    for (int j = 0; j < L; j++) {
      if (!(f[j] & FAILED))
        continue;
      if (first < 0)
        first = j;
      if (last >= 0 && j - last > best_gap)
        best_gap = j - last, start = j;
      last = j;
      count++;
    }
    if (first < 0)
      return;
    if (first + L - last > best_gap)
      start = first;
  } else {
    for (int j = 0; j < L; j++)
      count += (f[j] & FAILED) != 0;
    if (!count)
      return;
  }
  run *runs = malloc((size_t)count * sizeof *runs);
  if (!runs) {
    out->failed = 1;
    return;
  }
  int nruns = 0;
  long steps = 0;
  for (int i = 0; i < L; i++) {
    const int j = start + i < L ? start + i : start + i - L;
    if (!(f[j] & FAILED))
      continue;
    const int need_ahead = (f[j] & FAIL_AHEAD) ? imax(lw->need[0][j], MIN_LOOKAHEAD) : 0;
    const int need_behind =
        (f[j] & FAIL_BEHIND) ? imax(lw->need[1][j], MIN_LOOKAHEAD) : 0;
    run *last = nruns ? &runs[nruns - 1] : NULL;
    if (last && i - last->i1 <= imax(last->ahead, MIN_LOOKAHEAD)) {
      last->ahead = imax(last->ahead - (i - last->i1), need_ahead);
      last->behind = imax(last->behind, need_behind - (i - last->i0));
      last->i1 = i;
    } else {
      runs[nruns++] = (run){i, i, need_ahead, need_behind};
    }
  }
  for (int q = 0; q < nruns; q++)
    steps += runs[q].i1 - runs[q].i0 + 1 + runs[q].ahead + runs[q].behind;
  if (round_line && L <= job->long_line && steps >= L) {
    out->round = 1;
    free(runs);
    return;
  }
  out->stretch = malloc((size_t)nruns * sizeof *out->stretch);
  out->want = malloc((size_t)count + (size_t)L);
  if (!out->stretch || !out->want) {
    out->failed = 1;
    free(runs);
    return;
  }
  unsigned char *want = out->want;
  for (int q = 0; q < nruns; q++) {
    const run *u = &runs[q];
    const int len = u->i1 - u->i0 + 1,
              j0 = start + u->i0 < L ? start + u->i0 : start + u->i0 - L;
    bb__stretch st = {0, 0, len, u->behind, u->ahead, 0, 0, want};
    texel_at(job, sd, j0, &st.x, &st.y);
    for (int i = 0; i < len; i++) {
      const int j = j0 + i < L ? j0 + i : j0 + i - L;
      want[i] =
          (unsigned char)(((f[j] & FAIL_AHEAD) ? 1 : 0) | ((f[j] & FAIL_BEHIND) ? 2 : 0));
    }
    want += len;
    if (!round_line) { /* the line's own profile is exact on the side it reaches */
      const int behind = j0 + B, ahead = (L - 1 - (j0 + len - 1)) + lw->after;
      st.exact_behind = st.before >= behind, st.exact_ahead = st.after >= ahead;
      st.before = imin(st.before, behind), st.after = imin(st.after, ahead);
    } else if (st.before > job->long_line || st.after > job->long_line) {
      /* a line too long to sweep round: a chunk's look-ahead, marches past it */
      st.before = imin(st.before, (int)job->long_line);
      st.after = imin(st.after, (int)job->long_line);
    }
    out->stretch[out->count++] = st;
  }
  free(runs);
}

/* The highest vertex a step from position (x, y) reads (its template's
 * whole rectangle), old or new, a little above (a breakpoint between two
 * vertices may round a little above both). */
static double step_top(const pair_job *job, long x, long y) {
  const bb__retrace *r = job->r;
  const bb_pyramid *p = r->p;
  const bb__template_extent *e = &job->ext;
  double top = -INFINITY;
  for (int dy = e->min_dy; dy <= e->max_dy; dy++)
    for (int dx = e->min_dx; dx <= e->max_dx; dx++) {
      const int vx = bb__address((int)(x + dx), p->width, p->addressing);
      const int vy = bb__address((int)(y + dy), p->height, p->addressing);
      double z = (double)p->z[(size_t)vy * (size_t)p->width + (size_t)vx];
      if (changed_texel(r, vx, vy)) {
        int i = vx - r->x0, j = vy - r->y0;
        if (i < 0)
          i += p->width;
        if (j < 0)
          j += p->height;
        const double old = (double)r->old_z[(size_t)j * (size_t)r->width + (size_t)i];
        if (old > z)
          z = old;
      }
      if (z > top)
        top = z;
    }
  return top + (fabs(top) + 1.0) * 1e-12;
}

/* The moved steps of a walked line and their heights (lw->moved); 0 when
 * out of memory. Their breakpoints' heights are those the sweeps compute
 * (bb__lattice_height of the template's vertices). */
static int moved_heights(const pair_job *job, const seed *sd, line_walk *lw) {
  const bb_pyramid *p = job->r->p;
  const int first = periodic(p) ? 0 : -lw->before, end = lw->len + lw->after;
  const int points = job->point_count;
  int count = 0;
  for (int j = first; j < end; j++)
    count += lw->flags[j + lw->before] & MOVED;
  lw->moved = malloc((size_t)count * sizeof *lw->moved + 1);
  lw->moved_z = malloc((size_t)count * sizeof *lw->moved_z + 1);
  lw->point_z = malloc((size_t)count * (size_t)points * sizeof *lw->point_z + 1);
  lw->point_top = malloc((size_t)count * sizeof *lw->point_top + 1);
  if (!lw->moved || !lw->moved_z || !lw->point_z || !lw->point_top)
    return 0;
  lw->moved_top = -INFINITY;
  for (int j = first; j < end; j++) {
    if (!(lw->flags[j + lw->before] & MOVED))
      continue;
    long x = (long)sd->x + (long)j * job->a, y = (long)sd->y + (long)j * job->b;
    if (periodic(p)) {
      int xi, yi;
      texel_at(job, sd, j, &xi, &yi);
      x = xi, y = yi;
    }
    const int q = lw->moved_count++;
    lw->moved[q] = j;
    lw->moved_z[q] = step_top(job, x, y);
    if (lw->moved_z[q] > lw->moved_top)
      lw->moved_top = lw->moved_z[q];
    double *z = lw->point_z + (size_t)q * (size_t)points, top = -INFINITY;
    for (int e = 0; e < points; e++) {
      const bb__template_point *t = &job->points[e];
      const int x1 = bb__address((int)x + t->x1, p->width, p->addressing);
      const int y1 = bb__address((int)y + t->y1, p->height, p->addressing);
      const int x2 = bb__address((int)x + t->x2, p->width, p->addressing);
      const int y2 = bb__address((int)y + t->y2, p->height, p->addressing);
      z[e] = bb__lattice_height((double)p->z[(size_t)y1 * (size_t)p->width + (size_t)x1],
                                (double)p->z[(size_t)y2 * (size_t)p->width + (size_t)x2],
                                t->w);
      if (z[e] > top)
        top = z[e];
    }
    lw->point_top[q] = top;
  }
  return 1;
}

/* One line of the pair (work item): walked, tested, its stretches made. */
static void line_item(void *user, int i) {
  pair_job *job = user;
  const bb_pyramid *p = job->r->p;
  const seed *sd = &job->seeds[i];
  line_out *out = &job->out[i];
  line_walk lw = {.len = sd->len};
  if (!periodic(p))
    bb__clamped_line_extent(p, job->a, job->b, sd->x, sd->y, sd->len, &lw.before,
                            &lw.after);
  lw.most = periodic(p) ? sd->len : lw.before + sd->len + lw.after;
  const int positions = lw.before + lw.len + lw.after;
  lw.texel = malloc((size_t)lw.len * sizeof *lw.texel);
  lw.flags = calloc((size_t)positions, 1);
  lw.need[0] = malloc((size_t)lw.len * sizeof(int));
  lw.need[1] = malloc((size_t)lw.len * sizeof(int));
  int p0 = -1, heights = 0;
  if (!lw.texel || !lw.flags || !lw.need[0] || !lw.need[1]) {
    out->failed = 1;
  } else if (periodic(p)) {
    const int w = p->width, h = p->height, sa = job->a % w, sb = job->b % h;
    for (int j = 0, x = sd->x, y = sd->y; j < lw.len;
         j++, x = bb__wrap_near(x + sa, w), y = bb__wrap_near(y + sb, h)) {
      lw.texel[j] = (size_t)y * (size_t)w + (size_t)x;
      const unsigned char f =
          (unsigned char)((moved_step(job, x, y) ? MOVED : 0) |
                          (changed_texel(job->r, x, y) ? CHANGED : 0));
      lw.flags[j] = f;
      if ((f & MOVED) && p0 < 0)
        p0 = j;
    }
    if (p0 >= 0 && (heights = moved_heights(job, sd, &lw)))
      test_round(job, &lw, p0);
  } else {
    for (int j = -lw.before; j < lw.len + lw.after; j++) {
      const long x = (long)sd->x + (long)j * job->a, y = (long)sd->y + (long)j * job->b;
      unsigned char f = moved_step(job, x, y) ? MOVED : 0;
      if (j >= 0 && j < lw.len) {
        lw.texel[j] = (size_t)y * (size_t)p->width + (size_t)x;
        if (changed_texel(job->r, (int)x, (int)y))
          f |= CHANGED;
      }
      lw.flags[j + lw.before] = f;
      if (f & MOVED)
        p0 = 0;
    }
    if (p0 >= 0 && (heights = moved_heights(job, sd, &lw)))
      test_ends(job, &lw);
  }
  if (p0 >= 0 && !heights)
    out->failed = 1, p0 = -1;
  if (p0 >= 0)
    stretches_of(job, sd, &lw, out);
  free(lw.texel);
  free(lw.flags);
  free(lw.need[0]);
  free(lw.need[1]);
  free(lw.moved);
  free(lw.moved_z);
  free(lw.point_z);
  free(lw.point_top);
  out->found_here = lw.found_here;
}

static int seed_order(const void *pa, const void *pb) {
  const seed *a = pa, *b = pb;
  if (a->y != b->y)
    return a->y < b->y ? -1 : 1;
  return (a->x > b->x) - (a->x < b->x);
}

/* A clamped line through (x, y): its first texel and its texels. */
static seed clamped_seed(const bb_pyramid *p, int a, int b, int x, int y) {
  /* steps back, and then forward, until the next would leave the image */
  long back = LONG_MAX, ahead = LONG_MAX;
  if (a > 0)
    back = x / a;
  if (a < 0)
    back = (p->width - 1 - x) / -a;
  if (b > 0)
    back = back < y / b ? back : y / b;
  if (b < 0)
    back = back < (p->height - 1 - y) / -b ? back : (p->height - 1 - y) / -b;
  const int x0 = (int)(x - back * a), y0 = (int)(y - back * b);
  if (a > 0)
    ahead = (p->width - 1 - x0) / a;
  if (a < 0)
    ahead = x0 / -a;
  if (b > 0)
    ahead = ahead < (p->height - 1 - y0) / b ? ahead : (p->height - 1 - y0) / b;
  if (b < 0)
    ahead = ahead < y0 / -b ? ahead : y0 / -b;
  return (seed){x0, y0, (int)ahead + 1};
}

/* Appends the seeds of the lines through the texels of a rectangle (in the
 * image) to job->seeds; with skip_inner, not those of texels whose previous
 * texel lies in the rectangle too (the line is found there, if it leaves
 * the rectangle at all). */
static void seeds_of_rect(pair_job *job, int x0, int y0, int dw, int dh, int skip_inner) {
  const bb_pyramid *p = job->r->p;
  const int w = p->width, h = p->height;
  const int leaves = (job->b != 0 && dh < h) || (job->a != 0 && dw < w);
  for (int j = 0; j < dh; j++)
    for (int i = 0; i < dw; i++) {
      int x = x0 + i, y = y0 + j;
      seed sd;
      if (periodic(p)) {
        x = bb__wrap_near(x, w), y = bb__wrap_near(y, h);
        const int bx = bb__wrap(x - job->a, w), by = bb__wrap(y - job->b, h);
        if (skip_inner && leaves && (dw >= w || in_wrapped(bx, x0, dw, w)) &&
            (dh >= h || in_wrapped(by, y0, dh, h)))
          continue;
        bb__line_seed(p, job->a, job->b, x, y, &sd.x, &sd.y);
        sd.len = (int)job->period;
      } else {
        const int bx = x - job->a, by = y - job->b;
        if (skip_inner && bx >= x0 && bx < x0 + dw && by >= y0 && by < y0 + dh)
          continue;
        sd = clamped_seed(p, job->a, job->b, x, y);
      }
      job->seeds[job->seed_count++] = sd;
    }
}

/* The lines whose steps read a changed vertex, each once: those through
 * the rectangle of texels whose steps can (the changed one moved back by
 * the template's extent). On a clamped map, a line's steps past its ends
 * read the border's vertices, and run on along the border until both
 * coordinates have turned flat: so when the change lies within reach of a
 * border, every line ending or starting in a band along that border is
 * taken too. */
static bb_status find_lines(pair_job *job, bb_error *err) {
  const bb__retrace *r = job->r;
  const bb_pyramid *p = r->p;
  const bb__template_extent *e = &job->ext;
  const int w = p->width, h = p->height, a = abs(job->a), b = abs(job->b);
  int x0 = r->x0 - e->max_dx, y0 = r->y0 - e->max_dy;
  int dw = r->width + e->max_dx - e->min_dx, dh = r->height + e->max_dy - e->min_dy;
  /* the border bands (clamp): left, right, top, bottom */
  int band[4][4], bands = 0;
  if (periodic(p)) {
    x0 = bb__wrap(x0, w), y0 = bb__wrap(y0, h);
    dw = imin(dw, w), dh = imin(dh, h);
  } else {
    const int x1 = imin(x0 + dw, w), y1 = imin(y0 + dh, h);
    x0 = imax(x0, 0), y0 = imax(y0, 0);
    dw = imax(x1 - x0, 0), dh = imax(y1 - y0, 0);
    const int reach_x = e->max_dx - e->min_dx + a + 1,
              reach_y = e->max_dy - e->min_dy + b + 1;
    const int bx = imin(reach_x + a, w), by = imin(reach_y + b, h);
    if (r->x0 <= reach_x)
      band[bands][0] = 0, band[bands][1] = 0, band[bands][2] = bx, band[bands++][3] = h;
    if (r->x0 + r->width - 1 >= w - 1 - reach_x)
      band[bands][0] = w - bx, band[bands][1] = 0, band[bands][2] = bx,
      band[bands++][3] = h;
    if (r->y0 <= reach_y)
      band[bands][0] = 0, band[bands][1] = 0, band[bands][2] = w, band[bands++][3] = by;
    if (r->y0 + r->height - 1 >= h - 1 - reach_y)
      band[bands][0] = 0, band[bands][1] = h - by, band[bands][2] = w,
      band[bands++][3] = by;
  }
  size_t most = (size_t)dw * (size_t)dh;
  for (int i = 0; i < bands; i++)
    most += (size_t)band[i][2] * (size_t)band[i][3];
  job->seeds = malloc((most ? most : 1) * sizeof *job->seeds);
  if (!job->seeds)
    return bb__fail(err, BB_ERR_MEMORY, "retrace: out of memory");
  job->seed_count = 0;
  seeds_of_rect(job, x0, y0, dw, dh, 1);
  for (int i = 0; i < bands; i++)
    seeds_of_rect(job, band[i][0], band[i][1], band[i][2], band[i][3], 1);
  const int n = job->seed_count;
  qsort(job->seeds, (size_t)n, sizeof *job->seeds, seed_order);
  int unique = 0;
  for (int i = 0; i < n; i++)
    if (unique == 0 || seed_order(&job->seeds[unique - 1], &job->seeds[i]) != 0)
      job->seeds[unique++] = job->seeds[i];
  job->seed_count = unique;
  return BB_OK;
}

/* The line hook: each horizon found that differs from the kept one is
 * written, its texel marked. */
typedef struct hook_ctx {
  float *const *horizons;
  unsigned char *dirty;
} hook_ctx;

static void write_found(void *user, const bb__line_view *line) {
  const hook_ctx *c = user;
  for (int k = 0; k < 2; k++) {
    if (!line->dir[k] || !line->found[k])
      continue;
    float *kept = c->horizons[line->dir[k]->slice];
    for (int j = 0; j < line->len; j++) {
      if (line->want && !(line->want[j] & (1 << k)))
        continue;
      const size_t t = line->texel[j];
      if (memcmp(&kept[t], &line->found[k][j], sizeof(float)) != 0) {
        kept[t] = line->found[k][j];
        c->dirty[t] |= 1;
      }
    }
  }
}

/* The stretches and whole lines of every line of the pair, swept. */
static bb_status sweep_pair(pair_job *job, double *found, bb_error *err) {
  const bb__retrace *r = job->r;
  int stretches = 0, rounds = 0;
  for (int i = 0; i < job->seed_count; i++) {
    if (job->out[i].failed)
      return bb__fail(err, BB_ERR_MEMORY, "retrace: out of memory");
    stretches += job->out[i].count;
    rounds += job->out[i].round;
  }
  bb__stretch *st = malloc((size_t)imax(stretches + rounds, 1) * sizeof *st);
  if (!st)
    return bb__fail(err, BB_ERR_MEMORY, "retrace: out of memory");
  int n = 0;
  for (int i = 0; i < job->seed_count; i++)
    for (int k = 0; k < job->out[i].count; k++)
      st[n++] = job->out[i].stretch[k];
  for (int i = 0; i < job->seed_count; i++)
    if (job->out[i].round)
      st[n++] = (bb__stretch){
          job->seeds[i].x, job->seeds[i].y, job->seeds[i].len, 0, 0, 1, 1, NULL};
  const bb__sweep_dir along = {r->rs, job->slice[0], NULL, NULL};
  const bb__sweep_dir opposite = {r->rs, job->slice[1], NULL, NULL};
  const bb__sweep_dir *dir0 = job->slice[0] >= 0 ? &along : NULL;
  const bb__sweep_dir *dir1 = job->slice[1] >= 0 ? &opposite : NULL;
  hook_ctx hc = {r->horizons, r->dirty};
  bb_status st_ =
      bb__sweep_stretches(r->p, job->a, job->b, dir0, dir1, r->bias, r->threads, st,
                          stretches, 0, write_found, &hc, err);
  if (st_ == BB_OK)
    st_ = bb__sweep_stretches(r->p, job->a, job->b, dir0, dir1, r->bias, r->threads,
                              st + stretches, rounds, 1, write_found, &hc, err);
  for (int i = 0; i < n; i++)
    *found += (double)st[i].len * ((dir0 != NULL) + (dir1 != NULL));
  for (int i = 0; i < job->seed_count; i++)
    *found += (double)job->out[i].found_here;
  free(st);
  return st_;
}

static int opposite_steps(const bb_rayset *rs, int s, int t) {
  return rs->slice_step[2 * s] == -rs->slice_step[2 * t] &&
         rs->slice_step[2 * s + 1] == -rs->slice_step[2 * t + 1];
}

static bb_status retrace_pair(bb__retrace *r, int s, int t, bb_error *err) {
  pair_job job = {.r = r,
                  .a = r->rs->slice_step[2 * s],
                  .b = r->rs->slice_step[2 * s + 1],
                  .slice = {s, t}};
  bb__sweep_template_extent(job.a, job.b, &job.ext);
  bb__template_point points[4 * BB__MAX_LATTICE_STEP + 1];
  job.points = points;
  job.point_count = bb__sweep_template(job.a, job.b, points);
  job.inverse_length = bb__step_inverse(job.a, job.b);
  if (periodic(r->p)) {
    const int w = r->p->width, h = r->p->height;
    job.period = bb__line_period(r->p, job.a, job.b);
    job.long_line = bb__sweep_long_line(job.a, job.b);
    /* the steps that read the rectangle: those in it, moved back by the extent */
    job.move_x0 = bb__wrap(r->x0 - job.ext.max_dx, w);
    job.move_y0 = bb__wrap(r->y0 - job.ext.max_dy, h);
    job.move_w = imin(r->width + job.ext.max_dx - job.ext.min_dx, w);
    job.move_h = imin(r->height + job.ext.max_dy - job.ext.min_dy, h);
  }
  bb_status st = find_lines(&job, err);
  if (st == BB_OK) {
    job.out = calloc((size_t)imax(job.seed_count, 1), sizeof *job.out);
    if (!job.out)
      st = bb__fail(err, BB_ERR_MEMORY, "retrace: out of memory");
  }
  if (st == BB_OK)
    st = bb__parallel_for(job.seed_count, r->threads, line_item, &job, NULL, NULL, err);
  if (st == BB_OK)
    st = sweep_pair(&job, &r->horizons_found, err);
  if (job.out)
    for (int i = 0; i < job.seed_count; i++)
      free(job.out[i].stretch), free(job.out[i].want);
  free(job.out);
  free(job.seeds);
  return st;
}

bb_status bb__retrace_run(bb__retrace *r, bb_error *err) {
  const bb_rayset *rs = r->rs;
  r->horizons_found = 0.0;
  if (r->width <= 0 || r->height <= 0)
    return BB_OK;
  bb_status st = BB_OK;
  for (int k = 0; st == BB_OK && k < rs->slice_count;) {
    const int s = r->order[k];
    const int pair = k + 1 < rs->slice_count && opposite_steps(rs, s, r->order[k + 1]);
    st = retrace_pair(r, s, pair ? r->order[k + 1] : -1, err);
    k += pair ? 2 : 1;
    if (st == BB_OK && r->progress && r->progress(r->progress_user, k, rs->slice_count))
      st = bb__fail(err, BB_ERR_CANCELLED, "trace: cancelled by the progress callback");
  }
  return st;
}
