/* sweep.h: every texel's horizon along one lattice step by line
 * sweeps (sweep.c), for the batch trace. */
#ifndef BB_TRACE_SWEEP_H
#define BB_TRACE_SWEEP_H

#include "bumpbake.h"
#include "core/internal.h"

#include <stddef.h>
#include <stdint.h>

/* One direction of a line sweep: slice s of rs, whose loss at each texel is
 * added to sums (1 + basis_count floats per texel); horizon (may be NULL)
 * receives each texel's horizon (tests, and bb_trace_horizons, which gives
 * sums NULL: horizons only, nothing added). One of the two is needed; when
 * both directions of a sweep add, they add to the same sums. */
typedef struct bb__sweep_dir {
  const bb_rayset *rs;
  int slice;
  float *sums;
  float *horizon;
} bb__sweep_dir;

/* Either addressing mode: for the lattice step (a, b) of `along` and its
 * opposite, by line sweeps (sweep.c), origins lifted by bias. Either
 * direction may be NULL; both share one profile of each line. Periodic lines
 * longer than long_line steps (0: the default) are cut into chunks whose far
 * texels are checked, and marched when the chunk cannot vouch for them. */
bb_status bb__sweep_lines(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                          const bb__sweep_dir *opposite, double bias, int threads,
                          long long_line, bb_error *err);

/* ------------------------------------------------ lines for other passes */

/* A breakpoint of one step, relative to the step's first texel: the surface
 * there is bb__lattice_height(z(x1, y1), z(x2, y2), w), w = r / m, at n / m
 * steps from an origin k whole steps behind the step, n = k m + i. */
typedef struct bb__template_point {
  double frac; /* i / m, in (0, 1]: for ordering and hull geometry */
  int m, i;    /* m = 1, i = 1: the next texel, a vertex */
  double inverse_m,
      w; /* bb__lattice_inverse(m), bb__lattice_weight(r, m) (0: the vertex) */
  int x1, y1, x2, y2;
  long offset1, offset2; /* x + y * width of the two vertices, for interior steps */
} bb__template_point;

/* A tangent key: the step of a point relative to the origin's step, times
 * BB__KEY_STEP, plus its template point. */
#define BB__KEY_STEP 1024
static inline int bb__key_step(int64_t key) { /* floors: the point index is >= 0 */
  return (int)(key >> 10);
}
static inline int bb__key_point(int64_t key) {
  return (int)(key & (BB__KEY_STEP - 1));
}

/* One line of a sweep once its horizons are found, for a pass that does
 * more with them than the trace's sums (bounce.c). Texel j of the line is
 * at (x0 + j a, y0 + j b) (periodic coordinates wrap; clamped ones are the
 * image's own, and the steps before and after the line lie outside it);
 * step s runs from texel s to texel s + 1 through the template's points.
 * For each side k (0: along (a, b), 1: along (-a, -b); found[k] NULL when
 * not wanted), texel j's horizon (texels of rise per texel) and its
 * tangent point's key, relative to the texel's step. A round line is a
 * periodic line closed after len steps: its point at step s + len is that
 * at step s. */
typedef struct bb__line_view {
  const bb_pyramid *p;
  int a, b;
  const bb__template_point *points;
  int point_count;
  int round;
  int x0, y0;
  int first_step, steps; /* the steps profiled: first_step .. first_step + steps - 1 */
  int len;
  const size_t *texel; /* image index of texel j */
  const double *vz;    /* height of texel j */
  double bias;
  const bb__sweep_dir *dir[2];
  const float *found[2];
  const int64_t *tangent_key[2];
  const unsigned char *want; /* the stretch's (bb__stretch), NULL: all */
} bb__line_view;

/* Called once per line, from the sweep's worker threads, instead of adding
 * the slices' losses to the sums. */
typedef void (*bb__line_hook)(void *ctx, const bb__line_view *line);

/* bb__sweep_lines with a hook for every line in place of the sums (the
 * directions' sums may then be NULL). */
bb_status bb__sweep_lines_hooked(const bb_pyramid *p, int a, int b,
                                 const bb__sweep_dir *along,
                                 const bb__sweep_dir *opposite, double bias, int threads,
                                 long long_line, bb__line_hook hook, void *hook_ctx,
                                 bb_error *err);

/* ------------------------------------------------ walks for other passes */

/* A point of a line as a walk sees it: u, steps from the line's texel 0
 * (negated along (-a, -b), so that u grows away from every origin the walk
 * asks about), its height, and its key (bb__key_step of it is its step,
 * never negated, plus bb__key_point its template point). */
typedef struct bb__walk_point {
  double u, z;
  int64_t key;
} bb__walk_point;

/* What a pass sees of a sweep's walks (bb__sweep_lines_walked). Each line
 * is walked on one worker thread, both sides at once (their calls
 * interleave; side 0 walks along (a, b), side 1 along (-a, -b)). */
typedef struct bb__walk_visitor {
  /* Before a line's walks (its texels and heights are known, not its
   * horizons): the state the calls below receive, or NULL when out of
   * memory (the sweep then fails with BB_ERR_MEMORY). */
  void *(*line_begin)(void *ctx, const bb__line_view *line);
  /* Each point pushed on side k's hull, nearer to the origins still to come
   * than every point pushed before it: hull[size - 1], the hull as it now is
   * (the array origin() is given). May be NULL. */
  void (*push)(void *state, int side, const bb__walk_point *hull, int size);
  /* Origin j (texel j of the line, at u0 along the walk, height oz) once
   * every point beyond it is pushed: the hull hull[0..size-1] (the upper
   * hull of those points, nearest last), the index of its tangent vertex (-1
   * when there is none) and the horizon that vertex makes, the trace's bits
   * (in a chunk the sweep may later march the texel instead: line_end's
   * found[] says). */
  void (*origin)(void *state, int side, int j, double u0, double oz,
                 const bb__walk_point *hull, int size, int tangent, float horizon);
  /* After the walks, with every horizon found (line->found, tangent_key);
   * the state is not used again after it. */
  void (*line_end)(void *state, const bb__line_view *line);
  /* Whether a line is walked at all (before line_begin; NULL: every one).
   * A line left out has no calls and its horizons are not found. */
  int (*line_wanted)(void *ctx, const bb__line_view *line);
} bb__walk_visitor;

/* bb__sweep_lines with a visitor of its walks in place of the sums (the
 * directions' sums may be NULL); checkpoint (may be NULL) is polled every
 * 50 ms and may cancel (BB_ERR_CANCELLED). */
bb_status bb__sweep_lines_walked(const bb_pyramid *p, int a, int b,
                                 const bb__sweep_dir *along,
                                 const bb__sweep_dir *opposite, double bias, int threads,
                                 const bb__walk_visitor *visitor, void *ctx,
                                 const bb__checkpoint *checkpoint, bb_error *err);

/* The index of the vertex of hull[0..size-1] (a walk's upper hull, nearest
 * last, u growing away from the origin) of largest slope from the origin
 * (u0, z0) behind every point; -1 when size is 0. The sweeps' own search. */
int bb__hull_tangent(const bb__walk_point *hull, int size, double u0, double z0);

/* ------------------------------------------------------ parts of lines */

/* A stretch of one line for bb__sweep_stretches: the line's texels 0 ..
 * len-1, texel 0 at (x, y) (periodic coordinates in the image; clamped ones
 * may start anywhere on a line), profiled `before` steps behind texel 0
 * and `after` steps past texel len-1. On a side marked exact the profile
 * holds everything that can decide a horizon (a clamped line's, out to
 * where it turns flat); on the other sides a texel whose horizon the points
 * beyond the profile could beat (bb_pyramid's global max at their nearest
 * distance) is marched, which finds the same bits, as for the chunks of a
 * long line. */
typedef struct bb__stretch {
  int x, y, len;
  int before, after;
  int exact_behind, exact_ahead;
  /* NULL, or per texel bit k set when the caller wants its horizon along
   * side k (0: (a, b), 1: (-a, -b)); a horizon not wanted is never marched
   * and may be wrong where the profile cannot vouch for it */
  const unsigned char *want;
} bb__stretch;

/* bb__sweep_lines_hooked over the given stretches of lines only. With
 * round 1 (periodic addressing), each is a whole line of the period's
 * texels (before and after unused), swept once round as the whole trace
 * sweeps it: from the line's texel the whole trace starts at
 * (bb__line_seed), the same bits. */
bb_status bb__sweep_stretches(const bb_pyramid *p, int a, int b,
                              const bb__sweep_dir *along, const bb__sweep_dir *opposite,
                              double bias, int threads, const bb__stretch *stretches,
                              int count, int round, bb__line_hook hook, void *hook_ctx,
                              bb_error *err);

/* The texel at which bb__sweep_lines starts the periodic line of step
 * (a, b) through texel (x, y). */
void bb__line_seed(const bb_pyramid *p, int a, int b, int x, int y, int *x0, int *y0);

/* The steps the whole trace profiles before and after the clamped line of
 * step (a, b) whose first texel is (x, y) and which has len texels: out to
 * where the surface turns flat at either end. */
void bb__clamped_line_extent(const bb_pyramid *p, int a, int b, int x, int y, int len,
                             int *before, int *after);

/* Periodic lines of step (a, b) longer than this many steps are swept in
 * chunks (bb__sweep_lines with long_line 0). */
long bb__sweep_long_line(int a, int b);

/* The breakpoints of the step from (0, 0) to (a, b), by rising u, the next
 * texel last, as the sweeps compute them (offset1 and offset2 unset): into
 * out (room for 4 BB__MAX_LATTICE_STEP + 1); returns their count. */
int bb__sweep_template(int a, int b, bb__template_point *out);

/* Where the breakpoints of the step from a texel read vertices, relative to
 * the texel (the texel itself included), and the fraction of the step at
 * which its first point lies and its last point before the next texel (0
 * when it has none). */
typedef struct bb__template_extent {
  int min_dx, max_dx, min_dy, max_dy;
  double first_frac, last_inner_frac;
} bb__template_extent;
void bb__sweep_template_extent(int a, int b, bb__template_extent *out);

#endif /* BB_TRACE_SWEEP_H */
