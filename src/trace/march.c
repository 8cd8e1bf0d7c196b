/* march.c: horizons over the height field, marched through the max-mip
 * pyramid (no triangle database): of any ray (bb__ray_horizon,
 * bb__ray_occluded) and of a bake's lattice slices, which the sweeps fall
 * back to where a chunk of a long line cannot vouch for a texel.
 *
 * Exact horizons. Over a cell the surface is two planar triangles, so along
 * the vertical half-plane of a ray it is piecewise linear in the horizontal
 * distance t, with breakpoints where the ray's 2D line crosses a cell edge
 * or a cell's diagonal. On each linear piece (surface(t) - oz) / t is
 * monotone, so the largest slope over the surface ahead (the horizon) is the
 * largest over the breakpoints at t > 0, and a ray of tangent T is blocked
 * exactly when it is >= T. The origin itself (t = 0) never counts: that is
 * the one rule for the ray's start on the surface, and it makes bias 0 well
 * defined. Horizons below 0 count as 0: H is the upper hemisphere.
 *
 * The march keeps the best slope so far and descends only into nodes whose
 * max could raise it (node max >= oz + t * best at the node's near end, with
 * a margin far beyond rounding); it stops when nothing ahead can (the root's
 * max is below that line), past its maximum distance (a periodic lattice
 * line is new for one period only), or where a clamped surface turns flat.
 *
 * Two ways to compute a breakpoint. For any ray (bb__ray_horizon and
 * bb__ray_occluded) from its line's index, the origin and the direction. For
 * a bake's slice, which follows an integer lattice step (a, b) from a
 * vertex, from integers only: the crossing index n and the family's count m
 * per step (distance n / m steps, interpolation weight r / m), exactly as
 * the line sweeps compute them from their template (sweep.c). Either way a
 * breakpoint's slope does not depend on the path that reached it, so the
 * march, the brute-force DDA and the sweeps find bit-identical horizons.
 */
#include "trace/testing.h"
#include "core/internal.h"
#include "trace/march.h"
#include "trace/pyramid.h"

#include <limits.h>
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

/* A march along lattice step (a, b) from the vertex (x0, y0). */
typedef struct lattice {
  int x0, y0, a, b;
  int ma, mb, md;  /* crossings per step: of vertical lines, horizontal lines, diagonals */
  int sa, sb, sd;  /* the signs of a, b, a + b */
  long cap;        /* largest distance considered, in steps */
  double length, inverse_length; /* |(a, b)| and 1 / |(a, b)| */
  double inverse_m[3]; /* 1 / ma, 1 / mb, 1 / md */
} lattice;

/* Walking state: the cell (ix, iy) the ray is in, unwrapped, its addressed
 * index (cx, cy), and the distance t at which the ray got there. The best
 * slope is in texels of rise per texel, or per step in lattice mode. */
typedef struct walker {
  const bb_pyramid *p;
  direction d;
  const lattice *lat; /* NULL: any ray */
  double ox, oy, oz, osum;
  int ix, iy, cx, cy;
  double t;
  double max_t;       /* no breakpoint beyond this distance counts (any ray) */
  double margin;      /* slack of every skip test, far beyond rounding */
  double best;        /* the horizon so far */
  double raised_at;   /* where it last rose */
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

static inline long floor_div(long num, long den) { /* den > 0 */
  const long q = num / den;
  return q * den > num ? q - 1 : q;
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

/* Clamp mode only: the ray is past the border (or on its last cells) along
 * each axis it moves on, going away, so every corner of this cell and of all
 * cells ahead is clamped to the same heights: the surface is flat under the
 * ray from here on, and no breakpoint ahead is steeper than one already
 * tested at the same height. */
static inline int is_flat_beyond(const walker *w) {
  const int W = w->p->width, H = w->p->height;
  const double dx = w->d.dx, dy = w->d.dy;
  return !is_periodic(w) && (dx == 0.0 || (dx > 0.0 ? w->ix >= W - 1 : w->ix < 0)) &&
         (dy == 0.0 || (dy > 0.0 ? w->iy >= H - 1 : w->iy < 0));
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

static void walker_init(walker *w, const bb_pyramid *p, const direction *d, const lattice *lat,
                        double ox, double oy, double oz, double best) {
  w->p = p;
  w->d = *d;
  w->lat = lat;
  w->ox = ox;
  w->oy = oy;
  w->oz = oz;
  w->osum = ox + oy;
  w->margin = 1e-7 * (1.0 + fabs((double)p->global_max) + fabs((double)p->global_min) + fabs(oz));
  w->t = 0.0;
  w->max_t = INFINITY;
  w->best = best;
  w->raised_at = 0.0;
  set_cell(w, cell_along(ox, d->sx), cell_along(oy, d->sy));
}

/* The best slope in texels of rise per texel, for the skip tests. */
static inline double best_per_texel(const walker *w) {
  return w->lat ? w->best * w->lat->inverse_length : w->best;
}

static inline void offer(walker *w, double slope, double t) {
  if (slope > w->best) {
    w->best = slope;
    w->raised_at = t;
  }
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

/* Any ray. Where it crosses the vertical line x = X: the surface there lies
 * on the edge from (X, row) to (X, row + 1). Returns the distance, or 0 if
 * the crossing is not in (0, t_max], and the surface height in *z. */
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

/* A lattice ray's crossings, from integers. Each returns the slope per step,
 * or -INFINITY when the crossing is behind the origin, past the cap, or
 * (by the ray's geometry) farther than t_max. */
static inline double lattice_vertical(const corners *c, double t_max, int X) {
  const walker *w = c->w;
  const lattice *L = w->lat;
  const long n = (long)(X - L->x0) * L->sa;
  if (L->ma == 0 || n <= 0 || n > L->cap * L->ma) return -INFINITY;
  if (((double)X - w->ox) * w->d.inv_dx > t_max) return -INFINITY;
  const long num = n * L->b, row = floor_div(num, L->ma), r = num - row * L->ma;
  const int Y = L->y0 + (int)row;
  const double z = bb__lattice_height(corner_z(c, X, Y), corner_z(c, X, Y + 1),
                                      bb__lattice_weight(r, L->inverse_m[0]));
  return (z - w->oz) / bb__lattice_distance(n, L->inverse_m[0]);
}

static inline double lattice_horizontal(const corners *c, double t_max, int Y) {
  const walker *w = c->w;
  const lattice *L = w->lat;
  const long n = (long)(Y - L->y0) * L->sb;
  if (L->mb == 0 || n <= 0 || n > L->cap * L->mb) return -INFINITY;
  if (((double)Y - w->oy) * w->d.inv_dy > t_max) return -INFINITY;
  const long num = n * L->a, col = floor_div(num, L->mb), r = num - col * L->mb;
  const int X = L->x0 + (int)col;
  const double z = bb__lattice_height(corner_z(c, X, Y), corner_z(c, X + 1, Y),
                                      bb__lattice_weight(r, L->inverse_m[1]));
  return (z - w->oz) / bb__lattice_distance(n, L->inverse_m[1]);
}

static inline double lattice_diagonal(const corners *c, double t_max, int K) {
  const walker *w = c->w;
  const lattice *L = w->lat;
  const long n = (long)(K - L->x0 - L->y0) * L->sd;
  if (L->md == 0 || n <= 0 || n > L->cap * L->md) return -INFINITY;
  if (((double)K - w->osum) * w->d.inv_dsum > t_max) return -INFINITY;
  const long num = n * L->a, col = floor_div(num, L->md), r = num - col * L->md;
  const int X = L->x0 + (int)col, row = K - 1 - X;
  /* from (X + 1, row) to (X, row + 1), at weight 1 - r / md; r = 0 is the
   * vertex (X, row + 1) */
  const double zb = corner_z(c, X, row + 1);
  const double z = r == 0 ? zb
                          : bb__lattice_height(corner_z(c, X + 1, row), zb,
                                               bb__lattice_weight(L->md - r, L->inverse_m[2]));
  return (z - w->oz) / bb__lattice_distance(n, L->inverse_m[2]);
}

/* The exact cell test: the breakpoints on the current cell's exit edges and
 * its diagonal. Its entry edges are the exit edges of the cell before, or lie
 * on the boundary of a node skipped just before (whose max bounds them), or
 * hold the origin. */
static inline void test_cell(walker *w) {
  const int X = w->ix + (w->d.sx > 0), Y = w->iy + (w->d.sy > 0), K = w->ix + w->iy + 1;
  /* Lines of this cell crossed far beyond it (by a nearly parallel ray) are
   * other cells' business; the slack keeps every crossing of this one. */
  const double exit_x = ((double)X - w->ox) * w->d.inv_dx;
  const double exit_y = ((double)Y - w->oy) * w->d.inv_dy;
  double t_max = (exit_x < exit_y ? exit_x : exit_y) + 1.0;
  corners c;
  corners_load(&c, w);
  if (w->lat) {
    offer(w, lattice_vertical(&c, t_max, X), w->t);
    offer(w, lattice_horizontal(&c, t_max, Y), w->t);
    offer(w, lattice_diagonal(&c, t_max, K), w->t);
    return;
  }
  if (t_max > w->max_t) t_max = w->max_t;
  double z, t;
  if ((t = cross_vertical(&c, t_max, X, &z)) > 0.0) offer(w, (z - w->oz) / t, t);
  if ((t = cross_horizontal(&c, t_max, Y, &z)) > 0.0) offer(w, (z - w->oz) / t, t);
  if ((t = cross_diagonal(&c, t_max, K, &z)) > 0.0) offer(w, (z - w->oz) / t, t);
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

/* What the march looks for: breakpoints of slope > the best so far and >=
 * floor (texels per texel), until the best reaches stop_at (native units)
 * or the walker passes end_t. */
typedef struct goal {
  double floor, stop_at, end_t;
} goal;

/* Height under which nothing can raise the best at distance t. */
static inline double skip_limit(const walker *w, const goal *g) {
  const double slope = best_per_texel(w);
  return w->oz + w->t * (slope > g->floor ? slope : g->floor) - w->margin;
}

/* The march proper. hint (may be NULL) is in: a distance where a nearby
 * parallel ray met its horizon (0 for none); out: where this one did. That
 * cell is tested first: the order in which breakpoints are tested does not
 * change the answer, but a horizon found early raises the height below which
 * whole nodes are skipped. */
static void march(walker *w, const goal *g, double *hint) {
  const bb_pyramid *p = w->p;
  const int top = p->levels - 1;
  int k = 0;
  if (hint && *hint > 0.0) {
    walker probe = *w;
    jump_to(&probe, *hint);
    test_cell(&probe);
    w->best = probe.best;
    w->raised_at = probe.raised_at;
  }
  while (w->best < g->stop_at && w->t <= g->end_t) {
    const double limit = skip_limit(w, g);
    if (!is_inside(w)) { /* clamp mode, past the border: never comes back */
      if ((double)p->border_max < limit) break;
      test_cell(w);
      if (is_flat_beyond(w)) break;
      advance(w, 0);
      continue;
    }
    if ((double)node_max(p, k, w->cx, w->cy) < limit) {
      if (k == top) break; /* nothing ahead can rise above the best for good */
      advance(w, k);
      k++;
      continue;
    }
    if (k > 0) {
      k--;
      continue;
    }
    test_cell(w);
    if (is_flat_beyond(w)) break;
    advance(w, 0);
  }
  if (hint) *hint = w->raised_at;
}

/* The brute-force twin: every cell, the same tests and stops, no nodes. */
static void march_brute(walker *w, const goal *g) {
  const bb_pyramid *p = w->p;
  while (w->best < g->stop_at && w->t <= g->end_t) {
    const double limit = skip_limit(w, g);
    if ((double)p->global_max < limit) break;
    if (!is_inside(w) && (double)p->border_max < limit) break;
    test_cell(w);
    if (is_flat_beyond(w)) break;
    advance(w, 0);
  }
}

/* ---- any ray ------------------------------------------------------------- */

static void ray_walker(walker *w, const bb_pyramid *p, const bb__march_ray *r, double best) {
  direction d;
  direction_init(&d, r->dx, r->dy);
  walker_init(w, p, &d, NULL, r->ox, r->oy, r->oz, best);
}

static int occluded(const bb_pyramid *p, const bb__march_ray *r, double tan_el, int brute) {
  walker w;
  ray_walker(&w, p, r, -INFINITY);
  const goal g = {tan_el, tan_el, INFINITY};
  if (brute)
    march_brute(&w, &g);
  else
    march(&w, &g, NULL);
  return w.best >= tan_el;
}

int bb__march_occluded(const bb_pyramid *p, const bb__march_ray *r, double tan_el) {
  return occluded(p, r, tan_el, 0);
}

int bb__march_occluded_brute(const bb_pyramid *p, const bb__march_ray *r, double tan_el) {
  return occluded(p, r, tan_el, 1);
}

static double horizon(const bb_pyramid *p, const bb__march_ray *r, double max_distance,
                      int brute) {
  walker w;
  ray_walker(&w, p, r, 0.0);
  w.max_t = max_distance;
  const goal g = {0.0, INFINITY, max_distance};
  if (brute)
    march_brute(&w, &g);
  else
    march(&w, &g, NULL);
  return w.best;
}

/* Splits a 3D ray into the march's horizontal line and tangent. Returns 0 for
 * a vertical ray. */
static int to_march_ray(const bb__ray *ray, bb__march_ray *r, double *tan_el) {
  double h = hypot(ray->direction[0], ray->direction[1]);
  if (!(h > 0.0)) return 0;
  r->ox = ray->origin[0];
  r->oy = ray->origin[1];
  r->oz = ray->origin[2];
  r->dx = ray->direction[0] / h;
  r->dy = ray->direction[1] / h;
  *tan_el = ray->direction[2] / h;
  return 1;
}

/* A vertical ray: nothing above the origin can block it. */
int bb__ray_occluded(const bb_pyramid *p, const bb__ray *ray) {
  bb__march_ray r;
  double tan_el;
  return to_march_ray(ray, &r, &tan_el) ? bb__march_occluded(p, &r, tan_el) : 0;
}

int bb__ray_occluded_brute(const bb_pyramid *p, const bb__ray *ray) {
  bb__march_ray r;
  double tan_el;
  return to_march_ray(ray, &r, &tan_el) ? bb__march_occluded_brute(p, &r, tan_el) : 0;
}

static double ray_horizon(const bb_pyramid *p, const bb__ray *ray, double max_distance,
                          int brute) {
  bb__march_ray r;
  double tan_el;
  if (!p || !ray || !(max_distance > 0.0) || !to_march_ray(ray, &r, &tan_el)) return -1.0;
  if (p->addressing == BB_ADDRESS_PERIODIC && !isfinite(max_distance)) return -1.0;
  return horizon(p, &r, max_distance, brute);
}

double bb__ray_horizon(const bb_pyramid *p, const bb__ray *ray, double max_distance) {
  return ray_horizon(p, ray, max_distance, 0);
}

double bb__ray_horizon_brute(const bb_pyramid *p, const bb__ray *ray, double max_distance) {
  return ray_horizon(p, ray, max_distance, 1);
}

/* ---- lattice slices ------------------------------------------------------ */

long bb__line_period(const bb_pyramid *p, int a, int b) {
  const long px = p->width / bb__gcd(a, p->width), py = p->height / bb__gcd(b, p->height);
  return px / bb__gcd(px, py) * py;
}

static inline int sign(long v) {
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

/* The lattice state of step (a, b) from vertex (x, y), and its direction. */
static void lattice_init(lattice *L, direction *d, const bb_pyramid *p, int x, int y, int a,
                         int b) {
  L->x0 = x, L->y0 = y, L->a = a, L->b = b;
  L->ma = abs(a), L->mb = abs(b), L->md = abs(a + b);
  L->sa = sign(a), L->sb = sign(b), L->sd = sign(a + b);
  L->length = bb__step_length(a, b);
  L->inverse_length = bb__step_inverse(a, b);
  L->inverse_m[0] = bb__lattice_inverse(L->ma ? L->ma : 1);
  L->inverse_m[1] = bb__lattice_inverse(L->mb ? L->mb : 1);
  L->inverse_m[2] = bb__lattice_inverse(L->md ? L->md : 1);
  L->cap = p->addressing == BB_ADDRESS_PERIODIC ? bb__line_period(p, a, b) : (1L << 40);
  direction_init(d, a / L->length, b / L->length);
}

/* One slice's horizon from a texel: the march, or the brute-force twin when
 * brute. hint as in march(). */
static float slice_horizon(const bb_pyramid *p, int x, int y, double bias, int a, int b,
                           int brute, double *hint, double best, double from_steps) {
  lattice L;
  direction d;
  lattice_init(&L, &d, p, x, y, a, b);
  walker w;
  const double oz = (double)p->z[(size_t)y * (size_t)p->width + (size_t)x] + bias;
  walker_init(&w, p, &d, &L, x, y, oz, best > 0.0 ? best : 0.0);
  if (from_steps > 0.0)
    jump_to(&w, from_steps * L.length);
  /* a breakpoint n / m <= cap steps away lies within cap + 1 steps of geometry */
  const goal g = {0.0, INFINITY,
                  p->addressing == BB_ADDRESS_PERIODIC ? ((double)L.cap + 1.0) * L.length
                                                       : INFINITY};
  if (brute)
    march_brute(&w, &g);
  else
    march(&w, &g, hint);
  return bb__lattice_horizon(w.best, L.inverse_length);
}

float bb__slice_horizon(const bb_pyramid *p, int x, int y, double bias, int a, int b) {
  return slice_horizon(p, x, y, bias, a, b, 0, NULL, 0.0, 0.0);
}

float bb__slice_horizon_hinted(const bb_pyramid *p, int x, int y, double bias, int a, int b,
                               double *hint) {
  return slice_horizon(p, x, y, bias, a, b, 0, hint, 0.0, 0.0);
}

float bb__slice_horizon_above(const bb_pyramid *p, int x, int y, double bias, int a,
                              int b, double slope, double from_steps) {
  return slice_horizon(p, x, y, bias, a, b, 0, NULL, slope, from_steps);
}

float bb__slice_horizon_brute(const bb_pyramid *p, int x, int y, double bias, int a, int b) {
  return slice_horizon(p, x, y, bias, a, b, 1, NULL, 0.0, 0.0);
}
