/* imgstats.c: per-channel mean difference (bias), and mean, 99th-percentile and largest
 * absolute difference of two images.
 *
 *   imgstats A B
 *
 * Reads both with bb_image_read (integer files as value / max code, float
 * files as stored), which must have the same size and channel count. Prints
 * one JSON line on stdout, {"a":..,"b":..,"width":..,"height":..,"channels":
 * [{"mean":..,"mean_abs":..,"p99_abs":..,"max_abs":..},...]}, where mean is
 * the signed mean of A - B, and one human line per
 * channel on stderr. The 99th percentile is the nearest-rank one: the
 * smallest difference that at least 99 % of the texels do not exceed.
 * Exits 1 when a file cannot be read or the images do not match, 2 on a bad
 * command line.
 */
#include "bumpbake.h"
#include "core/internal.h"
#include "core/json.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct channel_stats {
  double mean, mean_abs, p99_abs, max_abs;
} channel_stats;

static int compare_floats(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* Statistics of channel c; scratch holds width*height floats. */
static channel_stats channel_difference(const bb_image *a, const bb_image *b, int c,
                                        float *scratch) {
  const size_t n = (size_t)a->width * (size_t)a->height, stride = (size_t)a->channels;
  double sum = 0.0, signed_sum = 0.0;
  for (size_t i = 0; i < n; i++) {
    signed_sum += (double)a->pixels[i * stride + (size_t)c] - (double)b->pixels[i * stride + (size_t)c];
    const float d =
        fabsf(a->pixels[i * stride + (size_t)c] - b->pixels[i * stride + (size_t)c]);
    /* a NaN on either side counts as an infinite difference, so it shows */
    scratch[i] = isnan(d) ? INFINITY : d;
    sum += scratch[i];
  }
  qsort(scratch, n, sizeof *scratch, compare_floats);
  /* nearest rank: ceil(0.99 n), 1-based */
  size_t rank = (size_t)ceil(0.99 * (double)n);
  channel_stats s = {signed_sum / (double)n, sum / (double)n, scratch[rank > 0 ? rank - 1 : 0],
                     scratch[n - 1]};
  return s;
}

static int read_image(const char *path, bb_image *img) {
  bb_error err = {{0}};
  if (bb_image_read(path, img, NULL, &err) == BB_OK)
    return 0;
  fprintf(stderr, "imgstats: %s\n", err.message);
  return 1;
}

/* Prints the statistics of every channel of two matching images. */
static int report(const char *pa, const char *pb, const bb_image *a, const bb_image *b) {
  float *scratch = malloc((size_t)a->width * (size_t)a->height * sizeof(float));
  if (!scratch) {
    fprintf(stderr, "imgstats: out of memory\n");
    return 1;
  }
  printf("{\"a\":");
  bb__json_quoted(stdout, pa);
  printf(",\"b\":");
  bb__json_quoted(stdout, pb);
  printf(",\"width\":%d,\"height\":%d,\"channels\":[", a->width, a->height);
  for (int c = 0; c < a->channels; c++) {
    channel_stats s = channel_difference(a, b, c, scratch);
    printf("%s{\"mean\":%.6g,\"mean_abs\":%.6g,\"p99_abs\":%.6g,\"max_abs\":%.6g}",
           c ? "," : "", s.mean, s.mean_abs, s.p99_abs, s.max_abs);
    fprintf(stderr,
            "imgstats: %s vs %s channel %d: mean d %+.5f, mean |d| %.5f, p99 |d| %.5f, "
            "max |d| %.5f\n",
            pa, pb, c, s.mean, s.mean_abs, s.p99_abs, s.max_abs);
  }
  printf("]}\n");
  free(scratch);
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: imgstats A B\n");
    return 2;
  }
  bb_image a = {0}, b = {0};
  int rc = read_image(argv[1], &a) || read_image(argv[2], &b);
  if (!rc && (a.width != b.width || a.height != b.height || a.channels != b.channels)) {
    fprintf(stderr, "imgstats: %s is %dx%d with %d channel(s), %s is %dx%d with %d\n",
            argv[1], a.width, a.height, a.channels, argv[2], b.width, b.height,
            b.channels);
    rc = 1;
  }
  if (!rc)
    rc = report(argv[1], argv[2], &a, &b);
  bb_image_free(&a);
  bb_image_free(&b);
  return rc;
}
