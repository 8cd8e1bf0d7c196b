/* smooth.c: Valve's tileable bilateral filter of a height field (docs/conventions.md
 * "Smoothing").
 *
 * Invariant: every output texel is the sum over the same cut kernel, taken in
 * the same fixed order, of values read at fixed offsets from it. So the
 * result does not depend on the thread count, and a periodic shift of the
 * input shifts the output bit for bit.
 */

#include "bake/bake_internal.h"
#include "core/internal.h"
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#include <stdint.h>
#endif

/* Kernel entries whose spatial weight is below this fraction of the centre
 * weight (1) are dropped: the result is the same to float precision. */
#define CUT_FRACTION 1e-7

/* A radius beyond the largest image side has no meaning and would make the
 * kernel needlessly large. */
#define MAX_RADIUS BB_MAX_DIMENSION

/* Largest cut reach: sqrt(2 * MAX_RADIUS * 0.033 * ln(1e7)) = 264.2. */
#define MAX_REACH 265

/* Most channels bb_image_alloc accepts; sizes the per-texel accumulator. */
#define MAX_CHANNELS 64

void bb__smooth_options_init(bb_smooth_options *o) {
  o->radius_texels = 10;
  o->threshold = 2.0f / 255.0f;
  o->addressing = BB_ADDRESS_PERIODIC;
}

typedef struct kernel_tap {
  int dx, dy;    /* offset from the centre texel */
  double weight; /* spatial term g */
} kernel_tap;

typedef struct cut_kernel {
  kernel_tap *taps; /* row-major over dy then dx: the fixed summation order */
  int count;
  int reach; /* max |dx|, |dy| of any tap */
} cut_kernel;

/* Spatial weight g = exp(-(ix^2 + iy^2) / (2 * R * 0.033)), Valve's constant. */
static double spatial_weight(int dx, int dy, int radius) {
  double d2 = (double)dx * dx + (double)dy * dy;
  return exp(-d2 / (2.0 * radius * 0.033));
}

/* Largest |d| along an axis whose weight survives the cut (<= radius). */
static int cut_reach(int radius) {
  int reach = 0;
  while (reach < radius && spatial_weight(reach + 1, 0, radius) >= CUT_FRACTION)
    reach++;
  return reach;
}

static bb_status kernel_make(int radius, cut_kernel *k, bb_error *err) {
  k->reach = cut_reach(radius);
  assert(k->reach <= MAX_REACH);
  int side = 2 * k->reach + 1;
  k->taps = malloc((size_t)side * (size_t)side * sizeof *k->taps);
  if (!k->taps)
    return bb__fail(err, BB_ERR_MEMORY, "cannot allocate the filter kernel");
  k->count = 0;
  for (int dy = -k->reach; dy <= k->reach; dy++)
    for (int dx = -k->reach; dx <= k->reach; dx++) {
      double g = spatial_weight(dx, dy, radius);
      if (g < CUT_FRACTION)
        continue;
      k->taps[k->count++] = (kernel_tap){dx, dy, g};
    }
  return BB_OK;
}

typedef struct smooth_job {
  const bb_image *in;
  const bb_image *guide;
  bb_image *out;
  const cut_kernel *kernel;
  double threshold;
  bb_addressing addressing;
  /* Addressed column index of x + dx for x + dx in -reach .. width+reach-1,
   * stored at [x + dx + reach], so the inner loop does no modulo. */
  const int *column;
} smooth_job;

/* One texel: the taps in their fixed order; row[] holds the offset of the
 * first texel of each kernel row (dy = -reach .. reach) in the image. */
static void smooth_texel(const smooth_job *job, const size_t *row, int x, double centre,
                         float *out) {
  const bb_image *in = job->in;
  const int channels = in->channels;
  const size_t in_stride = (size_t)channels, guide_stride = (size_t)job->guide->channels;
  const cut_kernel *k = job->kernel;
  const int *column = job->column + x + k->reach;
  double acc[MAX_CHANNELS];
  double weight_sum = 0.0;
  memset(acc, 0, (size_t)channels * sizeof acc[0]);
  for (int t = 0; t < k->count; t++) {
    const kernel_tap *tap = &k->taps[t];
    size_t texel = row[tap->dy + k->reach] + (size_t)column[tap->dx];
    double h = (double)job->guide->pixels[texel * guide_stride];
    /* s = max(0, ...) without a branch: a zero weight adds exactly 0. */
    double w = fmax(0.0, 1.0 - fabs(h - centre) / job->threshold) * tap->weight;
    const float *q = in->pixels + texel * in_stride;
    for (int c = 0; c < channels; c++)
      acc[c] += w * (double)q[c];
    weight_sum += w;
  }
  /* The centre tap has s = g = 1, so weight_sum >= 1. */
  for (int c = 0; c < channels; c++)
    out[c] = (float)(acc[c] / weight_sum);
}

#if defined(__SSE2__)
/* 8 texels x .. x+7 of a 1-channel image and guide, all at least `reach` from
 * the left and right sides, so every tap reads the plain columns x + b + dx
 * (the column table is the identity there in both addressing modes).
 *
 * Each texel is one lane of a packed SSE2 double and gets exactly
 * smooth_texel's operations in smooth_texel's order (IEEE double add, sub,
 * mul, div and the float conversions round the same packed as scalar), so
 * the bits are the same. What changes is that eight independent sums run at
 * once, two to a division, instead of one serial chain through a call to
 * fmax per tap. SSE2 is part of x86-64; other targets take the scalar path.
 * (Plain C with lane arrays is not vectorised by GCC 12: the max becomes a
 * branch.) */
#define BLOCK 8

/* Two neighbouring floats widened to doubles, exactly as (double)p[0], (double)p[1]. */
static inline __m128d load2(const float *p) {
  return _mm_cvtps_pd(
      _mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(const void *)p)));
}

static void smooth_block_1(const smooth_job *job, const size_t *row, int x, float *out) {
  const cut_kernel *k = job->kernel;
  const float *in = job->in->pixels + x, *guide = job->guide->pixels + x;
  const __m128d one = _mm_set1_pd(1.0), zero = _mm_setzero_pd(),
                threshold = _mm_set1_pd(job->threshold),
                abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX));
  __m128d centre[BLOCK / 2], acc[BLOCK / 2], weight_sum[BLOCK / 2];
  for (int v = 0; v < BLOCK / 2; v++) {
    centre[v] = load2(guide + row[k->reach] + 2 * v);
    acc[v] = weight_sum[v] = zero;
  }
  for (int t = 0; t < k->count; t++) {
    const kernel_tap *tap = &k->taps[t];
    /* Signed: dx < 0 on row 0 gives a negative offset, but x + dx >= 0. */
    const ptrdiff_t texel = (ptrdiff_t)row[tap->dy + k->reach] + tap->dx;
    const __m128d g = _mm_set1_pd(tap->weight);
    for (int v = 0; v < BLOCK / 2; v++) {
      __m128d h = load2(guide + texel + 2 * v), q = load2(in + texel + 2 * v);
      __m128d s = _mm_sub_pd(
          one, _mm_div_pd(_mm_and_pd(_mm_sub_pd(h, centre[v]), abs_mask), threshold));
      /* fmax(0.0, s): s where s >= 0 (-0 and all), else +0 (NaN too). */
      __m128d w = _mm_mul_pd(_mm_and_pd(_mm_cmpge_pd(s, zero), s), g);
      acc[v] = _mm_add_pd(acc[v], _mm_mul_pd(w, q));
      weight_sum[v] = _mm_add_pd(weight_sum[v], w);
    }
  }
  for (int v = 0; v < BLOCK / 2; v++) {
    __m128 r = _mm_cvtpd_ps(_mm_div_pd(acc[v], weight_sum[v]));
    _mm_storel_pi((__m64 *)(out + 2 * v), r);
  }
}
#endif

static void smooth_row(void *user, int y) {
  const smooth_job *job = user;
  const bb_image *in = job->in;
  const int reach = job->kernel->reach, width = in->width;
  size_t row[2 * (MAX_REACH) + 1];
  for (int dy = -reach; dy <= reach; dy++)
    row[dy + reach] =
        (size_t)bb__address(y + dy, in->height, job->addressing) * (size_t)width;
  const float *guide_row = job->guide->pixels + row[reach] * (size_t)job->guide->channels;
  float *out_row = job->out->pixels + row[reach] * (size_t)in->channels;
  /* Blocks where every tap is inside the row; texels near the sides (and
   * images with several channels) take the general per-texel path. */
  int x = 0;
#if defined(__SSE2__)
  if (in->channels == 1 && job->guide->channels == 1) {
    for (; x < reach && x < width; x++)
      smooth_texel(job, row, x, (double)guide_row[x], out_row + x);
    for (; x + BLOCK - 1 + reach < width; x += BLOCK)
      smooth_block_1(job, row, x, out_row + x);
  }
#endif
  for (; x < width; x++)
    smooth_texel(job, row, x, (double)guide_row[(size_t)x * (size_t)job->guide->channels],
                 out_row + (size_t)x * (size_t)in->channels);
}

static bb_status check_arguments(const bb_image *in, const bb_image *guide,
                                 const bb_smooth_options *o, const bb_image *out,
                                 bb_error *err) {
  if (!in || !guide || !o || !out || !in->pixels || !guide->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: missing image or options");
  if (out == in || out == guide)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: the output must be a separate image");
  if (o->radius_texels < 0 || o->radius_texels > MAX_RADIUS)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: filter radius %d is outside 0..%d",
                    o->radius_texels, MAX_RADIUS);
  if (!(o->threshold > 0.0f)) /* also rejects NaN */
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: filter threshold %g must be > 0",
                    (double)o->threshold);
  if (o->addressing != BB_ADDRESS_PERIODIC && o->addressing != BB_ADDRESS_CLAMP)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: unknown addressing mode %d",
                    (int)o->addressing);
  if (in->channels < 1 || in->channels > MAX_CHANNELS || guide->channels < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: unsupported channel count %d",
                    in->channels);
  if (guide->width != in->width || guide->height != in->height)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: guide is %dx%d but the input is %dx%d",
                    guide->width, guide->height, in->width, in->height);
  return BB_OK;
}

/* A NaN guide height would give the centre tap s = NaN and poison the sums. */
static bb_status check_guide_finite(const bb_image *guide, bb_error *err) {
  if (bb__image_all_finite(guide))
    return BB_OK;
  for (int y = 0; y < guide->height; y++)
    for (int x = 0; x < guide->width; x++)
      if (!isfinite(*bb_image_texel(guide, x, y)))
        return bb__fail(err, BB_ERR_VALUE,
                        "smooth: guide height at (%d, %d) is not finite", x, y);
  return BB_OK;
}

/* The cut kernel of o's radius and the table of addressed columns for an
 * image of in's width (smooth_job.column); free both when done. */
static bb_status smoother_make(const bb_image *in, const bb_smooth_options *o,
                               cut_kernel *kernel, int **column, bb_error *err) {
  bb_status st = kernel_make(o->radius_texels, kernel, err);
  if (st != BB_OK)
    return st;
  *column = malloc((size_t)(in->width + 2 * kernel->reach) * sizeof **column);
  if (!*column) {
    free(kernel->taps);
    return bb__fail(err, BB_ERR_MEMORY, "smooth: cannot allocate the column table");
  }
  for (int i = 0; i < in->width + 2 * kernel->reach; i++)
    (*column)[i] = bb__address(i - kernel->reach, in->width, o->addressing);
  return BB_OK;
}

static bb_status copy_image(const bb_image *in, bb_image *out, bb_error *err) {
  bb_status st = bb_image_alloc(out, in->width, in->height, in->channels, err);
  if (st != BB_OK)
    return st;
  size_t count = (size_t)in->width * (size_t)in->height * (size_t)in->channels;
  memcpy(out->pixels, in->pixels, count * sizeof(float));
  return BB_OK;
}

bb_status bb__smooth_bilateral_all_cores(const bb_image *in, const bb_image *guide,
                              const bb_smooth_options *o, bb_image *out, bb_error *err) {
  return bb__smooth_bilateral(in, guide, o, 0, NULL, out, err);
}

bb_status bb__smooth_bilateral(const bb_image *in, const bb_image *guide,
                               const bb_smooth_options *o, int threads,
                               const bb__checkpoint *checkpoint, bb_image *out, bb_error *err) {
  bb_status st = check_arguments(in, guide, o, out, err);
  if (st != BB_OK)
    return st;
  if (o->radius_texels == 0)
    return copy_image(in, out, err);
  if ((st = check_guide_finite(guide, err)) != BB_OK)
    return st;

  cut_kernel kernel;
  int *column = NULL;
  if ((st = smoother_make(in, o, &kernel, &column, err)) != BB_OK)
    return st;

  st = bb_image_alloc(out, in->width, in->height, in->channels, err);
  if (st == BB_OK) {
    smooth_job job = {in,    guide, out, &kernel, (double)o->threshold, o->addressing,
                      column};
    st = bb__parallel_for_checked(in->height, threads, smooth_row, &job, checkpoint, err);
    if (st != BB_OK)
      bb_image_free(out);
  }
  free(column);
  free(kernel.taps);
  return st;
}

/* ------------------------------------------------------------- regions */

typedef struct region_job {
  smooth_job smooth;
  int x0, y0, width; /* the rectangle's left column and top row (addressed), its width */
} region_job;

/* Row `item` of the rectangle: its texels one by one, smooth_texel's sum,
 * which the blocks of a whole row reproduce bit for bit. */
static void smooth_region_row(void *user, int item) {
  const region_job *job = user;
  const bb_image *in = job->smooth.in;
  const int reach = job->smooth.kernel->reach, w = in->width;
  const int y = bb__address(job->y0 + item, in->height, job->smooth.addressing);
  size_t row[2 * (MAX_REACH) + 1];
  for (int dy = -reach; dy <= reach; dy++)
    row[dy + reach] =
        (size_t)bb__address(y + dy, in->height, job->smooth.addressing) * (size_t)w;
  const size_t guide_stride = (size_t)job->smooth.guide->channels;
  for (int i = 0; i < job->width; i++) {
    const int x = bb__address(job->x0 + i, w, job->smooth.addressing);
    const size_t texel = (size_t)y * (size_t)w + (size_t)x; /* row[reach] + x */
    smooth_texel(&job->smooth, row, x,
                 (double)job->smooth.guide->pixels[texel * guide_stride],
                 job->smooth.out->pixels + texel * (size_t)in->channels);
  }
}

bb_status bb__smooth_region(const bb_image *in, const bb_image *guide,
                            const bb_smooth_options *o, int x0, int y0, int width,
                            int height, int threads, bb_image *out, bb_error *err) {
  bb_status st = check_arguments(in, guide, o, out, err);
  if (st != BB_OK)
    return st;
  if (!out->pixels || out->width != in->width || out->height != in->height ||
      out->channels != in->channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "smooth: the output must be the input's size");
  if (width > in->width)
    width = in->width;
  if (height > in->height)
    height = in->height;
  if (o->radius_texels == 0) {
    for (int j = 0; j < height; j++)
      for (int i = 0; i < width; i++) {
        const size_t t =
            (size_t)bb__address(y0 + j, in->height, o->addressing) * (size_t)in->width +
            (size_t)bb__address(x0 + i, in->width, o->addressing);
        memcpy(out->pixels + t * (size_t)in->channels,
               in->pixels + t * (size_t)in->channels,
               (size_t)in->channels * sizeof(float));
      }
    return BB_OK;
  }
  cut_kernel kernel;
  int *column = NULL;
  if ((st = smoother_make(in, o, &kernel, &column, err)) != BB_OK)
    return st;
  region_job job = {
      {in, guide, out, &kernel, (double)o->threshold, o->addressing, column},
      x0,
      y0,
      width};
  st = bb__parallel_for(height, threads, smooth_region_row, &job, NULL, NULL, err);
  free(column);
  free(kernel.taps);
  return st;
}

int bb__smooth_reach(int radius_texels) {
  return radius_texels > 0 ? cut_reach(radius_texels) : 0;
}
