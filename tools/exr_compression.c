/* exr_compression.c: what each lossless OpenEXR compression costs and saves
 * on bumpbake's maps, the measurement behind bb__exr_compression's rule
 * (docs/performance.md, "EXR compression").
 *
 *   exr_compression [--threads N] [--runs R] MAP...
 *
 * Each MAP (any image bumpbake reads: the float EXR maps of a bake) is
 * written as half and as float OpenEXR with none, RLE, ZIPS, ZIP at levels
 * 1, 4 (OpenImageIO's default) and 6, and PIZ, through the library's own
 * writer (staged, fsynced, then removed), R times each (default 3), its
 * chunks compressed on N threads (default 1). Prints, per map, depth and
 * compression: the median CPU seconds of the process over the write (every
 * thread's), the median wall seconds, the bytes and their share of the
 * samples' own bytes, and marks the library's choice. The CPU seconds
 * include the half conversion and the copies every compression shares; none
 * is that floor.
 */
#include "bumpbake.h"
#include "image/formats.h"
#include "image/oiio_calls.h"
#include "files/safe_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define MAX_RUNS 9

static double clock_seconds(clockid_t clock) {
  struct timespec ts;
  clock_gettime(clock, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return v[(n - 1) / 2];
}

int main(int argc, char **argv) {
  int threads = 1, runs = 3, first = 1;
  for (; first < argc && argv[first][0] == '-'; first += 2) {
    if (first + 1 >= argc) break;
    if (strcmp(argv[first], "--threads") == 0)
      threads = atoi(argv[first + 1]);
    else if (strcmp(argv[first], "--runs") == 0)
      runs = atoi(argv[first + 1]);
    else
      break;
  }
  if (first >= argc || runs < 1 || runs > MAX_RUNS || threads < 0) {
    fprintf(stderr, "usage: exr_compression [--threads N] [--runs 1..%d] MAP...\n", MAX_RUNS);
    return 2;
  }
  static const char *const compressions[] = {"none", "rle", "zips", "zip:1", "zip", "zip:6",
                                             "piz"};
  const int ncomp = (int)(sizeof compressions / sizeof compressions[0]);
  const char *dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
  char path[512];
  snprintf(path, sizeof path, "%s/bb_exr_compression_%ld.exr", dir, (long)getpid());
  printf("%-24s %-5s %-6s %8s %8s %10s %6s\n", "map", "depth", "comp", "cpu_s", "wall_s", "bytes",
         "share");
  for (int m = first; m < argc; m++) {
    bb_image img;
    bb_error err;
    if (bb_image_read(argv[m], &img, NULL, &err) != BB_OK) {
      fprintf(stderr, "exr_compression: %s\n", err.message);
      return 1;
    }
    const char *name = strrchr(argv[m], '/') ? strrchr(argv[m], '/') + 1 : argv[m];
    for (int d = 0; d < 2; d++) {
      const bb_depth depth = d == 0 ? BB_DEPTH_HALF : BB_DEPTH_FLOAT;
      const double raw = (double)img.width * img.height * img.channels * (d == 0 ? 2 : 4);
      for (int c = 0; c < ncomp; c++) {
        double cpu[MAX_RUNS], wall[MAX_RUNS];
        long long bytes = 0;
        for (int r = 0; r < runs; r++) {
          bb_staged_file f;
          bb__safe_init(&f);
          const double c0 = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
          const double w0 = clock_seconds(CLOCK_MONOTONIC);
          bb_status st = bb__oiio_write_image(path, &img, depth, BB_RANGE_UNIT, NULL, threads,
                                              compressions[c], &f, &err);
          cpu[r] = clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - c0;
          wall[r] = clock_seconds(CLOCK_MONOTONIC) - w0;
          if (st != BB_OK) {
            fprintf(stderr, "exr_compression: %s\n", err.message);
            return 1;
          }
          bytes = (long long)bb__safe_size(&f);
          bb__safe_discard(&f);
        }
        const int chosen = strcmp(compressions[c], bb__exr_compression(depth)) == 0;
        printf("%-24s %-5s %-6s %8.3f %8.3f %10lld %5.1f%%%s\n", name, d == 0 ? "half" : "float",
               compressions[c], median(cpu, runs), median(wall, runs), bytes,
               100.0 * (double)bytes / raw, chosen ? "  <- bumpbake" : "");
      }
    }
    bb_image_free(&img);
  }
  return 0;
}
