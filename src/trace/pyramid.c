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
  int k;          /* the level being built */
  float *row_max; /* level k's nodes along x, for every row of cells */
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

/* Level k straight from level 0, separably (rows, then columns): every level
 * costs O(W*H) and the wrapped last node needs no special case. */
static void level_rows(void *user, int y) { /* cells of row y -> row_max */
  const build_job *job = user;
  const bb_pyramid *p = job->p;
  const int w = p->width, lw = p->level_width[job->k], span = 1 << job->k;
  const float *cells = p->level_max[0] + (size_t)y * (size_t)w;
  for (int i = 0; i < lw; i++)
    job->row_max[(size_t)y * (size_t)lw + (size_t)i] =
        addressed_max(cells, 1, w, i * span, span, p->addressing);
}

static void level_columns(void *user, int j) { /* row_max -> node row j */
  const build_job *job = user;
  const bb_pyramid *p = job->p;
  const int lw = p->level_width[job->k], span = 1 << job->k;
  for (int i = 0; i < lw; i++)
    p->level_max[job->k][(size_t)j * (size_t)lw + (size_t)i] =
        addressed_max(job->row_max + i, (size_t)lw, p->height, j * span, span, p->addressing);
}

static bb_status build_levels(bb_pyramid *p, float *row_max, int threads, bb_error *err) {
  build_job job = {p, 0, row_max};
  bb_status st = bb__parallel_for(p->height, threads, build_cells_row, &job, NULL, NULL, err);
  for (job.k = 1; st == BB_OK && job.k < p->levels; job.k++) {
    st = bb__parallel_for(p->height, threads, level_rows, &job, NULL, NULL, err);
    if (st == BB_OK)
      st = bb__parallel_for(p->level_height[job.k], threads, level_columns, &job, NULL, NULL,
                            err);
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

bb_status bb_pyramid_build(const bb_image *height_texels, bb_addressing addressing,
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
  float *row_max = malloc(n * sizeof(float));
  int ok = p->z && row_max;
  for (int k = 0; ok && k < levels; k++) {
    p->level_width[k] = ceil_shift(w, k);
    p->level_height[k] = ceil_shift(h, k);
    p->level_max[k] = malloc((size_t)p->level_width[k] * (size_t)p->level_height[k] * sizeof(float));
    ok = p->level_max[k] != NULL;
  }
  if (!ok) {
    free(row_max);
    bb_pyramid_free(p);
    return bb__fail(err, BB_ERR_MEMORY, "pyramid: out of memory for %dx%d", w, h);
  }
  memcpy(p->z, height_texels->pixels, n * sizeof(float));
  st = build_levels(p, row_max, threads, err);
  free(row_max);
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

void bb_pyramid_free(bb_pyramid *p) {
  if (!p) return;
  for (int k = 0; k < p->levels; k++) free(p->level_max[k]);
  free(p->z);
  free(p);
}
