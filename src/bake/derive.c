/* derive.c: the maps derived per texel from normals and visibility, for any
 * basis (basis.c). */

#include "bake/bake_internal.h"
#include "trace/basis.h"
#include "core/internal.h"
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double dot3(const float n[3], const double b[3]) {
  return (double)n[0] * b[0] + (double)n[1] * b[1] + (double)n[2] * b[2];
}

static double saturate(double v) {
  return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

static bb_status check_image(const bb_image *img, const char *what, int min_channels,
                             int max_channels, bb_error *err) {
  if (!img || !img->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "derive: missing %s image", what);
  if (img->channels < min_channels || img->channels > max_channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "derive: %s has %d channels, not %d..%d", what,
                    img->channels, min_channels, max_channels);
  return BB_OK;
}

static bb_status check_output(const bb_image *out, const bb_image *a, const bb_image *b,
                              bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "derive: missing output image");
  if (out == a || out == b)
    return bb__fail(err, BB_ERR_ARGUMENT, "derive: the output must be a separate image");
  return BB_OK;
}

/* max(0, v) with the value glibc's fmax(0.0, v) returns, which the maps have
 * always used: v < 0 and NaN (a NaN normal) give +0, and -0 stays -0. Inline
 * because fmax is a library call per texel. */
static double max0(double v) {
  return v >= 0.0 ? v : 0.0;
}

/* The inputs, output and basis of one derive call; each parallel work item is
 * one row, and each texel depends only on its own inputs. */
typedef struct derive_job {
  const bb_image *in, *vis;
  bb_image *out;
  int count; /* basis vectors used */
  double basis[BB_MAX_BASIS][3];
} derive_job;

static void job_init(derive_job *job, const bb_image *in, const bb_image *vis,
                     bb_image *out, const bb_basis *basis) {
  job->in = in;
  job->vis = vis;
  job->out = out;
  job->count = basis ? basis->count : 0;
  for (int c = 0; c < job->count; c++)
    for (int k = 0; k < 3; k++)
      job->basis[c][k] = basis->vector[c][k];
}

/* The basis a map of `channels` basis channels is derived with: basis
 * itself, whose count must match, or for NULL Half-Life 2's (hl2+z for a
 * fourth channel). */
static bb_status resolve_basis(const bb_basis *basis, int channels, const char *what,
                               bb_basis *out, bb_error *err) {
  if (basis) {
    bb_status st = bb__basis_check(basis, "derive", err);
    if (st != BB_OK)
      return st;
    if (channels >= 0 && channels != basis->count)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "derive: %s has %d basis channels but the basis %s has %d directions",
                      what, channels, basis->name, basis->count);
    *out = *basis;
    return BB_OK;
  }
  if (channels >= 0 && channels != 3 && channels != 4)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "derive: %s has %d basis channels; without a basis, 3 (hl2) or 4 (hl2+z)",
                    what, channels);
  return bb__basis_parse(channels == 4 ? "hl2+z" : "hl2", out, err);
}

/* Runs fn over the rows of job->out on `threads` threads (0 = all cores);
 * frees job->out if that fails. */
static bb_status run_rows(derive_job *job, bb__work_fn fn, int threads, bb_error *err) {
  bb_status st = bb__parallel_for(job->out->height, threads, fn, job, NULL, NULL, err);
  if (st != BB_OK)
    bb_image_free(job->out);
  return st;
}

/* Flat index of the first texel of row y. */
static size_t row_start(const bb_image *img, int y) {
  return (size_t)y * (size_t)img->width;
}

/* One texel of each map, for the rows below and for a bake that derives
 * texels one by one (bb__derive_texel_*): the same operations, so the same
 * bits. */
static inline void weights_texel(const double (*basis)[3], int count, const float *n,
                                 float *out) {
  double w[BB_MAX_BASIS], sum = 0.0;
  for (int c = 0; c < count; c++) {
    double s = saturate(dot3(n, basis[c]));
    w[c] = s * s;
    sum += w[c];
  }
  /* A normal facing away from every direction has no preferred one. */
  for (int c = 0; c < count; c++)
    out[c] = (float)(sum > 0.0 ? w[c] / sum : 1.0 / count);
}

/* v: the basis channels of the texel's visibility (after ao) */
static inline void ssbump_texel(const double (*basis)[3], int count, const float *n,
                                const float *v, float *s) {
  for (int c = 0; c < count; c++)
    s[c] = (float)(max0(dot3(n, basis[c])) * (double)v[c]);
}

static inline void bent_texel(const double (*basis)[3], int count, const float *s,
                              float *o) {
  double b[3] = {0.0, 0.0, 0.0};
  for (int c = 0; c < count; c++)
    for (int k = 0; k < 3; k++)
      b[k] += (double)s[c] * basis[c][k];
  double len = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  /* Fully shadowed: no light direction to bend towards, so report straight up. */
  if (!(len > 0.0)) {
    o[0] = 0.0f, o[1] = 0.0f, o[2] = 1.0f;
    return;
  }
  for (int k = 0; k < 3; k++)
    o[k] = (float)(b[k] / len);
}

void bb__derive_texel_weights(const bb_basis *basis, const float n[3], float *weights) {
  weights_texel(basis->vector, basis->count, n, weights);
}

void bb__derive_texel_ssbump(const bb_basis *basis, const float n[3], const float *vis,
                             float *ssbump) {
  ssbump_texel(basis->vector, basis->count, n, vis + 1, ssbump);
}

void bb__derive_texel_bent(const bb_basis *basis, const float *ssbump, float bent[3]) {
  bent_texel(basis->vector, basis->count, ssbump, bent);
}

static void weights_row(void *user, int y) {
  const derive_job *job = user;
  const bb_image *normals = job->in;
  const size_t first = row_start(normals, y), end = first + (size_t)normals->width;
  for (size_t i = first; i < end; i++)
    weights_texel(job->basis, job->count, normals->pixels + 3 * i,
                  job->out->pixels + (size_t)job->count * i);
}

bb_status bb__derive_weights_all_cores(const bb_image *normals, const bb_basis *basis,
                                      bb_image *out, bb_error *err) {
  /* A caller's normals may hold NaN (a bake's never do: its heights are
   * checked), which would come out as 1 / count in every channel. */
  bb_status st = check_image(normals, "normal", 3, 3, err);
  if (st == BB_OK)
    st = bb__check_finite(normals, 3, "normals", err);
  return st == BB_OK ? bb__derive_weights(normals, basis, 0, out, err) : st;
}

bb_status bb__derive_weights(const bb_image *normals, const bb_basis *basis, int threads,
                             bb_image *out, bb_error *err) {
  bb_status st;
  bb_basis b;
  if ((st = check_image(normals, "normal", 3, 3, err)) != BB_OK)
    return st;
  if ((st = resolve_basis(basis, -1, "weights", &b, err)) != BB_OK)
    return st;
  if ((st = check_output(out, normals, NULL, err)) != BB_OK)
    return st;
  if ((st = bb_image_alloc(out, normals->width, normals->height, b.count, err)) != BB_OK)
    return st;
  derive_job job;
  job_init(&job, normals, NULL, out, &b);
  return run_rows(&job, weights_row, threads, err);
}

static void ssbump_row(void *user, int y) {
  const derive_job *job = user;
  const bb_image *vis = job->vis;
  const int count = job->count;
  const size_t first = row_start(vis, y), end = first + (size_t)vis->width;
  for (size_t i = first; i < end; i++)
    ssbump_texel(job->basis, count, job->in->pixels + 3 * i,
                 vis->pixels + (size_t)vis->channels * i + 1 /* skip ao */,
                 job->out->pixels + (size_t)count * i);
}

bb_status bb__derive_ssbump_all_cores(const bb_image *normals, const bb_image *vis,
                           const bb_basis *basis, bb_image *out, bb_error *err) {
  return bb__derive_ssbump(normals, vis, basis, 0, out, err);
}

bb_status bb__derive_ssbump(const bb_image *normals, const bb_image *vis,
                            const bb_basis *basis, int threads, bb_image *out, bb_error *err) {
  bb_status st;
  bb_basis b;
  if ((st = check_image(normals, "normal", 3, 3, err)) != BB_OK)
    return st;
  if ((st = check_image(vis, "visibility", 4, 1 + BB_MAX_BASIS, err)) != BB_OK)
    return st;
  if ((st = resolve_basis(basis, vis->channels - 1, "visibility", &b, err)) != BB_OK)
    return st;
  if (vis->width != normals->width || vis->height != normals->height)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "derive: visibility is %dx%d but normals are %dx%d", vis->width,
                    vis->height, normals->width, normals->height);
  if ((st = check_output(out, normals, vis, err)) != BB_OK)
    return st;
  if ((st = bb_image_alloc(out, vis->width, vis->height, b.count, err)) != BB_OK)
    return st;
  derive_job job;
  job_init(&job, normals, vis, out, &b);
  return run_rows(&job, ssbump_row, threads, err);
}

/* ssbump of one texel row from its normals (3 floats a texel). */
static void ssbump_of_row(const derive_job *job, const float *normals, int y) {
  const bb_image *vis = job->vis;
  const int count = job->count;
  const size_t first = row_start(vis, y);
  for (int x = 0; x < vis->width; x++)
    ssbump_texel(job->basis, count, normals + 3 * (size_t)x,
                 vis->pixels + (size_t)vis->channels * (first + (size_t)x) + 1,
                 job->out->pixels + (size_t)count * (first + (size_t)x));
}

/* Rows of texels the fused derive computes normals for at a time. */
enum { NORMAL_BAND_ROWS = 16 };

typedef struct fused_job {
  derive_job derive;
  const bb_image *filtered;
  float scale;
  bb_normal_filter filter;
  bb_addressing addressing;
  atomic_int out_of_memory;
} fused_job;

static void fused_band(void *user, int band) {
  fused_job *job = user;
  const int width = job->filtered->width, rows = job->filtered->height;
  const int y0 = band * NORMAL_BAND_ROWS;
  const int y1 = y0 + NORMAL_BAND_ROWS < rows ? y0 + NORMAL_BAND_ROWS : rows;
  float *normals = malloc((size_t)(y1 - y0) * (size_t)width * 3 * sizeof(float));
  if (!normals) {
    atomic_store(&job->out_of_memory, 1);
    return;
  }
  bb__normals_rows(job->filtered, job->scale, job->filter, job->addressing, y0, y1, normals);
  for (int y = y0; y < y1; y++)
    ssbump_of_row(&job->derive, normals + 3 * (size_t)(y - y0) * (size_t)width, y);
  free(normals);
}

bb_status bb__derive_ssbump_from_height(const bb_image *filtered, float height_scale,
                                        bb_normal_filter filter, bb_addressing addressing,
                                        const bb_image *vis, const bb_basis *basis, int threads,
                                        bb_image *out, bb_error *err) {
  bb_status st;
  bb_basis b;
  if ((st = check_image(filtered, "height", 1, 1, err)) != BB_OK)
    return st;
  if ((st = check_image(vis, "visibility", 4, 1 + BB_MAX_BASIS, err)) != BB_OK)
    return st;
  if ((st = resolve_basis(basis, vis->channels - 1, "visibility", &b, err)) != BB_OK)
    return st;
  if (vis->width != filtered->width || vis->height != filtered->height)
    return bb__fail(err, BB_ERR_ARGUMENT, "derive: visibility is %dx%d but the height is %dx%d",
                    vis->width, vis->height, filtered->width, filtered->height);
  if ((st = check_output(out, filtered, vis, err)) != BB_OK)
    return st;
  if ((st = bb_image_alloc(out, vis->width, vis->height, b.count, err)) != BB_OK)
    return st;
  fused_job job = {.filtered = filtered, .scale = height_scale, .filter = filter,
                   .addressing = addressing};
  job_init(&job.derive, NULL, vis, out, &b);
  atomic_init(&job.out_of_memory, 0);
  const int bands = (vis->height + NORMAL_BAND_ROWS - 1) / NORMAL_BAND_ROWS;
  st = bb__parallel_for(bands, threads, fused_band, &job, NULL, NULL, err);
  if (st == BB_OK && atomic_load(&job.out_of_memory))
    st = bb__fail(err, BB_ERR_MEMORY, "derive: out of memory for a band of normals");
  if (st != BB_OK)
    bb_image_free(out);
  return st;
}

static void ao_row(void *user, int y) {
  const derive_job *job = user;
  const bb_image *vis = job->vis;
  const size_t first = row_start(vis, y), end = first + (size_t)vis->width;
  for (size_t i = first; i < end; i++)
    job->out->pixels[i] = vis->pixels[(size_t)vis->channels * i];
}

bb_status bb__derive_ao_all_cores(const bb_image *vis, bb_image *out, bb_error *err) {
  return bb__derive_ao(vis, 0, out, err);
}

bb_status bb__derive_ao(const bb_image *vis, int threads, bb_image *out, bb_error *err) {
  bb_status st;
  if ((st = check_image(vis, "visibility", 1, 64, err)) != BB_OK)
    return st;
  if ((st = check_output(out, vis, NULL, err)) != BB_OK)
    return st;
  if ((st = bb_image_alloc(out, vis->width, vis->height, 1, err)) != BB_OK)
    return st;
  derive_job job;
  job_init(&job, NULL, vis, out, NULL);
  return run_rows(&job, ao_row, threads, err);
}

static void bent_row(void *user, int y) {
  const derive_job *job = user;
  const bb_image *ssbump = job->in;
  const int count = job->count;
  const size_t first = row_start(ssbump, y), end = first + (size_t)ssbump->width;
  for (size_t i = first; i < end; i++)
    bent_texel(job->basis, count, ssbump->pixels + (size_t)count * i,
               job->out->pixels + 3 * i);
}

bb_status bb__derive_bent_all_cores(const bb_image *ssbump, const bb_basis *basis, bb_image *out,
                         bb_error *err) {
  return bb__derive_bent(ssbump, basis, 0, out, err);
}

bb_status bb__derive_bent(const bb_image *ssbump, const bb_basis *basis, int threads,
                          bb_image *out, bb_error *err) {
  bb_status st;
  bb_basis b;
  if ((st = check_image(ssbump, "ssbump", 3, BB_MAX_BASIS, err)) != BB_OK)
    return st;
  if ((st = resolve_basis(basis, ssbump->channels, "ssbump", &b, err)) != BB_OK)
    return st;
  if ((st = check_output(out, ssbump, NULL, err)) != BB_OK)
    return st;
  if ((st = bb_image_alloc(out, ssbump->width, ssbump->height, 3, err)) != BB_OK)
    return st;
  derive_job job;
  job_init(&job, ssbump, NULL, out, &b);
  return run_rows(&job, bent_row, threads, err);
}

/* ---------------------------------------------------------------- grey */

bb_status bb__image_grey(const bb_image *img, int width, int height, const char *what,
                         bb_image *out, bb_error *err) {
  memset(out, 0, sizeof *out);
  if (!img || !img->pixels || img->channels < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s has no pixels", what);
  if (img->width != width || img->height != height)
    return bb__fail(err, BB_ERR_SIZE, "%s is %dx%d, not %dx%d", what, img->width, img->height,
                    width, height);
  bb_status st = bb_image_alloc(out, width, height, 1, err);
  if (st != BB_OK) return st;
  const size_t n = (size_t)width * (size_t)height, c = (size_t)img->channels;
  for (size_t i = 0; i < n; i++) {
    const float *p = img->pixels + i * c;
    const double v = c >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : (double)p[0];
    if (!isfinite(v)) {
      bb_image_free(out);
      return bb__fail(err, BB_ERR_VALUE, "%s is not finite at (%zu, %zu)", what,
                      i % (size_t)width, i / (size_t)width);
    }
    out->pixels[i] = (float)v;
  }
  return BB_OK;
}

/* ---------------------------------------------------------- brightness */

typedef struct brightness_job {
  const bb_image *map, *grey;
  bb_image *out;
  int scaled;   /* channels multiplied */
  int cap_one;  /* 1: a scaled channel holds at most 1, the texel scaled down to keep ratios */
} brightness_job;

static inline void brightness_texel(const float *in, int channels, int scaled,
                                    int cap_one, float grey, float *out) {
  memcpy(out, in, (size_t)channels * sizeof(float));
  double b = (double)grey;
  if (!(b > 0.0))
    b = 0.0;
  double largest = 0.0;
  for (int c = 0; c < scaled; c++)
    largest = fmax(largest, (double)in[c] * b);
  if (cap_one && largest > 1.0)
    b /= largest;
  for (int c = 0; c < scaled; c++)
    out[c] = (float)((double)in[c] * b);
}

void bb__derive_texel_brightness(const float *map, int channels, float grey, float *out) {
  brightness_texel(map, channels, channels, 1, grey, out);
}

static void brightness_row(void *user, int y) {
  const brightness_job *job = user;
  const int channels = job->map->channels;
  const size_t first = row_start(job->map, y), end = first + (size_t)job->map->width;
  for (size_t i = first; i < end; i++)
    brightness_texel(job->map->pixels + i * (size_t)channels, channels, job->scaled,
                     job->cap_one, job->grey->pixels[i],
                     job->out->pixels + i * (size_t)channels);
}

bb_status bb__derive_brightness(const bb_image *map, int scaled, const bb_image *brightness,
                                const char *who, int threads, bb_image *out, bb_error *err) {
  bb_status st = check_image(map, "map", 1, 64, err);
  if (st != BB_OK) return st;
  if ((st = check_output(out, map, brightness, err)) != BB_OK) return st;
  bb_image grey;
  char what[96];
  snprintf(what, sizeof what, "%s: the brightness map", who);
  if ((st = bb__image_grey(brightness, map->width, map->height, what, &grey, err)) != BB_OK)
    return st;
  if ((st = bb_image_alloc(out, map->width, map->height, map->channels, err)) == BB_OK) {
    brightness_job job = {map, &grey, out, scaled < map->channels ? scaled : map->channels, 1};
    st = bb__parallel_for(map->height, threads, brightness_row, &job, NULL, NULL, err);
    if (st != BB_OK) bb_image_free(out);
  }
  bb_image_free(&grey);
  return st;
}
