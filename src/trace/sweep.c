/* sweep.c: the horizons of every texel for a lattice slice direction and its
 * opposite, by sweeps along each line of texels, integrated on the spot.
 *
 * A slice follows a lattice step (a, b) (coprime integers), so texel P and
 * P + j (a, b) lie on one line, and so do all the breakpoints of the surface
 * between them: crossings of vertical lines, horizontal lines and the
 * diagonals x + y = k of Valve's triangles. Between two texels of the line
 * the breakpoints sit at the same fractions of the step for every step (the
 * "template"), so a line is a sequence of points (u, z), u = distance in
 * steps: the line's profile. A texel's horizon in that direction is the
 * largest slope from its origin (u_P, z_P + bias) to a point ahead, which is
 * the tangent from the origin to the upper convex hull of the points ahead:
 * walking the line backwards, each point is pushed onto a hull stack once,
 * and each texel asks the stack for its tangent by a short walk from its
 * near end. The tangent's slope is then computed from integers exactly as
 * the march computes it (march.h), and what the slice loses to it
 * is added to the texel's sums: no per-slice buffer is kept.
 *
 * The opposite direction (-a, -b) runs along the same lines through the same
 * breakpoints, so one profile serves both: the sweep for (a, b) walks it
 * backwards, the sweep for (-a, -b) forwards (on mirrored u).
 *
 * Where a line ends:
 * - Periodic lines close after their period L. A point at u + L is the point
 *   at u again, farther away, so nothing beyond one period can be steeper.
 *   Better: nothing beyond the line's highest point P* is steeper than P*
 *   from behind it, so a line is swept once round, starting at P*, with the
 *   hull holding P* alone: one period of points, no look-ahead.
 * - Clamped lines (clamp mode) run from edge to edge; past the image the
 *   profile reads the clamped vertices (the border extruded) until it turns
 *   flat, and a flat stretch holds nothing steeper than its first point.
 * - Periodic lines longer than long_line steps (images whose sides share
 *   few factors) are cut into chunks with a look-ahead of one chunk each way.
 *   A texel whose horizon is not clearly above anything the points beyond
 *   the look-ahead could reach (global max over their nearest distance) is
 *   marched instead, which gives the same bits.
 * Lines (and chunks) are independent, so they run on all threads; each
 * texel is written by one of them per slice, in the slices' fixed order.
 */

#include "trace/sweep.h"
#include "core/internal.h"
#include "trace/integrate.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { CHUNK_STEPS = 4096 };
/* Periodic lines of more points than this are swept in chunks. */
#define LONG_LINE_POINTS (1L << 20)

/* A breakpoint of one step (sweep.h). */
typedef bb__template_point template_point;

/* One direction of a sweep with its slice's step. */
typedef struct sweep_side {
  const bb__sweep_dir *dir; /* NULL: this direction is not wanted */
  int a, b;                 /* its own lattice step */
  double inverse_length;    /* bb__step_inverse(a, b) */
  bb__slice_integral integral;
} sweep_side;

/* Whole periodic lines swept once round; chunks of long periodic lines;
 * whole clamped lines; a caller's stretches (bb__sweep_stretches). */
typedef enum line_kind { LINE_ROUND, LINE_CHUNK, LINE_CLAMPED, LINE_STRETCH } line_kind;

typedef struct sweep_job {
  const bb_pyramid *p;
  int a, b;
  template_point *points; /* the step's breakpoints, the next texel last */
  int point_count;
  line_kind kind;
  const int *item_x, *item_y,
      *item_len; /* first texel and texels of each line or chunk */
  int item_count;
  const bb__stretch *stretch; /* LINE_STRETCH: each item's extent and exact sides */
  long period;    /* periodic: steps of a line */
  int lookahead;  /* chunks: steps profiled past each end */
  double bias;
  int channels;         /* floats per texel in the sums */
  sweep_side side[2];   /* along (a, b) and along (-a, -b) */
  int reach_x, reach_y; /* how far template vertices lie from a step's texel */
  /* the template's offsets, fractions and weights, each in one array */
  long offset1[4 * BB__MAX_LATTICE_STEP + 1], offset2[4 * BB__MAX_LATTICE_STEP + 1];
  double frac[4 * BB__MAX_LATTICE_STEP + 1], weight[4 * BB__MAX_LATTICE_STEP + 1];
  int min_dx, max_dx, min_dy, max_dy; /* template vertex offsets */
  atomic_int out_of_memory;
  /* set when the checkpoint cancels: the bundles running stop at their next
   * line (a walked line can take tens of ms, a bundle seconds) */
  atomic_int cancelled;
  const bb__checkpoint *checkpoint; /* the caller's (job_run) */
  double *open_a, *open_b; /* where the wider chords apply (job_chords) */
  bb__line_hook hook;      /* NULL: the sums; else called per line */
  void *hook_ctx;
  bb__channels4 *table4; /* both sides' tables by channels (integrate.h), when 3 lobes */
  struct scratch *scratch; /* a slot per thread (sweep_bundle) */
  int scratch_count;
  const bb__walk_visitor *visitor; /* NULL: the sums or the hook */
  void *visitor_ctx;
} sweep_job;

static int cmp_frac(const void *pa, const void *pb) {
  const double a = ((const template_point *)pa)->frac,
               b = ((const template_point *)pb)->frac;
  return a < b ? -1 : a > b;
}

static inline long floor_div(long num, long den) { /* den > 0 */
  const long q = num / den;
  return q * den > num ? q - 1 : q;
}

static inline int sign(int v) {
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

static template_point template_at(int m, int i, long r, int x1, int y1, int x2, int y2) {
  const double inverse = bb__lattice_inverse(m);
  return (template_point){
      (double)i / m, m, i, inverse, bb__lattice_weight(r, inverse), x1, y1, x2, y2, 0, 0};
}

/* Breakpoints of the step from (0, 0) to (a, b), sorted by u, computed from
 * integers as the march computes them (trace.c: lattice_*). For coprime
 * (a, b) the three families meet only at the step's end, the next texel,
 * which is kept once, as the vertex itself. */
static int build_template(int a, int b, template_point *out) {
  int n = 0;
  const int ma = abs(a), mb = abs(b), md = abs(a + b);
  for (int i = 1; i < ma; i++) { /* vertical lines x = X */
    const long num = (long)i * b, row = floor_div(num, ma);
    const int X = i * sign(a);
    out[n++] = template_at(ma, i, num - row * ma, X, (int)row, X, (int)row + 1);
  }
  for (int i = 1; i < mb; i++) { /* horizontal lines y = Y */
    const long num = (long)i * a, col = floor_div(num, mb);
    const int Y = i * sign(b);
    out[n++] = template_at(mb, i, num - col * mb, (int)col, Y, (int)col + 1, Y);
  }
  for (int i = 1; i < md; i++) { /* diagonals x + y = K, from (c+1, K-1-c) to (c, K-c) */
    const long num = (long)i * a, col = floor_div(num, md);
    const int row = i * sign(a + b) - 1 - (int)col;
    out[n++] =
        template_at(md, i, md - (num - col * md), (int)col + 1, row, (int)col, row + 1);
  }
  out[n++] = template_at(1, 1, 0, a, b, a, b); /* the next texel */
  qsort(out, (size_t)n, sizeof *out, cmp_frac);
  return n;
}

static inline int imax(int a, int b) {
  return a > b ? a : b;
}

static inline int imin(int a, int b) {
  return a < b ? a : b;
}

/* ------------------------------------------------------------- profiles */

/* A point of a profile or a hull: where it is (u, in steps from the line's
 * texel 0, or mirrored), its height, and for the exact slope its key: the
 * step it belongs to and its template point, step * KEY_STEP + tp (a shift
 * of the step by d adds d * KEY_STEP). Fields are stored one by one: a copy
 * of the whole struct costs shuffles between registers. */
typedef bb__walk_point point;

#define KEY_STEP BB__KEY_STEP /* > 4 * BB__MAX_LATTICE_STEP + 1 template points */

static inline int64_t key_of(int step, int tp) {
  return (int64_t)step * KEY_STEP + tp;
}
static inline int key_step(int64_t key) { /* floors: tp >= 0 */
  return (int)(key >> 10);
}
static inline int key_tp(int64_t key) {
  return (int)(key & (KEY_STEP - 1));
}

/* The points of a line (or chunk) that can matter, by rising u: step
 * first_step + s covers u in (first_step + s, first_step + s + 1]. Origins
 * are the texels 0 .. len-1, of height vz[j] and image index texel[j]. */
typedef struct profile {
  int first_step, steps, len;
  int count;
  int top; /* the first point of the greatest height */
  point *pt;
  double *vz;
  size_t *texel;
  float *found[2]; /* each texel's horizon along (a, b) and along (-a, -b) */
  /* what each texel's walk found: the tangent vertex's height and its key
   * relative to the origin's step, turned into horizons after the walks
   * (horizons_of_line) */
  double *tangent_z[2];
  int64_t *tangent_key[2];
  /* per side (0: ahead, 1: behind): is a horizon that the points beyond
   * the profile could beat marched instead (chunks, a caller's stretches)? */
  int vouch[2];
  const unsigned char *want; /* a caller's stretch: bb__stretch.want, or NULL */
} profile;

/* The points of a block of steps of one line (profile_fill) or of LANES
 * lines side by side (profile_fill_lanes), for the kink filter. */
typedef struct fill_block {
  double *u;     /* the points' u, the same for every line */
  double *z;     /* their heights, point-major, the lines side by side */
  double *rise;  /* likewise; a point is kept when > 0 */
  int64_t *key;  /* lines side by side: the points' keys */
  int64_t *kept; /* lines side by side: a bit per point and line */
} fill_block;

/* Height of vertex (x, y) through the addressing; periodic coordinates lie
 * within a few periods of the image, clamped ones anywhere. */
static inline double field_z(const bb_pyramid *p, int x, int y) {
  if (p->addressing == BB_ADDRESS_PERIODIC)
    return (double)p->z[(size_t)bb__wrap_near(y, p->height) * (size_t)p->width +
                        (size_t)bb__wrap_near(x, p->width)];
  return (double)p->z[(size_t)bb__clampi(y, 0, p->height - 1) * (size_t)p->width +
                      (size_t)bb__clampi(x, 0, p->width - 1)];
}

/* A coordinate along an axis of n texels, and one lattice step from it:
 * periodic coordinates stay in [0, n), clamped ones (clamp mode) run on past
 * the edges. */
static inline int coordinate_at(const bb_pyramid *p, long v, int n) {
  return p->addressing == BB_ADDRESS_PERIODIC ? bb__wrap((int)(v % n), n) : (int)v;
}

/* step is already reduced (|step| < n) in periodic mode */
static inline int step_along(const bb_pyramid *p, int v, int step, int n) {
  return p->addressing == BB_ADDRESS_PERIODIC ? bb__wrap_near(v + step, n) : v + step;
}

/* The heights of the points of the step from texel (bx, by), in template
 * order. Away from the edges no vertex wraps or clamps, and each is a fixed
 * offset. */
static inline void step_heights(const sweep_job *job, int bx, int by, double *zs) {
  const bb_pyramid *p = job->p;
  const int tcount = job->point_count;
  if (bx >= job->reach_x && bx < p->width - job->reach_x && by >= job->reach_y &&
      by < p->height - job->reach_y) {
    const float *here = p->z + (size_t)by * (size_t)p->width + (size_t)bx;
    const long *const off1 = job->offset1, *const off2 = job->offset2;
    const double *const weight = job->weight;
    for (int k = 0; k < tcount; k++)
      zs[k] = bb__lattice_height(here[off1[k]], here[off2[k]], weight[k]);
  } else {
    for (int k = 0; k < tcount; k++) {
      const template_point *t = &job->points[k];
      zs[k] = bb__lattice_height(field_z(p, bx + t->x1, by + t->y1),
                                 field_z(p, bx + t->x2, by + t->y2), job->weight[k]);
    }
  }
}

/* The points of steps first_step .. first_step + steps - 1 of the line whose
 * texel 0 is (x0, y0), without those that can never decide a horizon.
 *
 * A point T on or under the chord of its neighbours L < T < X never does:
 * from an origin outside [L, X] the farther of L, X on the side of T's
 * slope is at least as steep; from an origin at L (or X, looking back),
 * which sits at or above its vertex (bias >= 0), X (or L) is. A run of such
 * points lies under the chord of the points kept around it (the profile is
 * convex along the run), so dropping them all at once is safe too. Half the
 * points go on rough maps, without a branch: each point is stored, and the
 * count moves on past it only when it is kept. (Keeping only each step's
 * upper hull would drop 42% of those kept, but the stack that finds it is
 * a chain through memory at every point and cost more than the walks save.)
 * Two wider chords, i-2..i+1 and i-1..i+2, are tested the same way where
 * both their ends lie in T's own step (its start vertex included): no
 * origin lies strictly between them, so the argument holds, and they drop a
 * fifth of the points the first test keeps. So does the chord of the whole
 * step, from its start vertex to its end vertex: it drops a sixth of what is
 * left (rock06: 39% of the breakpoints kept before it, 32% after). The ends
 * are kept. */
/* Steps whose points are made before the kink filter runs over them: their
 * heights and u first, then the chord test of every point at once (a loop
 * the compiler vectorises), then the kept points, copied out in order. */
enum { BLOCK_STEPS = 32 };

/* profile_fill's loops are vectorised; where the processor has AVX2
 * (chosen when the library loads) they run 4 doubles a vector instead of 2.
 * The same IEEE operations either way (no contraction), so the same bits. */
#if defined(__x86_64__) && defined(__GNUC__) && defined(__linux__)
#define PROFILE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define PROFILE_CLONES
#endif

static inline void put_point(point *pt, double u, double z, int64_t key) {
  pt->u = u, pt->z = z, pt->key = key;
}

/* How far T = (um, zm) rises above the chord from L = (ul, zl) to
 * R = (ur, zr), times the chord's width: T is kept when that is > 0 (a
 * difference of doubles is 0 only when they are equal, and keeps its
 * sign). The heights may be vectors of lines side by side (profile_fill_lanes),
 * the u are the same for all of them. */
#define CHORD_RISE(zl, zm, zr, ul, um, ur)                                               \
  (((zm) - (zl)) * ((ur) - (ul)) - ((zr) - (zl)) * ((um) - (ul)))

/* Copies the points of steps s0 .. s1-1 of the block out of the block
 * arrays (the step s0 starts at index base) and moves the count on past
 * those kept; the block's last point is left for the next block. */
static inline int keep_points(const sweep_job *job, const fill_block *fb,
                              const profile *pr, int s0, int s1, int base, int count) {
  const int tcount = job->point_count;
  const double *restrict u = fb->u, *restrict z = fb->z;
  const double *restrict rise = fb->rise;
  point *restrict out = pr->pt;
  for (int s = s0; s < s1; s++, base += tcount) {
    const int64_t key = key_of(pr->first_step + s, 0);
    const int last = s == s1 - 1 ? tcount - 1 : tcount;
    for (int k = 0; k < last; k++) {
      put_point(&out[count], u[base + k], z[base + k], key + k);
      count += rise[base + k] > 0.0;
    }
  }
  return count;
}

/* The first point of the greatest height among pt[0 .. to-1], given best,
 * that of pt[0 .. from-1] (0 when from is 0). Run on each block's points
 * while they are in the cache. */
static int highest_point(const point *pt, int from, int to, int best) {
  if (from == 0) {
    if (to == 0)
      return 0;
    best = 0, from = 1;
  }
  double best_z = pt[best].z;
  for (int q = from; q < to; q++)
    if (pt[q].z > best_z)
      best = q, best_z = pt[q].z;
  return best;
}

PROFILE_CLONES
static void profile_fill(const sweep_job *job, const fill_block *fb, int x0, int y0,
                         profile *pr) {
  const bb_pyramid *p = job->p;
  const int tcount = job->point_count;
  const double *const frac = job->frac;
  int bx = coordinate_at(p, (long)x0 + (long)pr->first_step * job->a, p->width);
  int by = coordinate_at(p, (long)y0 + (long)pr->first_step * job->b, p->height);
  const int periodic = p->addressing == BB_ADDRESS_PERIODIC;
  const int sa = periodic ? job->a % p->width : job->a,
            sb = periodic ? job->b % p->height : job->b;
  double *restrict u = fb->u, *restrict z = fb->z;
  double *restrict rise = fb->rise;
  int count = 0, top = 0;
  int n = 0; /* points in the block arrays: two carried over (after the first
              * block), then the block's */
  for (int s0 = 0; s0 < pr->steps; s0 += BLOCK_STEPS) {
    const int s1 = imin(s0 + BLOCK_STEPS, pr->steps), base = n;
    for (int s = s0; s < s1; s++, bx = step_along(p, bx, sa, p->width),
             by = step_along(p, by, sb, p->height)) {
      const int j = pr->first_step + s; /* texel of the line at the step's start */
      if (j >= 0 && j < pr->len) {
        pr->vz[j] = field_z(p, bx, by);
        pr->texel[j] = (size_t)by * (size_t)p->width + (size_t)bx;
      }
      step_heights(job, bx, by, z + n);
      const double ju = (double)j;
      for (int k = 0; k < tcount; k++)
        u[n + k] = ju + frac[k];
      n += tcount;
    }
    /* point i is kept when above the chord of its neighbours, a form the
     * compiler vectorises */
    for (int i = 1; i < n - 1; i++)
      rise[i] = CHORD_RISE(z[i - 1], z[i], z[i + 1], u[i - 1], u[i], u[i + 1]);
    /* the wider chords, where they stay in the step (open_a and open_b add
     * +infinity where they do not, which leaves the verdict above) */
    for (int i = 2; i < n - 2; i++) {
      const double wide_a =
          CHORD_RISE(z[i - 2], z[i], z[i + 1], u[i - 2], u[i], u[i + 1]) +
          job->open_a[i - base];
      const double wide_b =
          CHORD_RISE(z[i - 1], z[i], z[i + 2], u[i - 1], u[i], u[i + 2]) +
          job->open_b[i - base];
      const double wide = wide_a < wide_b ? wide_a : wide_b;
      rise[i] = wide < rise[i] ? wide : rise[i];
    }
    /* the chord from each step's start vertex to its end vertex */
    for (int s = 0; s < s1 - s0; s++) {
      const int st = base + s * tcount - 1, e = st + tcount;
      if (st < 0)
        continue;
      const double zs = z[st], ze = z[e], us = u[st], ue = u[e];
      for (int k = st + 1; k < e; k++) {
        const double full = CHORD_RISE(zs, z[k], ze, us, u[k], ue);
        rise[k] = full < rise[k] ? full : rise[k];
      }
    }
    if (s0 == 0)
      rise[0] = 1.0; /* the first point is an end */
    const int first_kept = count;
    if (s0 > 0) { /* the previous block's last point, carried at index 1 */
      put_point(&pr->pt[count], u[1], z[1], key_of(pr->first_step + s0 - 1, tcount - 1));
      count += rise[1] > 0.0;
    }
    count = keep_points(job, fb, pr, s0, s1, base, count);
    top = highest_point(pr->pt, first_kept, count, top);
    if (s1 < pr->steps) { /* the last two go on to the next block */
      u[0] = u[n - 2], z[0] = z[n - 2];
      u[1] = u[n - 1], z[1] = z[n - 1];
      n = 2;
    }
  }
  /* the last point is an end */
  put_point(&pr->pt[count++], u[n - 1], z[n - 1],
            key_of(pr->first_step + pr->steps - 1, tcount - 1));
  pr->top = highest_point(pr->pt, count - 1, count, top);
  pr->count = count;
}

/* ----------------------------------------------- lines filled side by side */

/* The periodic lines through (x0, y0) .. (x0 + LANES - 1, y0) run side by
 * side: at each step their texels are neighbours in a row, so each
 * breakpoint's heights for all of them are LANES neighbouring floats, and
 * the kink filter's arithmetic is the same for all but the heights (u is
 * the same). So one vector operation does every line's, each exactly as
 * profile_fill does it for that line alone (the same IEEE operations in the
 * same order, no contraction), and only the copying out of the kept points
 * is per line. rock06, 16 slices: the fill took 38% of the trace's
 * instructions one line at a time. */
enum { LANES = 4 };
typedef double lanes_z __attribute__((vector_size(LANES * sizeof(double))));
typedef float lanes_f __attribute__((vector_size(LANES * sizeof(float))));
typedef int64_t lanes_mask __attribute__((vector_size(LANES * sizeof(int64_t))));
/* The helpers below take and give vectors by value: always inlined, so no
 * call passes one, and GCC's note that such a call's ABI depends on AVX-512
 * does not apply. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

/* LANES neighbouring floats, as doubles. */
static inline __attribute__((always_inline)) lanes_z lanes_load(const float *z) {
  lanes_f f;
  memcpy(&f, z, sizeof f);
  return __builtin_convertvector(f, lanes_z);
}

/* *out = *a < *b ? *a : *b in each lane, as the scalar code takes its
 * minima (out may be b). Pointers, not vector arguments: clang refuses a
 * 4-double vector argument in the target_clones default (non-AVX) clone,
 * which `make fuzz` builds with. */
static inline __attribute__((always_inline)) void
lanes_min(lanes_z *out, const lanes_z *a, const lanes_z *b) {
  const lanes_mask less = *a < *b;
  *out = (lanes_z)(((lanes_mask)*a & less) | ((lanes_mask)*b & ~less));
}

/* step_heights for the lines side by side, the first at texel (bx, by). */
static inline void step_heights_lanes(const sweep_job *job, int bx, int by, lanes_z *zs) {
  const bb_pyramid *p = job->p;
  const int tcount = job->point_count;
  if (bx >= job->reach_x && bx + LANES - 1 < p->width - job->reach_x &&
      by >= job->reach_y && by < p->height - job->reach_y) {
    const float *here = p->z + (size_t)by * (size_t)p->width + (size_t)bx;
    for (int k = 0; k < tcount; k++) {
      const lanes_z za = lanes_load(here + job->offset1[k]),
                    zb = lanes_load(here + job->offset2[k]);
      zs[k] = za + (zb - za) * job->weight[k]; /* bb__lattice_height */
    }
  } else {
    for (int k = 0; k < tcount; k++) {
      const template_point *t = &job->points[k];
      for (int l = 0; l < LANES; l++)
        zs[k][l] =
            bb__lattice_height(field_z(p, bx + l + t->x1, by + t->y1),
                               field_z(p, bx + l + t->x2, by + t->y2), job->weight[k]);
    }
  }
}

/* Line l's kept points among block points i0 .. i1-1, appended to its
 * profile from pt[count]; kept[w] holds, for every line, a bit per point of
 * the block's points 64 w .. 64 w + 63. Returns the new count. Only the
 * kept points are visited (a third of them on rock06). */
static inline int keep_lane(const fill_block *fb, const lanes_mask *kept, int l, int i0,
                            int i1, point *restrict pt, int count) {
  const lanes_z *z = (const lanes_z *)fb->z;
  for (int w = i0 / 64; w * 64 < i1; w++) {
    uint64_t bits = (uint64_t)kept[w][l];
    if (w * 64 < i0)
      bits &= ~0ull << (i0 - w * 64);
    if (i1 - w * 64 < 64)
      bits &= ~(~0ull << (i1 - w * 64));
    for (; bits; bits &= bits - 1) {
      const int i = w * 64 + __builtin_ctzll(bits);
      put_point(&pt[count++], fb->u[i], z[i][l], fb->key[i]);
    }
  }
  return count;
}

/* profile_fill for the periodic lines through (x0 + l, y0), l < LANES, into
 * pr[l], all of one length and profiled whole. The block arrays hold each
 * point's u and key once and its heights and verdicts as vectors of the
 * lines; the verdicts become a bit per point and line, so that each line
 * visits only the points it keeps. */
PROFILE_CLONES
static void profile_fill_lanes(const sweep_job *job, const fill_block *fb, int x0, int y0,
                               profile *pr) {
  const bb_pyramid *p = job->p;
  const int tcount = job->point_count, steps = pr[0].steps, len = pr[0].len;
  const double *const frac = job->frac;
  int bx = bb__wrap(x0, p->width), by = bb__wrap(y0, p->height);
  const int sa = job->a % p->width, sb = job->b % p->height;
  double *restrict u = fb->u;
  int64_t *restrict key = fb->key;
  lanes_z *restrict z = (lanes_z *)fb->z, *restrict rise = (lanes_z *)fb->rise;
  lanes_mask *restrict kept = (lanes_mask *)fb->kept;
  int count[LANES] = {0}, top[LANES] = {0};
  int n = 0; /* as in profile_fill */
  for (int s0 = 0; s0 < steps; s0 += BLOCK_STEPS) {
    const int s1 = imin(s0 + BLOCK_STEPS, steps), base = n;
    for (int s = s0; s < s1; s++, bx = bb__wrap_near(bx + sa, p->width),
             by = bb__wrap_near(by + sb, p->height)) {
      if (s < len) /* texel s of each line */
        for (int l = 0; l < LANES; l++) {
          const int x = bb__wrap_near(bx + l, p->width);
          pr[l].vz[s] = field_z(p, x, by);
          pr[l].texel[s] = (size_t)by * (size_t)p->width + (size_t)x;
        }
      step_heights_lanes(job, bx, by, z + n);
      const double js = (double)s;
      for (int k = 0; k < tcount; k++)
        u[n + k] = js + frac[k], key[n + k] = key_of(s, k);
      n += tcount;
    }
    for (int i = 1; i < n - 1; i++)
      rise[i] = CHORD_RISE(z[i - 1], z[i], z[i + 1], u[i - 1], u[i], u[i + 1]);
    for (int i = 2; i < n - 2; i++) {
      const lanes_z wide_a =
          CHORD_RISE(z[i - 2], z[i], z[i + 1], u[i - 2], u[i], u[i + 1]) +
          job->open_a[i - base];
      const lanes_z wide_b =
          CHORD_RISE(z[i - 1], z[i], z[i + 2], u[i - 1], u[i], u[i + 2]) +
          job->open_b[i - base];
      lanes_z wide;
      lanes_min(&wide, &wide_a, &wide_b);
      lanes_min(&rise[i], &wide, &rise[i]);
    }
    for (int s = 0; s < s1 - s0; s++) {
      const int st = base + s * tcount - 1, e = st + tcount;
      if (st < 0)
        continue;
      for (int k = st + 1; k < e; k++) {
        const lanes_z chord = CHORD_RISE(z[st], z[k], z[e], u[st], u[k], u[e]);
        lanes_min(&rise[k], &chord, &rise[k]);
      }
    }
    if (s0 == 0)
      rise[0] = (lanes_z){0} + 1.0; /* the first point is an end */
    /* the verdicts of points 0 .. n-2 (the last waits for the next block) */
    for (int w = 0; w * 64 < n - 1; w++) {
      lanes_mask bits = {0};
      for (int q = 0; q < 64 && w * 64 + q < n - 1; q++)
        bits |= (rise[w * 64 + q] > 0.0) & (int64_t)(1ull << q);
      kept[w] = bits;
    }
    /* the carried point (index 1) first, then the block's own */
    const int i0 = s0 > 0 ? 1 : 0;
    for (int l = 0; l < LANES; l++) {
      const int first_kept = count[l];
      count[l] = keep_lane(fb, kept, l, i0, n - 1, pr[l].pt, count[l]);
      top[l] = highest_point(pr[l].pt, first_kept, count[l], top[l]);
    }
    if (s1 < steps) { /* the last two go on to the next block */
      u[0] = u[n - 2], z[0] = z[n - 2], key[0] = key[n - 2];
      u[1] = u[n - 1], z[1] = z[n - 1], key[1] = key[n - 1];
      n = 2;
    }
  }
  for (int l = 0; l < LANES; l++) { /* the last point is an end */
    put_point(&pr[l].pt[count[l]++], u[n - 1], z[n - 1][l], key[n - 1]);
    pr[l].top = highest_point(pr[l].pt, count[l] - 1, count[l], top[l]);
    pr[l].count = count[l];
  }
}

/* ------------------------------------------------------------------ hulls */

/* The hull: upper hull of the points ahead, nearest last (u may be
 * mirrored), an array of points; its size is passed around. */

/* Pushes a point nearer than all others, dropping those now under the hull;
 * then, if nothing ahead is higher than it, keeps it alone: from any origin
 * behind it is then either steeper than everything ahead (positive slope,
 * shorter distance) or everything is below the origin (horizon 0). */
/* Is hull vertex a on or under the segment from the new point (qu, qz) to
 * the vertex b beyond it? */
static inline int under(const point *a, const point *b, double qu, double qz) {
  return (a->z - qz) * (b->u - qu) <= (b->z - qz) * (a->u - qu);
}

/* A push mostly drops one vertex, sometimes none or two (rock06: 68%, 18%,
 * 11%; three or more 3%): the first two tests are made together and
 * combined without a branch, which would be mispredicted a third of the
 * time; the vertices dropped are those of a plain loop. */
static inline int hull_push(point *restrict v, int size, double qu, double qz,
                            int64_t key) {
  int more = 1; /* may more vertices go? */
  if (size >= 3) {
    const int one = under(&v[size - 1], &v[size - 2], qu, qz);
    const int two = one & under(&v[size - 2], &v[size - 3], qu, qz);
    size -= one + two;
    more = two;
  }
  while (more && size >= 2 && under(&v[size - 1], &v[size - 2], qu, qz))
    size--;
  if (size >= 1 && v[size - 1].z <= qz)
    size = 0;
  put_point(&v[size], qu, qz, key);
  return size + 1;
}

/* Is hull vertex far steeper from the origin than the vertex at (du, dz)
 * from it? (denominators are positive) */
static inline int steeper(const point *far, double du, double dz, double u0, double z0) {
  return (far->z - z0) * du > dz * (far->u - u0);
}

/* Index of the hull vertex of largest slope from (u0, z0), behind every
 * point: slopes to hull vertices rise, then fall, going away from the
 * origin, so a walk from the near end finds it, mostly within three steps.
 * The nearest vertex (a fraction of a step ahead, below an origin lifted by
 * the bias) is seldom the tangent, but whether the walk goes one or two
 * steps further is a toss-up: those two tests are made together and
 * combined without a branch, which the processor would mispredict half the
 * time. The tests and where the walk stops are those of a plain walk. */
static inline int hull_tangent(const point *v, int size, double u0, double z0) {
  int i = size - 1;
  if (i < 0)
    return -1; /* nothing there (a chunk's first origin, one step in) */
  double du = v[i].u - u0, dz = v[i].z - z0;
  if (i == 0 || !steeper(&v[i - 1], du, dz, u0, z0))
    return i;
  i--, du = v[i].u - u0, dz = v[i].z - z0;
  if (i >= 2) {
    const double du1 = v[i - 1].u - u0, dz1 = v[i - 1].z - z0;
    const int one = steeper(&v[i - 1], du, dz, u0, z0);
    const int two = one & steeper(&v[i - 2], du1, dz1, u0, z0);
    if (!two)
      return i - one;
    i -= 2, du = v[i].u - u0, dz = v[i].z - z0;
  }
  while (i > 0 && steeper(&v[i - 1], du, dz, u0, z0))
    i--, du = v[i].u - u0, dz = v[i].z - z0;
  return i;
}

int bb__hull_tangent(const bb__walk_point *hull, int size, double u0, double z0) {
  return hull_tangent(hull, size, u0, z0);
}

/* The canonical slope per step from an origin of height oz to the point of
 * height z and key `key`, relative to the origin's step: ahead of the origin
 * (forward) or behind it. */
static inline double tangent_slope(const sweep_job *job, double z, int64_t key, double oz,
                                   int forward) {
  const int step = key_step(key);
  const template_point *t = &job->points[key_tp(key)];
  const long n = forward ? (long)step * t->m + t->i : (long)(-step) * t->m - t->i;
  return (z - oz) / bb__lattice_distance(n, t->inverse_m);
}

/* The horizon in texels from the best slope per step. */
static inline float horizon_of(const sweep_job *job, int k, double slope) {
  return bb__lattice_horizon(slope > 0.0 ? slope : 0.0, job->side[k].inverse_length);
}

/* ---------------------------------------------------------- line sweeps */

/* Chunks only: is the slope from an origin at oz clearly above anything
 * beyond the profile, which lies at least `distance` steps away? */
static int vouched(const sweep_job *job, double slope, double oz, double distance) {
  const double rise = (double)job->p->global_max - oz;
  return rise <= 0.0 || slope >= rise / distance * (1.0 + 1e-9) + 1e-12;
}

/* Origin j of a line (texel j mod L, -L <= j < 2 L) asks the hull for its
 * tangent vertex, kept until the line's walks are done: its slope is worked
 * out after them (horizons_of_line). The walks' loops then carry only the
 * hull, with fewer values live across them, and the divisions of
 * neighbouring texels overlap in a loop of their own. */
static inline __attribute__((always_inline)) int query(const sweep_job *job,
                                                       const profile *pr, const point *h,
                                                       int size, int j, int forward) {
  const int L = pr->len;
  const int texel_j = j < 0 ? j + L : (j >= L ? j - L : j);
  const double oz = pr->vz[texel_j] + job->bias;
  const int k = forward ? 0 : 1;
  const double u0 = forward ? (double)j : -(double)j;
  const int i = hull_tangent(h, size, u0, oz);
  if (i >= 0) {
    pr->tangent_z[k][texel_j] = h[i].z;
    pr->tangent_key[k][texel_j] = h[i].key - (int64_t)j * KEY_STEP;
  } else { /* nothing there: a point at -infinity one step away, horizon 0 */
    pr->tangent_z[k][texel_j] = -INFINITY;
    pr->tangent_key[k][texel_j] = key_of(forward ? 0 : -2, job->point_count - 1);
  }
  return i;
}

/* The horizons of a line's texels along side k, from the tangents its walk
 * found. In a chunk, a texel the profile cannot vouch for (the points beyond
 * it lie at least `beyond` steps away) is marched instead, which finds the
 * same bits. */
static void horizons_of_line(const sweep_job *job, const profile *pr, int k) {
  const int forward = k == 0;
  const double *restrict tz = pr->tangent_z[k];
  const int64_t *restrict tkey = pr->tangent_key[k];
  float *restrict found = pr->found[k];
  for (int j = 0; j < pr->len; j++) {
    const double oz = pr->vz[j] + job->bias;
    found[j] = horizon_of(job, k, tangent_slope(job, tz[j], tkey[j], oz, forward));
  }
  if (!pr->vouch[k])
    return;
  /* (a loop of its own: the whole lines' loop above stays a plain one) */
  const unsigned char *want = pr->want, bit = (unsigned char)(1 << k);
  for (int j = 0; j < pr->len; j++) {
    if (want && !(want[j] & bit))
      continue;
    const double oz = pr->vz[j] + job->bias;
    const double slope = tangent_slope(job, tz[j], tkey[j], oz, forward);
    const double beyond = forward ? (double)(pr->first_step + pr->steps - j)
                                  : (double)(j - pr->first_step);
    if (!vouched(job, slope, oz, beyond)) {
      const size_t texel = pr->texel[j];
      const int x = (int)(texel % (size_t)job->p->width), y = (int)(texel / (size_t)job->p->width);
      /* the profile holds every point within `beyond` steps (a step less:
       * the march's first cell may reach back into it) */
      found[j] = bb__slice_horizon_above(job->p, x, y, job->bias, job->side[k].a,
                                         job->side[k].b, slope, beyond - 1.0);
    }
  }
}

/* A stretch of profile points, pt[from] to pt[to] inclusive (either way
 * round), moved on by `shift` steps (a whole number of periods). */
typedef struct stretch {
  int from, to, shift;
} stretch;

/* One walk along a line, with its own hull. Along (a, b) (forward) it
 * pushes the points of its stretches by falling u, and its origins j, from
 * the first down, each ask the hull once every point beyond them is on it.
 * Along (-a, -b) it takes the points by rising u, on mirrored u so the hull
 * code is the same, and the origins rising. The walk is driven by its
 * origins: each pushes the points beyond it not yet pushed, then asks, so
 * the points no origin wants are never pushed. Whether a point lies beyond
 * origin j is read from its key: along (a, b) its u > j exactly when its
 * step is j or later, along (-a, -b) its u < j exactly when it comes before
 * the vertex at the end of step j - 1 (u is j + its template fraction,
 * which never rounds to a whole number but at the vertex). */
typedef struct walk {
  point *h;
  int size;
  const point *pt; /* the profile */
  const stretch *st;
  int stretches, r;     /* the stretch under way */
  const point *q, *end; /* its next point, and the point past its last */
  double du;            /* its shift */
  int64_t dkey;
  int j; /* the next origin */
} walk;

/* Moves the walk on to the first stretch from r on that holds points; 0
 * when there is none. */
static inline int walk_enter(walk *w, int forward) {
  const int dq = forward ? -1 : 1;
  for (; w->r < w->stretches; w->r++) {
    const stretch *s = &w->st[w->r];
    if ((s->to - s->from) * dq < 0)
      continue;
    w->q = w->pt + s->from;
    w->end = w->pt + s->to + dq;
    w->du = (double)s->shift, w->dkey = (int64_t)s->shift * KEY_STEP;
    return 1;
  }
  w->q = w->end = NULL;
  return 0;
}

static walk walk_start(const profile *pr, point *h, const stretch *st, int stretches,
                       int j_first, int forward) {
  walk w = {.h = h, .pt = pr->pt, .st = st, .stretches = stretches, .j = j_first};
  walk_enter(&w, forward);
  return w;
}

/* A visited walk's origin: the visitor is told of it with the horizon its
 * tangent makes, worked out as horizons_of_line does. */
static void visit_origin(const sweep_job *job, const profile *pr, const walk *w,
                         int forward, int tangent, void *state) {
  const int L = pr->len, j = w->j;
  const int texel_j = j < 0 ? j + L : (j >= L ? j - L : j);
  const double oz = pr->vz[texel_j] + job->bias;
  const int k = forward ? 0 : 1;
  const double slope = tangent_slope(job, pr->tangent_z[k][texel_j],
                                     pr->tangent_key[k][texel_j], oz, forward);
  job->visitor->origin(state, k, texel_j, forward ? (double)j : -(double)j, oz, w->h,
                       w->size, tangent, horizon_of(job, k, slope));
}

/* The walk's next origin: the points beyond it are pushed, then it asks the
 * hull for its tangent. A visited walk (state not NULL) also tells the
 * visitor of each push and each origin. */
static inline __attribute__((always_inline)) void
walk_next(const sweep_job *job, const profile *pr, walk *w, int forward, void *state) {
  const int64_t beyond =
      forward ? (int64_t)w->j * KEY_STEP : key_of(w->j - 1, job->point_count - 1);
  for (;;) {
    if (w->q == w->end) {
      w->r++;
      if (!walk_enter(w, forward))
        break;
    }
    const point *next = w->q;
    const int64_t key = next->key + w->dkey;
    if (forward ? key < beyond : key >= beyond)
      break;
    const double u = next->u + w->du;
    w->size = hull_push(w->h, w->size, forward ? u : -u, next->z, key);
    if (state && job->visitor->push)
      job->visitor->push(state, forward ? 0 : 1, w->h, w->size);
    w->q += forward ? -1 : 1;
  }
  const int tangent = query(job, pr, w->h, w->size, w->j, forward);
  if (state)
    visit_origin(job, pr, w, forward, tangent, state);
  w->j += forward ? -1 : 1;
}

/* Both walks of a line (NULL: that side is not wanted), `origins` each,
 * one origin of each in turn. Each push waits on what the push before it
 * stored in the same hull; the two hulls are independent, so the processor
 * overlaps the two chains. The walks write different horizons (found[0],
 * found[1]), so the results are those of one walk after the other. */
static inline __attribute__((always_inline)) void
walk_pair_with(const sweep_job *job, const profile *pr, walk *ahead, walk *behind,
               int origins, void *state) {
  walk a = ahead ? *ahead : (walk){0}, b = behind ? *behind : (walk){0};
  if (ahead && behind)
    for (int i = 0; i < origins; i++) {
      walk_next(job, pr, &a, 1, state);
      walk_next(job, pr, &b, 0, state);
    }
  else if (ahead)
    for (int i = 0; i < origins; i++)
      walk_next(job, pr, &a, 1, state);
  else if (behind)
    for (int i = 0; i < origins; i++)
      walk_next(job, pr, &b, 0, state);
}

/* The trace's walks, and a visited line's (the visitor's state). */
static void walk_pair_traced(const sweep_job *job, const profile *pr, walk *ahead,
                             walk *behind, int origins) {
  walk_pair_with(job, pr, ahead, behind, origins, NULL);
}

static void walk_pair_visited(const sweep_job *job, const profile *pr, walk *ahead,
                              walk *behind, int origins, void *state) {
  walk_pair_with(job, pr, ahead, behind, origins, state);
}

static void walk_pair(const sweep_job *job, const profile *pr, walk *ahead, walk *behind,
                      int origins, void *state) {
  if (state)
    walk_pair_visited(job, pr, ahead, behind, origins, state);
  else
    walk_pair_traced(job, pr, ahead, behind, origins);
}

/* Once round a periodic line of L steps (points in u (0, L]), from its
 * highest point P* at u*. Along (a, b): from the copy of P* one period on,
 * backwards, for origins from just below it down to u*, so each sees
 * (j, u* + L]. Along (-a, -b): from the copy one period back, forwards, for
 * origins from just above it up to u*, so each sees [u* - L, j). */
static void walk_round(const sweep_job *job, const profile *pr, point *h[2],
                       void *state) {
  const int top = pr->top, n = pr->count, L = pr->len;
  const double u_top = pr->pt[top].u;
  const stretch down[2] = {{top, 0, L}, {n - 1, top + 1, 0}};
  const stretch up[2] = {{top, n - 1, -L}, {0, top - 1, 0}};
  const int first = (int)ceil(u_top), last = (int)floor(u_top);
  walk ahead = walk_start(pr, h[0], down, 2, first + L - 1, 1);
  walk behind = walk_start(pr, h[1], up, 2, last - L + 1, 0);
  walk_pair(job, pr, job->side[0].dir ? &ahead : NULL, job->side[1].dir ? &behind : NULL,
            L, state);
}

/* A line with ends (a clamped line, or a chunk): every point, every origin. */
static void walk_line(const sweep_job *job, const profile *pr, point *h[2], void *state) {
  const stretch down = {pr->count - 1, 0, 0}, up = {0, pr->count - 1, 0};
  walk ahead = walk_start(pr, h[0], &down, 1, pr->len - 1, 1);
  walk behind = walk_start(pr, h[1], &up, 1, 0, 0);
  walk_pair(job, pr, job->side[0].dir ? &ahead : NULL, job->side[1].dir ? &behind : NULL,
            pr->len, state);
}

/* The line's horizons from its tangents, and what its texels lose to them,
 * added to their sums: along (a, b) first, then along (-a, -b), as the
 * slices' order wants. The walks only find tangents; integrating here, in
 * loops of their own, lets the divisions and table reads of neighbouring
 * texels overlap. */
static bb__line_view line_view_of(const sweep_job *job, const profile *pr, int x0,
                                  int y0) {
  const bb__line_view line = {.p = job->p,
                              .a = job->a,
                              .b = job->b,
                              .points = job->points,
                              .point_count = job->point_count,
                              .round = job->kind == LINE_ROUND,
                              .x0 = x0,
                              .y0 = y0,
                              .first_step = pr->first_step,
                              .steps = pr->steps,
                              .len = pr->len,
                              .texel = pr->texel,
                              .vz = pr->vz,
                              .bias = job->bias,
                              .dir = {job->side[0].dir, job->side[1].dir},
                              .found = {job->side[0].dir ? pr->found[0] : NULL,
                                        job->side[1].dir ? pr->found[1] : NULL},
                              .tangent_key = {pr->tangent_key[0], pr->tangent_key[1]},
                              .want = pr->want};
  return line;
}

PROFILE_CLONES
static void integrate_line(const sweep_job *job, const profile *pr, int x0, int y0,
                           void *state) {
  const int channels = job->channels;
  for (int k = 0; k < 2; k++)
    if (job->side[k].dir)
      horizons_of_line(job, pr, k);
  if (job->hook || state) {
    const bb__line_view line = line_view_of(job, pr, x0, y0);
    if (state)
      job->visitor->line_end(state, &line);
    else
      job->hook(job->hook_ctx, &line);
    return;
  }
  for (int k = 0; k < 2; k++) {
    const bb__sweep_dir *dir = job->side[k].dir;
    if (!dir || !dir->horizon)
      continue;
    for (int j = 0; j < pr->len; j++)
      dir->horizon[pr->texel[j]] = pr->found[k][j];
  }
  if (job->side[0].dir && job->side[1].dir && job->side[0].dir->sums &&
      job->side[1].dir->sums) {
    const bb__slice_integral *along = &job->side[0].integral,
                             *opposite = &job->side[1].integral;
    float *sums = job->side[0].dir->sums;
    if (job->table4) {
      const bb__channels4 *t_along = job->table4,
                          *t_opposite = job->table4 + 4 * BB__TABLE_INTERVALS;
      for (int j = 0; j < pr->len; j++) {
        float *texel_sums = sums + pr->texel[j] * 4;
        bb__slice_accumulate4(along, t_along, pr->found[0][j], texel_sums);
        bb__slice_accumulate4(opposite, t_opposite, pr->found[1][j], texel_sums);
      }
      return;
    }
    for (int j = 0; j < pr->len; j++) {
      float *texel_sums = sums + pr->texel[j] * (size_t)channels;
      bb__slice_accumulate(along, pr->found[0][j], texel_sums);
      bb__slice_accumulate(opposite, pr->found[1][j], texel_sums);
    }
    return;
  }
  for (int k = 0; k < 2; k++) {
    const bb__sweep_dir *dir = job->side[k].dir;
    if (!dir || !dir->sums)
      continue; /* horizons only */
    for (int j = 0; j < pr->len; j++)
      bb__slice_accumulate(&job->side[k].integral, pr->found[k][j],
                           dir->sums + pr->texel[j] * (size_t)channels);
  }
}

/* ------------------------------------------------------------ work items */

/* Clamp mode: is the step from texel (x, y) flat, every template vertex
 * clamped to the same height along each axis the line moves on? */
static int step_is_flat(const sweep_job *job, long x, long y) {
  const bb_pyramid *p = job->p;
  const int flat_x =
      job->a == 0 || x + job->min_dx >= p->width - 1 || x + job->max_dx <= 0;
  const int flat_y =
      job->b == 0 || y + job->min_dy >= p->height - 1 || y + job->max_dy <= 0;
  return flat_x && flat_y;
}

/* Clamp mode: steps from texel (x, y), going by (sa, sb) per step, to the
 * first flat step, inclusive. */
static int steps_to_flat(const sweep_job *job, long x, long y, int sa, int sb) {
  int steps = 0;
  while (!step_is_flat(job, x, y))
    x += sa, y += sb, steps++;
  return steps + 1;
}

/* A clamped line's profile: ahead, the steps up to the first flat one,
 * which ends on a flat vertex; behind, the steps back to the first flat one
 * and one more, so that its first vertex is in the profile too (a step may
 * hold no other point than its end). */
static void clamped_extent(const sweep_job *job, int x, int y, int len, int *before,
                           int *after) {
  const long ex = (long)x + (long)(len - 1) * job->a,
             ey = (long)y + (long)(len - 1) * job->b;
  *after = steps_to_flat(job, ex, ey, job->a, job->b) - 1;
  *before = steps_to_flat(job, (long)x - job->a, (long)y - job->b, -job->a, -job->b) + 1;
}

/* The steps a work item profiles, before and after its texels. */
static void item_extent(const sweep_job *job, int item, int *before, int *after) {
  const int x = job->item_x[item], y = job->item_y[item], len = job->item_len[item];
  if (job->kind == LINE_ROUND) {
    *before = 0, *after = 0;
  } else if (job->kind == LINE_CHUNK) {
    *before = job->lookahead, *after = job->lookahead;
  } else if (job->kind == LINE_STRETCH) {
    *before = job->stretch[item].before, *after = job->stretch[item].after;
  } else {
    clamped_extent(job, x, y, len, before, after);
  }
}

/* Lines per work item: neighbouring lines write neighbouring texels, so a
 * bundle of them fills whole cache lines of the sums on one thread. */
enum { BUNDLE = 64 };

/* Periodic lines are profiled LANES at a time when the bundle has LANES
 * neighbours of one length (profile_fill_lanes) and their profiles are not too
 * long: the lanes' profiles are kept at once, LANES x 24 bytes a point. */
#define LANE_POINTS_MAX (1L << 17)

/* The steps a work item's profile takes, and in *first_step the first. */
static int item_steps(const sweep_job *job, int item, int *first_step) {
  int before, after;
  item_extent(job, item, &before, &after);
  *first_step = -before;
  return before + job->item_len[item] + after;
}

/* Walks a line's profile and adds up its horizons. */
static void walk_and_integrate(sweep_job *job, profile *pr, int x0, int y0, point *h[2]) {
  void *state = NULL;
  if (job->visitor) {
    const bb__line_view line = line_view_of(job, pr, x0, y0);
    if (job->visitor->line_wanted && !job->visitor->line_wanted(job->visitor_ctx, &line))
      return;
    state = job->visitor->line_begin(job->visitor_ctx, &line);
    if (!state) {
      atomic_store(&job->out_of_memory, 1);
      return;
    }
  }
  if (job->kind == LINE_ROUND)
    walk_round(job, pr, h, state);
  else
    walk_line(job, pr, h, state);
  integrate_line(job, pr, x0, y0, state);
}

/* Do items item .. item + LANES - 1 make a group for profile_fill_lanes? */
static int lanes_from(const sweep_job *job, int item, int last) {
  if (job->kind != LINE_ROUND || item + LANES > last ||
      (long)job->item_len[item] * job->point_count > LANE_POINTS_MAX)
    return 0;
  for (int l = 1; l < LANES; l++)
    if (job->item_x[item + l] != job->item_x[item] + l ||
        job->item_y[item + l] != job->item_y[item] ||
        job->item_len[item + l] != job->item_len[item])
      return 0;
  return 1;
}

/* A worker's buffers, kept from one bundle to the next and grown when a
 * bundle needs more: allocated per bundle, they went back to the system at
 * each free and faulted in again at the next bundle. At most one bundle per
 * thread runs at a time, so a slot per thread always has one free. A lane's
 * profile, texels and heights are those of one line of a group (lane 0 that
 * of a line alone); the walks' arrays are used by one line at a time. */
typedef struct scratch {
  atomic_flag busy;
  size_t points, lane_points, len; /* what pt, h[] and the per-texel arrays hold */
  point *pt[LANES], *h[2];         /* the profiles, a hull per walk */
  double *block_u, *block_z, *block_rise;
  int64_t *block_key, *block_kept;
  double *vz[LANES];
  size_t *texel[LANES];
  float *found[2];
  double *tangent_z[2];
  int64_t *tangent_key[2];
} scratch;

static void scratch_release(scratch *sc) {
  for (int l = 0; l < LANES; l++)
    free(sc->pt[l]), free(sc->vz[l]), free(sc->texel[l]);
  free(sc->h[0]);
  free(sc->h[1]);
  free(sc->block_u);
  free(sc->block_z);
  free(sc->block_rise);
  free(sc->block_key);
  free(sc->block_kept);
  free(sc->found[0]);
  free(sc->found[1]);
  for (int k = 0; k < 2; k++)
    free(sc->tangent_z[k]), free(sc->tangent_key[k]);
}

/* Room for `points` profile points and `len` texels in lane 0 and the
 * walks, and for lane_points and len in every lane; 0 when out of memory. */
static int scratch_reserve(scratch *sc, const sweep_job *job, size_t points,
                           size_t lane_points, size_t len) {
  if (!sc->block_u) {
    const size_t block = (size_t)BLOCK_STEPS * (size_t)job->point_count + 2;
    sc->block_u = malloc(block * sizeof(double));
    /* whole vectors of the lines side by side, aligned as vectors are */
    sc->block_z = aligned_alloc(sizeof(lanes_z), block * sizeof(lanes_z));
    sc->block_rise = aligned_alloc(sizeof(lanes_z), block * sizeof(lanes_z));
    sc->block_key = malloc(block * sizeof(int64_t));
    sc->block_kept =
        aligned_alloc(sizeof(lanes_mask), (block / 64 + 1) * sizeof(lanes_mask));
    if (!sc->block_u || !sc->block_z || !sc->block_rise || !sc->block_key ||
        !sc->block_kept)
      return 0;
  }
  if (points > sc->points) {
    free(sc->pt[0]), free(sc->h[0]), free(sc->h[1]);
    sc->pt[0] = malloc(points * sizeof(point));
    sc->h[0] = malloc(points * sizeof(point));
    sc->h[1] = malloc(points * sizeof(point));
    sc->points = sc->pt[0] && sc->h[0] && sc->h[1] ? points : 0;
    if (!sc->points)
      return 0;
  }
  if (lane_points > sc->lane_points) {
    int ok = 1;
    for (int l = 1; l < LANES; l++) {
      free(sc->pt[l]);
      sc->pt[l] = malloc(lane_points * sizeof(point));
      ok = ok && sc->pt[l];
    }
    sc->lane_points = ok ? lane_points : 0;
    if (!ok)
      return 0;
  }
  if (len > sc->len) {
    int ok = 1;
    for (int l = 0; l < LANES; l++) {
      free(sc->vz[l]), free(sc->texel[l]);
      sc->vz[l] = malloc(len * sizeof(double));
      sc->texel[l] = malloc(len * sizeof(size_t));
      ok = ok && sc->vz[l] && sc->texel[l];
    }
    for (int k = 0; k < 2; k++) {
      free(sc->found[k]), free(sc->tangent_z[k]), free(sc->tangent_key[k]);
      sc->found[k] = malloc(len * sizeof(float));
      sc->tangent_z[k] = malloc(len * sizeof(double));
      sc->tangent_key[k] = malloc(len * sizeof(int64_t));
      ok = ok && sc->found[k] && sc->tangent_z[k] && sc->tangent_key[k];
    }
    sc->len = ok ? len : 0;
    if (!ok)
      return 0;
  }
  return 1;
}

static scratch *scratch_take(sweep_job *job) {
  for (;;)
    for (int i = 0; i < job->scratch_count; i++)
      if (!atomic_flag_test_and_set(&job->scratch[i].busy))
        return &job->scratch[i];
}

static void sweep_bundle(void *user, int bundle) {
  sweep_job *job = user;
  const int first = bundle * BUNDLE, last = imin(first + BUNDLE, job->item_count);
  int steps = 0, len = 0, lane_steps = 0, first_step;
  for (int item = first; item < last; item++) {
    steps = imax(steps, item_steps(job, item, &first_step));
    len = imax(len, job->item_len[item]);
    if (lanes_from(job, item, last))
      lane_steps = imax(lane_steps, job->item_len[item]);
  }
  scratch *sc = scratch_take(job);
  const size_t tcount = (size_t)job->point_count;
  if (scratch_reserve(sc, job, (size_t)steps * tcount + 1,
                      lane_steps ? (size_t)lane_steps * tcount + 1 : 0, (size_t)len)) {
    const fill_block fb = {sc->block_u, sc->block_z, sc->block_rise, sc->block_key,
                           sc->block_kept};
    profile pr[LANES];
    for (int l = 0; l < LANES; l++)
      pr[l] = (profile){.pt = sc->pt[l],
                        .vz = sc->vz[l],
                        .texel = sc->texel[l],
                        .found = {sc->found[0], sc->found[1]},
                        .tangent_z = {sc->tangent_z[0], sc->tangent_z[1]},
                        .tangent_key = {sc->tangent_key[0], sc->tangent_key[1]}};
    for (int item = first; item < last && !atomic_load_explicit(&job->cancelled,
                                                                  memory_order_relaxed);) {
      const int x0 = job->item_x[item], y0 = job->item_y[item];
      const int lanes = lanes_from(job, item, last) ? LANES : 1;
      for (int l = 0; l < lanes; l++) {
        pr[l].len = job->item_len[item];
        pr[l].steps = item_steps(job, item, &pr[l].first_step);
        pr[l].vouch[0] = pr[l].vouch[1] = job->kind == LINE_CHUNK;
        pr[l].want = NULL;
        if (job->kind == LINE_STRETCH) {
          pr[l].vouch[0] = !job->stretch[item].exact_ahead;
          pr[l].vouch[1] = !job->stretch[item].exact_behind;
          pr[l].want = job->stretch[item].want;
        }
      }
      if (lanes > 1)
        profile_fill_lanes(job, &fb, x0, y0, pr);
      else
        profile_fill(job, &fb, x0, y0, pr);
      for (int l = 0; l < lanes; l++)
        walk_and_integrate(job, &pr[l], x0 + l, y0, sc->h);
      item += lanes;
    }
  } else {
    atomic_store(&job->out_of_memory, 1);
  }
  atomic_flag_clear(&sc->busy);
}

/* A growable list of work items. */
typedef struct items {
  int *x, *y, *len;
  int count, capacity;
} items;

static int items_add(items *it, int x, int y, int len) {
  if (it->count == it->capacity) {
    const int capacity = it->capacity ? 2 * it->capacity : 1024;
    int *nx = realloc(it->x, (size_t)capacity * sizeof(int));
    if (nx)
      it->x = nx;
    int *ny = realloc(it->y, (size_t)capacity * sizeof(int));
    if (ny)
      it->y = ny;
    int *nl = realloc(it->len, (size_t)capacity * sizeof(int));
    if (nl)
      it->len = nl;
    if (!nx || !ny || !nl)
      return -1;
    it->capacity = capacity;
  }
  it->x[it->count] = x, it->y[it->count] = y, it->len[it->count] = len;
  it->count++;
  return 0;
}

static void items_free(items *it) {
  free(it->x);
  free(it->y);
  free(it->len);
}

static inline int inside(const bb_pyramid *p, long x, long y) {
  return x >= 0 && x < p->width && y >= 0 && y < p->height;
}

/* Clamp mode: a line runs from a texel whose predecessor is outside the
 * image to the last texel before it leaves. */
static int clamped_lines(const bb_pyramid *p, int a, int b, items *it) {
  for (int y = 0; y < p->height; y++)
    for (int x = 0; x < p->width; x++) {
      if (inside(p, (long)x - a, (long)y - b))
        continue;
      int len = 0;
      for (long px = x, py = y; inside(p, px, py); px += a, py += b)
        len++;
      if (items_add(it, x, y, len))
        return -1;
    }
  return 0;
}

/* Periodic mode: every line of `period` steps once, whole, or cut into
 * chunks of chunk_len steps. y mod h, h = gcd(b, H), is the same all along a
 * line, and a line meets its row y0 < h every H / h steps, x moving on by
 * (H / h) a each time: so the lines are those through (x0, y0) for y0 < h
 * and x0 < gcd((H / h) a, W), each exactly once, and neighbours in x come
 * one after the other. */
static int periodic_lines(const bb_pyramid *p, int a, int b, long period, int chunk_len,
                          items *it) {
  const long W = p->width, H = p->height, h = bb__gcd(b, H);
  const long columns = bb__gcd((H / h) * a, W);
  for (long y0 = 0; y0 < h; y0++)
    for (long x0 = 0; x0 < columns; x0++) {
      if (!chunk_len) {
        if (items_add(it, (int)x0, (int)y0, (int)period))
          return -1;
        continue;
      }
      for (long j = 0; j < period; j += chunk_len) {
        const int x = (int)((x0 + (j % W) * (a % W) % W + W) % W);
        const int y = (int)((y0 + (j % H) * (b % H) % H + H) % H);
        if (items_add(it, x, y, (int)(period - j < chunk_len ? period - j : chunk_len)))
          return -1;
      }
    }
  return 0;
}

/* The inverse of v modulo n (v and n coprime, n >= 1), in [0, n). */
static long inverse_mod(long v, long n) {
  long r0 = n, r1 = ((v % n) + n) % n, t0 = 0, t1 = 1;
  while (r1) {
    const long q = r0 / r1, r = r0 - q * r1, t = t0 - q * t1;
    r0 = r1, r1 = r, t0 = t1, t1 = t;
  }
  return ((t0 % n) + n) % n;
}

void bb__line_seed(const bb_pyramid *p, int a, int b, int x, int y, int *x0, int *y0) {
  /* periodic_lines' seeds: y0 = y mod h, reached k1 steps back (mod H / h),
   * and there the line's texels in row y0 are x0 plus multiples of
   * gcd((H / h) a, W) */
  const long W = p->width, H = p->height, h = bb__gcd(b, H), rows = H / h;
  const long y_seed = ((long)y % h + h) % h;
  const long k1 = rows == 1 ? 0
                            : (((long)y - y_seed) / h % rows + rows) % rows *
                                  inverse_mod(b / h, rows) % rows;
  const long columns = bb__gcd(rows * a, W);
  const long x_back = (((long)x - k1 % W * (a % W)) % W + W) % W;
  *x0 = (int)(x_back % columns);
  *y0 = (int)y_seed;
}

static void job_template(sweep_job *job, template_point *pts) {
  const bb_pyramid *p = job->p;
  job->points = pts;
  job->point_count = build_template(job->a, job->b, pts);
  job->min_dx = job->min_dy = 1 << 30;
  job->max_dx = job->max_dy = -(1 << 30);
  for (int k = 0; k < job->point_count; k++) {
    template_point *t = &pts[k];
    t->offset1 = t->x1 + (long)t->y1 * p->width;
    t->offset2 = t->x2 + (long)t->y2 * p->width;
    job->offset1[k] = t->offset1;
    job->offset2[k] = t->offset2;
    job->frac[k] = t->frac;
    job->weight[k] = t->w;
    job->reach_x = imax(job->reach_x, imax(abs(t->x1), abs(t->x2)) + 1);
    job->reach_y = imax(job->reach_y, imax(abs(t->y1), abs(t->y2)) + 1);
    job->min_dx = imin(job->min_dx, imin(t->x1, t->x2));
    job->max_dx = imax(job->max_dx, imax(t->x1, t->x2));
    job->min_dy = imin(job->min_dy, imin(t->y1, t->y2));
    job->max_dy = imax(job->max_dy, imax(t->y1, t->y2));
  }
  /* the step's own texel is a vertex of it too */
  job->min_dx = imin(job->min_dx, 0), job->max_dx = imax(job->max_dx, 0);
  job->min_dy = imin(job->min_dy, 0), job->max_dy = imax(job->max_dy, 0);
}

/* Where the kink filter's wider chords stay within a point's step, for the
 * points of a block from its first step: template point k of a step (the
 * last is the next texel) may take the chord from k - 2 to k + 1 when
 * 1 <= k <= count - 2 (k - 2 = -1 is the step's start vertex), and the one
 * from k - 1 to k + 2 when k <= count - 3. Kept as arrays, not worked out
 * from i in the loop, so that the loop stays a plain vectorisable one.
 * 0 when out of memory (nothing is left allocated). */
static int job_chords(sweep_job *job) {
  const int count = job->point_count;
  const size_t block_points = (size_t)BLOCK_STEPS * (size_t)count;
  job->open_a = malloc(block_points * sizeof(double));
  job->open_b = malloc(block_points * sizeof(double));
  if (!job->open_a || !job->open_b) {
    free(job->open_a);
    free(job->open_b);
    return 0;
  }
  for (size_t q = 0; q < block_points; q++) {
    const int k = (int)(q % (size_t)count);
    job->open_a[q] = k >= 1 && k <= count - 2 ? 0.0 : INFINITY;
    job->open_b[q] = k <= count - 3 ? 0.0 : INFINITY;
  }
  return 1;
}

static bb_status check_dir(const bb__sweep_dir *dir, int hooked, bb_error *err) {
  if (dir && (!dir->rs || (!dir->sums && !dir->horizon && !hooked) || dir->slice < 0 ||
              dir->slice >= dir->rs->slice_count))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "trace: a sweep direction needs a slice, and sums or horizons");
  return BB_OK;
}

bb_status bb__sweep_lines(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                          const bb__sweep_dir *opposite, double bias, int threads,
                          long long_line, bb_error *err) {
  return bb__sweep_lines_hooked(p, a, b, along, opposite, bias, threads, long_line, NULL,
                                NULL, err);
}

/* The parts of a sweep every entry shares: the checks, both sides, the
 * template and the kink filter's chords, and the tables of both sides'
 * lobes at once when both add to sums. job_end frees what it made. */
static bb_status job_start(sweep_job *job, template_point *pts, const bb_pyramid *p,
                           int a, int b, const bb__sweep_dir *along,
                           const bb__sweep_dir *opposite, double bias, bb__line_hook hook,
                           void *hook_ctx, const bb__walk_visitor *visitor,
                           void *visitor_ctx, bb_error *err) {
  if (abs(a) > BB__MAX_LATTICE_STEP || abs(b) > BB__MAX_LATTICE_STEP || (a == 0 && b == 0))
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: lattice step (%d, %d) out of range", a, b);
  const int custom = hook != NULL || visitor != NULL;
  bb_status st = check_dir(along, custom, err);
  if (st == BB_OK) st = check_dir(opposite, custom, err);
  if (st != BB_OK)
    return st;
  *job = (sweep_job){.p = p,
                     .a = a,
                     .b = b,
                     .bias = bias,
                     .hook = hook,
                     .hook_ctx = hook_ctx,
                     .visitor = visitor,
                     .visitor_ctx = visitor_ctx};
  job->side[0] = (sweep_side){along, a, b, bb__step_inverse(a, b), {0}};
  job->side[1] = (sweep_side){opposite, -a, -b, bb__step_inverse(a, b), {0}};
  if (along)
    job->side[0].integral = bb__slice_integral_of(along->rs, along->slice);
  if (opposite)
    job->side[1].integral = bb__slice_integral_of(opposite->rs, opposite->slice);
  job->channels = 1 + (along ? along : opposite)->rs->basis_count;
  atomic_init(&job->out_of_memory, 0);
  atomic_init(&job->cancelled, 0);
  job_template(job, pts);
  if (!job_chords(job))
    return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for line sweeps");
  if (along && opposite && along->sums && opposite->sums && job->channels == 4 && !custom) {
    job->table4 = aligned_alloc(sizeof(bb__channels4),
                                8 * BB__TABLE_INTERVALS * sizeof(bb__channels4));
    if (job->table4) {
      bb__slice_table4(&job->side[0].integral, job->table4);
      bb__slice_table4(&job->side[1].integral, job->table4 + 4 * BB__TABLE_INTERVALS);
    } /* else the lobes one by one */
  }
  return BB_OK;
}

static void job_end(sweep_job *job) {
  free(job->open_a);
  free(job->open_b);
  free(job->table4);
}

/* The job's checkpoint, which also tells the running bundles to stop. */
static int job_checkpoint(void *user, long done, long total) {
  sweep_job *job = user;
  const int stop = job->checkpoint->fn(job->checkpoint->user, done, total);
  if (stop)
    atomic_store(&job->cancelled, 1);
  return stop;
}

/* Sweeps the job's items (x, y, len each) on all threads, a bundle of
 * them per work item, polling checkpoint (may be NULL). */
static bb_status job_run(sweep_job *job, const int *x, const int *y, const int *len,
                         int count, int threads, const bb__checkpoint *checkpoint,
                         bb_error *err) {
  job->item_x = x;
  job->item_y = y;
  job->item_len = len;
  job->item_count = count;
  const int bundles = (count + BUNDLE - 1) / BUNDLE;
  job->scratch_count = imin(imin(bb__thread_count(threads), bundles), 256);
  job->scratch = calloc((size_t)imax(job->scratch_count, 1), sizeof(scratch));
  if (!job->scratch)
    return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for line sweeps");
  for (int i = 0; i < job->scratch_count; i++)
    atomic_flag_clear(&job->scratch[i].busy);
  job->checkpoint = checkpoint;
  const bb__checkpoint own = {job_checkpoint, job};
  bb_status st = bb__parallel_for_checked(bundles, threads, sweep_bundle, job,
                                          checkpoint && checkpoint->fn ? &own : NULL, err);
  for (int i = 0; i < job->scratch_count; i++)
    scratch_release(&job->scratch[i]);
  free(job->scratch);
  job->scratch = NULL;
  if (st == BB_OK && atomic_load(&job->out_of_memory))
    st = bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for a line sweep");
  return st;
}

/* What a whole-image sweep does per line besides finding its horizons:
 * the hook, the visitor (whose sweep also polls the checkpoint) or neither
 * (the sums). */
typedef struct sweep_extra {
  bb__line_hook hook;
  void *hook_ctx;
  const bb__walk_visitor *visitor;
  void *visitor_ctx;
  const bb__checkpoint *checkpoint;
} sweep_extra;

static bb_status sweep_whole(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                             const bb__sweep_dir *opposite, double bias, int threads,
                             long long_line, const sweep_extra *extra, bb_error *err) {
  template_point pts[4 * BB__MAX_LATTICE_STEP + 1];
  if (!along && !opposite)
    return BB_OK;
  sweep_job job;
  bb_status st = job_start(&job, pts, p, a, b, along, opposite, bias, extra->hook,
                           extra->hook_ctx, extra->visitor, extra->visitor_ctx, err);
  if (st != BB_OK)
    return st;
  items it = {0};
  int failed;
  if (p->addressing == BB_ADDRESS_CLAMP) {
    job.kind = LINE_CLAMPED;
    failed = clamped_lines(p, a, b, &it);
  } else {
    job.period = bb__line_period(p, a, b);
    if (long_line <= 0)
      long_line = LONG_LINE_POINTS / job.point_count;
    job.kind = job.period <= long_line ? LINE_ROUND : LINE_CHUNK;
    job.lookahead = (int)(long_line < CHUNK_STEPS ? long_line : CHUNK_STEPS);
    failed = periodic_lines(p, a, b, job.period,
                            job.kind == LINE_CHUNK ? job.lookahead : 0, &it);
  }
  if (failed) st = bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for line sweeps");
  if (st == BB_OK)
    st = job_run(&job, it.x, it.y, it.len, it.count, threads, extra->checkpoint, err);
  items_free(&it);
  job_end(&job);
  return st;
}

bb_status bb__sweep_lines_hooked(const bb_pyramid *p, int a, int b,
                                 const bb__sweep_dir *along,
                                 const bb__sweep_dir *opposite, double bias, int threads,
                                 long long_line, bb__line_hook hook, void *hook_ctx,
                                 bb_error *err) {
  const sweep_extra extra = {hook, hook_ctx, NULL, NULL, NULL};
  return sweep_whole(p, a, b, along, opposite, bias, threads, long_line, &extra, err);
}

bb_status bb__sweep_lines_walked(const bb_pyramid *p, int a, int b,
                                 const bb__sweep_dir *along,
                                 const bb__sweep_dir *opposite, double bias, int threads,
                                 const bb__walk_visitor *visitor, void *ctx,
                                 const bb__checkpoint *checkpoint, bb_error *err) {
  if (!visitor || !visitor->line_begin || !visitor->origin || !visitor->line_end)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: a walk visitor needs every call");
  const sweep_extra extra = {NULL, NULL, visitor, ctx, checkpoint};
  return sweep_whole(p, a, b, along, opposite, bias, threads, 0, &extra, err);
}

void bb__clamped_line_extent(const bb_pyramid *p, int a, int b, int x, int y, int len,
                             int *before, int *after) {
  template_point pts[4 * BB__MAX_LATTICE_STEP + 1];
  sweep_job job = {.p = p, .a = a, .b = b};
  job_template(&job, pts);
  clamped_extent(&job, x, y, len, before, after);
}

long bb__sweep_long_line(int a, int b) {
  template_point pts[4 * BB__MAX_LATTICE_STEP + 1];
  return LONG_LINE_POINTS / build_template(a, b, pts);
}

int bb__sweep_template(int a, int b, bb__template_point *out) {
  return build_template(a, b, out);
}

void bb__sweep_template_extent(int a, int b, bb__template_extent *out) {
  template_point pts[4 * BB__MAX_LATTICE_STEP + 1];
  const int count = build_template(a, b, pts);
  *out = (bb__template_extent){0, 0,           0,
                               0, pts[0].frac, count > 1 ? pts[count - 2].frac : 0.0};
  for (int k = 0; k < count; k++) {
    out->min_dx = imin(out->min_dx, imin(pts[k].x1, pts[k].x2));
    out->max_dx = imax(out->max_dx, imax(pts[k].x1, pts[k].x2));
    out->min_dy = imin(out->min_dy, imin(pts[k].y1, pts[k].y2));
    out->max_dy = imax(out->max_dy, imax(pts[k].y1, pts[k].y2));
  }
}

bb_status bb__sweep_stretches(const bb_pyramid *p, int a, int b,
                              const bb__sweep_dir *along, const bb__sweep_dir *opposite,
                              double bias, int threads, const bb__stretch *stretches,
                              int count, int round, bb__line_hook hook, void *hook_ctx,
                              bb_error *err) {
  template_point pts[4 * BB__MAX_LATTICE_STEP + 1];
  if ((!along && !opposite) || count == 0)
    return BB_OK;
  if (round && p->addressing != BB_ADDRESS_PERIODIC)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: a clamped line is not swept round");
  sweep_job job;
  bb_status st =
      job_start(&job, pts, p, a, b, along, opposite, bias, hook, hook_ctx, NULL, NULL, err);
  if (st != BB_OK)
    return st;
  job.kind = round ? LINE_ROUND : LINE_STRETCH;
  job.stretch = stretches;
  if (round)
    job.period = bb__line_period(p, a, b);
  int *x = malloc((size_t)count * sizeof(int)), *y = malloc((size_t)count * sizeof(int)),
      *len = malloc((size_t)count * sizeof(int));
  if (!x || !y || !len)
    st = bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for line sweeps");
  for (int i = 0; st == BB_OK && i < count; i++) {
    x[i] = stretches[i].x, y[i] = stretches[i].y, len[i] = stretches[i].len;
    if (round && len[i] != job.period)
      st = bb__fail(err, BB_ERR_ARGUMENT, "trace: a round line has %ld texels, not %d",
                    job.period, len[i]);
  }
  if (st == BB_OK)
    st = job_run(&job, x, y, len, count, threads, NULL, err);
  free(x);
  free(y);
  free(len);
  job_end(&job);
  return st;
}
