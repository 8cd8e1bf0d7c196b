/* trace.c: occlusion of rays over the height field, marched through the
 * max-mip pyramid (no triangle database), and the batch trace of a bake.
 *
 * Exact test. Over a cell the surface is two planar triangles, so along the
 * vertical half-plane of a ray it is piecewise linear in the horizontal
 * distance t, with breakpoints where the ray's 2D line crosses a cell edge
 * or a cell's diagonal. On each linear piece (surface(t) - oz) / t is
 * monotone, so the ray of tangent T (rise per horizontal texel) meets the
 * surface iff some breakpoint at t > 0 has slope (surface - oz) / t >= T.
 * The origin itself (t = 0) never counts: that is the one rule for the ray's
 * start on the surface, and it makes bias 0 well defined.
 *
 * Every breakpoint is computed (cross_vertical/horizontal/diagonal) from its
 * line's index, the origin and the direction only, never from the path that
 * reached it. So the max-mip march, the brute-force DDA and a march of a
 * whole azimuth slice compute bit-identical slopes and give identical answers
 * whatever order they test breakpoints in: a skipped node only ever hides
 * breakpoints whose slope is below the threshold by more than `margin`, far
 * beyond rounding.
 *
 * Slices. All rays of an azimuth slice share the 2D line, so one march that
 * tracks the highest breakpoint slope seen (the horizon) answers all of them:
 * the rays of the slice are sorted by elevation, and the march only looks for
 * breakpoints that would block the lowest ray not yet blocked. The batch
 * trace gets each texel's count of blocked rays per slice from line sweeps
 * (sweep.c), or, past 4096 x 4096, from marches through square nodes, texel
 * by texel. Marches through direction bands (band.c) give the same counts;
 * the tests hold the three paths to each other.
 */
#include "internal.h"
#include "trace_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Per-direction constants of a march (shared by all texels of a slice). */
typedef struct direction {
  double dx, dy;             /* unit horizontal direction */
  double inv_dx, inv_dy;     /* 1/dx, 1/dy; +inf when 0 (never crosses those lines) */
  double inv_dsum;           /* 1/(dx+dy), 0 when the ray is parallel to the diagonals */
  int sx, sy;                /* step direction per axis, +1 or -1 */
} direction;

/* Walking state: the cell (ix, iy) the ray is in, unwrapped, its addressed
 * index (cx, cy), and the distance t at which the ray got there. */
typedef struct walker {
  const bb_pyramid *p;
  direction d;
  double ox, oy, oz, osum;
  int ix, iy, cx, cy;
  double t;
  double margin; /* slack of every skip test, far beyond rounding */
} walker;

static void direction_init(direction *d, double dx, double dy) {
  d->dx = dx;
  d->dy = dy;
  d->sx = dx < 0 ? -1 : 1;
  d->sy = dy < 0 ? -1 : 1;
  d->inv_dx = dx != 0.0 ? 1.0 / dx : INFINITY;
  d->inv_dy = dy != 0.0 ? 1.0 / dy : INFINITY;
  d->inv_dsum = (dx + dy) != 0.0 ? 1.0 / (dx + dy) : 0.0;
}

/* floor() without the libm call the x86-64 baseline makes of it. */
static inline int fast_floor(double v) {
  int i = (int)v;
  return (double)i > v ? i - 1 : i;
}

/* The cell index along an axis of a point moving with step sign s: on a
 * cell edge, the cell the ray is about to enter. */
static inline int cell_along(double v, int s) {
  return s > 0 ? fast_floor(v) : -fast_floor(-v) - 1;
}

static inline int is_periodic(const walker *w) {
  return w->p->addressing == BB_ADDRESS_PERIODIC;
}

/* Addressed column / row of vertex i, which lies near the current cell. */
static inline int vertex_col(const walker *w, int i) {
  return is_periodic(w) ? bb__wrap_near(w->cx + (i - w->ix), w->p->width)
                        : bb__clampi(i, 0, w->p->width - 1);
}

static inline int vertex_row(const walker *w, int i) {
  return is_periodic(w) ? bb__wrap_near(w->cy + (i - w->iy), w->p->height)
                        : bb__clampi(i, 0, w->p->height - 1);
}

static inline double vertex_z(const walker *w, int x, int y) {
  return w->p->z[(size_t)vertex_row(w, y) * (size_t)w->p->width + (size_t)vertex_col(w, x)];
}

/* Clamp mode only: a cell outside the image is the border extruded. */
static inline int is_inside(const walker *w) {
  return is_periodic(w) ||
         (w->ix >= 0 && w->ix < w->p->width && w->iy >= 0 && w->iy < w->p->height);
}

static void set_cell(walker *w, int ix, int iy) {
  w->ix = ix;
  w->iy = iy;
  w->cx = is_periodic(w) ? bb__wrap(ix, w->p->width) : bb__clampi(ix, 0, w->p->width - 1);
  w->cy = is_periodic(w) ? bb__wrap(iy, w->p->height) : bb__clampi(iy, 0, w->p->height - 1);
}

static void move_to(walker *w, int ix, int iy) {
  if (is_periodic(w)) {
    w->cx = bb__wrap_near(w->cx + (ix - w->ix), w->p->width);
    w->cy = bb__wrap_near(w->cy + (iy - w->iy), w->p->height);
    w->ix = ix;
    w->iy = iy;
  } else {
    set_cell(w, ix, iy);
  }
}

static void walker_init(walker *w, const bb_pyramid *p, const direction *d, double ox,
                        double oy, double oz) {
  w->p = p;
  w->d = *d;
  w->ox = ox;
  w->oy = oy;
  w->oz = oz;
  w->osum = ox + oy;
  w->margin = 1e-7 * (1.0 + fabs((double)p->global_max) + fabs((double)p->global_min) + fabs(oz));
  w->t = 0.0;
  set_cell(w, cell_along(ox, d->sx), cell_along(oy, d->sy));
}

/* Number of thresholds (from b on) that slope s, met at distance t, blocks,
 * plus b; *raised_at records where the horizon last rose. */
static inline int raise_horizon(const double *tan_el, int n, int b, double s, double t,
                                double *raised_at) {
  if (b < n && s >= tan_el[b]) {
    *raised_at = t;
    do b++;
    while (b < n && s >= tan_el[b]);
  }
  return b;
}

static inline double clamp01(double v) {
  return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

/* ---- breakpoints: each a pure function of its line and the ray ---------- */

/* The four corner heights of the walker's cell, read once per cell test;
 * vertices outside the cell (rare) are read through the addressing. */
typedef struct corners {
  const walker *w;
  double z00, z10, z01, z11; /* (ix, iy), (ix+1, iy), (ix, iy+1), (ix+1, iy+1) */
} corners;

static inline void corners_load(corners *c, const walker *w) {
  const bb_pyramid *p = w->p;
  int x1, y1;
  if (is_periodic(w)) {
    x1 = w->cx + 1 == p->width ? 0 : w->cx + 1;
    y1 = w->cy + 1 == p->height ? 0 : w->cy + 1;
  } else {
    x1 = bb__clampi(w->ix + 1, 0, p->width - 1);
    y1 = bb__clampi(w->iy + 1, 0, p->height - 1);
  }
  const float *r0 = p->z + (size_t)w->cy * (size_t)p->width;
  const float *r1 = p->z + (size_t)y1 * (size_t)p->width;
  c->w = w;
  c->z00 = r0[w->cx];
  c->z10 = r0[x1];
  c->z01 = r1[w->cx];
  c->z11 = r1[x1];
}

/* Height of vertex (x, y), from the cache when it is a corner of the cell. */
static inline double corner_z(const corners *c, int x, int y) {
  const int dx = x - c->w->ix, dy = y - c->w->iy;
  if ((unsigned)dx <= 1u && (unsigned)dy <= 1u)
    return dy ? (dx ? c->z11 : c->z01) : (dx ? c->z10 : c->z00);
  return vertex_z(c->w, x, y);
}

/* Where the ray crosses the vertical line x = X: the surface there lies on
 * the edge from (X, row) to (X, row + 1). Returns the distance, or 0 if the
 * crossing is not in (0, t_max], and the surface height in *z. */
static inline double cross_vertical(const corners *c, double t_max, int X, double *z) {
  const walker *w = c->w;
  const double t = ((double)X - w->ox) * w->d.inv_dx;
  if (!(t > 0.0) || t > t_max) return 0.0;
  const double y = w->oy + t * w->d.dy;
  const int row = fast_floor(y);
  const double za = corner_z(c, X, row), zb = corner_z(c, X, row + 1);
  *z = za + (zb - za) * clamp01(y - (double)row);
  return t;
}

static inline double cross_horizontal(const corners *c, double t_max, int Y, double *z) {
  const walker *w = c->w;
  const double t = ((double)Y - w->oy) * w->d.inv_dy;
  if (!(t > 0.0) || t > t_max) return 0.0;
  const double x = w->ox + t * w->d.dx;
  const int col = fast_floor(x);
  const double za = corner_z(c, col, Y), zb = corner_z(c, col + 1, Y);
  *z = za + (zb - za) * clamp01(x - (double)col);
  return t;
}

/* The diagonal x + y = K: in cell (c, K-1-c) it runs from (c+1, K-1-c) to
 * (c, K-c), the split of Valve's two triangles. */
static inline double cross_diagonal(const corners *c, double t_max, int K, double *z) {
  const walker *w = c->w;
  const double t = ((double)K - w->osum) * w->d.inv_dsum;
  if (!(t > 0.0) || t > t_max) return 0.0;
  const int col = fast_floor(w->ox + t * w->d.dx), row = K - 1 - col;
  const double za = corner_z(c, col + 1, row), zb = corner_z(c, col, row + 1);
  *z = za + (zb - za) * clamp01(w->oy + t * w->d.dy - (double)row);
  return t;
}

/* The exact cell test: the breakpoints on the current cell's exit edges and
 * its diagonal. Its entry edges are the exit edges of the cell before, or lie
 * on the boundary of a node skipped just before (whose max bounds them), or
 * hold the origin. */
static inline int test_cell(const walker *w, const double *tan_el, int n, int b,
                            double *raised_at) {
  const int X = w->ix + (w->d.sx > 0), Y = w->iy + (w->d.sy > 0);
  /* Lines of this cell crossed far beyond it (by a nearly parallel ray) are
   * other cells' business; the slack keeps every crossing of this one. */
  const double exit_x = ((double)X - w->ox) * w->d.inv_dx;
  const double exit_y = ((double)Y - w->oy) * w->d.inv_dy;
  const double t_max = (exit_x < exit_y ? exit_x : exit_y) + 1.0;
  corners c;
  corners_load(&c, w);
  double z, t;
  if ((t = cross_vertical(&c, t_max, X, &z)) > 0.0)
    b = raise_horizon(tan_el, n, b, (z - w->oz) / t, t, raised_at);
  if ((t = cross_horizontal(&c, t_max, Y, &z)) > 0.0)
    b = raise_horizon(tan_el, n, b, (z - w->oz) / t, t, raised_at);
  if ((t = cross_diagonal(&c, t_max, w->ix + w->iy + 1, &z)) > 0.0)
    b = raise_horizon(tan_el, n, b, (z - w->oz) / t, t, raised_at);
  return b;
}

/* ---- traversal ----------------------------------------------------------- */

/* A located cell index, never behind the current one: a ray through a
 * vertex can round to the cell it is leaving, and a walk that steps back
 * could skip the same node forever. */
static inline int no_backward(int located, int current, int s) {
  return s > 0 ? (located < current ? current : located) : (located > current ? current : located);
}

/* Moves the walker past the level-k node holding it (k = 0: the next cell).
 * The axis it leaves by advances exactly; the other is located by floor,
 * which rounding may put a hair off near a corner: harmless, since a cell
 * touched only within ~1e-12 texel of a corner of the node just skipped
 * holds nothing above that node's max by more than the skip margin. */
static void advance(walker *w, int k) {
  const int span = 1 << k, mask = span - 1;
  const int X = w->ix - (w->cx & mask) + (w->d.sx > 0 ? span : 0);
  const int Y = w->iy - (w->cy & mask) + (w->d.sy > 0 ? span : 0);
  const double tx = ((double)X - w->ox) * w->d.inv_dx;
  const double ty = ((double)Y - w->oy) * w->d.inv_dy;
  int ix, iy;
  if (tx < ty) {
    w->t = tx;
    ix = w->d.sx > 0 ? X : X - 1;
    iy = no_backward(cell_along(w->oy + tx * w->d.dy, w->d.sy), w->iy, w->d.sy);
  } else if (ty < tx) {
    w->t = ty;
    iy = w->d.sy > 0 ? Y : Y - 1;
    ix = no_backward(cell_along(w->ox + ty * w->d.dx, w->d.sx), w->ix, w->d.sx);
  } else { /* through a corner */
    w->t = tx;
    ix = w->d.sx > 0 ? X : X - 1;
    iy = w->d.sy > 0 ? Y : Y - 1;
  }
  move_to(w, ix, iy);
}

/* Puts the walker in the cell the ray is in at distance t. */
static void jump_to(walker *w, double t) {
  w->t = t;
  move_to(w, cell_along(w->ox + t * w->d.dx, w->d.sx), cell_along(w->oy + t * w->d.dy, w->d.sy));
}

static inline float node_max(const bb_pyramid *p, int k, int cx, int cy) {
  return p->level_max[k][(size_t)(cy >> k) * (size_t)p->level_width[k] + (size_t)(cx >> k)];
}

/* The march proper, for the ray from (ox, oy, oz) along d, against the n
 * rising tangents tan_el. *hint (may be NULL) is in: a distance where a
 * nearby parallel ray met its horizon (0 for none); out: where this one did.
 * That cell is tested first: the order in which breakpoints are tested does
 * not change the answer, but a horizon found early raises the threshold and
 * with it the height below which whole nodes are skipped. */
static int march(const bb_pyramid *p, const direction *d, double ox, double oy, double oz,
                 const double *tan_el, int n, double *hint) {
  walker w;
  walker_init(&w, p, d, ox, oy, oz);
  const int top = p->levels - 1;
  int b = 0, k = 0;
  double raised_at = 0.0;
  if (hint && *hint > 0.0) {
    walker probe = w;
    jump_to(&probe, *hint);
    b = test_cell(&probe, tan_el, n, b, &raised_at);
  }
  while (b < n) {
    /* Nothing under the ray below this height can block ray b or above. */
    const double limit = w.oz + w.t * tan_el[b] - w.margin;
    if (!is_inside(&w)) { /* clamp mode, past the border: never comes back */
      if ((double)p->border_max < limit) break;
      b = test_cell(&w, tan_el, n, b, &raised_at);
      advance(&w, 0);
      continue;
    }
    if ((double)node_max(p, k, w.cx, w.cy) < limit) {
      if (k == top) break; /* above the global maximum for good */
      advance(&w, k);
      k++;
      continue;
    }
    if (k > 0) {
      k--;
      continue;
    }
    b = test_cell(&w, tan_el, n, b, &raised_at);
    advance(&w, 0);
  }
  if (hint) *hint = raised_at;
  return b;
}

/* march() through the bands of the ray's own direction instead of the
 * square nodes: bands are thin along the path, so they bound it tighter and
 * let the ray skip further. Levels gallop, up after a skip and down after a
 * miss, since a band can start at any cell. x_major and periodic are
 * constants at each call, so each of the four variants compiles to a tight
 * loop with the walker's state in registers. */
static inline __attribute__((always_inline)) int
march_band_impl(const bb_pyramid *p, const bb__band *band, const direction *d, double ox,
                double oy, double oz, const double *tan_el, int n, double *hint,
                const int x_major, const int periodic) {
  walker w;
  walker_init(&w, p, d, ox, oy, oz);
  const int W = p->width, H = p->height, top = band->levels - 1;
  const int sx = d->sx, sy = d->sy;
  const double gmax = (double)p->global_max, margin = w.margin;
  const float *cells = p->level_max[0];
  int ix = w.ix, iy = w.iy, cx = w.cx, cy = w.cy;
  double t = 0.0;
  int b = 0, k = 0;
  double raised_at = 0.0;
  if (*hint > 0.0) {
    walker probe = w;
    jump_to(&probe, *hint);
    b = test_cell(&probe, tan_el, n, b, &raised_at);
  }
  while (b < n) {
    const double limit = oz + t * tan_el[b] - margin;
    if (gmax < limit) break; /* above everything for good */
    const int inside = periodic || (ix >= 0 && ix < W && iy >= 0 && iy < H);
    if (inside && (double)band->level_max[k][(size_t)cy * (size_t)W + (size_t)cx] < limit) {
      const int span = 1 << k; /* skip the 2^k cells along the major axis */
      if (x_major) {
        ix += sx * span;
        t = ((double)(sx > 0 ? ix : ix + 1) - ox) * d->inv_dx;
        const int row = no_backward(cell_along(oy + t * d->dy, sy), iy, sy);
        cx = periodic ? bb__wrap_near(cx + sx * span, W) : bb__clampi(ix, 0, W - 1);
        cy = periodic ? bb__wrap_near(cy + (row - iy), H) : bb__clampi(row, 0, H - 1);
        iy = row;
      } else {
        iy += sy * span;
        t = ((double)(sy > 0 ? iy : iy + 1) - oy) * d->inv_dy;
        const int col = no_backward(cell_along(ox + t * d->dx, sx), ix, sx);
        cy = periodic ? bb__wrap_near(cy + sy * span, H) : bb__clampi(iy, 0, H - 1);
        cx = periodic ? bb__wrap_near(cx + (col - ix), W) : bb__clampi(col, 0, W - 1);
        ix = col;
      }
      if (k < top) k++;
      continue;
    }
    if (inside && k > 0) {
      k--;
      continue;
    }
    /* Past the border (clamp) only border_max bounds the cells; inside, the
     * band's four rows are not all on the path, so the cell alone may pass. */
    const double bound = inside ? (double)cells[(size_t)cy * (size_t)W + (size_t)cx]
                                : (double)p->border_max;
    if (!inside && bound < limit) break; /* never comes back */
    if (bound >= limit) {
      w.ix = ix, w.iy = iy, w.cx = cx, w.cy = cy, w.t = t;
      b = test_cell(&w, tan_el, n, b, &raised_at);
    }
    /* DDA step to the next cell; through a corner, diagonally. */
    const double tx = ((double)(sx > 0 ? ix + 1 : ix) - ox) * d->inv_dx;
    const double ty = ((double)(sy > 0 ? iy + 1 : iy) - oy) * d->inv_dy;
    if (tx <= ty) {
      ix += sx;
      cx = periodic ? bb__wrap_near(cx + sx, W) : bb__clampi(ix, 0, W - 1);
    }
    if (ty <= tx) {
      iy += sy;
      cy = periodic ? bb__wrap_near(cy + sy, H) : bb__clampi(iy, 0, H - 1);
    }
    t = tx < ty ? tx : ty;
  }
  *hint = raised_at;
  return b;
}

static int march_band(const bb_pyramid *p, const bb__band *band, const direction *d,
                      double ox, double oy, double oz, const double *tan_el, int n,
                      double *hint) {
  const int periodic = p->addressing == BB_ADDRESS_PERIODIC;
  if (band->major_x)
    return periodic ? march_band_impl(p, band, d, ox, oy, oz, tan_el, n, hint, 1, 1)
                    : march_band_impl(p, band, d, ox, oy, oz, tan_el, n, hint, 1, 0);
  return periodic ? march_band_impl(p, band, d, ox, oy, oz, tan_el, n, hint, 0, 1)
                  : march_band_impl(p, band, d, ox, oy, oz, tan_el, n, hint, 0, 0);
}

int bb__march(const bb_pyramid *p, const bb__march_ray *r, const double *tan_el, int n) {
  direction d;
  direction_init(&d, r->dx, r->dy);
  return n > 0 ? march(p, &d, r->ox, r->oy, r->oz, tan_el, n, NULL) : 0;
}

int bb__march_brute(const bb_pyramid *p, const bb__march_ray *r, const double *tan_el,
                    int n) {
  direction d;
  direction_init(&d, r->dx, r->dy);
  walker w;
  walker_init(&w, p, &d, r->ox, r->oy, r->oz);
  int b = 0;
  double raised_at;
  while (b < n) {
    if ((double)p->global_max < w.oz + w.t * tan_el[b] - w.margin) break;
    b = test_cell(&w, tan_el, n, b, &raised_at);
    advance(&w, 0);
  }
  return b;
}

/* Splits a 3D ray into the march's horizontal line and tangent. Returns 0 for
 * a vertical ray, which nothing above the origin can block. */
static int to_march_ray(const bb_ray *ray, bb__march_ray *r, double *tan_el) {
  double h = hypot(ray->direction[0], ray->direction[1]);
  if (h == 0.0) return 0;
  r->ox = ray->origin[0];
  r->oy = ray->origin[1];
  r->oz = ray->origin[2];
  r->dx = ray->direction[0] / h;
  r->dy = ray->direction[1] / h;
  *tan_el = ray->direction[2] / h;
  return 1;
}

int bb_ray_occluded(const bb_pyramid *p, const bb_ray *ray) {
  bb__march_ray r;
  double tan_el;
  return to_march_ray(ray, &r, &tan_el) ? bb__march(p, &r, &tan_el, 1) : 0;
}

int bb_ray_occluded_brute(const bb_pyramid *p, const bb_ray *ray) {
  bb__march_ray r;
  double tan_el;
  return to_march_ray(ray, &r, &tan_el) ? bb__march_brute(p, &r, &tan_el, 1) : 0;
}

/* ------------------------------------------------------------ batch trace */

void bb_trace_options_init(bb_trace_options *o) {
  memset(o, 0, sizeof *o);
  o->bias_texels = 0.55;
}

/* Slices whose blocked counts are kept at once, 2 bytes per texel each (as
 * much as the 4 double sums they feed): a 256-ray set (16 slices) is one
 * batch, added up in one pass with no sums kept between passes. */
enum { SLICE_BATCH = 16 };

/* Per slice s and channel c, the weight of the rays a march leaves unblocked:
 * unblocked[c][start_s + s + b] = sum of the weights of rays b.. of slice s. */
typedef struct trace_job {
  const bb_pyramid *p;
  const bb_rayset *rs;
  const bb_trace_options *o;
  int channels;           /* 1 + basis_count */
  double *unblocked;      /* channels * (ray_count + slice_count) */
  double total[1 + BB_MAX_BASIS];
  direction *slice_dir;   /* per slice */
  int *order;             /* slices in the order their weights are summed */
  /* Slice paths: the blocked counts of a batch of slices, then added up. */
  uint16_t *blocked;      /* SLICE_BATCH planes of one count per texel */
  int batch[SLICE_BATCH]; /* the batch's slices, plane k holds batch[k]'s counts */
  int batch_size;
  int batch_first, batch_last; /* is it the first / last batch of the trace? */
  double *sums;           /* per texel and channel, weight summed by earlier batches */
  const bb__band *band;   /* band path: the bands of the slice of plane band_plane */
  int band_plane;
  float *vis;
} trace_job;

static double ray_weight(const bb_rayset *rs, int c, int ray) {
  return c == 0 ? rs->weight_ao[ray]
                : rs->weight_basis[(size_t)ray * (size_t)rs->basis_count + (size_t)(c - 1)];
}

static int opposite_steps(const bb_rayset *rs, int s, int t) {
  return rs->slice_step[2 * s] == -rs->slice_step[2 * t] &&
         rs->slice_step[2 * s + 1] == -rs->slice_step[2 * t + 1];
}

/* The order in which every path sums the slices' weights: each slice is
 * followed by its opposite (lattice step (-a, -b)), when the set has one, so
 * that one line sweep can serve both. A fixed order keeps the paths' sums,
 * and so their results, bit-identical. Returns -1 when out of memory. */
static int order_slices(const bb_rayset *rs, int *order) {
  unsigned char *placed = calloc((size_t)rs->slice_count, 1);
  if (!placed) return -1;
  int n = 0;
  for (int s = 0; s < rs->slice_count; s++) {
    if (placed[s]) continue;
    placed[s] = 1;
    order[n++] = s;
    for (int t = s + 1; t < rs->slice_count; t++)
      if (!placed[t] && opposite_steps(rs, s, t)) {
        placed[t] = 1;
        order[n++] = t;
        break;
      }
  }
  free(placed);
  return 0;
}

/* Suffix sums, and totals taken as the same sums in the same order, so a
 * texel with nothing blocked gets exactly 1. */
static bb_status prepare_job(trace_job *job, bb_error *err) {
  const bb_rayset *rs = job->rs;
  const size_t stride = (size_t)(rs->ray_count + rs->slice_count);
  job->unblocked = malloc((size_t)job->channels * stride * sizeof(double));
  job->slice_dir = malloc((size_t)rs->slice_count * sizeof(direction));
  job->order = malloc((size_t)rs->slice_count * sizeof(int));
  if (!job->unblocked || !job->slice_dir || !job->order || order_slices(rs, job->order) != 0)
    return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  for (int s = 0; s < rs->slice_count; s++)
    direction_init(&job->slice_dir[s], rs->slice_dir[2 * s], rs->slice_dir[2 * s + 1]);
  for (int c = 0; c < job->channels; c++) {
    double *u = job->unblocked + (size_t)c * stride;
    job->total[c] = 0.0;
    for (int i = 0; i < rs->slice_count; i++) {
      const int s = job->order[i], start = rs->slice_start[s],
                count = rs->slice_start[s + 1] - start;
      double *slice = u + start + s;
      slice[count] = 0.0;
      for (int e = count - 1; e >= 0; e--) slice[e] = slice[e + 1] + ray_weight(rs, c, start + e);
      job->total[c] += slice[0];
    }
  }
  return BB_OK;
}

static void release_job(trace_job *job) {
  free(job->unblocked);
  free(job->slice_dir);
  free(job->order);
  free(job->sums);
  free(job->blocked);
}

/* Adds slice s's unblocked weight for `blocked` blocked rays to sum[]. */
static inline void add_slice(const trace_job *job, int s, int blocked, double *sum) {
  const size_t stride = (size_t)(job->rs->ray_count + job->rs->slice_count);
  const size_t at = (size_t)(job->rs->slice_start[s] + s + blocked);
  for (int c = 0; c < job->channels; c++) sum[c] += job->unblocked[(size_t)c * stride + at];
}

static void store_texel(const trace_job *job, size_t texel, const double *sum) {
  float *out = job->vis + texel * (size_t)job->channels;
  for (int c = 0; c < job->channels; c++)
    out[c] = job->total[c] > 0.0 ? (float)(sum[c] / job->total[c]) : 1.0f;
}

/* Plane k of the batch's blocked counts. */
static inline uint16_t *plane(const trace_job *job, int k) {
  return job->blocked + (size_t)k * (size_t)job->p->width * (size_t)job->p->height;
}

static inline double origin_z(const trace_job *job, int x, int y) {
  return (double)job->p->z[(size_t)y * (size_t)job->p->width + (size_t)x] + job->o->bias_texels;
}

/* Band path: one slice over one row. */
static void band_slice_row(void *user, int y) {
  const trace_job *job = user;
  const bb_rayset *rs = job->rs;
  const int s = job->batch[job->band_plane], start = rs->slice_start[s],
            count = rs->slice_start[s + 1] - start;
  uint16_t *blocked = plane(job, job->band_plane);
  double hint = 0.0; /* where the previous texel's horizon was */
  for (int x = 0; x < job->p->width; x++)
    blocked[(size_t)y * (size_t)job->p->width + (size_t)x] = (uint16_t)march_band(
        job->p, job->band, &job->slice_dir[s], x, y, origin_z(job, x, y),
        rs->tan_elevation + start, count, &hint);
}

/* A texel's sums grow batch by batch and, within one, plane by plane:
 * always in the summing order, so the result does not depend on threads.
 * The last batch stores the visibility. */
static void add_batch_row(void *user, int y) {
  const trace_job *job = user;
  const int w = job->p->width, channels = job->channels;
  const size_t texels = (size_t)w * (size_t)job->p->height;
  for (int x = 0; x < w; x++) {
    const size_t texel = (size_t)y * (size_t)w + (size_t)x;
    double sum[1 + BB_MAX_BASIS] = {0};
    double *kept = job->sums ? job->sums + texel * (size_t)channels : NULL;
    if (!job->batch_first)
      for (int c = 0; c < channels; c++) sum[c] = kept[c];
    for (int k = 0; k < job->batch_size; k++)
      add_slice(job, job->batch[k], job->blocked[(size_t)k * texels + texel], sum);
    if (job->batch_last)
      store_texel(job, texel, sum);
    else
      for (int c = 0; c < channels; c++) kept[c] = sum[c];
  }
}

/* Square path: every slice of a texel through the square nodes. */
static void trace_row(void *user, int y) {
  const trace_job *job = user;
  const bb_rayset *rs = job->rs;
  double hint[256] = {0}; /* per slice: where the previous texel's horizon was */
  for (int x = 0; x < job->p->width; x++) {
    double sum[1 + BB_MAX_BASIS] = {0};
    for (int i = 0; i < rs->slice_count; i++) {
      const int s = job->order[i], start = rs->slice_start[s],
                count = rs->slice_start[s + 1] - start;
      add_slice(job, s, march(job->p, &job->slice_dir[s], x, y, origin_z(job, x, y),
                              rs->tan_elevation + start, count, &hint[s]), sum);
    }
    store_texel(job, (size_t)y * (size_t)job->p->width + (size_t)x, sum);
  }
}

static bb__sweep_dir sweep_dir(const trace_job *job, int k) {
  const bb_rayset *rs = job->rs;
  const int s = job->batch[k], start = rs->slice_start[s];
  return (bb__sweep_dir){rs->tan_elevation + start, rs->slice_start[s + 1] - start,
                         plane(job, k)};
}

/* The blocked counts at every texel of the batch's planes k (and k + 1 when
 * `pair`): by line sweeps, which take a slice and its opposite at once, or
 * (`sweep` 0) by marches through the slice's direction bands. */
static bb_status blocked_counts(trace_job *job, int k, int pair, int sweep, bb_error *err) {
  const bb_pyramid *p = job->p;
  const bb_rayset *rs = job->rs;
  const int s = job->batch[k];
  if (sweep) {
    const bb__sweep_dir along = sweep_dir(job, k);
    bb__sweep_dir opposite = {0};
    if (pair) opposite = sweep_dir(job, k + 1);
    return bb__sweep_lines(p, rs->slice_step[2 * s], rs->slice_step[2 * s + 1], &along,
                           pair ? &opposite : NULL, job->o->bias_texels, job->o->threads, err);
  }
  job->band_plane = k;
  bb__band band;
  bb_status st = bb__band_build(p, job->slice_dir[s].dx, job->slice_dir[s].dy, job->o->threads,
                                &band, err);
  if (st != BB_OK) return st;
  job->band = &band;
  st = bb__parallel_for(p->height, job->o->threads, band_slice_row, job, NULL, NULL, err);
  bb__band_free(&band);
  job->band = NULL;
  return st;
}

/* Fills the batch with the slices order[*next ..], a slice and its opposite
 * side by side when sweeps can take them together (is_pair[k] marks the
 * first plane of such a pair). */
static void fill_batch(trace_job *job, int sweep, int *next, int *is_pair) {
  const bb_rayset *rs = job->rs;
  job->batch_size = 0;
  while (*next < rs->slice_count && job->batch_size < SLICE_BATCH) {
    const int s = job->order[*next];
    const int t = *next + 1 < rs->slice_count ? job->order[*next + 1] : -1;
    const int pair = sweep && t >= 0 && opposite_steps(rs, s, t);
    if (pair && job->batch_size + 2 > SLICE_BATCH) break;
    is_pair[job->batch_size] = pair;
    job->batch[job->batch_size++] = s;
    if (pair) {
      is_pair[job->batch_size] = 0;
      job->batch[job->batch_size++] = t;
    }
    *next += pair ? 2 : 1;
  }
}

/* Slices in the summing order, batch by batch. */
static bb_status trace_slices(trace_job *job, int sweep, bb_error *err) {
  const bb_pyramid *p = job->p;
  const bb_rayset *rs = job->rs;
  const size_t texels = (size_t)p->width * (size_t)p->height;
  const int planes = rs->slice_count < SLICE_BATCH ? rs->slice_count : SLICE_BATCH;
  job->blocked = malloc((size_t)planes * texels * sizeof(uint16_t));
  if (rs->slice_count > SLICE_BATCH) /* more than one batch: sums kept between them */
    job->sums = malloc(texels * (size_t)job->channels * sizeof(double));
  if (!job->blocked || (rs->slice_count > SLICE_BATCH && !job->sums))
    return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  bb_status st = BB_OK;
  int next = 0, is_pair[SLICE_BATCH];
  for (job->batch_first = 1; st == BB_OK && next < rs->slice_count; job->batch_first = 0) {
    fill_batch(job, sweep, &next, is_pair);
    job->batch_last = next == rs->slice_count;
    for (int k = 0; st == BB_OK && k < job->batch_size; k += is_pair[k] ? 2 : 1) {
      st = blocked_counts(job, k, is_pair[k], sweep, err);
      if (job->o->progress)
        job->o->progress(job->o->progress_user, next - job->batch_size + k + 1 + is_pair[k],
                         rs->slice_count);
    }
    if (st == BB_OK)
      st = bb__parallel_for(p->height, job->o->threads, add_batch_row, job, NULL, NULL, err);
  }
  return st;
}

bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err) {
  memset(vis, 0, sizeof *vis);
  if (!p || !rs || !o || rs->ray_count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: missing pyramid, ray set or options");
  if (!(o->bias_texels >= 0.0) || !isfinite(o->bias_texels))
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: bias must be finite and >= 0 (got %g)",
                    o->bias_texels);
  trace_job job = {.p = p, .rs = rs, .o = o, .channels = 1 + rs->basis_count};
  bb_status st = prepare_job(&job, err);
  if (st == BB_OK) st = bb_image_alloc(vis, p->width, p->height, job.channels, err);
  if (st == BB_OK) {
    job.vis = vis->pixels;
    st = path == BB__TRACE_SQUARE
             ? bb__parallel_for(p->height, o->threads, trace_row, &job, o->progress,
                                o->progress_user, err)
             : trace_slices(&job, path == BB__TRACE_SWEEP, err);
  }
  release_job(&job);
  if (st != BB_OK) bb_image_free(vis);
  return st;
}

bb_status bb_trace_occlusion(const bb_pyramid *p, const bb_rayset *rs,
                             const bb_trace_options *o, bb_image *vis,
                             double *rays_traced, bb_error *err) {
  /* Slice by slice, the counts of a batch of slices cost 32 bytes per texel
   * (and large ray sets as much again for sums): past 4096 x 4096 the square
   * nodes, texel by texel, do without. */
  const int by_slice = p && (long)p->width * p->height <= 4096L * 4096L;
  bb_status st = bb__trace_occlusion_path(p, rs, o, by_slice ? BB__TRACE_SWEEP : BB__TRACE_SQUARE,
                                          vis, err);
  if (st == BB_OK && rays_traced)
    *rays_traced = (double)p->width * (double)p->height * (double)rs->ray_count;
  return st;
}
