/* compare.c: channel-by-channel statistics of the difference of two images. */
#include "core/internal.h"
#include "maps/maps_internal.h"

#include <math.h>
#include <string.h>

/* Difference of one channel value. Equal values (including equal infinities,
 * whose subtraction would give NaN) and two NaNs differ by 0, so an image
 * compares equal to itself as idiff finds it; a NaN against a number is the
 * worst possible difference, so a NaN can never hide under a threshold
 * (idiff's comparisons, false for NaN, let it pass). */
static double channel_difference(float a, float b) {
  if (a == b || (isnan(a) && isnan(b)))
    return 0.0;
  if (isnan(a) || isnan(b))
    return INFINITY;
  return fabs((double)a - (double)b);
}

static int same_shape(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels;
}

static bb_status check_inputs(const bb_image *a, const bb_image *b, bb_error *err) {
  if (!a || !b || !a->pixels || !b->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: an image has no pixels");
  if (a->width <= 0 || a->height <= 0 || a->channels <= 0)
    return bb__fail(err, BB_ERR_SIZE, "compare: empty image %dx%dx%d", a->width,
                    a->height, a->channels);
  if (!same_shape(a, b))
    return bb__fail(err, BB_ERR_SIZE,
                    "compare: images differ in size or channels: %dx%d, %d channels vs "
                    "%dx%d, %d channels",
                    a->width, a->height, a->channels, b->width, b->height, b->channels);
  return BB_OK;
}

bb_status bb__compare_images(const bb_image *a, const bb_image *b, double fail_threshold,
                            double warn_threshold, bb_compare_stats *stats,
                            bb_image *diff, bb_error *err) {
  bb_status st = check_inputs(a, b, err);
  if (st != BB_OK)
    return st;
  if (!stats)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: stats is NULL");
  if (isnan(fail_threshold) || isnan(warn_threshold))
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: threshold is NaN");
  if (diff) {
    st = bb_image_alloc(diff, a->width, a->height, a->channels, err);
    if (st != BB_OK)
      return st;
  }

  memset(stats, 0, sizeof *stats);
  const int channels = a->channels;
  const size_t pixels = (size_t)a->width * (size_t)a->height;
  /* Sums in double: a 8192^2 x 4 image has 2^28 terms, far past what float
   * accumulation can add without losing the small differences. */
  double sum = 0.0, sum_squares = 0.0, max_abs = 0.0;
  size_t worst_index = 0;
  int worst_channel = 0;
  long over_fail = 0, over_warn = 0;

  for (size_t p = 0; p < pixels; p++) {
    const float *pa = a->pixels + p * (size_t)channels;
    const float *pb = b->pixels + p * (size_t)channels;
    double pixel_max = 0.0;
    for (int c = 0; c < channels; c++) {
      double d = channel_difference(pa[c], pb[c]);
      sum += d;
      sum_squares += d * d;
      if (d > max_abs) { /* strict: the first worst value in scan order wins */
        max_abs = d;
        worst_index = p;
        worst_channel = c;
      }
      if (d > pixel_max)
        pixel_max = d;
      if (diff)
        diff->pixels[p * (size_t)channels + (size_t)c] = (float)d;
    }
    /* A pixel is over a threshold when its worst channel is. */
    if (pixel_max > fail_threshold)
      over_fail++;
    if (pixel_max > warn_threshold)
      over_warn++;
  }

  const double values = (double)pixels * (double)channels;
  stats->mean_abs = sum / values;
  stats->rms = sqrt(sum_squares / values);
  stats->max_abs = max_abs;
  stats->worst_x = (int)(worst_index % (size_t)a->width);
  stats->worst_y = (int)(worst_index / (size_t)a->width);
  stats->worst_channel = worst_channel;
  stats->pixels = (long)pixels;
  stats->over_fail = over_fail;
  stats->over_warn = over_warn;
  return BB_OK;
}

void bb__compare_limits_init(bb_compare_limits *limits) {
  limits->fail = 1e-6; /* idiff's defaults */
  limits->fail_percent = 0.0;
  limits->hard_fail = INFINITY;
  limits->allow_failures = 0;
  limits->warn = 1e-6;
  limits->warn_percent = 0.0;
  limits->hard_warn = INFINITY;
}

const bb__range bb__range_compare_threshold = {"threshold", 0.0, HUGE_VAL, 0, 0};
const bb__range bb__range_compare_percent = {"percent", 0.0, 100.0, 0, 0};
const bb__range bb__range_compare_count = {"count", 0.0, HUGE_VAL, 0, 1};

bb_status bb__compare_limits_check(const bb_compare_limits *l, bb_error *err) {
  if (!l)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: no limits");
  const struct {
    const char *who;
    double value;
    const bb__range *range;
  } checks[] = {{"compare: fail", l->fail, &bb__range_compare_threshold},
                {"compare: failpercent", l->fail_percent, &bb__range_compare_percent},
                {"compare: hardfail", l->hard_fail, &bb__range_compare_threshold},
                {"compare: allowfailures", (double)l->allow_failures, &bb__range_compare_count},
                {"compare: warn", l->warn, &bb__range_compare_threshold},
                {"compare: warnpercent", l->warn_percent, &bb__range_compare_percent},
                {"compare: hardwarn", l->hard_warn, &bb__range_compare_threshold}};
  bb_status st = BB_OK;
  for (size_t i = 0; i < sizeof checks / sizeof checks[0] && st == BB_OK; i++)
    st = bb__range_check(checks[i].range, checks[i].value, checks[i].who, err);
  return st;
}

bb_compare_verdict bb__compare_judge(const bb_compare_stats *s,
                                    const bb_compare_limits *l) {
  /* The order is idiff's: allowed failures pass before anything else is
   * looked at, so a CI script gets the exit code idiff would give. */
  const double pixels = (double)s->pixels;
  if (s->over_fail <= l->allow_failures)
    return BB_COMPARE_PASS;
  if ((double)s->over_fail > l->fail_percent / 100.0 * pixels || s->max_abs > l->hard_fail)
    return BB_COMPARE_FAIL;
  if ((double)s->over_warn > l->warn_percent / 100.0 * pixels || s->max_abs > l->hard_warn)
    return BB_COMPARE_WARN;
  return BB_COMPARE_PASS;
}
