/* test_mips.c: mip chains (sizes, box averages, renormalised normals), the
 * paper's claim that the mip of an ssbump lights like the mean of the lit
 * texels, mip-mapped TIFF and EXR files read back level by level, and the
 * direct halving of even sides giving OpenImageIO's box resize's bits. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bumpbake.h"
#include "image/oiio.h"
#include "image/formats.h"
#include "image/image_write.h"
#include "bake/bake_internal.h"

static bb_image noise(int w, int h, int channels, unsigned seed, float lo, float hi) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  unsigned s = seed;
  for (size_t i = 0; i < (size_t)w * (size_t)h * (size_t)channels; i++) {
    s = s * 1664525u + 1013904223u;
    img.pixels[i] = lo + (hi - lo) * (float)(s >> 8) / (float)(1u << 24);
  }
  return img;
}

static bb_image noise_normals(int w, int h, unsigned seed) {
  bb_image n = noise(w, h, 3, seed, -1.0f, 1.0f);
  for (int i = 0; i < w * h; i++) {
    float *t = n.pixels + 3 * i;
    t[2] = fabsf(t[2]) + 0.2f;
    float len = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int k = 0; k < 3; k++)
      t[k] /= len;
  }
  return n;
}

static bb_image *chain(const bb_image *img, bb_mip_filter f, int *count) {
  bb_image *levels = NULL;
  bb_error err;
  cr_assert_eq(bb_mip_chain(img, f, &levels, count, &err), BB_OK, "%s", err.message);
  return levels;
}

/* Mean of the 2 x 2 texels of `up` under texel (x, y) of the next level. */
static double block_mean(const bb_image *up, int x, int y, int c) {
  double sum = 0.0;
  for (int dy = 0; dy < 2; dy++)
    for (int dx = 0; dx < 2; dx++)
      sum += bb_image_texel(up, 2 * x + dx, 2 * y + dy)[c];
  return sum / 4.0;
}

Test(mips, level_sizes) {
  const int sizes[][2] = {{16, 8}, {5, 3}, {1, 7}, {64, 64}};
  const int expected_counts[] = {5, 3, 3, 7};
  for (int s = 0; s < 4; s++) {
    bb_image img = noise(sizes[s][0], sizes[s][1], 2, 1, 0, 1);
    int count = 0;
    bb_image *levels = chain(&img, BB_MIP_AVERAGE, &count);
    cr_assert_eq(count, expected_counts[s], "%dx%d: %d levels", sizes[s][0], sizes[s][1],
                 count);
    int w = sizes[s][0], h = sizes[s][1];
    for (int k = 0; k < count; k++) {
      cr_assert(levels[k].width == w && levels[k].height == h && levels[k].channels == 2,
                "level %d is %dx%d, expected %dx%d", k, levels[k].width, levels[k].height,
                w, h);
      w = w / 2 > 1 ? w / 2 : 1;
      h = h / 2 > 1 ? h / 2 : 1;
    }
    cr_assert_eq(
        memcmp(levels[0].pixels, img.pixels, (size_t)img.width * (size_t)img.height * 2 * sizeof(float)), 0,
        "level 0 is the image");
    bb_mip_chain_free(levels, count);
    bb_image_free(&img);
  }
}

/* ssbump, weights, ao: each texel of a level is the plain mean of the 2 x 2
 * texels above it, so the mean over the image never changes. */
Test(mips, averages_are_box_means) {
  bb_image img = noise(32, 16, 4, 2, 0, 1);
  int count = 0;
  bb_image *levels = chain(&img, BB_MIP_AVERAGE, &count);
  for (int k = 1; k < count; k++)
    for (int y = 0; y < levels[k].height; y++)
      for (int x = 0; x < levels[k].width; x++)
        for (int c = 0; c < 4; c++) {
          if (levels[k - 1].height == 1) /* the last levels of a 2:1 image: 2 x 1 boxes */
            break;
          cr_assert_float_eq(bb_image_texel(&levels[k], x, y)[c],
                             block_mean(&levels[k - 1], x, y, c), 1e-6,
                             "level %d (%d, %d)", k, x, y);
        }
  double mean0 = 0.0;
  for (int i = 0; i < 32 * 16; i++)
    mean0 += img.pixels[4 * i] / (32.0 * 16.0);
  cr_assert_float_eq(bb_image_texel(&levels[count - 1], 0, 0)[0], mean0, 1e-6);
  bb_mip_chain_free(levels, count);
  bb_image_free(&img);
}

Test(mips, normals_are_renormalised_per_level) {
  bb_image n = noise_normals(16, 16, 3);
  int count = 0;
  bb_image *levels = chain(&n, BB_MIP_RENORMALIZE, &count);
  cr_assert_eq(count, 5);
  for (int k = 1; k < count; k++)
    for (int y = 0; y < levels[k].height; y++)
      for (int x = 0; x < levels[k].width; x++) {
        const float *t = bb_image_texel(&levels[k], x, y);
        double m[3], len = 0.0;
        for (int c = 0; c < 3; c++) {
          m[c] = block_mean(&levels[k - 1], x, y, c);
          len += m[c] * m[c];
        }
        len = sqrt(len);
        cr_assert_float_eq(t[0] * t[0] + t[1] * t[1] + t[2] * t[2], 1.0, 2e-6,
                           "unit length");
        for (int c = 0; c < 3; c++)
          cr_assert_float_eq(t[c], m[c] / len, 2e-6, "direction of the 2 x 2 mean");
      }
  bb_mip_chain_free(levels, count);
  bb_image_free(&n);
}

/* Source's static lighting: s_0 L_0 + s_1 L_1 + s_2 L_2 (three lightmap
 * colours), per colour channel. */
static const double LIGHTMAPS[3][3] = {{1.0, 0.3, 0.1}, {0.2, 0.9, 0.4}, {0.1, 0.2, 1.3}};

static void lit(const float *s, double rgb[3]) {
  for (int k = 0; k < 3; k++)
    rgb[k] = s[0] * LIGHTMAPS[0][k] + s[1] * LIGHTMAPS[1][k] + s[2] * LIGHTMAPS[2][k];
}

/* The paper: "no special handling is needed for mip-mapping". A mip texel
 * of an ssbump lights exactly like the mean of its lit texels; a normal
 * map's mip (Source's dp_c = sat(N.B_c)^2 weights) does not. */
Test(mips, mip_of_an_ssbump_lights_like_the_mean_of_the_lit_texels) {
  bb_image ss = noise(16, 16, 3, 4, 0.0f, 0.8f);
  int count = 0;
  bb_image *levels = chain(&ss, BB_MIP_AVERAGE, &count);
  for (int k = 1; k < count; k++)
    for (int y = 0; y < levels[k].height; y++)
      for (int x = 0; x < levels[k].width; x++) {
        double mip[3], mean[3] = {0, 0, 0};
        lit(bb_image_texel(&levels[k], x, y), mip);
        for (int dy = 0; dy < 2; dy++)
          for (int dx = 0; dx < 2; dx++) {
            double one[3];
            lit(bb_image_texel(&levels[k - 1], 2 * x + dx, 2 * y + dy), one);
            for (int c = 0; c < 3; c++)
              mean[c] += one[c] / 4.0;
          }
        for (int c = 0; c < 3; c++)
          cr_assert_float_eq(mip[c], mean[c], 1e-5, "level %d (%d, %d) colour %d", k, x,
                             y, c);
      }
  bb_mip_chain_free(levels, count);

  /* The same for a normal map lit through dp_c: the mean of the lit texels
   * and the lit mean normal part ways. */
  bb_image n = noise_normals(16, 16, 5), w;
  levels = chain(&n, BB_MIP_RENORMALIZE, &count);
  bb_image w1;
  cr_assert_eq(bb__derive_weights_all_cores(&n, NULL, &w, NULL), BB_OK);
  cr_assert_eq(bb__derive_weights_all_cores(&levels[1], NULL, &w1, NULL), BB_OK);
  double worst = 0.0;
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++) {
      /* bb__derive_weights_all_cores normalises by the sum: compare the weight shares. */
      for (int c = 0; c < 3; c++)
        worst = fmax(worst, fabs(bb_image_texel(&w1, x, y)[c] - block_mean(&w, x, y, c)));
    }
  cr_assert_gt(worst, 0.05, "a normal map's mip should not light like its mean (%g)",
               worst);
  bb_image_free(&w);
  bb_image_free(&w1);
  bb_mip_chain_free(levels, count);
  bb_image_free(&n);
  bb_image_free(&ss);
}

static char *temp_path(const char *ext) {
  static char dir[64];
  if (!dir[0]) {
    snprintf(dir, sizeof dir, "/tmp/bb_mips_XXXXXX");
    cr_assert_not_null(mkdtemp(dir));
  }
  static char path[128];
  snprintf(path, sizeof path, "%s/m.%s", dir, ext);
  return path;
}

/* Every level of a written file reads back as the chain held it. */
Test(mips, files_hold_every_level) {
  const struct {
    const char *ext;
    bb_depth depth;
    double tolerance;
  } files[] = {{"tif", BB_DEPTH_8, 0.51 / 255},
               {"tif", BB_DEPTH_16, 0.51 / 65535},
               {"tiff", BB_DEPTH_FLOAT, 0.0},
               {"exr", BB_DEPTH_HALF, 1e-3},
               {"exr", BB_DEPTH_FLOAT, 0.0}};
  bb_image img = noise(20, 12, 3, 6, 0, 1);
  int count = 0;
  bb_image *levels = chain(&img, BB_MIP_AVERAGE, &count);
  for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
    const char *path = temp_path(files[f].ext);
    cr_assert(bb__path_supports_mips(path));
    bb_write_options o = {files[f].depth, BB_RANGE_UNIT, "test=1\n", NULL};
    bb_error err;
    cr_assert_eq(bb__image_write_mips(path, levels, count, &o, &err), BB_OK, "%s",
                 err.message);
    /* bb_image_read sees level 0, with the provenance. */
    bb_image top;
    bb_image_info info;
    cr_assert_eq(bb_image_read(path, &top, &info, &err), BB_OK, "%s", err.message);
    cr_assert(top.width == 20 && top.height == 12);
    cr_assert_str_eq(info.description, "test=1\n");
    bb_image_free(&top);
    bb_image_info_free(&info);
    for (int k = 0; k < count; k++) {
      bb_image got;
      int file_levels = 0;
      cr_assert_eq(bb__image_read_mip(path, k, &got, NULL, &file_levels, &err), BB_OK,
                   "%s", err.message);
      cr_assert_eq(file_levels, count, "%s", path);
      cr_assert(got.width == levels[k].width && got.height == levels[k].height);
      for (size_t i = 0; i < (size_t)got.width * (size_t)got.height * 3; i++)
        cr_assert_float_eq(got.pixels[i], levels[k].pixels[i], files[f].tolerance + 1e-9,
                           "%s level %d sample %zu", path, k, i);
      bb_image_free(&got);
    }
    bb_image extra;
    cr_assert_eq(bb__image_read_mip(path, count, &extra, NULL, NULL, &err),
                 BB_ERR_ARGUMENT);
    cr_assert(strstr(err.message, "no mip level"), "%s", err.message);
    unlink(path);
  }
  bb_mip_chain_free(levels, count);
  bb_image_free(&img);
}

Test(mips, refusals) {
  bb_image img = noise(8, 8, 3, 7, 0, 1);
  int count = 0;
  bb_image *levels = chain(&img, BB_MIP_AVERAGE, &count);
  bb_error err;
  const char *png = temp_path("png");
  cr_assert(!bb__path_supports_mips(png));
  cr_assert_eq(bb__image_write_mips(png, levels, count, NULL, &err), BB_ERR_FORMAT);
  cr_assert(access(png, F_OK) != 0, "no file");
  /* A chain whose levels do not halve is not a mip chain. */
  const char *tif = temp_path("tif");
  bb_image swapped = levels[1];
  levels[1] = levels[2];
  cr_assert_eq(bb__image_write_mips(tif, levels, count, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "mip level 1"), "%s", err.message);
  cr_assert(access(tif, F_OK) != 0, "no file");
  levels[2] = levels[1];
  levels[1] = swapped;
  bb_image grey = noise(4, 4, 1, 8, 0, 1), *out = NULL;
  int n = 0;
  cr_assert_eq(bb_mip_chain(&grey, BB_MIP_RENORMALIZE, &out, &n, &err), BB_ERR_ARGUMENT);
  grey.pixels[3] = NAN;
  cr_assert_eq(bb_mip_chain(&grey, BB_MIP_AVERAGE, &out, &n, &err), BB_ERR_VALUE);
  cr_assert_null(out);
  bb_image_free(&grey);
  bb_mip_chain_free(levels, count);
  bb_image_free(&img);
}

Test(mips, even_levels_have_the_bits_of_openimageios_box_resize) {
  /* bb_mip_chain halves a level with even sides itself (mips.c): each
   * level must hold the bits OpenImageIO's box resize gives from the one
   * above, on values of every sign and size (some tiny, some large). */
  const int channels[3] = {1, 3, 4};
  for (int k = 0; k < 3; k++) {
    bb_image img = noise(96, 64, channels[k], 7u + (unsigned)k, -3.0f, 3.0f);
    const size_t n = (size_t)96 * 64 * (size_t)channels[k];
    for (size_t i = 0; i < n; i += 7)
      img.pixels[i] *= i % 3 == 0 ? 1e6f : i % 3 == 1 ? 1e-30f : 1e-40f; /* 1e-40: subnormal */
    bb_image *levels = NULL;
    int count = 0;
    cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &levels, &count, NULL), BB_OK);
    cr_assert_eq(count, 7); /* 96 x 64 .. 6 x 4, 3 x 2; then 1 x 1 from odd 3 x 2 */
    for (int l = 1; l < count; l++) {
      const bb_image *up = &levels[l - 1];
      bb_image oiio;
      cr_assert_eq(bb__image_resize_box(up, levels[l].width, levels[l].height, &oiio, NULL),
                   BB_OK);
      const size_t bytes = (size_t)oiio.width * (size_t)oiio.height *
                           (size_t)oiio.channels * sizeof(float);
      cr_assert_eq(memcmp(oiio.pixels, levels[l].pixels, bytes), 0,
                   "%d channels, level %d (%d x %d)", channels[k], l, oiio.width,
                   oiio.height);
      bb_image_free(&oiio);
    }
    bb_mip_chain_free(levels, count);
    bb_image_free(&img);
  }
}

/* The texture writer's chain: the map itself its top level (not a copy),
 * the levels below the bits of bb_mip_chain's on any thread count (bands
 * of rows on threads), an odd side included (OpenImageIO's resize there). */
Test(mips, borrowed_chain_on_threads_has_the_bits_of_the_copied_one) {
  const int sizes[][2] = {{256, 128}, {96, 200}, {8, 1}};
  for (int s = 0; s < 3; s++)
    for (int normal = 0; normal <= 1; normal++) {
      bb_image img = normal ? noise_normals(sizes[s][0], sizes[s][1], 11u + (unsigned)s)
                            : noise(sizes[s][0], sizes[s][1], 4, 5u + (unsigned)s, -0.5f, 1.5f);
      const bb_mip_filter f = normal ? BB_MIP_RENORMALIZE : BB_MIP_AVERAGE;
      int count = 0;
      bb_image *want = chain(&img, f, &count);
      for (int threads = 1; threads <= 3; threads++) {
        bb_image *got = NULL;
        int n = 0;
        bb_error err = {{0}};
        cr_assert_eq(bb__mip_chain_borrowed(&img, f, threads, &got, &n, &err), BB_OK, "%s",
                     err.message);
        cr_assert_eq(n, count);
        cr_assert(got[0].pixels == img.pixels, "level 0 is the map itself");
        for (int k = 1; k < n; k++) {
          const size_t bytes = (size_t)got[k].width * (size_t)got[k].height *
                               (size_t)got[k].channels * sizeof(float);
          cr_assert(got[k].width == want[k].width && got[k].height == want[k].height &&
                        memcmp(got[k].pixels, want[k].pixels, bytes) == 0,
                    "%d x %d, normal %d, %d threads: level %d differs", sizes[s][0],
                    sizes[s][1], normal, threads, k);
        }
        bb__mip_chain_borrowed_free(got, n);
      }
      bb_mip_chain_free(want, count);
      bb_image_free(&img);
    }
}
