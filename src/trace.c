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
 * Every breakpoint is computed by process_cell() from the cell's integer
 * position, the origin and the direction only, never from the path that
 * reached it. So the max-mip march, the brute-force DDA and a march of a
 * whole azimuth slice compute bit-identical slopes and give identical answers:
 * a skipped node only ever hides breakpoints whose slope is below the
 * threshold by more than `margin`, far beyond rounding.
 *
 * Slices. All rays of an azimuth slice share the 2D line, so one march that
 * tracks the highest breakpoint slope seen (the horizon) answers all of them:
 * the rays of the slice are sorted by elevation, and the march only looks for
 * breakpoints that would block the lowest ray not yet blocked.
 */
#include "internal.h"
#include "trace_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Walking state: the current cell in unwrapped coordinates (ix, iy), its
 * addressed index (cx, cy), the distance t at which the ray entered it and
 * the distances to its exit edges. */
typedef struct walker {
  const bb_pyramid *p;
  bb__march_ray r;
  double inv_dx, inv_dy, inv_dsum; /* reciprocals; 0 where the component is 0 */
  double osum;                     /* ox + oy, for the diagonals x + y = k */
  int sx, sy;                      /* step direction, +1 or -1 */
  int ix, iy, cx, cy;
  double t, tnx, tny;
  double margin;                   /* slack of every skip test, >> rounding */
} walker;

/* Distance along the ray to the vertical line x = X (infinite if parallel). */
static inline double cross_x(const walker *w, int X) {
  return w->r.dx == 0.0 ? INFINITY : ((double)X - w->r.ox) * w->inv_dx;
}

static inline double cross_y(const walker *w, int Y) {
  return w->r.dy == 0.0 ? INFINITY : ((double)Y - w->r.oy) * w->inv_dy;
}

/* floor() without the libm call the x86-64 baseline makes of it. */
static inline int fast_floor(double v) {
  int i = (int)v;
  return (double)i > v ? i - 1 : i;
}

static inline int is_periodic(const walker *w) {
  return w->p->addressing == BB_ADDRESS_PERIODIC;
}

static inline int address(const walker *w, int i, int n) {
  return is_periodic(w) ? bb__wrap(i, n) : bb__clampi(i, 0, n - 1);
}

/* Clamp mode only: a cell outside the image is the border extruded. */
static inline int is_inside(const walker *w) {
  return is_periodic(w) ||
         (w->ix >= 0 && w->ix < w->p->width && w->iy >= 0 && w->iy < w->p->height);
}

static void update_exits(walker *w) {
  w->tnx = cross_x(w, w->sx > 0 ? w->ix + 1 : w->ix);
  w->tny = cross_y(w, w->sy > 0 ? w->iy + 1 : w->iy);
}

static void set_cell(walker *w, int ix, int iy) {
  w->ix = ix;
  w->iy = iy;
  w->cx = address(w, ix, w->p->width);
  w->cy = address(w, iy, w->p->height);
  update_exits(w);
}

/* The first cell is the one the ray enters from its origin: an origin on a
 * cell edge belongs to the cell on the side the ray goes. */
static void walker_init(walker *w, const bb_pyramid *p, const bb__march_ray *r) {
  memset(w, 0, sizeof *w);
  w->p = p;
  w->r = *r;
  w->sx = r->dx < 0 ? -1 : 1;
  w->sy = r->dy < 0 ? -1 : 1;
  w->inv_dx = r->dx != 0.0 ? 1.0 / r->dx : 0.0;
  w->inv_dy = r->dy != 0.0 ? 1.0 / r->dy : 0.0;
  w->inv_dsum = (r->dx + r->dy) != 0.0 ? 1.0 / (r->dx + r->dy) : 0.0;
  w->osum = r->ox + r->oy;
  w->margin = 1e-7 * (1.0 + fabs((double)p->global_max) + fabs((double)p->global_min) +
                      fabs(r->oz));
  int ix = (int)floor(r->ox), iy = (int)floor(r->oy);
  if (r->dx < 0 && (double)ix == r->ox) ix--;
  if (r->dy < 0 && (double)iy == r->oy) iy--;
  w->t = 0.0;
  set_cell(w, ix, iy);
}

/* Number of thresholds (from b on) that slope s blocks, plus b. */
static inline int raise_horizon(const double *tan_el, int n, int b, double s) {
  while (b < n && s >= tan_el[b]) b++;
  return b;
}

static inline double clamp01(double v) {
  return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

/* The exact cell test: the slopes of the diagonal crossing inside the current
 * cell and of the exit crossing. The entry crossing is the previous cell's
 * exit, so each breakpoint is tested once. Returns the new blocked count. */
static int process_cell(const walker *w, const double *tan_el, int n, int b) {
  const bb_pyramid *p = w->p;
  const int wd = p->width;
  const int x0 = w->cx, y0 = w->cy;
  const int x1 = is_periodic(w) ? (x0 + 1 == wd ? 0 : x0 + 1) : bb__clampi(w->ix + 1, 0, wd - 1);
  const int y1 = is_periodic(w) ? (y0 + 1 == p->height ? 0 : y0 + 1)
                                : bb__clampi(w->iy + 1, 0, p->height - 1);
  const float *row0 = p->z + (size_t)y0 * (size_t)wd, *row1 = p->z + (size_t)y1 * (size_t)wd;
  const double z00 = row0[x0], z10 = row0[x1], z01 = row1[x0], z11 = row1[x1];
  const double t_out = w->tnx < w->tny ? w->tnx : w->tny;

  if (w->inv_dsum != 0.0) { /* diagonal from (ix+1, iy) to (ix, iy+1) */
    double td = ((double)(w->ix + w->iy + 1) - w->osum) * w->inv_dsum;
    if (td > w->t && td < t_out) {
      double u = clamp01(w->r.oy + td * w->r.dy - (double)w->iy);
      double surface = z10 + (z01 - z10) * u;
      b = raise_horizon(tan_el, n, b, (surface - w->r.oz) / td);
      if (b == n) return b;
    }
  }
  double surface;
  if (w->tnx <= w->tny) { /* leaves through a vertical edge */
    double v = clamp01(w->r.oy + t_out * w->r.dy - (double)w->iy);
    double za = w->sx > 0 ? z10 : z00, zb = w->sx > 0 ? z11 : z01;
    surface = za + (zb - za) * v;
  } else { /* through a horizontal edge */
    double u = clamp01(w->r.ox + t_out * w->r.dx - (double)w->ix);
    double za = w->sy > 0 ? z01 : z00, zb = w->sy > 0 ? z11 : z10;
    surface = za + (zb - za) * u;
  }
  return raise_horizon(tan_el, n, b, (surface - w->r.oz) / t_out);
}

static inline int wrap_step(int c, int s, int n) {
  c += s;
  return c == n ? 0 : (c < 0 ? n - 1 : c);
}

/* The 2D DDA step to the next cell; a corner crossing moves diagonally. */
static void step_cell(walker *w) {
  const int move_x = w->tnx <= w->tny, move_y = w->tny <= w->tnx;
  w->t = move_x ? w->tnx : w->tny;
  if (move_x) {
    w->ix += w->sx;
    w->cx = is_periodic(w) ? wrap_step(w->cx, w->sx, w->p->width)
                           : bb__clampi(w->ix, 0, w->p->width - 1);
    w->tnx = cross_x(w, w->sx > 0 ? w->ix + 1 : w->ix);
  }
  if (move_y) {
    w->iy += w->sy;
    w->cy = is_periodic(w) ? wrap_step(w->cy, w->sy, w->p->height)
                           : bb__clampi(w->iy, 0, w->p->height - 1);
    w->tny = cross_y(w, w->sy > 0 ? w->iy + 1 : w->iy);
  }
}

/* The column the ray is in at distance t, by the same comparisons the DDA
 * makes, so a jump over a node lands in the cell the DDA would reach. */
static int locate_x(const walker *w, double t, int ix) {
  if (w->r.dx == 0.0) return ix;
  ix = fast_floor(w->r.ox + t * w->r.dx);
  if (w->sx > 0) {
    while (cross_x(w, ix + 1) <= t) ix++;
    while (cross_x(w, ix) > t) ix--;
  } else {
    while (cross_x(w, ix) <= t) ix--;
    while (cross_x(w, ix + 1) > t) ix++;
  }
  return ix;
}

static int locate_y(const walker *w, double t, int iy) {
  if (w->r.dy == 0.0) return iy;
  iy = fast_floor(w->r.oy + t * w->r.dy);
  if (w->sy > 0) {
    while (cross_y(w, iy + 1) <= t) iy++;
    while (cross_y(w, iy) > t) iy--;
  } else {
    while (cross_y(w, iy) <= t) iy--;
    while (cross_y(w, iy + 1) > t) iy++;
  }
  return iy;
}

/* Periodic index of c, known to lie within a few periods of [0, n). */
static inline int rewrap(int c, int n) {
  while (c >= n) c -= n;
  while (c < 0) c += n;
  return c;
}

/* set_cell() for a nearby cell, without the divisions of bb__wrap. */
static void move_to(walker *w, int ix, int iy) {
  if (is_periodic(w)) {
    w->cx = rewrap(w->cx + (ix - w->ix), w->p->width);
    w->cy = rewrap(w->cy + (iy - w->iy), w->p->height);
    w->ix = ix;
    w->iy = iy;
    update_exits(w);
  } else {
    set_cell(w, ix, iy);
  }
}

/* Moves the walker to the first cell past the level-k node holding it. */
static void skip_node(walker *w, int k) {
  const int span = 1 << k, mask = span - 1;
  const int bx = w->ix - (w->cx & mask), by = w->iy - (w->cy & mask);
  const int X = w->sx > 0 ? bx + span : bx, Y = w->sy > 0 ? by + span : by;
  const double tx = cross_x(w, X), ty = cross_y(w, Y);
  const double t = tx < ty ? tx : ty;
  int ix, iy;
  if (tx <= ty) ix = w->sx > 0 ? X : X - 1;
  else ix = locate_x(w, t, w->ix);
  if (ty <= tx) iy = w->sy > 0 ? Y : Y - 1;
  else iy = locate_y(w, t, w->iy);
  w->t = t;
  move_to(w, ix, iy);
}

static inline float node_max(const bb_pyramid *p, int k, int cx, int cy) {
  return p->level_max[k][(size_t)(cy >> k) * (size_t)p->level_width[k] + (size_t)(cx >> k)];
}

int bb__march(const bb_pyramid *p, const bb__march_ray *r, const double *tan_el, int n) {
  if (n <= 0) return 0;
  walker w;
  walker_init(&w, p, r);
  const int top = p->levels - 1;
  int b = 0, k = 0;
  for (;;) {
    /* Nothing under the ray below this height can block ray b or above. */
    const double limit = w.r.oz + w.t * tan_el[b] - w.margin;
    if (!is_inside(&w)) { /* clamp mode, past the border: never comes back */
      if ((double)p->border_max < limit) return b;
      b = process_cell(&w, tan_el, n, b);
      if (b == n) return n;
      step_cell(&w);
      continue;
    }
    if ((double)node_max(p, k, w.cx, w.cy) < limit) {
      if (k == top) return b; /* above the global maximum for good */
      skip_node(&w, k);
      k++;
      continue;
    }
    if (k > 0) {
      k--;
      continue;
    }
    b = process_cell(&w, tan_el, n, b);
    if (b == n) return n;
    step_cell(&w);
  }
}

int bb__march_brute(const bb_pyramid *p, const bb__march_ray *r, const double *tan_el,
                    int n) {
  if (n <= 0) return 0;
  walker w;
  walker_init(&w, p, r);
  int b = 0;
  for (;;) {
    if ((double)p->global_max < w.r.oz + w.t * tan_el[b] - w.margin) return b;
    b = process_cell(&w, tan_el, n, b);
    if (b == n) return n;
    step_cell(&w);
  }
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

/* Per slice s and channel c, the weight of the rays a march leaves unblocked:
 * unblocked[c][start_s + s + b] = sum of the weights of rays b.. of slice s. */
typedef struct trace_job {
  const bb_pyramid *p;
  const bb_rayset *rs;
  const bb_trace_options *o;
  int channels;        /* 1 + basis_count */
  double *unblocked;   /* channels * (ray_count + slice_count) */
  double total[1 + BB_MAX_BASIS];
  float *vis;
} trace_job;

static double ray_weight(const bb_rayset *rs, int c, int ray) {
  return c == 0 ? rs->weight_ao[ray] : rs->weight_basis[(size_t)ray * (size_t)rs->basis_count + (size_t)(c - 1)];
}

/* Suffix sums, and totals taken as the same sums in the same order, so a
 * texel with nothing blocked gets exactly 1. */
static bb_status prepare_sums(trace_job *job, bb_error *err) {
  const bb_rayset *rs = job->rs;
  const size_t stride = (size_t)(rs->ray_count + rs->slice_count);
  job->unblocked = malloc((size_t)job->channels * stride * sizeof(double));
  if (!job->unblocked) return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  for (int c = 0; c < job->channels; c++) {
    double *u = job->unblocked + (size_t)c * stride;
    job->total[c] = 0.0;
    for (int s = 0; s < rs->slice_count; s++) {
      const int start = rs->slice_start[s], count = rs->slice_start[s + 1] - start;
      double *slice = u + start + s;
      slice[count] = 0.0;
      for (int e = count - 1; e >= 0; e--) slice[e] = slice[e + 1] + ray_weight(rs, c, start + e);
      job->total[c] += slice[0];
    }
  }
  return BB_OK;
}

static void trace_row(void *user, int y) {
  const trace_job *job = user;
  const bb_pyramid *p = job->p;
  const bb_rayset *rs = job->rs;
  const size_t stride = (size_t)(rs->ray_count + rs->slice_count);
  for (int x = 0; x < p->width; x++) {
    double sum[1 + BB_MAX_BASIS] = {0};
    bb__march_ray r = {.ox = x, .oy = y};
    r.oz = (double)p->z[(size_t)y * (size_t)p->width + (size_t)x] + job->o->bias_texels;
    for (int s = 0; s < rs->slice_count; s++) {
      const int start = rs->slice_start[s], count = rs->slice_start[s + 1] - start;
      r.dx = rs->slice_dir[2 * s];
      r.dy = rs->slice_dir[2 * s + 1];
      const int blocked = bb__march(p, &r, rs->tan_elevation + start, count);
      for (int c = 0; c < job->channels; c++)
        sum[c] += job->unblocked[(size_t)c * stride + (size_t)(start + s + blocked)];
    }
    float *out = job->vis + ((size_t)y * (size_t)p->width + (size_t)x) * (size_t)job->channels;
    for (int c = 0; c < job->channels; c++)
      out[c] = job->total[c] > 0.0 ? (float)(sum[c] / job->total[c]) : 1.0f;
  }
}

bb_status bb_trace_occlusion(const bb_pyramid *p, const bb_rayset *rs,
                             const bb_trace_options *o, bb_image *vis,
                             double *rays_traced, bb_error *err) {
  memset(vis, 0, sizeof *vis);
  if (!p || !rs || !o || rs->ray_count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: missing pyramid, ray set or options");
  if (!(o->bias_texels >= 0.0) || !isfinite(o->bias_texels))
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: bias must be finite and >= 0 (got %g)",
                    o->bias_texels);
  if (o->jitter)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: --jitter is not implemented yet");
  trace_job job = {.p = p, .rs = rs, .o = o, .channels = 1 + rs->basis_count};
  bb_status st = prepare_sums(&job, err);
  if (st != BB_OK) return st;
  st = bb_image_alloc(vis, p->width, p->height, job.channels, err);
  if (st == BB_OK) {
    job.vis = vis->pixels;
    st = bb__parallel_for(p->height, o->threads, trace_row, &job, o->progress,
                          o->progress_user, err);
  }
  free(job.unblocked);
  if (st != BB_OK) bb_image_free(vis);
  else if (rays_traced)
    *rays_traced = (double)p->width * (double)p->height * (double)rs->ray_count;
  return st;
}
