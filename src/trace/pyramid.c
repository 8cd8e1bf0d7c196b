/* pyramid.c: the max-mip (quadtree) pyramid the tracer marches through.
 *
 * Invariant: node (i, j) of level k bounds the surface over the level-0
 * cells [i*2^k, (i+1)*2^k) x [j*2^k, (j+1)*2^k), cell indices taken through
 * the addressing mode. Level 0 cell (x, y) spans the vertices (x, y) ..
 * (x+1, y+1); with two triangles per cell the surface over it never exceeds
 * its highest corner, so the max of the four corners is a tight bound.
 *
 * Odd sizes: level k has ceil(W / 2^k) x ceil(H / 2^k) nodes. The last node
 * of a row may reach past the width; in periodic mode the cells it covers
 * there are the wrapped ones (0, 1, ...), in clamp mode they are the border
 * cell repeated, and either way the node's max includes them. So a node is
 * always a conservative bound for the unwrapped cells under it, which is all
 * the march needs. The last level has a single node, the global maximum.
 */
#include "trace/testing.h"
#include "core/internal.h"
#include "trace/pyramid.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

int bb__pyramid_levels(const bb_pyramid *p) {
  return p->levels;
}

float bb__pyramid_node_max(const bb_pyramid *p, int level, int x, int y) {
  assert(level >= 0 && level < p->levels);
  assert(x >= 0 && x < p->level_width[level] && y >= 0 && y < p->level_height[level]);
  return p->level_max[level][(size_t)y * (size_t)p->level_width[level] + (size_t)x];
}

static int ceil_shift(int n, int k) {
  return (int)(((long)n + (1L << k) - 1) >> k);
}

/* The rows of a level's build run on all cores; a max does not depend on
 * the order it is taken in, so neither does the pyramid. */
typedef struct build_job {
  bb_pyramid *p;
  int k; /* the level being built */
} build_job;

/* Level 0, row y: the max of each cell's four corners. */
static void build_cells_row(void *user, int y) {
  const build_job *job = user;
  const bb_pyramid *p = job->p;
  const int w = p->width, h = p->height;
  float *cells = p->level_max[0];
  const float *r0 = p->z + (size_t)y * (size_t)w;
  const float *r1 = p->z + (size_t)bb__address(y + 1, h, p->addressing) * (size_t)w;
  for (int x = 0; x < w; x++) {
    int x1 = x + 1 < w ? x + 1 : bb__address(x + 1, w, p->addressing);
    float m = r0[x];
    if (r0[x1] > m) m = r0[x1];
    if (r1[x] > m) m = r1[x];
    if (r1[x1] > m) m = r1[x1];
    cells[(size_t)y * (size_t)w + (size_t)x] = m;
  }
}

/* Max of row[addressed(i)] for i in [start, start + count). Only the last
 * node of a row reaches past n, so the addressing is kept for that part. */
static float addressed_max(const float *row, size_t stride, int n, int start, int count,
                           bb_addressing a) {
  const int end = start + count, inside = end < n ? end : n;
  float m = -FLT_MAX;
  for (int i = start; i < inside; i++) {
    float v = row[(size_t)i * stride];
    if (v > m) m = v;
  }
  for (int i = inside; i < end; i++) {
    float v = row[(size_t)bb__address(i, n, a) * stride];
    if (v > m) m = v;
  }
  return m;
}

static void node_update(bb_pyramid *p, int k, int i, int j);

/* Level k >= 1, node row j: each node from its children on level k - 1
 * (node_update), so a level costs a quarter of the one below it. */
static void level_row(void *user, int j) {
  const build_job *job = user;
  for (int i = 0; i < job->p->level_width[job->k]; i++)
    node_update(job->p, job->k, i, j);
}

/* A level of fewer nodes than this is built on the calling thread: starting
 * and joining the threads would cost more than its maxima. */
enum { PARALLEL_LEVEL_NODES = 1 << 16 };

static bb_status build_levels(bb_pyramid *p, int threads, bb_error *err) {
  build_job job = {p, 0};
  bb_status st = bb__parallel_for(p->height, threads, build_cells_row, &job, NULL, NULL, err);
  for (job.k = 1; st == BB_OK && job.k < p->levels; job.k++) {
    const long nodes = (long)p->level_width[job.k] * (long)p->level_height[job.k];
    st = bb__parallel_for(p->level_height[job.k], nodes < PARALLEL_LEVEL_NODES ? 1 : threads,
                          level_row, &job, NULL, NULL, err);
  }
  return st;
}

static float border_max(const bb_pyramid *p) {
  const int w = p->width, h = p->height;
  float m = -FLT_MAX;
  for (int x = 0; x < w; x++) {
    if (p->z[x] > m) m = p->z[x];
    if (p->z[(size_t)(h - 1) * (size_t)w + (size_t)x] > m) m = p->z[(size_t)(h - 1) * (size_t)w + (size_t)x];
  }
  for (int y = 0; y < h; y++) {
    if (p->z[(size_t)y * (size_t)w] > m) m = p->z[(size_t)y * (size_t)w];
    if (p->z[(size_t)y * (size_t)w + (size_t)(w - 1)] > m) m = p->z[(size_t)y * (size_t)w + (size_t)(w - 1)];
  }
  return m;
}

static bb_status check_heights(const bb_image *z, bb_error *err) {
  if (!z || !z->pixels || z->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "pyramid: need a 1-channel height field");
  size_t n = (size_t)z->width * (size_t)z->height;
  for (size_t i = 0; i < n; i++)
    if (!(z->pixels[i] > -FLT_MAX && z->pixels[i] < FLT_MAX))
      return bb__fail(err, BB_ERR_VALUE, "pyramid: non-finite height at texel (%d, %d)",
                      (int)(i % (size_t)z->width), (int)(i / (size_t)z->width));
  return BB_OK;
}

bb_status bb__pyramid_build_all_cores(const bb_image *height_texels, bb_addressing addressing,
                           bb_pyramid **out, bb_error *err) {
  return bb__pyramid_build(height_texels, addressing, 0, out, err);
}

bb_status bb__pyramid_build(const bb_image *height_texels, bb_addressing addressing,
                            int threads, bb_pyramid **out, bb_error *err) {
  *out = NULL;
  bb_status st = check_heights(height_texels, err);
  if (st != BB_OK) return st;
  bb_pyramid *p = calloc(1, sizeof *p);
  if (!p) return bb__fail(err, BB_ERR_MEMORY, "pyramid: out of memory");
  const int w = height_texels->width, h = height_texels->height;
  p->width = w;
  p->height = h;
  p->addressing = addressing;
  int levels = 1;
  while ((1L << (levels - 1)) < w || (1L << (levels - 1)) < h) levels++;
  p->levels = levels;
  size_t n = (size_t)w * (size_t)h;
  p->z = malloc(n * sizeof(float));
  int ok = p->z != NULL;
  for (int k = 0; ok && k < levels; k++) {
    p->level_width[k] = ceil_shift(w, k);
    p->level_height[k] = ceil_shift(h, k);
    p->level_max[k] = malloc((size_t)p->level_width[k] * (size_t)p->level_height[k] * sizeof(float));
    ok = p->level_max[k] != NULL;
  }
  if (!ok) {
    bb_pyramid_free(p);
    return bb__fail(err, BB_ERR_MEMORY, "pyramid: out of memory for %dx%d", w, h);
  }
  memcpy(p->z, height_texels->pixels, n * sizeof(float));
  st = build_levels(p, threads, err);
  if (st != BB_OK) {
    bb_pyramid_free(p);
    return st;
  }
  p->global_max = p->level_max[levels - 1][0];
  p->global_min = p->z[0];
  for (size_t i = 1; i < n; i++)
    if (p->z[i] < p->global_min) p->global_min = p->z[i];
  p->border_max = border_max(p);
  *out = p;
  return BB_OK;
}

/* ------------------------------------------------------------- updates */

/* The node columns (or rows) of level k whose cells meet the cells
 * [first, first + count) of an axis of n cells at level 0 (periodic: the
 * interval may pass n and wrap), as up to three intervals lo[i]..hi[i]. */
static int nodes_of(const bb_pyramid *p, int k, int first, int count, int n, int nodes,
                    int *lo, int *hi) {
  int spans = 0;
  if (count >= n) {
    lo[0] = 0, hi[0] = nodes - 1;
    return 1;
  }
  /* the interval as plain ones inside [0, n) */
  int s[2], e[2], parts = 0;
  if (first + count <= n) {
    s[parts] = first, e[parts++] = first + count - 1;
  } else {
    s[parts] = first, e[parts++] = n - 1;
    s[parts] = 0, e[parts++] = first + count - 1 - n;
  }
  for (int i = 0; i < parts; i++)
    lo[spans] = s[i] >> k, hi[spans++] = e[i] >> k;
  /* the last node's cells past n are the first ones again (periodic) or
   * the border cell (clamp: inside the last node already) */
  const long past = ((long)nodes << k) - n;
  if (past > 0 && p->addressing == BB_ADDRESS_PERIODIC)
    for (int i = 0; i < parts; i++)
      if (s[i] < past) {
        lo[spans] = hi[spans] = nodes - 1;
        spans++;
        break;
      }
  return spans;
}

/* Node (i, j) of level k >= 1: the max of its four children when all of
 * them exist, which cover its cells exactly; otherwise (the last node of an
 * odd level, whose cells past the side are addressed) from the cells. The
 * build and the updates both take every node here. */
static void node_update(bb_pyramid *p, int k, int i, int j) {
  const int cw = p->level_width[k - 1], ch = p->level_height[k - 1];
  float m;
  if (2 * i + 1 < cw && 2 * j + 1 < ch) {
    const float *c = p->level_max[k - 1];
    const size_t r0 = (size_t)(2 * j) * (size_t)cw, r1 = r0 + (size_t)cw;
    m = c[r0 + (size_t)(2 * i)];
    if (c[r0 + (size_t)(2 * i + 1)] > m)
      m = c[r0 + (size_t)(2 * i + 1)];
    if (c[r1 + (size_t)(2 * i)] > m)
      m = c[r1 + (size_t)(2 * i)];
    if (c[r1 + (size_t)(2 * i + 1)] > m)
      m = c[r1 + (size_t)(2 * i + 1)];
  } else {
    const int span = 1 << k, w = p->width;
    m = -FLT_MAX;
    for (int y = j * span; y < (j + 1) * span; y++) {
      const float *row =
          p->level_max[0] + (size_t)bb__address(y, p->height, p->addressing) * (size_t)w;
      const float v = addressed_max(row, 1, w, i * span, span, p->addressing);
      if (v > m)
        m = v;
    }
  }
  p->level_max[k][(size_t)j * (size_t)p->level_width[k] + (size_t)i] = m;
}

bb_status bb__pyramid_update(bb_pyramid *p, int x0, int y0, int width, int height,
                             float old_min) {
  const int w = p->width, h = p->height;
  if (width <= 0 || height <= 0)
    return BB_OK;
  /* the cells with a changed corner: one more to the left and above */
  int cx = x0 - 1, cw = width + 1, cy = y0 - 1, ch = height + 1;
  if (p->addressing == BB_ADDRESS_PERIODIC) {
    cx = bb__wrap(cx, w), cy = bb__wrap(cy, h);
  } else {
    if (cx < 0)
      cx = 0, cw--;
    if (cy < 0)
      cy = 0, ch--;
  }
  if (cw > w)
    cw = w;
  if (ch > h)
    ch = h;
  int lo_x[3], hi_x[3], lo_y[3], hi_y[3];
  const int nx = nodes_of(p, 0, cx, cw, w, w, lo_x, hi_x);
  const int ny = nodes_of(p, 0, cy, ch, h, h, lo_y, hi_y);
  for (int a = 0; a < ny; a++)
    for (int y = lo_y[a]; y <= hi_y[a]; y++) {
      /* a row of cells at a time: build_cells_row's own arithmetic */
      const float *r0 = p->z + (size_t)y * (size_t)w;
      const float *r1 = p->z + (size_t)bb__address(y + 1, h, p->addressing) * (size_t)w;
      for (int b = 0; b < nx; b++)
        for (int x = lo_x[b]; x <= hi_x[b]; x++) {
          const int x1 = x + 1 < w ? x + 1 : bb__address(x + 1, w, p->addressing);
          float m = r0[x];
          if (r0[x1] > m)
            m = r0[x1];
          if (r1[x] > m)
            m = r1[x];
          if (r1[x1] > m)
            m = r1[x1];
          p->level_max[0][(size_t)y * (size_t)w + (size_t)x] = m;
        }
    }
  for (int k = 1; k < p->levels; k++) {
    const int mx = nodes_of(p, k, cx, cw, w, p->level_width[k], lo_x, hi_x);
    const int my = nodes_of(p, k, cy, ch, h, p->level_height[k], lo_y, hi_y);
    for (int a = 0; a < my; a++)
      for (int j = lo_y[a]; j <= hi_y[a]; j++)
        for (int b = 0; b < mx; b++)
          for (int i = lo_x[b]; i <= hi_x[b]; i++)
            node_update(p, k, i, j);
  }
  p->global_max = p->level_max[p->levels - 1][0];
  /* the least height: a rescan only when the old least one may have gone */
  float changed_min = FLT_MAX;
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++) {
      const float v = p->z[(size_t)bb__address(y0 + y, h, p->addressing) * (size_t)w +
                           (size_t)bb__address(x0 + x, w, p->addressing)];
      if (v < changed_min)
        changed_min = v;
    }
  if (changed_min <= p->global_min) {
    p->global_min = changed_min;
  } else if (old_min <= p->global_min) {
    const size_t n = (size_t)w * (size_t)h;
    p->global_min = p->z[0];
    for (size_t i = 1; i < n; i++)
      if (p->z[i] < p->global_min)
        p->global_min = p->z[i];
  }
  p->border_max = border_max(p);
  return BB_OK;
}

void bb_pyramid_free(bb_pyramid *p) {
  if (!p) return;
  for (int k = 0; k < p->levels; k++) free(p->level_max[k]);
  free(p->z);
  free(p);
}
