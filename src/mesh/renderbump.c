/* renderbump.c: DOOM 3's RenderBumpFlat on the CPU: a flat sculpt projected
 * orthographically onto a rectangle, its front-most surface's normal and
 * height averaged over samples per texel.
 *
 * Stages: project every vertex to image space (u right, v down, in texels;
 * d = height towards the viewer), bin triangle copies (one per tile they
 * reach with tile on) into bands of texel rows, then per band on all
 * threads: rasterise the band's triangles in mesh order into a sample
 * buffer (rasterize.c) and resolve each texel from its samples. A band's
 * result depends only on its triangles in mesh order, so outputs are the
 * same for any thread count.
 */
#include "core/internal.h"
#include "mesh/mesh_internal.h"
#include "mesh/renderbump_notes.h"
#include "mesh/rasterize.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Most (triangle copy, band) pairs binned: 64 M entries of 12 bytes. */
#define BIN_LIMIT (1L << 26)
/* Farthest tile, in periods, that a tiled model may reach from the rect. */
#define TILE_REACH_LIMIT (1L << 20)
/* Target samples per band buffer (12 bytes each). */
#define BAND_SAMPLES (1L << 18)

void bb__renderbump_options_init(bb_renderbump_options *o) {
  memset(o, 0, sizeof *o);
  o->width = 256;
  o->height = 256;
  o->samples = 4;
  o->axis = BB_AXIS_NEG_Y;
}

void bb_renderbump_result_free(bb_renderbump_result *r) {
  if (!r)
    return;
  bb_image_free(&r->normal);
  bb_image_free(&r->height);
  memset(r, 0, sizeof *r);
}

/* One triangle copy in a band's bin: the triangle and its tile shift. */
typedef struct bin_entry {
  uint32_t triangle;
  int32_t shift_u, shift_v; /* in periods of the rectangle */
} bin_entry;

typedef struct rb_job {
  const bb_mesh *mesh;
  const bb_renderbump_options *o;
  double right[3], up[3], out[3];
  double *uvd;            /* 3 per vertex: u, v in texels, d in model units */
  float *normal_t;        /* 3 per vertex: unit normal in the tangent frame */
  unsigned char *has_normal; /* per vertex; NULL when normals are not used */
  double ref_depth;       /* smallest vertex d: heights are stored from it */
  int band_rows, bands;
  size_t *bin_start;      /* bands + 1 */
  bin_entry *bins;
  double reach;           /* estimated samples the copies reach (see reach_of) */
  double copies;          /* triangle copies drawn */
  bb_renderbump_result *r;
  atomic_int out_of_memory;
} rb_job;

/* ------------------------------------------------------------- checking */

const bb__range bb__range_renderbump_samples = {"renderbump: samples per side", 1, 16, 0, 1};

static bb_status check_options(const bb_renderbump_options *o, bb_error *err) {
  if (o->width < 1 || o->height < 1 || o->width > BB_MAX_DIMENSION ||
      o->height > BB_MAX_DIMENSION || (long long)o->width * o->height > BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_SIZE, "renderbump: size %d x %d is not in 1..%d per side "
                    "and %ld texels", o->width, o->height, BB_MAX_DIMENSION,
                    (long)BB_MAX_PIXELS);
  if (!bb__range_holds(&bb__range_renderbump_samples, o->samples))
    return bb__range_check(&bb__range_renderbump_samples, o->samples, NULL, err);
  if ((int)o->axis < 0 || (int)o->axis > BB_AXIS_NEG_X)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: unknown axis %d", (int)o->axis);
  bb_status st = bb__range_check(&bb__range_threads, o->threads, "renderbump: threads", err);
  if (st != BB_OK)
    return st;
  if (o->rect_given) {
    for (int k = 0; k < 4; k++)
      if (!isfinite(o->rect[k]))
        return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: rectangle is not finite");
    if (!(o->rect[2] > o->rect[0]) || !(o->rect[3] > o->rect[1]))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "renderbump: rectangle needs left < right and bottom < top");
  }
  return BB_OK;
}

static bb_status check_mesh(const bb_mesh *m, bb_error *err) {
  if (!m || !m->positions || !m->indices || m->vertex_count == 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: empty mesh");
  if (m->triangle_count == 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: the mesh has no triangles");
  if (m->vertex_count > BB_MAX_MESH_ELEMENTS || m->triangle_count > BB_MAX_MESH_ELEMENTS)
    return bb__fail(err, BB_ERR_SIZE, "renderbump: mesh over the maximum size");
  for (size_t i = 0; i < 3 * m->triangle_count; i++)
    if (m->indices[i] >= m->vertex_count)
      return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: triangle %zu refers to vertex %u of %zu",
                      i / 3, m->indices[i], m->vertex_count);
  for (size_t i = 0; i < 3 * m->vertex_count; i++)
    if (!isfinite(m->positions[i]))
      return bb__fail(err, BB_ERR_VALUE, "renderbump: vertex %zu is not finite", i / 3);
  return BB_OK;
}

/* ----------------------------------------------------------- projection */

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void vertex_position(const bb_mesh *m, size_t i, double p[3]) {
  for (int k = 0; k < 3; k++)
    p[k] = (double)m->positions[3 * i + (size_t)k];
}

/* The bounding rectangle (left, bottom, right, top) of the vertices the
 * triangles use, along right and up. */
static void bounding_rect(const rb_job *job, double rect[4]) {
  rect[0] = rect[1] = INFINITY;
  rect[2] = rect[3] = -INFINITY;
  for (size_t i = 0; i < 3 * job->mesh->triangle_count; i++) {
    double p[3];
    vertex_position(job->mesh, job->mesh->indices[i], p);
    double x = dot3(p, job->right), y = dot3(p, job->up);
    rect[0] = fmin(rect[0], x), rect[2] = fmax(rect[2], x);
    rect[1] = fmin(rect[1], y), rect[3] = fmax(rect[3], y);
  }
}

/* Image-space u, v (texels; v grows downwards from the top edge) and d of
 * every vertex, and the smallest d. */
static bb_status project_vertices(rb_job *job, bb_error *err) {
  const bb_mesh *m = job->mesh;
  const double *rect = job->r->rect;
  const double texels_u = job->o->width / (rect[2] - rect[0]);
  const double texels_v = job->o->height / (rect[3] - rect[1]);
  job->uvd = malloc(3 * m->vertex_count * sizeof(double));
  if (!job->uvd)
    return bb__fail(err, BB_ERR_MEMORY, "renderbump: cannot allocate projected vertices");
  job->ref_depth = INFINITY;
  for (size_t i = 0; i < m->vertex_count; i++) {
    double p[3];
    vertex_position(m, i, p);
    double *uvd = job->uvd + 3 * i;
    uvd[0] = (dot3(p, job->right) - rect[0]) * texels_u;
    uvd[1] = (rect[3] - dot3(p, job->up)) * texels_v;
    uvd[2] = dot3(p, job->out);
    if (!isfinite(uvd[0]) || !isfinite(uvd[1]))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "renderbump: the rectangle is too small for the model's coordinates");
    job->ref_depth = fmin(job->ref_depth, uvd[2]);
  }
  return BB_OK;
}

/* A model-space vector in the tangent frame: x right, y DOWN, z out. */
static void to_tangent(const rb_job *job, const double v[3], double t[3]) {
  t[0] = dot3(v, job->right);
  t[1] = -dot3(v, job->up);
  t[2] = dot3(v, job->out);
}

static int normalize3(double v[3]) {
  double len = sqrt(dot3(v, v));
  if (!(len > 0.0) || !isfinite(len))
    return 0;
  for (int k = 0; k < 3; k++)
    v[k] /= len;
  return 1;
}

/* Unit vertex normals in the tangent frame; a vertex whose normal is zero
 * or not finite has none. Skipped (has_normal NULL) for face normals. */
static bb_status prepare_normals(rb_job *job, bb_error *err) {
  const bb_mesh *m = job->mesh;
  if (!m->normals || job->o->face_normals)
    return BB_OK;
  job->normal_t = malloc(3 * m->vertex_count * sizeof(float));
  job->has_normal = calloc(m->vertex_count, 1);
  if (!job->normal_t || !job->has_normal)
    return bb__fail(err, BB_ERR_MEMORY, "renderbump: cannot allocate vertex normals");
  for (size_t i = 0; i < m->vertex_count; i++) {
    double n[3], t[3];
    for (int k = 0; k < 3; k++)
      n[k] = (double)m->normals[3 * i + (size_t)k];
    to_tangent(job, n, t);
    job->has_normal[i] = (unsigned char)normalize3(t);
    for (int k = 0; k < 3; k++)
      job->normal_t[3 * i + (size_t)k] = job->has_normal[i] ? (float)t[k] : 0.0f;
  }
  return BB_OK;
}

/* ------------------------------------------------------------- binning */

/* Range of whole periods k for which [lo + k n, hi + k n] meets [0, n];
 * 0 when it reaches past TILE_REACH_LIMIT periods. */
static int period_range(double lo, double hi, int n, long *first, long *last) {
  double f = ceil(-hi / n), l = floor((n - lo) / n);
  if (!(fabs(f) <= TILE_REACH_LIMIT && fabs(l) <= TILE_REACH_LIMIT))
    return 0; /* also keeps the conversions below defined */
  *first = (long)f;
  *last = (long)l;
  return 1;
}

static void triangle_box(const rb_job *job, size_t t, double box[4]) {
  const uint32_t *idx = job->mesh->indices + 3 * t;
  box[0] = box[1] = INFINITY;
  box[2] = box[3] = -INFINITY;
  for (int k = 0; k < 3; k++) {
    const double *uvd = job->uvd + 3 * (size_t)idx[k];
    box[0] = fmin(box[0], uvd[0]), box[2] = fmax(box[2], uvd[0]);
    box[1] = fmin(box[1], uvd[1]), box[3] = fmax(box[3], uvd[1]);
  }
}

/* The bands rows lo..hi of the image (clipped to it) fall in. */
static void band_range(const rb_job *job, double lo, double hi, int *first, int *last) {
  double f = floor(fmax(lo, 0.0) / job->band_rows);
  double l = floor(fmin(hi, (double)job->o->height) / job->band_rows);
  *first = (int)f;
  *last = l >= job->bands ? job->bands - 1 : (int)l;
}

/* Sample rows or columns whose centres (k + 0.5) / n lie in [lo, hi],
 * within 0 .. count * n - 1 (count texels). */
static double samples_within(double lo, double hi, int n, int count) {
  double first = fmax(ceil(lo * n - 0.5), 0.0);
  double last = fmin(floor(hi * n - 0.5), (double)count * n - 1.0);
  return last >= first ? last - first + 1.0 : 0.0;
}

/* Twice the area (texels^2) and the perimeter (texels) of triangle t in
 * image space. */
static void triangle_measure(const rb_job *job, size_t t, double *area2, double *perimeter) {
  const uint32_t *idx = job->mesh->indices + 3 * t;
  const double *p[3];
  for (int k = 0; k < 3; k++)
    p[k] = job->uvd + 3 * (size_t)idx[k];
  *area2 = fabs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) -
                (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]));
  *perimeter = 0.0;
  for (int k = 0; k < 3; k++) {
    const double *a = p[k], *b = p[(k + 1) % 3];
    *perimeter += hypot(b[0] - a[0], b[1] - a[1]);
  }
}

/* What drawing one copy (its box shifted into place) costs at most, in
 * samples: one per sample row it spans (the run of each row is found in a
 * few tests), plus the samples it covers: no more than the part of its box
 * inside the image, nor than a convex shape of its area and perimeter can
 * hold (area + perimeter / 2 + 1, in samples). */
static double reach_of(const rb_job *job, const double box[4], double area2, double perimeter) {
  const int n = job->o->samples;
  const double rows = samples_within(box[1], box[3], n, job->o->height);
  const double columns = samples_within(box[0], box[2], n, job->o->width);
  const double shape = 0.5 * area2 * n * n + 0.5 * perimeter * n + 1.0;
  return rows + fmin(rows * columns, shape);
}

/* One pass over every triangle copy and the bands it reaches, in mesh
 * order: counts entries per band into count[] (fill 0), or writes them at
 * cursor[] (fill 1). Returns the total, or -1 past BIN_LIMIT or the tile
 * reach limit. */
static long bin_pass(rb_job *job, int fill, size_t *count_or_cursor) {
  const int W = job->o->width, H = job->o->height;
  long total = 0;
  job->reach = job->copies = 0.0;
  for (size_t t = 0; t < job->mesh->triangle_count; t++) {
    double box[4], area2 = 0.0, perimeter = 0.0;
    triangle_box(job, t, box);
    if (!fill)
      triangle_measure(job, t, &area2, &perimeter);
    long ku0 = 0, ku1 = 0, kv0 = 0, kv1 = 0;
    if (job->o->tile) {
      if (!period_range(box[0], box[2], W, &ku0, &ku1) ||
          !period_range(box[1], box[3], H, &kv0, &kv1) ||
          (double)(ku1 - ku0 + 1) * (double)(kv1 - kv0 + 1) > (double)(BIN_LIMIT - total))
        return -1; /* before a loop over that many copies */
    } else if (box[2] < 0.0 || box[0] > W || box[3] < 0.0 || box[1] > H) {
      continue; /* outside the rectangle */
    }
    for (long kv = kv0; kv <= kv1; kv++) {
      int b0, b1;
      band_range(job, box[1] + (double)kv * H, box[3] + (double)kv * H, &b0, &b1);
      for (long ku = ku0; ku <= ku1; ku++) {
        if (!fill) {
          const double shifted[4] = {box[0] + (double)ku * W, box[1] + (double)kv * H,
                                     box[2] + (double)ku * W, box[3] + (double)kv * H};
          job->reach += reach_of(job, shifted, area2, perimeter);
          job->copies += 1.0;
        }
        for (int b = b0; b <= b1; b++) {
          if (++total > BIN_LIMIT)
            return -1;
          if (fill)
            job->bins[count_or_cursor[b]++] =
                (bin_entry){(uint32_t)t, (int32_t)ku, (int32_t)kv};
          else
            count_or_cursor[b]++;
        }
      }
    }
  }
  return total;
}

static bb_status bin_triangles(rb_job *job, bb_error *err) {
  job->bin_start = calloc((size_t)job->bands + 1, sizeof(size_t));
  size_t *cursor = calloc((size_t)job->bands, sizeof(size_t));
  if (!job->bin_start || !cursor) {
    free(cursor);
    return bb__fail(err, BB_ERR_MEMORY, "renderbump: cannot allocate bins");
  }
  long total = bin_pass(job, 0, cursor);
  if (total < 0) {
    free(cursor);
    return bb__fail(err, BB_ERR_SIZE,
                    "renderbump: the model covers the image too many times over (more than "
                    "%ld triangle-bands, or tiles over %ld periods away)",
                    BIN_LIMIT, TILE_REACH_LIMIT);
  }
  /* The work bound, before anything is drawn or allocated for drawing. */
  const double samples = (double)job->o->width * job->o->height * job->o->samples *
                         job->o->samples;
  if (job->reach > (double)BB_MAX_RENDERBUMP_LAYERS * (samples + job->copies)) {
    free(cursor);
    return bb__fail(err, BB_ERR_SIZE,
                    "renderbump: the model's %.0f triangles reach about %.3g samples, %.0f "
                    "times the image's %.0f: over the %d layers a render may draw",
                    job->copies, job->reach, job->reach / samples, samples,
                    BB_MAX_RENDERBUMP_LAYERS);
  }
  for (int b = 0; b < job->bands; b++) {
    job->bin_start[b + 1] = job->bin_start[b] + cursor[b];
    cursor[b] = job->bin_start[b];
  }
  job->bins = malloc((size_t)(total ? total : 1) * sizeof(bin_entry));
  if (!job->bins) {
    free(cursor);
    return bb__fail(err, BB_ERR_MEMORY, "renderbump: cannot allocate bins");
  }
  bin_pass(job, 1, cursor);
  free(cursor);
  job->r->triangles_drawn = (size_t)total;
  return BB_OK;
}

/* ------------------------------------------------------------ shading */

/* One bin entry made ready for a band: its raster setup and how its
 * samples are shaded. */
typedef struct prepared {
  bb__raster_setup raster;
  double face[3];      /* plane normal, tangent frame, on the viewer's side */
  const float *vertex_n[3]; /* unit tangent-frame vertex normals, or NULL */
  double vertex_sign;  /* -1 when the vertex normals point away from the viewer */
} prepared;

static void entry_triangle(const rb_job *job, const bin_entry *e, bb__raster_tri *tri) {
  const uint32_t *idx = job->mesh->indices + 3 * (size_t)e->triangle;
  const double su = (double)e->shift_u * job->o->width;
  const double sv = (double)e->shift_v * job->o->height;
  for (int k = 0; k < 3; k++) {
    const double *uvd = job->uvd + 3 * (size_t)idx[k];
    tri->u[k] = uvd[0] + su;
    tri->v[k] = uvd[1] + sv;
    tri->d[k] = uvd[2];
  }
}

/* The plane normal of triangle t in the tangent frame, on the viewer's side
 * (n[2] >= 0): the front-most surface is seen from the front, whatever the
 * winding. 0 when the triangle is degenerate. */
static int face_normal(const rb_job *job, uint32_t t, double n[3]) {
  const uint32_t *idx = job->mesh->indices + 3 * (size_t)t;
  double p0[3], p1[3], p2[3], a[3], b[3], g[3];
  vertex_position(job->mesh, idx[0], p0);
  vertex_position(job->mesh, idx[1], p1);
  vertex_position(job->mesh, idx[2], p2);
  for (int k = 0; k < 3; k++)
    a[k] = p1[k] - p0[k], b[k] = p2[k] - p0[k];
  g[0] = a[1] * b[2] - a[2] * b[1];
  g[1] = a[2] * b[0] - a[0] * b[2];
  g[2] = a[0] * b[1] - a[1] * b[0];
  to_tangent(job, g, n);
  if (n[2] < 0.0)
    for (int k = 0; k < 3; k++)
      n[k] = -n[k];
  return normalize3(n);
}

static int uses_vertex_normals(const rb_job *job, uint32_t t) {
  if (!job->has_normal)
    return 0;
  const uint32_t *idx = job->mesh->indices + 3 * (size_t)t;
  return job->has_normal[idx[0]] && job->has_normal[idx[1]] && job->has_normal[idx[2]];
}

/* Sets p up for entry e; 0 when it draws nothing (zero area). Vertex
 * normals pointing away from the viewer as a whole (a model wound the
 * other way round than its normals) are turned to the plane normal's side. */
static int prepare(const rb_job *job, const bin_entry *e, prepared *p) {
  bb__raster_tri tri;
  entry_triangle(job, e, &tri);
  if (!bb__raster_setup_make(&tri, &p->raster) || !face_normal(job, e->triangle, p->face))
    return 0;
  p->vertex_n[0] = NULL;
  p->vertex_sign = 1.0;
  if (!uses_vertex_normals(job, e->triangle))
    return 1;
  const uint32_t *idx = job->mesh->indices + 3 * (size_t)e->triangle;
  double towards = 0.0;
  for (int k = 0; k < 3; k++) {
    p->vertex_n[k] = job->normal_t + 3 * (size_t)idx[k];
    for (int c = 0; c < 3; c++)
      towards += (double)p->vertex_n[k][c] * p->face[c];
  }
  p->vertex_sign = towards < 0.0 ? -1.0 : 1.0;
  return 1;
}

/* The unit normal of the surface p at sample (u, v), tangent frame: the
 * interpolated vertex normal, or the plane normal (also where the
 * interpolation vanishes). */
static void sample_normal(const prepared *p, double u, double v, double n[3]) {
  if (p->vertex_n[0]) {
    double w[3];
    bb__raster_weights(&p->raster, u, v, w);
    for (int c = 0; c < 3; c++)
      n[c] = p->vertex_sign * (w[0] * p->vertex_n[0][c] + w[1] * p->vertex_n[1][c] +
                               w[2] * p->vertex_n[2][c]);
    if (normalize3(n))
      return;
  }
  memcpy(n, p->face, sizeof p->face);
}

/* ---------------------------------------------------------------- bands */

/* Texel (x, y) from its samples: the mean unit normal (renormalised), the
 * covered fraction, and the mean d (less ref_depth) into the height. */
static void resolve_texel(const rb_job *job, const bb__sample_band *sb, const prepared *entry,
                          int x, int y) {
  const int s = sb->per_texel;
  double sum_n[3] = {0.0, 0.0, 0.0}, sum_d = 0.0;
  int covered = 0;
  for (int j = 0; j < s; j++) {
    const int row = y * s + j;
    const long base = (long)(row - sb->first_row) * sb->columns + (long)x * s;
    for (int i = 0; i < s; i++) {
      const int32_t w = sb->winner[base + i];
      if (w < 0)
        continue;
      double n[3];
      sample_normal(&entry[w], (x * s + i + 0.5) / s, (row + 0.5) / s, n);
      for (int c = 0; c < 3; c++)
        sum_n[c] += n[c];
      sum_d += sb->depth[base + i];
      covered++;
    }
  }
  float *px = bb_image_texel(&job->r->normal, x, y);
  if (!covered || !normalize3(sum_n))
    sum_n[0] = sum_n[1] = 0.0, sum_n[2] = 1.0;
  for (int c = 0; c < 3; c++)
    px[c] = (float)sum_n[c];
  px[3] = (float)covered / (float)(s * s);
  *bb_image_texel(&job->r->height, x, y) =
      covered ? (float)(sum_d / covered - job->ref_depth) : 0.0f;
}

/* Rasterises the band's entries in mesh order, then resolves its texels. */
static void draw_band(const rb_job *job, bb__sample_band *sb, prepared *entry, int band) {
  const bin_entry *bin = job->bins + job->bin_start[band];
  const size_t count = job->bin_start[band + 1] - job->bin_start[band];
  for (size_t e = 0; e < count; e++)
    if (prepare(job, &bin[e], &entry[e]))
      bb__band_draw(sb, &entry[e].raster, (int32_t)e);
  const int y0 = sb->first_row / sb->per_texel, y1 = y0 + sb->rows / sb->per_texel;
  for (int y = y0; y < y1; y++)
    for (int x = 0; x < job->o->width; x++)
      resolve_texel(job, sb, entry, x, y);
}

static void band_work(void *user, int band) {
  rb_job *job = user;
  const int s = job->o->samples;
  const int y0 = band * job->band_rows;
  const int y1 = y0 + job->band_rows < job->o->height ? y0 + job->band_rows : job->o->height;
  bb__sample_band sb = {job->o->width * s, (y1 - y0) * s, y0 * s, s, NULL, NULL};
  const size_t n = (size_t)sb.columns * (size_t)sb.rows;
  const size_t count = job->bin_start[band + 1] - job->bin_start[band];
  sb.depth = malloc(n * sizeof(double));
  sb.winner = malloc(n * sizeof(int32_t));
  prepared *entry = malloc((count ? count : 1) * sizeof(prepared));
  if (!sb.depth || !sb.winner || !entry) {
    atomic_store(&job->out_of_memory, 1);
  } else {
    for (size_t k = 0; k < n; k++)
      sb.winner[k] = -1;
    draw_band(job, &sb, entry, band);
  }
  free(entry);
  free(sb.depth);
  free(sb.winner);
}

/* ----------------------------------------------------------- finishing */

/* Heights from d to h in [0, 1] over the covered texels; fails when no
 * texel is covered at all. */
static bb_status normalise_height(rb_job *job, bb_error *err) {
  bb_renderbump_result *r = job->r;
  const size_t texels = (size_t)r->height.width * (size_t)r->height.height;
  float lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < texels; i++)
    if (r->normal.pixels[4 * i + 3] > 0.0f) {
      lo = fminf(lo, r->height.pixels[i]);
      hi = fmaxf(hi, r->height.pixels[i]);
    }
  if (!(lo <= hi))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "renderbump: no surface faces the viewer inside the rectangle along %s",
                    bb__axis_name(job->o->axis));
  const double range = (double)hi - (double)lo;
  for (size_t i = 0; i < texels; i++) {
    float *h = &r->height.pixels[i];
    *h = r->normal.pixels[4 * i + 3] > 0.0f && range > 0.0
             ? (float)(((double)*h - lo) / range)
             : 0.0f;
  }
  r->depth_min = job->ref_depth + (double)lo;
  r->depth_max = job->ref_depth + (double)hi;
  r->height_scale = (r->depth_max - r->depth_min) / r->texel_size;
  return BB_OK;
}

static int any_vertex_normals_drawn(const rb_job *job) {
  size_t total = job->bin_start[job->bands];
  for (size_t e = 0; e < total; e++)
    if (uses_vertex_normals(job, job->bins[e].triangle))
      return 1;
  return 0;
}

/* The rectangle (given or bounding) and its texel size; fails when it is
 * degenerate. */
static bb_status choose_rect(rb_job *job, bb_error *err) {
  bb_renderbump_result *r = job->r;
  if (job->o->rect_given)
    memcpy(r->rect, job->o->rect, sizeof r->rect);
  else
    bounding_rect(job, r->rect);
  const double w = r->rect[2] - r->rect[0], h = r->rect[3] - r->rect[1];
  if (!(w > 0.0) || !(h > 0.0) || !isfinite(w) || !isfinite(h))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "renderbump: the bounding rectangle seen along %s is degenerate "
                    "(%g x %g model units); try another axis",
                    bb__axis_name(job->o->axis), w, h);
  const double tu = w / job->o->width, tv = h / job->o->height;
  r->texel_size = sqrt(tu * tv);
  r->texel_aspect = tu / tv;
  if (!(r->texel_size > 0.0))
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: the rectangle is too small");
  return BB_OK;
}

static bb_status render(rb_job *job, bb_error *err) {
  const bb_renderbump_options *o = job->o;
  bb_status st = choose_rect(job, err);
  if (st == BB_OK)
    st = bb_image_alloc(&job->r->normal, o->width, o->height, 4, err);
  if (st == BB_OK)
    st = bb_image_alloc(&job->r->height, o->width, o->height, 1, err);
  if (st == BB_OK)
    st = project_vertices(job, err);
  if (st == BB_OK)
    st = prepare_normals(job, err);
  if (st != BB_OK)
    return st;
  const long per_row = (long)o->width * o->samples * o->samples;
  long rows = BAND_SAMPLES / per_row;
  job->band_rows = rows < 1 ? 1 : (rows > 64 ? 64 : (int)rows);
  job->bands = (o->height + job->band_rows - 1) / job->band_rows;
  st = bin_triangles(job, err);
  if (st == BB_OK)
    st = bb__parallel_for(job->bands, o->threads, band_work, job, NULL, NULL, err);
  if (st == BB_OK && atomic_load(&job->out_of_memory))
    st = bb__fail(err, BB_ERR_MEMORY, "renderbump: cannot allocate a band's samples");
  if (st == BB_OK)
    st = normalise_height(job, err);
  if (st == BB_OK)
    job->r->used_vertex_normals = any_vertex_normals_drawn(job);
  return st;
}

bb_status bb__renderbump_flat(const bb_mesh *mesh, const bb_renderbump_options *o,
                             bb_renderbump_result *result, bb_error *err) {
  if (!o || !result)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump: missing options or result");
  memset(result, 0, sizeof *result);
  bb_status st = check_options(o, err);
  if (st == BB_OK)
    st = check_mesh(mesh, err);
  if (st != BB_OK)
    return st;
  rb_job job;
  memset(&job, 0, sizeof job);
  job.mesh = mesh;
  job.o = o;
  job.r = result;
  atomic_init(&job.out_of_memory, 0);
  bb__axis_frame(o->axis, job.right, job.up, job.out);
  st = render(&job, err);
  free(job.uvd);
  free(job.normal_t);
  free(job.has_normal);
  free(job.bin_start);
  free(job.bins);
  if (st != BB_OK) {
    bb_renderbump_result_free(result);
    return st;
  }
  result->triangles = mesh->triangle_count;
  result->vertices = mesh->vertex_count;
  result->model_hash = bb__mesh_hash(mesh);
  bb__renderbump_notes(o, result);
  return st;
}

/* ---------------------------------------------------------- provenance */

char *bb__renderbump_describe(const bb_renderbump_options *o, const bb_renderbump_result *r) {
  if (!o || !r)
    return NULL;
  const size_t cap = 1024;
  char *text = malloc(cap);
  if (!text)
    return NULL;
  /* %.17g: every double reads back exactly. */
  snprintf(text, cap,
           "axis=%s\nsize=%dx%d\nsamples=%d\nnormals=%s\n"
           "rect=%.17g,%.17g,%.17g,%.17g\ntile=%s\n"
           "depth_min=%.17g\ndepth_max=%.17g\nscale=%.9g\n",
           bb__axis_name(o->axis), o->width, o->height, o->samples,
           r->used_vertex_normals ? "vertex" : "face", r->rect[0], r->rect[1], r->rect[2],
           r->rect[3], o->tile ? "on" : "off", r->depth_min, r->depth_max,
           r->height_scale);
  return text;
}
