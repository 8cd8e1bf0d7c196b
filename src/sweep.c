/* sweep.c: the horizons of every texel for a lattice slice direction and its
 * opposite, by sweeps along each line of texels.
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
 * near end. The rays of the slice blocked at a texel are those whose tangent
 * tan_el * |(a, b)| is at most that slope.
 *
 * The opposite direction (-a, -b) runs along the same lines through the same
 * breakpoints, so one profile serves both: the sweep for (a, b) walks it
 * backwards, the sweep for (-a, -b) forwards (on mirrored u).
 *
 * Lines are cut into chunks of at most CHUNK_STEPS texels, each profiled
 * with a look-ahead past both ends of as many steps as a ray of the lowest
 * elevation needs to rise above the global maximum. Periodic lines (the
 * texture tiles) wrap, and after one whole period nothing new can come; in
 * clamp mode a line runs from one edge to the other, and past the image the
 * look-ahead reads the clamped vertices (the border extruded) until the
 * profile is flat. Chunks are independent, so they run on all threads with
 * the same result.
 */
#include "internal.h"
#include "trace_internal.h"

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { CHUNK_STEPS = 4096 };

/* A breakpoint of one step, relative to the step's first texel: the surface
 * there is z(v1) + (z(v2) - z(v1)) * w. */
typedef struct template_point {
  double u;       /* fraction of the step, in (0, 1] */
  int x1, y1, x2, y2;
  double w;
  long offset1, offset2; /* x + y * width of the two vertices, for interior steps */
} template_point;

/* One direction of a sweep (trace_internal.h's bb__sweep_dir) with its
 * thresholds per step. */
typedef struct sweep_side {
  const double *tan_step; /* slopes per step that block: tan_el * |(a, b)|, rising */
  int n;
  uint16_t *blocked;      /* per texel; NULL: this direction is not wanted */
} sweep_side;

typedef struct sweep_job {
  const bb_pyramid *p;
  int a, b;
  template_point *points;                   /* the step's breakpoints, the next texel last */
  int point_count;
  const int *chunk_x, *chunk_y, *chunk_len; /* first texel and length of each chunk */
  int ahead, behind; /* steps profiled past a chunk's end (for (a, b)) and before its start */
  double bias;
  sweep_side side[2]; /* along (a, b) and along (-a, -b) */
  int reach_x, reach_y; /* how far template vertices lie from a step's texel */
  atomic_int out_of_memory;
} sweep_job;

static int cmp_u(const void *pa, const void *pb) {
  const double a = ((const template_point *)pa)->u, b = ((const template_point *)pb)->u;
  return a < b ? -1 : a > b;
}

/* Breakpoints of the step from (0, 0) to (a, b), sorted by u. For coprime
 * (a, b) the three families meet only at the step's end, the next texel,
 * which is kept once, as the vertex itself. */
static int build_template(int a, int b, template_point *out) {
  int n = 0;
  const int ma = abs(a), mb = abs(b), md = abs(a + b);
  for (int i = 1; i < ma; i++) { /* vertical lines x = X */
    const double u = (double)i / ma, y = u * b;
    const int X = i * (a > 0 ? 1 : -1), row = (int)floor(y);
    out[n++] = (template_point){u, X, row, X, row + 1, y - row, 0, 0};
  }
  for (int i = 1; i < mb; i++) { /* horizontal lines y = Y */
    const double u = (double)i / mb, x = u * a;
    const int Y = i * (b > 0 ? 1 : -1), col = (int)floor(x);
    out[n++] = (template_point){u, col, Y, col + 1, Y, x - col, 0, 0};
  }
  for (int i = 1; i < md; i++) { /* diagonals x + y = K, from (c+1, K-1-c) to (c, K-c) */
    const double u = (double)i / md, x = u * a, y = u * b;
    const int K = i * (a + b > 0 ? 1 : -1), col = (int)floor(x), row = K - 1 - col;
    out[n++] = (template_point){u, col + 1, row, col, row + 1, y - row, 0, 0};
  }
  out[n++] = (template_point){1.0, a, b, a, b, 0.0, 0, 0}; /* the next texel */
  qsort(out, (size_t)n, sizeof *out, cmp_u);
  return n;
}

static inline int imax(int a, int b) {
  return a > b ? a : b;
}

/* Upper hull of the points ahead, nearest last. */
typedef struct hull {
  double *u, *z;
  int size;
} hull;

/* Pushes a point nearer than all others, dropping those now under the hull. */
static inline void hull_push(hull *h, double u, double z) {
  while (h->size >= 2) {
    const double ua = h->u[h->size - 1], za = h->z[h->size - 1];
    const double ub = h->u[h->size - 2], zb = h->z[h->size - 2];
    /* a is on or under the segment from the new point to b */
    if ((za - z) * (ub - u) <= (zb - z) * (ua - u)) h->size--;
    else break;
  }
  h->u[h->size] = u;
  h->z[h->size] = z;
  h->size++;
}

/* Largest slope from (u0, z0), behind every point, to the hull: slopes to
 * hull vertices rise, then fall, going away from the origin. The hull is
 * short (hull_push_cut keeps it so: 3.6 vertices on average on rock06) and
 * the tangent is mostly at the nearest vertex or the next, so a walk from
 * the near end beats a binary search. */
static inline double hull_tangent(const hull *h, double u0, double z0) {
  int i = h->size - 1;
  double du = h->u[i] - u0, dz = h->z[i] - z0;
  while (i > 0) {
    const double du_far = h->u[i - 1] - u0, dz_far = h->z[i - 1] - z0;
    /* is the farther vertex steeper? (denominators are positive) */
    if (!(dz_far * du > dz * du_far)) break;
    du = du_far;
    dz = dz_far;
    i--;
  }
  return dz / du;
}

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

static inline int step_along(const bb_pyramid *p, int v, int step, int n) {
  return p->addressing == BB_ADDRESS_PERIODIC ? bb__wrap_near(v + step % n, n) : v + step;
}

/* hull_push, then: if nothing ahead rises from the new point as steeply as
 * the lowest ray (tan_low), drop all but the new point. For an origin behind
 * it, either the new point is steeper than everything ahead of it, or every
 * slope is below the lowest ray: the dropped points never decide a count. */
static inline void hull_push_cut(hull *h, double u, double z, double tan_low) {
  hull_push(h, u, z);
  if (h->size >= 2 && h->z[h->size - 2] - z < tan_low * (h->u[h->size - 2] - u)) {
    h->u[0] = u;
    h->z[0] = z;
    h->size = 1;
  }
}

/* Rays of `side` blocked from (u0, z0), behind every point of the hull. */
static inline uint16_t count_blocked(const sweep_side *side, const hull *h, double u0,
                                     double z0) {
  const double slope = hull_tangent(h, u0, z0);
  int blocked = 0;
  while (blocked < side->n && slope >= side->tan_step[blocked]) blocked++;
  return (uint16_t)blocked;
}

/* A chunk's profile: step i (i = 0 .. steps-1) starts at texel
 * j = i - behind of the chunk, whose height is vz[i] (one more entry: the end
 * of the last step). Its points, by rising u (u = j + the template's
 * fraction), are the vertices and breakpoints that can matter: pu, pz. */
typedef struct profile {
  int steps, count;
  double *vz;
  double *pu, *pz;
  size_t *texel; /* image index of the chunk's texels */
} profile;

/* Keeps the points of a profile that are not convex kinks. A point on or
 * under the chord of its two neighbours never decides a count: walking
 * either way, once its nearer neighbour is on the hull it lies under the
 * hull; and before that, for the one origin queried in between, which sits
 * at or above that neighbour (bias >= 0), the farther neighbour is at least
 * as steep. A run of such points lies under the chord of the points kept
 * around it (the profile is convex along the run), so dropping them all at
 * once is safe too. About half the points go on rough maps. */
typedef struct kink_filter {
  profile *pr;
  int seen;              /* points offered so far */
  double ua, za, ub, zb; /* the last two offered: a before b; b is undecided */
} kink_filter;

static inline void kink_offer(kink_filter *f, double u, double z) {
  if (f->seen >= 2) {
    const int keep = (f->zb - f->za) * (u - f->ua) > (z - f->za) * (f->ub - f->ua);
    f->pr->pu[f->pr->count] = f->ub;
    f->pr->pz[f->pr->count] = f->zb;
    f->pr->count += keep;
  } else if (f->seen == 1) { /* the first point is an end: kept */
    f->pr->pu[0] = f->ub;
    f->pr->pz[0] = f->zb;
    f->pr->count = 1;
  }
  f->ua = f->ub, f->za = f->zb;
  f->ub = u, f->zb = z;
  f->seen++;
}

static inline void kink_finish(kink_filter *f) { /* the last point is an end: kept */
  f->pr->pu[f->pr->count] = f->ub;
  f->pr->pz[f->pr->count] = f->zb;
  f->pr->count++;
}

/* Heights along the chunk's line, from behind its start to ahead of its end. */
static void profile_fill(const sweep_job *job, int chunk, profile *pr) {
  const bb_pyramid *p = job->p;
  const long first = -(long)job->behind; /* the first step's texel */
  int bx = coordinate_at(p, (long)job->chunk_x[chunk] + first * job->a, p->width);
  int by = coordinate_at(p, (long)job->chunk_y[chunk] + first * job->b, p->height);
  kink_filter f = {.pr = pr};
  pr->count = 0;
  for (int i = 0; i <= pr->steps; i++, bx = step_along(p, bx, job->a, p->width),
           by = step_along(p, by, job->b, p->height)) {
    const int j = i - job->behind; /* texel of the chunk */
    pr->vz[i] = field_z(p, bx, by);
    kink_offer(&f, (double)j, pr->vz[i]);
    if (j >= 0 && j < job->chunk_len[chunk])
      pr->texel[j] = (size_t)by * (size_t)p->width + (size_t)bx;
    if (i == pr->steps) break;
    /* Away from the edges no vertex wraps or clamps, and each is a fixed
     * offset. */
    const int interior = bx >= job->reach_x && bx < p->width - job->reach_x &&
                         by >= job->reach_y && by < p->height - job->reach_y;
    const float *here = interior ? p->z + (size_t)by * (size_t)p->width + (size_t)bx : NULL;
    for (int k = 0; k < job->point_count - 1; k++) {
      const template_point *t = &job->points[k];
      double za, zb;
      if (interior) {
        za = here[t->offset1];
        zb = here[t->offset2];
      } else {
        za = field_z(p, bx + t->x1, by + t->y1);
        zb = field_z(p, bx + t->x2, by + t->y2);
      }
      kink_offer(&f, (double)j + t->u, za + (zb - za) * t->w);
    }
  }
  kink_finish(&f);
}

/* Along (a, b): walk the profile backwards from its far end; origin j asks
 * once every point beyond it is on the hull. */
static void sweep_ahead(const sweep_job *job, const profile *pr, int len, hull *h) {
  const sweep_side *side = &job->side[0];
  const double tan_low = side->tan_step[0];
  int k = pr->count - 1;
  h->size = 0;
  for (int j = len - 1 + job->ahead; j >= 0; j--) {
    for (; k >= 0 && pr->pu[k] > (double)j; k--) hull_push_cut(h, pr->pu[k], pr->pz[k], tan_low);
    if (j < len)
      side->blocked[pr->texel[j]] =
          count_blocked(side, h, (double)j, pr->vz[j + job->behind] + job->bias);
  }
}

/* Along (-a, -b): walk the profile forwards from its near end, on mirrored
 * u, so the hull code is the same. */
static void sweep_behind(const sweep_job *job, const profile *pr, int len, hull *h) {
  const sweep_side *side = &job->side[1];
  const double tan_low = side->tan_step[0];
  int k = 0;
  h->size = 0;
  for (int j = -job->behind; j < len; j++) {
    for (; k < pr->count && pr->pu[k] < (double)j; k++)
      hull_push_cut(h, -pr->pu[k], pr->pz[k], tan_low);
    if (j >= 0)
      side->blocked[pr->texel[j]] =
          count_blocked(side, h, -(double)j, pr->vz[j + job->behind] + job->bias);
  }
}

static void sweep_chunk(void *user, int chunk) {
  sweep_job *job = user;
  const int len = job->chunk_len[chunk];
  profile pr = {.steps = job->behind + len + job->ahead};
  const size_t points = (size_t)(pr.steps + 1) * (size_t)job->point_count;
  hull h = {0};
  pr.vz = malloc((size_t)(pr.steps + 1) * sizeof(double));
  pr.pu = malloc(points * sizeof(double));
  pr.pz = malloc(points * sizeof(double));
  pr.texel = malloc((size_t)len * sizeof(size_t));
  h.u = malloc(points * sizeof(double));
  h.z = malloc(points * sizeof(double));
  if (pr.vz && pr.pu && pr.pz && pr.texel && h.u && h.z) {
    profile_fill(job, chunk, &pr);
    if (job->side[0].blocked) sweep_ahead(job, &pr, len, &h);
    if (job->side[1].blocked) sweep_behind(job, &pr, len, &h);
  } else {
    atomic_store(&job->out_of_memory, 1);
  }
  free(pr.vz);
  free(pr.pu);
  free(pr.pz);
  free(pr.texel);
  free(h.u);
  free(h.z);
}

static inline int inside(const bb_pyramid *p, int x, int y) {
  return x >= 0 && x < p->width && y >= 0 && y < p->height;
}

/* Clamp mode: a line runs from a texel whose predecessor is outside the
 * image to the last texel before it leaves. Returns the number of chunks. */
static int clamped_chunks(const bb_pyramid *p, int a, int b, int *cx, int *cy, int *clen) {
  int c = 0;
  for (int y = 0; y < p->height; y++)
    for (int x = 0; x < p->width; x++) {
      if (inside(p, x - a, y - b)) continue;
      int run = 0;
      for (int px = x, py = y; inside(p, px, py); px += a, py += b) {
        if (run == 0) cx[c] = px, cy[c] = py;
        if (++run == CHUNK_STEPS) clen[c++] = run, run = 0;
      }
      if (run) clen[c++] = run;
    }
  return c;
}

/* Cuts the lines of step (a, b) into chunks: the first texel and length of
 * each. A periodic line closes when it comes back to its first texel. */
static bb_status make_chunks(const bb_pyramid *p, int a, int b, int **cx, int **cy, int **clen,
                             int *count, bb_error *err) {
  const size_t n = (size_t)p->width * (size_t)p->height;
  const int periodic = p->addressing == BB_ADDRESS_PERIODIC;
  unsigned char *seen = periodic ? calloc(n, 1) : NULL; /* texels already in a line */
  *cx = malloc(n * sizeof(int));
  *cy = malloc(n * sizeof(int));
  *clen = malloc(n * sizeof(int));
  if ((periodic && !seen) || !*cx || !*cy || !*clen) {
    free(seen);
    return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for line sweeps");
  }
  if (!periodic) {
    *count = clamped_chunks(p, a, b, *cx, *cy, *clen);
    return BB_OK;
  }
  int c = 0;
  for (int y = 0; y < p->height; y++)
    for (int x = 0; x < p->width; x++) {
      if (seen[(size_t)y * (size_t)p->width + (size_t)x]) continue;
      int px = x, py = y, run = 0;
      while (!seen[(size_t)py * (size_t)p->width + (size_t)px]) {
        if (run == 0) {
          (*cx)[c] = px;
          (*cy)[c] = py;
        }
        seen[(size_t)py * (size_t)p->width + (size_t)px] = 1;
        px = bb__wrap_near(px + a % p->width, p->width);
        py = bb__wrap_near(py + b % p->height, p->height);
        if (++run == CHUNK_STEPS) {
          (*clen)[c++] = run;
          run = 0;
        }
      }
      if (run) (*clen)[c++] = run;
    }
  free(seen);
  *count = c;
  return BB_OK;
}

/* Steps past which the lowest ray of `side` is above the global maximum,
 * and no more than can bring anything new: a periodic line repeats after its
 * period (at most W * H steps); a clamped one (clamp mode) is flat once every
 * vertex of its steps is clamped, a step's reach past the image, and on a
 * flat stretch no point beyond the first can be steeper from behind. */
static int lookahead_steps(const bb_pyramid *p, const sweep_side *side) {
  if (!side->blocked) return 0;
  const double rise = (double)p->global_max - (double)p->global_min;
  const double reach = side->tan_step[0] > 0.0 ? ceil(rise / side->tan_step[0]) + 2.0 : 1e9;
  const long longest = p->width > p->height ? p->width : p->height;
  const long limit = p->addressing == BB_ADDRESS_PERIODIC
                         ? (long)p->width * p->height
                         : longest + 2L * (BB__MAX_LATTICE_STEP + 2);
  return (int)(reach < (double)limit ? reach : (double)limit);
}

static bb_status set_side(const bb__sweep_dir *dir, double step_length, sweep_side *side,
                          bb_error *err) {
  if (!dir) return BB_OK;
  if (dir->n < 1 || !dir->blocked)
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: a sweep direction needs rays and counts");
  double *tan_step = malloc((size_t)dir->n * sizeof(double));
  if (!tan_step) return bb__fail(err, BB_ERR_MEMORY, "trace: out of memory");
  for (int e = 0; e < dir->n; e++) tan_step[e] = dir->tan_el[e] * step_length;
  *side = (sweep_side){tan_step, dir->n, dir->blocked};
  return BB_OK;
}

bb_status bb__sweep_lines(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                          const bb__sweep_dir *opposite, double bias, int threads,
                          bb_error *err) {
  template_point pts[4 * BB__MAX_LATTICE_STEP + 1];
  if (abs(a) > BB__MAX_LATTICE_STEP || abs(b) > BB__MAX_LATTICE_STEP || (a == 0 && b == 0))
    return bb__fail(err, BB_ERR_ARGUMENT, "trace: lattice step (%d, %d) out of range", a, b);
  sweep_job job = {.p = p, .a = a, .b = b, .points = pts, .bias = bias};
  atomic_init(&job.out_of_memory, 0);
  int *cx = NULL, *cy = NULL, *clen = NULL, chunks = 0;
  bb_status st = set_side(along, hypot(a, b), &job.side[0], err);
  if (st == BB_OK) st = set_side(opposite, hypot(a, b), &job.side[1], err);
  if (st == BB_OK) st = make_chunks(p, a, b, &cx, &cy, &clen, &chunks, err);
  if (st == BB_OK) {
    job.chunk_x = cx;
    job.chunk_y = cy;
    job.chunk_len = clen;
    job.point_count = build_template(a, b, pts);
    for (int k = 0; k < job.point_count; k++) {
      template_point *t = &pts[k];
      t->offset1 = t->x1 + (long)t->y1 * p->width;
      t->offset2 = t->x2 + (long)t->y2 * p->width;
      job.reach_x = imax(job.reach_x, imax(abs(t->x1), abs(t->x2)) + 1);
      job.reach_y = imax(job.reach_y, imax(abs(t->y1), abs(t->y2)) + 1);
    }
    job.ahead = lookahead_steps(p, &job.side[0]);
    job.behind = lookahead_steps(p, &job.side[1]);
    st = bb__parallel_for(chunks, threads, sweep_chunk, &job, NULL, NULL, err);
    if (st == BB_OK && atomic_load(&job.out_of_memory))
      st = bb__fail(err, BB_ERR_MEMORY, "trace: out of memory for a line sweep");
  }
  free((void *)job.side[0].tan_step);
  free((void *)job.side[1].tan_step);
  free(cx);
  free(cy);
  free(clen);
  return st;
}
