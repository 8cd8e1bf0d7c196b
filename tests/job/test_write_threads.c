/* test_write_threads.c: a set of outputs written by bb_outputs_write is the
 * same bytes on 1, 2 and 3 threads, whatever encodes each file on more than
 * one (an engine texture's blocks, an OpenEXR file's chunks on
 * image/exr_pool.h's workers, several PNGs side by side); and OpenEXR files
 * carry the compression chosen for their depth (PIZ for half, none for
 * float: docs/performance.md), with the pixels the image had. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */
#define _DEFAULT_SOURCE   /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "file_bytes.h"
#include "job/job_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

TestSuite(write_threads, .init = harness_setup, .fini = harness_teardown, .timeout = 120);

/* 256 x 256 texels of waves and a little hash noise, so that every chunk
 * and block differs and compresses differently; channels 1 or 3; signed
 * (a unit normal field) or in [0, 1]. */
static bb_image map(int channels, int normal) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 256, 256, channels, NULL), BB_OK);
  for (int y = 0; y < 256; y++)
    for (int x = 0; x < 256; x++) {
      float *t = img.pixels + ((size_t)y * 256 + (size_t)x) * (size_t)channels;
      const unsigned h = ((unsigned)x * 73856093u) ^ ((unsigned)y * 19349663u);
      const double noise = (double)(h % 1000u) / 1000.0 - 0.5;
      if (normal) {
        double n[3] = {0.5 * sin(0.05 * x) + 0.05 * noise, 0.4 * cos(0.07 * y), 1.0};
        const double len = sqrt(n[0] * n[0] + n[1] * n[1] + 1.0);
        for (int c = 0; c < 3; c++)
          t[c] = (float)(n[c] / len);
      } else {
        for (int c = 0; c < channels; c++)
          t[c] = (float)(0.5 + 0.4 * sin(0.03 * x * (c + 1) + 0.05 * y) + 0.08 * noise);
      }
    }
  return img;
}

/* The value of an OpenEXR file's "compression" attribute (0 none, 1 RLE, 2
 * ZIPS, 3 ZIP, 4 PIZ), from its header: name, type name, size 1, value. */
static int exr_compression(const unsigned char *file, size_t size) {
  static const char attr[] = "compression\0compression";
  for (size_t i = 8; i + sizeof attr + 5 <= size; i++)
    if (memcmp(file + i, attr, sizeof attr) == 0)
      return file[i + sizeof attr + 4];
  return -1;
}

Test(write_threads, same_bytes_on_any_thread_count) {
  bb_image ss = map(3, 0), ao = map(1, 0), nm = map(3, 1);
  bb_texture_options vtf, dds;
  bb_texture_options_init(&vtf);
  bb_texture_options_init(&dds);
  dds.format = BB_TEXTURE_FORMAT_BC1;
  const char *description = "bumpbake_version=test\nscale=1";
  enum { FILES = 10 };
  const struct {
    const char *name, *kind;
    const bb_image *image;
    bb_range range;
    bb_depth depth;
    int mips;
    const bb_texture_options *texture;
  } set[FILES] = {
      {"ss.png", "ssbump", &ss, BB_RANGE_UNIT, BB_DEPTH_8, 0, NULL},
      {"ss16.png", "ssbump", &ss, BB_RANGE_UNIT, BB_DEPTH_16, 0, NULL},
      {"n.png", "normal", &nm, BB_RANGE_SIGNED, BB_DEPTH_8, 0, NULL},
      {"ssh.exr", "ssbump", &ss, BB_RANGE_UNIT, BB_DEPTH_HALF, 0, NULL},
      {"ssf.exr", "ssbump", &ss, BB_RANGE_UNIT, BB_DEPTH_FLOAT, 0, NULL},
      {"aoh.exr", "ao", &ao, BB_RANGE_UNIT, BB_DEPTH_HALF, 1, NULL},
      {"nf.exr", "normal", &nm, BB_RANGE_SIGNED, BB_DEPTH_FLOAT, 1, NULL},
      {"ss.vtf", "ssbump", &ss, BB_RANGE_UNIT, BB_DEPTH_DEFAULT, 0, &vtf},
      {"ss.dds", "ssbump", &ss, BB_RANGE_UNIT, BB_DEPTH_DEFAULT, 0, &dds},
      {"n.dds", "normal", &nm, BB_RANGE_SIGNED, BB_DEPTH_DEFAULT, 0, NULL},
  };
  unsigned char *first[FILES] = {0};
  size_t first_size[FILES] = {0};
  for (int threads = 1; threads <= 3; threads++) {
    char sub[16];
    snprintf(sub, sizeof sub, "t%d", threads);
    cr_assert_eq(bb__directory_create(tmp(sub), NULL), BB_OK);
    bb_output_file files[FILES];
    const char *paths[FILES];
    for (int i = 0; i < FILES; i++) {
      char name[64];
      snprintf(name, sizeof name, "%s/%s", sub, set[i].name);
      paths[i] = tmp(name);
      files[i] = (bb_output_file){paths[i],     set[i].kind, set[i].image, set[i].range,
                                  set[i].depth, set[i].mips, description,  NULL,
                                  0,            set[i].texture};
    }
    bb_error err = {{0}};
    cr_assert_eq(bb_outputs_write(files, FILES, threads, &err), BB_OK, "%s", err.message);
    for (int i = 0; i < FILES; i++) {
      size_t size;
      unsigned char *bytes = file_bytes(paths[i], &size);
      if (threads == 1) {
        first[i] = bytes, first_size[i] = size;
        continue;
      }
      cr_assert(size == first_size[i] && memcmp(bytes, first[i], size) == 0,
                "%s differs on %d threads from 1", set[i].name, threads);
      free(bytes);
    }
  }
  /* The compressions, and the pixels back: float exactly, half to half's
   * precision (a relative 2^-11). */
  for (int i = 0; i < FILES; i++) {
    const char *dot = strrchr(set[i].name, '.');
    if (strcmp(dot, ".exr") == 0) {
      const int want = set[i].depth == BB_DEPTH_HALF ? 4 : 0;
      cr_expect_eq(exr_compression(first[i], first_size[i]), want, "%s", set[i].name);
      char name[64];
      snprintf(name, sizeof name, "t2/%s", set[i].name);
      bb_image back = harness_read(tmp(name), NULL);
      const double worst = harness_max_difference(&back, set[i].image);
      cr_expect_leq(worst, set[i].depth == BB_DEPTH_HALF ? 1.0 / 2048 : 0.0, "%s: %g",
                    set[i].name, worst);
      bb_image_free(&back);
    }
    free(first[i]);
  }
  bb_image_free(&ss);
  bb_image_free(&ao);
  bb_image_free(&nm);
}
