/* test_image_files.c: image file reading and writing (src/image/) against real files. */
#include <criterion/criterion.h>

#include "bumpbake.h"
#include "hostile_tiff.h"
#include "files/safe_file.h"
#include "image/formats.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "image/oiio_module.h"
#include "mesh/mesh_internal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* ------------------------------------------------------------- fixtures */

static char tmpdir[256];

static void remove_tree(const char *path) {
  struct stat st;
  if (lstat(path, &st) != 0) return;
  if (S_ISDIR(st.st_mode)) {
    chmod(path, 0700);
    DIR *d = opendir(path);
    if (d) {
      struct dirent *e;
      while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        char child[1024];
        snprintf(child, sizeof child, "%s/%s", path, e->d_name);
        remove_tree(child);
      }
      closedir(d);
    }
    rmdir(path);
  } else {
    unlink(path);
  }
}

static void make_tmpdir(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/bb-test-io-XXXXXX");
  cr_assert_not_null(mkdtemp(tmpdir), "mkdtemp: %s", strerror(errno));
}

static void remove_tmpdir(void) { remove_tree(tmpdir); }

TestSuite(image_files, .init = make_tmpdir, .fini = remove_tmpdir);

/* Criterion's runner leaks one 48-byte block when it exits after parallel
 * jobs: the only suppression (OpenImageIO's known PNG leak is handled where
 * it happens, see src/core/sanitizer_options.h). These hooks are process-wide:
 * they cover every test file. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libcriterion.so\n"; }
const char *__lsan_default_options(void);
const char *__lsan_default_options(void) { return "print_suppressions=0"; }

/* Path of a file in the test's temporary directory (static buffer rotation). */
static const char *tmp_path(const char *name) {
  static char buf[4][512];
  static int next = 0;
  char *p = buf[next++ % 4];
  snprintf(p, 512, "%s/%s", tmpdir, name);
  return p;
}

static int file_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

/* Number of entries of dir whose name starts with prefix. */
static int count_entries(const char *dir, const char *prefix) {
  DIR *d = opendir(dir);
  cr_assert_not_null(d);
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strncmp(e->d_name, prefix, strlen(prefix)) == 0) n++;
  closedir(d);
  return n;
}

static void write_bytes(const char *path, const void *bytes, size_t size) {
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  cr_assert_eq(fwrite(bytes, 1, size, f), size);
  fclose(f);
}

static long file_size(const char *path) {
  struct stat st;
  cr_assert_eq(stat(path, &st), 0);
  return (long)st.st_size;
}

/* Deterministic values in [lo, hi). */
static void fill_pseudo_random(bb_image *img, float lo, float hi, uint32_t seed) {
  size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  for (size_t i = 0; i < n; i++) {
    seed = seed * 1664525u + 1013904223u;
    img->pixels[i] = lo + (hi - lo) * (float)(seed >> 8) / 16777216.0f;
  }
}

static bb_image make_image(int w, int h, int c, float lo, float hi, uint32_t seed) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, c, NULL), BB_OK);
  fill_pseudo_random(&img, lo, hi, seed);
  return img;
}

static bb_write_options options(bb_depth depth, bb_range range, const char *description) {
  bb_write_options o = {depth, range, description, NULL};
  return o;
}

/* Writes img, reads it back and checks every sample within tolerance. */
static void check_round_trip(const char *name, const bb_image *img, bb_depth depth,
                             double tolerance, const char *format_name, int is_float,
                             int bits) {
  const char *path = tmp_path(name);
  bb_write_options o = options(depth, BB_RANGE_UNIT, NULL);
  bb_error err = {{0}};
  cr_assert_eq(bb__image_write(path, img, &o, &err), BB_OK, "%s", err.message);

  bb_image back;
  bb_image_info info;
  cr_assert_eq(bb_image_read(path, &back, &info, &err), BB_OK, "%s", err.message);
  cr_assert_eq(back.width, img->width);
  cr_assert_eq(back.height, img->height);
  cr_assert_eq(back.channels, img->channels);
  cr_assert_str_eq(info.format_name, format_name);
  cr_assert_eq(info.is_float, is_float);
  cr_assert_eq(info.bits_per_sample, bits);
  size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  for (size_t i = 0; i < n; i++) {
    if (tolerance == 0.0)
      cr_assert_eq(back.pixels[i], img->pixels[i], "%s sample %zu: %.9g != %.9g", name, i,
                   back.pixels[i], img->pixels[i]);
    else
      cr_assert_float_eq(back.pixels[i], img->pixels[i], tolerance, "%s sample %zu", name, i);
  }
  bb_image_free(&back);
  bb_image_info_free(&info);
}

/* Half a quantisation step, plus float slack. */
#define HALF_STEP_8 (0.5 / 255.0 + 1e-6)
#define HALF_STEP_16 (0.5 / 65535.0 + 1e-7)

/* ---------------------------------------------------------- round trips */

Test(image_files, round_trip_png8) {
  bb_image img = make_image(7, 5, 3, 0.0f, 1.0f, 1);
  check_round_trip("a.png", &img, BB_DEPTH_DEFAULT, HALF_STEP_8, "png", 0, 8);
  bb_image_free(&img);
}

Test(image_files, round_trip_png16) {
  bb_image img = make_image(7, 5, 3, 0.0f, 1.0f, 2);
  check_round_trip("a.png", &img, BB_DEPTH_16, HALF_STEP_16, "png", 0, 16);
  bb_image_free(&img);
}

/* Big enough for many deflate blocks and rows, with flat runs beside noise:
 * the PNG and TIFF encoders' speed settings must stay lossless. */
Test(image_files, round_trip_large_png_and_tif_with_runs) {
  bb_image img = make_image(517, 301, 3, 0.0f, 1.0f, 11);
  for (int y = 0; y < img.height; y += 2)
    for (int x = 0; x < img.width / 2; x++)
      for (int c = 0; c < 3; c++)
        img.pixels[((size_t)y * 517 + (size_t)x) * 3 + (size_t)c] = 0.25f;
  check_round_trip("big.png", &img, BB_DEPTH_8, HALF_STEP_8, "png", 0, 8);
  check_round_trip("big16.png", &img, BB_DEPTH_16, HALF_STEP_16, "png", 0, 16);
  check_round_trip("big.tif", &img, BB_DEPTH_8, HALF_STEP_8, "tiff", 0, 8);
  check_round_trip("bigf.tif", &img, BB_DEPTH_FLOAT, 0.0, "tiff", 1, 32);
  bb_image_free(&img);
}

Test(image_files, round_trip_tga) {
  bb_image img = make_image(6, 4, 4, 0.0f, 1.0f, 3);
  check_round_trip("a.tga", &img, BB_DEPTH_DEFAULT, HALF_STEP_8, "targa", 0, 8);
  bb_image_free(&img);
}

Test(image_files, round_trip_tif8_and_tiff16) {
  bb_image img = make_image(5, 6, 1, 0.0f, 1.0f, 4);
  check_round_trip("a.tif", &img, BB_DEPTH_8, HALF_STEP_8, "tiff", 0, 8);
  check_round_trip("b.tiff", &img, BB_DEPTH_16, HALF_STEP_16, "tiff", 0, 16);
  bb_image_free(&img);
}

Test(image_files, round_trip_tif_float_is_exact) {
  bb_image img = make_image(5, 3, 3, -4.0f, 4.0f, 5);
  check_round_trip("a.tif", &img, BB_DEPTH_FLOAT, 0.0, "tiff", 1, 32);
  bb_image_free(&img);
}

Test(image_files, round_trip_exr_float_is_exact) {
  bb_image img = make_image(9, 4, 4, -3.0f, 7.0f, 6);
  img.pixels[0] = 1e-30f; /* a tiny value a lossy path would flush */
  check_round_trip("a.exr", &img, BB_DEPTH_DEFAULT, 0.0, "openexr", 1, 32);
  bb_image_free(&img);
}

Test(image_files, round_trip_exr_half) {
  /* In [0.5, 1) half has 10 fraction bits: error at most 2^-12 after rounding. */
  bb_image img = make_image(8, 8, 2, 0.5f, 1.0f, 7);
  check_round_trip("a.exr", &img, BB_DEPTH_HALF, 1.0 / 4096.0 + 1e-7, "openexr", 1, 16);
  bb_image_free(&img);
}

/* A basis map of more than 4 directions: every channel comes back in its
 * place (OpenEXR sorts channels by name, so B0..B15 unpadded would read
 * back as B0, B1, B10, ...), none of them as alpha, at every depth. */
Test(image_files, round_trip_basis_maps_of_many_channels) {
  const int counts[] = {5, 6, 11, 16};
  for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
    bb_image img = make_image(5, 4, counts[i], 0.0f, 1.0f, 40 + (uint32_t)i);
    check_round_trip("many.exr", &img, BB_DEPTH_FLOAT, 0.0, "openexr", 1, 32);
    check_round_trip("many_half.exr", &img, BB_DEPTH_HALF, 1.0 / 2048.0, "openexr", 1, 16);
    check_round_trip("many.tif", &img, BB_DEPTH_8, HALF_STEP_8, "tiff", 0, 8);
    check_round_trip("many16.tif", &img, BB_DEPTH_16, HALF_STEP_16, "tiff", 0, 16);
    check_round_trip("manyf.tif", &img, BB_DEPTH_FLOAT, 0.0, "tiff", 1, 32);
    const char *names[] = {"many.exr", "many.tif"};
    for (int k = 0; k < 2; k++) {
      bb_image_info info;
      cr_assert_eq(bb_image_read_info(tmp_path(names[k]), NULL, NULL, NULL, &info, NULL), BB_OK);
      cr_expect_eq(info.alpha_channel, -1, "%s, %d channels: channel %d read as alpha",
                   names[k], counts[i], info.alpha_channel);
      bb_image_info_free(&info);
    }
    bb_image_free(&img);
  }
  cr_assert_eq(bb__path_max_channels("a.png"), 4);
  cr_assert_eq(bb__path_max_channels("a.TGA"), 4);
  cr_assert_eq(bb__path_max_channels("a.tif"), 64);
  cr_assert_eq(bb__path_max_channels("a.exr"), 64);
  cr_assert_eq(bb__path_max_channels("a.jpg"), 0);
  cr_assert_eq(bb__path_max_channels(NULL), 0);
}

/* ------------------------------------------------------------ encoding */

/* Writes a 1-row image of the given values and reads back the codes. */
static void write_and_read_codes(const char *name, const float *values, int count,
                                 bb_depth depth, bb_range range, double max_code,
                                 long *codes) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, count, 1, 1, NULL), BB_OK);
  memcpy(img.pixels, values, (size_t)count * sizeof(float));
  bb_write_options o = options(depth, range, NULL);
  bb_error err;
  const char *path = tmp_path(name);
  cr_assert_eq(bb__image_write(path, &img, &o, &err), BB_OK, "%s", err.message);
  bb_image back;
  cr_assert_eq(bb_image_read(path, &back, NULL, &err), BB_OK, "%s", err.message);
  for (int i = 0; i < count; i++) {
    /* A 16-bit code read back as float is off by up to ~0.004 of a code. */
    double code = back.pixels[i] * max_code;
    cr_assert_float_eq(code, round(code), 1e-2, "not a code: %g", code);
    codes[i] = lround(code);
  }
  bb_image_free(&back);
  bb_image_free(&img);
}

Test(image_files, unit_range_rounds_half_up_and_clamps) {
  /* 0.5 * 255 = 127.5 and 0.25 * 255 = 63.75 are exact in float and double. */
  const float v[] = {0.0f, 1.0f, 0.5f, 0.25f, -0.2f, 1.7f, NAN, 3.0f / 255.0f};
  const long want[] = {0, 255, 128, 64, 0, 255, 0, 3};
  long got[8];
  write_and_read_codes("u.png", v, 8, BB_DEPTH_8, BB_RANGE_UNIT, 255.0, got);
  for (int i = 0; i < 8; i++) cr_assert_eq(got[i], want[i], "value %d: %ld != %ld", i, got[i], want[i]);
}

Test(image_files, unit_range_16_bit_rounds_half_up) {
  const float v[] = {0.5f, 0.25f, 1.0f, 0.0f};
  const long want[] = {32768, 16384, 65535, 0}; /* 32767.5 -> 32768, 16383.75 -> 16384 */
  long got[4];
  write_and_read_codes("u16.png", v, 4, BB_DEPTH_16, BB_RANGE_UNIT, 65535.0, got);
  for (int i = 0; i < 4; i++) cr_assert_eq(got[i], want[i], "value %d: %ld != %ld", i, got[i], want[i]);
}

Test(image_files, signed_range_maps_minus_one_to_one_onto_codes) {
  const float v[] = {-1.0f, 0.0f, 1.0f, -0.5f, 0.5f, 2.0f, -3.0f};
  /* 0.5+0.5v: 0, 0.5 (127.5 -> 128), 1, 0.25 (63.75 -> 64), 0.75 (191.25 -> 191), clamped */
  const long want[] = {0, 128, 255, 64, 191, 255, 0};
  long got[7];
  write_and_read_codes("s.tga", v, 7, BB_DEPTH_8, BB_RANGE_SIGNED, 255.0, got);
  for (int i = 0; i < 7; i++) cr_assert_eq(got[i], want[i], "value %d: %ld != %ld", i, got[i], want[i]);
}

Test(image_files, signed_range_16_bit_tif) {
  const float v[] = {0.0f, -1.0f, 1.0f};
  const long want[] = {32768, 0, 65535};
  long got[3];
  write_and_read_codes("s.tif", v, 3, BB_DEPTH_16, BB_RANGE_SIGNED, 65535.0, got);
  for (int i = 0; i < 3; i++) cr_assert_eq(got[i], want[i], "value %d: %ld != %ld", i, got[i], want[i]);
}

/* The writer's quantisation against the naive formula, floor(u * max + 0.5)
 * with u clamped to [0, 1], at the float values on either side of every code
 * boundary and at the special values, so a faster quantiser cannot drift. */
static double naive_code(float v, bb_range range, double max_code) {
  double u = range == BB_RANGE_SIGNED ? 0.5 + 0.5 * (double)v : (double)v;
  if (isnan(u) || u < 0.0) u = 0.0;
  if (u > 1.0) u = 1.0;
  return floor(u * max_code + 0.5);
}

static void check_codes_match_naive(const char *name, bb_depth depth, bb_range range,
                                    double max_code) {
  const int boundaries = max_code > 255.0 ? 4096 : 256;
  const int count = boundaries * 3 + 8;
  float *v = malloc((size_t)count * sizeof *v);
  long *got = malloc((size_t)count * sizeof *got);
  cr_assert(v && got);
  int n = 0;
  for (int b = 0; b < boundaries; b++) {
    /* Spread the 16-bit boundaries over the whole code range. */
    double k = max_code > 255.0 ? (double)b * (max_code / boundaries) : (double)b;
    double u = (floor(k) + 0.5) / max_code;
    float x = (float)(range == BB_RANGE_SIGNED ? 2.0 * u - 1.0 : u);
    v[n++] = nextafterf(x, -INFINITY);
    v[n++] = x;
    v[n++] = nextafterf(x, INFINITY);
  }
  const float special[] = {NAN, -NAN, INFINITY, -INFINITY, -0.0f, 0.0f, -1.0f, 1.0f};
  for (int i = 0; i < 8; i++) v[n++] = special[i];
  write_and_read_codes(name, v, count, depth, range, max_code, got);
  for (int i = 0; i < count; i++)
    cr_assert_eq((double)got[i], naive_code(v[i], range, max_code),
                 "%s: value %.9g: code %ld", name, (double)v[i], got[i]);
  free(got);
  free(v);
}

Test(image_files, codes_match_the_naive_formula_8_bit) {
  check_codes_match_naive("n8u.png", BB_DEPTH_8, BB_RANGE_UNIT, 255.0);
  check_codes_match_naive("n8s.tga", BB_DEPTH_8, BB_RANGE_SIGNED, 255.0);
}

Test(image_files, codes_match_the_naive_formula_16_bit) {
  check_codes_match_naive("n16u.png", BB_DEPTH_16, BB_RANGE_UNIT, 65535.0);
  check_codes_match_naive("n16s.tif", BB_DEPTH_16, BB_RANGE_SIGNED, 65535.0);
}

Test(image_files, float_formats_store_signed_values_raw) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 3, 1, 1, NULL), BB_OK);
  img.pixels[0] = -1.0f;
  img.pixels[1] = 0.25f;
  img.pixels[2] = 1.5f;
  bb_write_options o = options(BB_DEPTH_DEFAULT, BB_RANGE_SIGNED, NULL);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("raw.exr"), &img, &o, &err), BB_OK, "%s", err.message);
  bb_image back;
  cr_assert_eq(bb_image_read(tmp_path("raw.exr"), &back, NULL, &err), BB_OK, "%s", err.message);
  for (int i = 0; i < 3; i++) cr_assert_eq(back.pixels[i], img.pixels[i]);
  bb_image_free(&back);
  bb_image_free(&img);
}

/* OIIO premultiplies colour by alpha on read and divides on write unless told
 * not to; bumpbake's channels are data, so colour under alpha 0 must survive. */
static void check_alpha_kept(const char *name) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 2, 1, 4, NULL), BB_OK);
  const float px[8] = {0.8f, 0.4f, 0.2f, 0.0f, 0.6f, 0.6f, 0.6f, 0.2f};
  memcpy(img.pixels, px, sizeof px);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path(name), &img, NULL, &err), BB_OK, "%s", err.message);
  bb_image back;
  bb_image_info info;
  cr_assert_eq(bb_image_read(tmp_path(name), &back, &info, &err), BB_OK, "%s", err.message);
  cr_assert_eq(info.alpha_channel, 3);
  for (int i = 0; i < 8; i++)
    cr_assert_float_eq(back.pixels[i], px[i], HALF_STEP_8, "%s sample %d", name, i);
  bb_image_free(&back);
  bb_image_free(&img);
}

Test(image_files, alpha_is_not_premultiplied_png) { check_alpha_kept("alpha.png"); }
Test(image_files, alpha_is_not_premultiplied_tga) { check_alpha_kept("alpha.tga"); }
Test(image_files, alpha_is_not_premultiplied_tif) { check_alpha_kept("alpha.tif"); }

/* --------------------------------------------------------- description */

static void check_description(const char *name) {
  const char *text = "bumpbake_version=0.1.0\noutput=ssbump\nscale=2.5";
  bb_image img = make_image(3, 2, 3, 0.0f, 1.0f, 8);
  bb_write_options o = options(BB_DEPTH_DEFAULT, BB_RANGE_UNIT, text);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path(name), &img, &o, &err), BB_OK, "%s", err.message);
  bb_image back;
  bb_image_info info;
  cr_assert_eq(bb_image_read(tmp_path(name), &back, &info, &err), BB_OK, "%s", err.message);
  cr_assert_not_null(info.description, "%s lost its description", name);
  cr_assert_str_eq(info.description, text);
  bb_image_info_free(&info);
  cr_assert_null(info.description);
  bb_image_free(&back);
  bb_image_free(&img);
}

Test(image_files, description_round_trips_png) { check_description("d.png"); }
Test(image_files, description_round_trips_tif) { check_description("d.tif"); }
Test(image_files, description_round_trips_exr) { check_description("d.exr"); }
/* OIIO 2.4 keeps it in the TGA 2.0 extension area's comment field. */
Test(image_files, description_round_trips_tga) { check_description("d.tga"); }

Test(image_files, no_description_reads_as_null) {
  bb_image img = make_image(3, 2, 1, 0.0f, 1.0f, 9);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("n.png"), &img, NULL, &err), BB_OK, "%s", err.message);
  bb_image back;
  bb_image_info info;
  cr_assert_eq(bb_image_read(tmp_path("n.png"), &back, &info, &err), BB_OK, "%s", err.message);
  cr_assert_null(info.description);
  cr_assert_eq(info.alpha_channel, -1);
  bb_image_free(&back);
  bb_image_free(&img);
}

/* -------------------------------------------------------- write errors */

Test(image_files, unknown_extension_is_a_format_error) {
  bb_image img = make_image(2, 2, 1, 0.0f, 1.0f, 10);
  bb_error err;
  const char *path = tmp_path("out.xyz");
  cr_assert_eq(bb__image_write(path, &img, NULL, &err), BB_ERR_FORMAT);
  cr_assert_not_null(strstr(err.message, "unknown output format '.xyz'"), "%s", err.message);
  cr_assert_not_null(strstr(err.message, path), "%s", err.message);
  cr_assert_not(file_exists(path));
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  bb_image_free(&img);
}

Test(image_files, writable_format_by_extension_ignores_case) {
  cr_assert(bb__path_is_writable_format("a.png"));
  cr_assert(bb__path_is_writable_format("dir.d/A.PNG"));
  cr_assert(bb__path_is_writable_format("x.TiFf"));
  cr_assert(bb__path_is_writable_format("x.tga"));
  cr_assert(bb__path_is_writable_format("x.exr"));
  cr_assert_not(bb__path_is_writable_format("x.jpg"));
  cr_assert_not(bb__path_is_writable_format("noext"));
  cr_assert_not(bb__path_is_writable_format("dir.png/noext"));
  cr_assert_not(bb__path_is_writable_format(NULL));
}

Test(image_files, upper_case_extension_writes_that_format) {
  bb_image img = make_image(2, 2, 3, 0.0f, 1.0f, 11);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("UP.TIF"), &img, NULL, &err), BB_OK, "%s", err.message);
  bb_image back;
  bb_image_info info;
  cr_assert_eq(bb_image_read(tmp_path("UP.TIF"), &back, &info, &err), BB_OK, "%s", err.message);
  cr_assert_str_eq(info.format_name, "tiff");
  bb_image_free(&back);
  bb_image_free(&img);
}

static void check_depth_refused(const char *name, bb_depth depth) {
  bb_image img = make_image(2, 2, 1, 0.0f, 1.0f, 12);
  bb_write_options o = options(depth, BB_RANGE_UNIT, NULL);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path(name), &img, &o, &err), BB_ERR_FORMAT, "%s", name);
  cr_assert_not_null(strstr(err.message, "not supported"), "%s", err.message);
  cr_assert_not(file_exists(tmp_path(name)));
  bb_image_free(&img);
}

Test(image_files, unsupported_depths_are_refused) {
  check_depth_refused("h.png", BB_DEPTH_HALF);
  check_depth_refused("f.png", BB_DEPTH_FLOAT);
  check_depth_refused("s.tga", BB_DEPTH_16);
  check_depth_refused("f.tga", BB_DEPTH_FLOAT);
  check_depth_refused("h.tif", BB_DEPTH_HALF);
  check_depth_refused("b.exr", BB_DEPTH_8);
  check_depth_refused("s.exr", BB_DEPTH_16);
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
}

Test(image_files, unknown_enum_values_are_argument_errors) {
  bb_image img = make_image(2, 2, 1, 0.0f, 1.0f, 12);
  bb_write_options o = options((bb_depth)42, BB_RANGE_UNIT, NULL);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("x.png"), &img, &o, &err), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(err.message, "42"), "%s", err.message);
  o = options(BB_DEPTH_DEFAULT, (bb_range)-1, NULL);
  cr_assert_eq(bb__image_write(tmp_path("x.png"), &img, &o, &err), BB_ERR_ARGUMENT);
  cr_assert_not(file_exists(tmp_path("x.png")));
  bb_image_free(&img);
}

Test(image_files, too_many_channels_for_png_is_a_format_error) {
  bb_image img = make_image(2, 2, 5, 0.0f, 1.0f, 13);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("five.png"), &img, NULL, &err), BB_ERR_FORMAT);
  cr_assert_not(file_exists(tmp_path("five.png")));
  /* TIFF holds any count. */
  cr_assert_eq(bb__image_write(tmp_path("five.tif"), &img, NULL, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
}

Test(image_files, empty_image_is_an_argument_error) {
  bb_image img = {0, 0, 0, NULL};
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("e.png"), &img, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__image_write(tmp_path("e.png"), NULL, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert_not(file_exists(tmp_path("e.png")));
}

Test(image_files, unwritable_directory_is_an_io_error) {
  bb_image img = make_image(2, 2, 1, 0.0f, 1.0f, 14);
  char path[600];
  if (geteuid() == 0) {
    /* root ignores directory permissions: make the parent a regular file. */
    write_bytes(tmp_path("somefile"), "x", 1);
    snprintf(path, sizeof path, "%s/somefile/out.png", tmpdir);
  } else {
    cr_assert_eq(mkdir(tmp_path("ro"), 0500), 0);
    snprintf(path, sizeof path, "%s/ro/out.png", tmpdir);
  }
  bb_error err;
  cr_assert_eq(bb__image_write(path, &img, NULL, &err), BB_ERR_IO);
  cr_assert_not_null(strstr(err.message, "cannot write"), "%s", err.message);
  cr_assert_not_null(strstr(err.message, path), "%s", err.message);
  cr_assert_not(file_exists(path));
  bb_image_free(&img);
}

Test(image_files, missing_directory_is_an_io_error) {
  bb_image img = make_image(2, 2, 1, 0.0f, 1.0f, 15);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("nodir/out.exr"), &img, NULL, &err), BB_ERR_IO);
  cr_assert_not_null(strstr(err.message, "cannot write"), "%s", err.message);
  bb_image_free(&img);
}

/* The rename fails when the destination is a directory: the temporary file
 * was fully written by then and must be removed. */
Test(image_files, failed_rename_leaves_no_temporary_file) {
  bb_image img = make_image(4, 4, 3, 0.0f, 1.0f, 16);
  cr_assert_eq(mkdir(tmp_path("taken.png"), 0700), 0);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("taken.png"), &img, NULL, &err), BB_ERR_IO);
  cr_assert_not_null(strstr(err.message, "cannot write"), "%s", err.message);
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  struct stat st;
  cr_assert_eq(stat(tmp_path("taken.png"), &st), 0);
  cr_assert(S_ISDIR(st.st_mode), "the destination was replaced");
  bb_image_free(&img);
}

Test(image_files, successful_write_leaves_no_temporary_file) {
  bb_image img = make_image(4, 4, 3, 0.0f, 1.0f, 17);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("ok.exr"), &img, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  cr_assert_eq(count_entries(tmpdir, "ok.exr"), 1);
  bb_image_free(&img);
}

Test(image_files, overwrite_replaces_content_with_umask_mode) {
  umask(022);
  bb_image a = make_image(4, 4, 1, 0.0f, 1.0f, 18);
  bb_image b = make_image(3, 5, 1, 0.0f, 1.0f, 19);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("o.png"), &a, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__image_write(tmp_path("o.png"), &b, NULL, &err), BB_OK, "%s", err.message);
  bb_image back;
  cr_assert_eq(bb_image_read(tmp_path("o.png"), &back, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(back.width, 3);
  cr_assert_eq(back.height, 5);
  struct stat st;
  cr_assert_eq(stat(tmp_path("o.png"), &st), 0);
  cr_assert_eq(st.st_mode & 0777, 0644, "mode %o", (unsigned)(st.st_mode & 0777));
  bb_image_free(&back);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* bb__file_write: the bytes, whole, replacing what was there; nothing left
 * behind and the destination untouched when it cannot be written. */
Test(image_files, file_write_replaces_whole_and_fails_cleanly) {
  const char *path = tmp_path("deps.d");
  bb_error err;
  cr_assert_eq(bb__file_write(path, "old rule\n", 9, &err), BB_OK, "%s", err.message);
  const char text[] = "a.png b.png: in.png\n";
  cr_assert_eq(bb__file_write(path, text, sizeof text - 1, &err), BB_OK, "%s", err.message);
  char back[64] = {0};
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f);
  size_t n = fread(back, 1, sizeof back - 1, f);
  fclose(f);
  cr_assert_eq(n, sizeof text - 1);
  cr_assert_str_eq(back, text);
  cr_assert_eq(bb__file_write(path, "", 0, &err), BB_OK, "%s", err.message);
  cr_assert_eq(file_size(path), 0, "an empty write leaves an empty file");

  cr_assert_eq(mkdir(tmp_path("taken.d"), 0700), 0);
  cr_assert_eq(bb__file_write(tmp_path("taken.d"), text, 4, &err), BB_ERR_IO);
  cr_assert_not_null(strstr(err.message, "cannot write"), "%s", err.message);
  struct stat st;
  cr_assert_eq(stat(tmp_path("taken.d"), &st), 0);
  cr_assert(S_ISDIR(st.st_mode), "the destination was replaced");
  cr_assert_eq(bb__file_write(tmp_path("nodir/x.d"), text, 4, &err), BB_ERR_IO);
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  cr_assert_eq(bb__file_write(path, NULL, 4, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__file_write(NULL, text, 4, &err), BB_ERR_ARGUMENT);
}

/* --------------------------------------------------------- read errors */

static void check_read_fails(const char *path, bb_status want, const char *needle) {
  bb_image out = {1, 1, 1, (float *)&out}; /* garbage that must be cleared */
  bb_image_info info;
  bb_error err = {{0}};
  bb_status st = bb_image_read(path, &out, &info, &err);
  cr_assert_eq(st, want, "%s: status %s, message '%s'", path, bb_status_name(st), err.message);
  cr_assert_null(out.pixels);
  cr_assert_eq(out.width, 0);
  cr_assert_null(info.description);
  cr_assert_not_null(strstr(err.message, path), "message does not name the file: %s",
                     err.message);
  if (needle) cr_assert_not_null(strstr(err.message, needle), "%s", err.message);
  cr_assert_null(strchr(err.message, '\n'), "multi-line message: %s", err.message);
}

Test(image_files, missing_file_is_an_io_error) {
  check_read_fails(tmp_path("nothere.png"), BB_ERR_IO, "no such file");
}

Test(image_files, directory_is_an_io_error) { check_read_fails(tmpdir, BB_ERR_IO, NULL); }

Test(image_files, unreadable_file_is_an_io_error) {
  if (geteuid() == 0) {
    remove_tmpdir(); /* a skipped test does not run .fini */
    cr_skip_test("root reads files whatever their mode");
  }
  bb_image img = make_image(2, 2, 1, 0.0f, 1.0f, 20);
  cr_assert_eq(bb__image_write(tmp_path("secret.png"), &img, NULL, NULL), BB_OK);
  cr_assert_eq(chmod(tmp_path("secret.png"), 0), 0);
  check_read_fails(tmp_path("secret.png"), BB_ERR_IO, "cannot read");
  bb_image_free(&img);
}

Test(image_files, random_bytes_are_a_format_error) {
  unsigned char bytes[1000];
  uint32_t s = 12345;
  for (size_t i = 0; i < sizeof bytes; i++) {
    s = s * 1664525u + 1013904223u;
    bytes[i] = (unsigned char)(s >> 24);
  }
  write_bytes(tmp_path("random.png"), bytes, sizeof bytes);
  check_read_fails(tmp_path("random.png"), BB_ERR_FORMAT, NULL);
}

Test(image_files, zero_byte_file_is_a_format_error) {
  write_bytes(tmp_path("empty.exr"), "", 0);
  check_read_fails(tmp_path("empty.exr"), BB_ERR_FORMAT, NULL);
}

/* libpng prints its own "libpng error: ..." line on stderr for a truncated
 * PNG before OpenImageIO returns the error these tests check (the CLI mutes
 * it the same way), so `make test` would show errors that are expected.
 * Each test runs in its own process and Criterion reports through a pipe,
 * so muting this process's stderr hides nothing else. */
static void mute_stderr(void) {
  fflush(stderr);
  int null_fd = open("/dev/null", O_WRONLY);
  cr_assert_geq(null_fd, 0);
  cr_assert_geq(dup2(null_fd, STDERR_FILENO), 0);
  close(null_fd);
}

/* Writes a noisy image (so compression leaves most of the file as pixel
 * data), cuts the file to `keep` of its size and expects a format error. */
static void check_truncation_detected(const char *name, double keep) {
  bb_image img = make_image(64, 64, 3, 0.0f, 1.0f, 21);
  bb_error err;
  const char *path = tmp_path(name);
  cr_assert_eq(bb__image_write(path, &img, NULL, &err), BB_OK, "%s", err.message);
  long size = file_size(path);
  cr_assert_eq(truncate(path, (off_t)((double)size * keep)), 0);
  mute_stderr();
  check_read_fails(path, BB_ERR_FORMAT, NULL);
  bb_image_free(&img);
}

Test(image_files, truncated_png_is_a_format_error) { check_truncation_detected("cut.png", 0.5); }
Test(image_files, truncated_png_tail_is_a_format_error) { check_truncation_detected("cut2.png", 0.97); }
Test(image_files, truncated_exr_is_a_format_error) { check_truncation_detected("cut.exr", 0.8); }
Test(image_files, truncated_tif_is_a_format_error) { check_truncation_detected("cut.tif", 0.6); }
Test(image_files, truncated_tga_is_a_format_error) { check_truncation_detected("cut.tga", 0.5); }

/* --------------------------------------------------------- size limits */

static uint32_t crc32_of(const unsigned char *p, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

static void put_be32(unsigned char *p, uint32_t v) {
  p[0] = (unsigned char)(v >> 24);
  p[1] = (unsigned char)(v >> 16);
  p[2] = (unsigned char)(v >> 8);
  p[3] = (unsigned char)v;
}

/* A PNG signature, IHDR chunk (8-bit grey) declaring width x height and a
 * token IDAT (libpng stops reading the header there) with almost no pixel
 * data: it must be refused from the header alone. */
static void write_png_header(const char *path, uint32_t width, uint32_t height) {
  unsigned char f[8 + 25 + 14 + 12] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  unsigned char *ihdr = f + 8;
  put_be32(ihdr, 13);
  memcpy(ihdr + 4, "IHDR", 4);
  put_be32(ihdr + 8, width);
  put_be32(ihdr + 12, height);
  ihdr[16] = 8; /* bit depth; colour type 0 (grey), no interlace: zeros */
  put_be32(ihdr + 21, crc32_of(ihdr + 4, 17));
  unsigned char *idat = ihdr + 25;
  put_be32(idat, 2);
  memcpy(idat + 4, "IDAT\x78\x9c", 6); /* a zlib stream header, no data */
  put_be32(idat + 10, crc32_of(idat + 4, 6));
  unsigned char *iend = idat + 14;
  memcpy(iend + 4, "IEND", 4);
  put_be32(iend + 8, crc32_of(iend + 4, 4));
  write_bytes(path, f, sizeof f);
}

Test(image_files, huge_png_dimension_is_a_size_error) {
  write_png_header(tmp_path("huge.png"), 100000, 100000);
  check_read_fails(tmp_path("huge.png"), BB_ERR_SIZE, "over the maximum");
}

Test(image_files, png_with_too_many_pixels_is_a_size_error) {
  /* Each side is allowed; the product is over BB_MAX_PIXELS. */
  write_png_header(tmp_path("wide.png"), 65536, 16385);
  check_read_fails(tmp_path("wide.png"), BB_ERR_SIZE, "over the maximum");
}

Test(image_files, huge_tga_is_a_size_error) {
  /* Uncompressed true-colour TGA header, 65535 x 65535 x 24 bits, no pixels. */
  unsigned char h[18] = {0, 0, 2};
  h[12] = 0xFF;
  h[13] = 0xFF; /* width, little endian */
  h[14] = 0xFF;
  h[15] = 0xFF; /* height */
  h[16] = 24;
  h[17] = 0x20; /* top-left origin */
  write_bytes(tmp_path("huge.tga"), h, sizeof h);
  check_read_fails(tmp_path("huge.tga"), BB_ERR_SIZE, NULL);
}

Test(image_files, zero_size_image_is_a_size_error) {
  /* OIIO opens a PGM header that declares 0 x 0. */
  write_bytes(tmp_path("zero.pgm"), "P5\n0 0\n255\n", 11);
  check_read_fails(tmp_path("zero.pgm"), BB_ERR_SIZE, NULL);
}

Test(image_files, read_info_of_grey_alpha_png) {
  bb_image img = make_image(3, 3, 2, 0.0f, 1.0f, 22);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("ga.png"), &img, NULL, &err), BB_OK, "%s", err.message);
  bb_image back;
  bb_image_info info;
  cr_assert_eq(bb_image_read(tmp_path("ga.png"), &back, &info, &err), BB_OK, "%s", err.message);
  cr_assert_eq(back.channels, 2);
  cr_assert_eq(info.alpha_channel, 1);
  bb_image_free(&back);
  bb_image_free(&img);
}

Test(image_files, supports_depth_follows_the_format_table) {
  cr_assert(bb__path_supports_depth("a.png", BB_DEPTH_16));
  cr_assert(bb__path_supports_depth("a.PNG", BB_DEPTH_DEFAULT));
  cr_assert_not(bb__path_supports_depth("a.tga", BB_DEPTH_16));
  cr_assert_not(bb__path_supports_depth("a.png", BB_DEPTH_HALF));
  cr_assert(bb__path_supports_depth("dir.x/a.exr", BB_DEPTH_HALF));
  cr_assert(bb__path_supports_depth("a.tiff", BB_DEPTH_FLOAT));
  cr_assert_not(bb__path_supports_depth("a.jpg", BB_DEPTH_DEFAULT));
  cr_assert_not(bb__path_supports_depth(NULL, BB_DEPTH_8));
}

/* ----------------------------------------------------------------- full disk */

/* One output format and depth a writer must protect. */
typedef struct format_case {
  const char *name;
  bb_depth depth;
} format_case;

static const format_case every_format[] = {
    {"f8.png", BB_DEPTH_8},   {"f16.png", BB_DEPTH_16},    {"f8.tga", BB_DEPTH_8},
    {"f8.tif", BB_DEPTH_8},   {"f16.tif", BB_DEPTH_16},    {"ff.tif", BB_DEPTH_FLOAT},
    {"fh.exr", BB_DEPTH_HALF}, {"ff.exr", BB_DEPTH_FLOAT},
};

/* Runs fn(arg, err) in a forked child (which alarm() ends after 30 s if it
 * hangs) and returns its status; the child's message goes to msg. Library
 * calls that must run under resource limits go through here. */
typedef bb_status (*child_fn)(const void *arg, bb_error *err);

static bb_status run_in_child(child_fn fn, const void *arg, char *msg, size_t cap) {
  /* The OpenImageIO module loaded once here (src/image/oiio_module.h), so
   * each child inherits it, as it inherited OpenImageIO when the binary
   * linked it, rather than loading it again (and inside its limits). */
  cr_assert_not_null(bb__oiio_module());
  int fds[2];
  cr_assert_eq(pipe(fds), 0);
  fflush(NULL);
  pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    alarm(30);
    close(fds[0]);
    bb_error err = {{0}};
    bb_status st = fn(arg, &err);
    ssize_t n = write(fds[1], err.message, strlen(err.message));
    (void)n;
    _exit((int)st);
  }
  close(fds[1]);
  ssize_t got = read(fds[0], msg, cap - 1);
  msg[got > 0 ? got : 0] = '\0';
  close(fds[0]);
  int status = 0;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  cr_assert(WIFEXITED(status), "the child died of signal %d",
            WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return (bb_status)WEXITSTATUS(status);
}

/* Which writer a limited write goes through. */
typedef enum writer { WRITE_IMAGE, WRITE_MIPS, WRITE_GIF, WRITE_MESH } writer;

typedef struct limited_write {
  const char *path;
  const bb_image *img;
  bb_depth depth;
  rlim_t limit;
  writer kind;
} limited_write;

/* Three frames of img (3 channels) as an animated GIF. */
static bb_status write_gif(const char *path, const bb_image *img, bb_error *err) {
  bb_animation *a = NULL;
  bb_status st = bb__animation_open(path, img->width, img->height, 10.0, &a, err);
  for (int k = 0; k < 3 && st == BB_OK; k++) st = bb__animation_add_frame(a, img, err);
  if (st != BB_OK) {
    bb__animation_abort(a);
    return st;
  }
  return bb__animation_close(a, err);
}

/* A grid mesh of img's size (two triangles per cell), heights from img. */
static bb_status write_mesh(const char *path, const bb_image *img, bb_error *err) {
  const int w = img->width, h = img->height;
  bb_mesh m;
  bb_status st = bb__mesh_alloc(&m, (size_t)w * (size_t)h, 2 * (size_t)(w - 1) * (size_t)(h - 1),
                               0, err);
  if (st != BB_OK) return st;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float *p = m.positions + 3 * ((size_t)y * (size_t)w + (size_t)x);
      p[0] = (float)x, p[1] = (float)y, p[2] = bb_image_texel(img, x, y)[0];
    }
  uint32_t *t = m.indices;
  for (int y = 0; y + 1 < h; y++)
    for (int x = 0; x + 1 < w; x++) {
      uint32_t i = (uint32_t)(y * w + x);
      const uint32_t quad[6] = {i, i + 1, i + (uint32_t)w, i + 1, i + 1 + (uint32_t)w,
                                i + (uint32_t)w};
      memcpy(t, quad, sizeof quad);
      t += 6;
    }
  st = bb__mesh_write(path, &m, err);
  bb__mesh_free(&m);
  return st;
}

static bb_status write_mip_file(const char *path, const bb_image *img, bb_depth depth,
                                bb_error *err) {
  bb_image *levels = NULL;
  int count = 0;
  bb_status st = bb_mip_chain(img, BB_MIP_AVERAGE, &levels, &count, err);
  bb_write_options o = options(depth, BB_RANGE_UNIT, "provenance text");
  if (st == BB_OK) st = bb__image_write_mips(path, levels, count, &o, err);
  bb_mip_chain_free(levels, count);
  return st;
}

static bb_status write_with_limit(const void *arg, bb_error *err) {
  const limited_write *w = arg;
  signal(SIGXFSZ, SIG_IGN);
  struct rlimit rl = {w->limit, w->limit};
  if (setrlimit(RLIMIT_FSIZE, &rl) != 0) _exit(100);
  bb_write_options o = options(w->depth, BB_RANGE_UNIT, "provenance text");
  switch (w->kind) {
  case WRITE_MIPS: return write_mip_file(w->path, w->img, w->depth, err);
  case WRITE_GIF: return write_gif(w->path, w->img, err);
  case WRITE_MESH: return write_mesh(w->path, w->img, err);
  case WRITE_IMAGE: break;
  }
  return bb__image_write(w->path, w->img, &o, err);
}

/* Runs bb__image_write in a child whose files may not grow past limit bytes
 * (RLIMIT_FSIZE: the small filesystem a test can make without root), with
 * SIGXFSZ ignored so that writes fail with EFBIG as on a full disk. Every
 * write of a test that uses this must happen in such a child: a fork after
 * OpenEXR has started its thread pool would leave the child waiting for
 * threads it lacks. */
static bb_status write_under_file_size_limit(const char *path, const bb_image *img,
                                             bb_depth depth, rlim_t limit, char *msg,
                                             size_t cap) {
  limited_write w = {path, img, depth, limit, WRITE_IMAGE};
  return run_in_child(write_with_limit, &w, msg, cap);
}

/* The same for the other writers: mip-mapped files, GIFs and meshes. */
static bb_status write_kind_under_limit(writer kind, const char *path, const bb_image *img,
                                        bb_depth depth, rlim_t limit, char *msg,
                                        size_t cap) {
  limited_write w = {path, img, depth, limit, kind};
  return run_in_child(write_with_limit, &w, msg, cap);
}

/* Every format and depth, cut off before its first byte, half way and one
 * byte short: an I/O error naming the file and the system's reason, nothing
 * at the final name and no temporary left. A 256 x 256 noise image spans
 * several write buffers in every format. */
Test(image_files, every_format_fails_cleanly_on_a_full_disk, .timeout = 300) {
  bb_image img = make_image(256, 256, 3, 0.0f, 1.0f, 40);
  for (size_t i = 0; i < sizeof every_format / sizeof every_format[0]; i++) {
    const format_case *fc = &every_format[i];
    char full[600], path[600];
    snprintf(full, sizeof full, "%s/full-%s", tmpdir, fc->name);
    snprintf(path, sizeof path, "%s/%s", tmpdir, fc->name);
    char msg[600];
    cr_assert_eq(write_under_file_size_limit(full, &img, fc->depth, RLIM_INFINITY, msg,
                                             sizeof msg),
                 BB_OK, "%s", msg);
    const long size = file_size(full);
    const rlim_t limits[] = {0, (rlim_t)size / 2, (rlim_t)size - 1};
    for (size_t k = 0; k < sizeof limits / sizeof limits[0]; k++) {
      bb_status st =
          write_under_file_size_limit(path, &img, fc->depth, limits[k], msg, sizeof msg);
      cr_expect_eq(st, BB_ERR_IO, "%s, %ld of %ld bytes: status %d (%s)", fc->name,
                   (long)limits[k], size, st, msg);
      cr_expect(strstr(msg, path) && strstr(msg, "File too large"),
                "%s, limit %ld: message '%s'", fc->name, (long)limits[k], msg);
      cr_expect_not(file_exists(path), "%s, limit %ld: a file was left at the final name",
                    fc->name, (long)limits[k]);
      cr_expect_eq(count_entries(tmpdir, ".bb-tmp-"), 0, "%s, limit %ld: temporary left",
                   fc->name, (long)limits[k]);
    }
    /* With room for every byte the same child succeeds: the limit, not the
     * harness, made the writes above fail. */
    cr_expect_eq(write_under_file_size_limit(path, &img, fc->depth, (rlim_t)size, msg,
                                             sizeof msg),
                 BB_OK, "%s with exactly %ld bytes allowed: %s", fc->name, size, msg);
    cr_expect_eq(file_size(path), size, "%s", fc->name);
  }
  bb_image_free(&img);
}

/* The writers added since: mip-mapped TIFF (written by name and read back,
 * see src/image/oiio_mips.cpp) and EXR, the animated GIF and the mesh formats, cut off
 * at nothing, half way and one byte short like every image format above. */
Test(image_files, every_other_writer_fails_cleanly_on_a_full_disk, .timeout = 450) {
  bb_image img = make_image(96, 64, 3, 0.0f, 1.0f, 47);
  const struct {
    writer kind;
    const char *name;
    bb_depth depth;
  } cases[] = {
      {WRITE_MIPS, "m8.tif", BB_DEPTH_8},    {WRITE_MIPS, "m16.tif", BB_DEPTH_16},
      {WRITE_MIPS, "mf.tif", BB_DEPTH_FLOAT}, {WRITE_MIPS, "mh.exr", BB_DEPTH_HALF},
      {WRITE_MIPS, "mf.exr", BB_DEPTH_FLOAT}, {WRITE_GIF, "a.gif", BB_DEPTH_8},
      {WRITE_MESH, "g.obj", BB_DEPTH_DEFAULT}, {WRITE_MESH, "g.ply", BB_DEPTH_DEFAULT},
      {WRITE_MESH, "g.stl", BB_DEPTH_DEFAULT}, {WRITE_MESH, "g.glb", BB_DEPTH_DEFAULT},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    char full[600], path[600], msg[600];
    snprintf(full, sizeof full, "%s/full-%s", tmpdir, cases[i].name);
    snprintf(path, sizeof path, "%s/%s", tmpdir, cases[i].name);
    cr_assert_eq(write_kind_under_limit(cases[i].kind, full, &img, cases[i].depth,
                                        RLIM_INFINITY, msg, sizeof msg),
                 BB_OK, "%s: %s", cases[i].name, msg);
    const long size = file_size(full);
    const rlim_t limits[] = {0, (rlim_t)size / 2, (rlim_t)size - 1};
    for (size_t k = 0; k < 3; k++) {
      bb_status st = write_kind_under_limit(cases[i].kind, path, &img, cases[i].depth,
                                            limits[k], msg, sizeof msg);
      cr_expect_eq(st, BB_ERR_IO, "%s, %ld of %ld bytes: status %d (%s)", cases[i].name,
                   (long)limits[k], size, st, msg);
      cr_expect(strstr(msg, path) != NULL, "%s: message '%s'", cases[i].name, msg);
      cr_expect_not(file_exists(path), "%s, limit %ld: a file was left at the final name",
                    cases[i].name, (long)limits[k]);
      cr_expect_eq(count_entries(tmpdir, ".bb-tmp-"), 0, "%s, limit %ld: temporary left",
                   cases[i].name, (long)limits[k]);
    }
  }
  bb_image_free(&img);
}

/* Mip-mapped files are bit-identical from run to run: the padding of edge
 * tiles was uninitialised memory, so TIFF chains differed in bytes and size
 * (which also made the size - 1 cut above pass now and then). */
Test(image_files, mip_files_are_the_same_bytes_every_time) {
  bb_image img = make_image(96, 64, 3, 0.0f, 1.0f, 48);
  bb_image *levels = NULL;
  int count = 0;
  bb_error err;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &levels, &count, &err), BB_OK);
  const char *names[][2] = {{"d1.tif", "d2.tif"}, {"d1.exr", "d2.exr"}};
  for (int f = 0; f < 2; f++) {
    bb_write_options o = options(f ? BB_DEPTH_HALF : BB_DEPTH_16, BB_RANGE_UNIT, "p=1\n");
    size_t sizes[2];
    unsigned char *bytes[2];
    for (int k = 0; k < 2; k++) {
      char path[600];
      snprintf(path, sizeof path, "%s/%s", tmpdir, names[f][k]);
      cr_assert_eq(bb__image_write_mips(path, levels, count, &o, &err), BB_OK, "%s",
                   err.message);
      FILE *in = fopen(path, "rb");
      cr_assert_not_null(in);
      bytes[k] = malloc(1 << 20);
      sizes[k] = fread(bytes[k], 1, 1 << 20, in);
      fclose(in);
    }
    cr_expect(sizes[0] == sizes[1] && !memcmp(bytes[0], bytes[1], sizes[0]),
              "%s: %zu and %zu bytes", names[f][0], sizes[0], sizes[1]);
    free(bytes[0]);
    free(bytes[1]);
  }
  bb_mip_chain_free(levels, count);
  bb_image_free(&img);
}

/* The whole content of path (malloc'd, at most 1 MiB), its size in *size. */
static unsigned char *slurp_file(const char *path, size_t *size) {
  FILE *in = fopen(path, "rb");
  cr_assert_not_null(in, "%s", path);
  unsigned char *bytes = malloc(1 << 20);
  cr_assert_not_null(bytes);
  *size = fread(bytes, 1, 1 << 20, in);
  fclose(in);
  return bytes;
}

/* TIFF and EXR carry a DateTime that OpenImageIO fills with the write time
 * unless told otherwise: two writes in different seconds must still be the
 * same bytes (goldens and build caches compare files). */
Test(image_files, files_written_seconds_apart_are_the_same_bytes) {
  bb_image img = make_image(24, 16, 3, 0.0f, 1.0f, 49);
  const char *exts[] = {"tif", "exr"};
  for (int f = 0; f < 2; f++) {
    bb_write_options o = options(f ? BB_DEPTH_HALF : BB_DEPTH_16, BB_RANGE_UNIT, "p=1\n");
    size_t sizes[2];
    unsigned char *bytes[2];
    bb_error err;
    for (int k = 0; k < 2; k++) {
      char path[600];
      snprintf(path, sizeof path, "%s/when%d.%s", tmpdir, k, exts[f]);
      const time_t start = time(NULL);
      while (k == 1 && time(NULL) == start)
        nanosleep(&(struct timespec){0, 20000000}, NULL); /* into the next second */
      cr_assert_eq(bb__image_write(path, &img, &o, &err), BB_OK, "%s", err.message);
      bytes[k] = slurp_file(path, &sizes[k]);
    }
    cr_expect(sizes[0] == sizes[1] && !memcmp(bytes[0], bytes[1], sizes[0]),
              "%s: the two writes differ", exts[f]);
    free(bytes[0]);
    free(bytes[1]);
  }
  bb_image_free(&img);
}

/* A failed write must leave an existing file at the final name untouched. */
Test(image_files, failed_write_keeps_the_previous_file) {
  bb_image old_img = make_image(8, 8, 1, 0.0f, 1.0f, 41);
  bb_image new_img = make_image(128, 128, 3, 0.0f, 1.0f, 42);
  const char *path = tmp_path("keep.png");
  bb_error err;
  cr_assert_eq(bb__image_write(path, &old_img, NULL, &err), BB_OK, "%s", err.message);
  long before = file_size(path);
  char msg[600];
  cr_assert_eq(write_under_file_size_limit(path, &new_img, BB_DEPTH_8, 1000, msg, sizeof msg),
               BB_ERR_IO, "%s", msg);
  cr_assert_eq(file_size(path), before);
  bb_image back;
  cr_assert_eq(bb_image_read(path, &back, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(back.width, 8);
  bb_image_free(&back);
  bb_image_free(&old_img);
  bb_image_free(&new_img);
}

/* ------------------------------------------------------------ staged writes */

Test(image_files, staged_write_appears_only_on_commit) {
  bb_image img = make_image(16, 16, 3, 0.0f, 1.0f, 43);
  const char *path = tmp_path("staged.exr");
  bb_staged_file *f = NULL;
  bb_error err;
  cr_assert_eq(bb__image_write_staged_all_cores(path, &img, NULL, &f, &err), BB_OK, "%s", err.message);
  cr_assert_not_null(f);
  cr_assert_str_eq(bb__staged_file_path(f), path);
  cr_assert_not(file_exists(path), "nothing at the final name before the commit");
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 1, "the staged file waits");
  cr_assert_eq(bb__staged_file_commit(f, &err), BB_OK, "%s", err.message);
  cr_assert(file_exists(path));
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  bb_image back;
  cr_assert_eq(bb_image_read(path, &back, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(memcmp(back.pixels, img.pixels, 16 * 16 * 3 * sizeof(float)), 0);
  bb_image_free(&back);
  bb_image_free(&img);
}

Test(image_files, staged_write_discard_leaves_nothing) {
  bb_image img = make_image(16, 16, 1, 0.0f, 1.0f, 44);
  bb_staged_file *f = NULL;
  bb_error err;
  cr_assert_eq(bb__image_write_staged_all_cores(tmp_path("gone.png"), &img, NULL, &f, &err), BB_OK,
               "%s", err.message);
  bb__staged_file_discard(f);
  bb__staged_file_discard(NULL);
  cr_assert_eq(count_entries(tmpdir, ""), 2, "only . and .. are left");
  /* A failed staging gives no handle. */
  f = (bb_staged_file *)&err; /* any non-NULL value must be overwritten */
  cr_assert_eq(bb__image_write_staged_all_cores(tmp_path("x.jpg2"), &img, NULL, &f, &err),
               BB_ERR_FORMAT);
  cr_assert_null(f);
  bb_image_free(&img);
}

/* What a SIGINT handler calls: the temporaries of writes in progress go, a
 * file already in place stays. */
Test(image_files, tempfiles_remove_takes_pending_temporaries_only) {
  bb_image img = make_image(8, 8, 1, 0.0f, 1.0f, 45);
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("done.png"), &img, NULL, &err), BB_OK, "%s",
               err.message);
  bb_staged_file *a = NULL, *b = NULL, *m = NULL;
  cr_assert_eq(bb__image_write_staged_all_cores(tmp_path("a.tif"), &img, NULL, &a, &err), BB_OK);
  cr_assert_eq(bb__image_write_staged_all_cores(tmp_path("b.exr"), &img, NULL, &b, &err), BB_OK);
  /* A mip-mapped TIFF waits in a private directory of its own. */
  bb_image *chain = NULL;
  int levels = 0;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &chain, &levels, &err), BB_OK);
  cr_assert_eq(bb__image_write_mips_staged_all_cores(tmp_path("m.tif"), chain, levels, NULL, &m, &err),
               BB_OK, "%s", err.message);
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 3);
  bb__tempfiles_remove();
  cr_assert_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  cr_assert(file_exists(tmp_path("done.png")));
  /* The handles are still freed normally; their commit now fails. */
  cr_assert_eq(bb__staged_file_commit(a, &err), BB_ERR_IO);
  cr_assert_eq(bb__staged_file_commit(m, &err), BB_ERR_IO);
  bb__staged_file_discard(b);
  cr_assert_not(file_exists(tmp_path("a.tif")));
  cr_assert_not(file_exists(tmp_path("m.tif")));
  bb_mip_chain_free(chain, levels);
  bb_image_free(&img);
}

/* Once a signal's cleanup has run the process is ending: a write that
 * starts then makes no temporary the cleanup could not see (one made by
 * another thread just as the handler walked the list was left behind by a
 * SIGTERM under load). */
Test(image_files, no_temporary_is_made_once_the_cleanup_has_run) {
  bb_image img = make_image(8, 8, 1, 0.0f, 1.0f, 45);
  bb_error err;
  bb__tempfiles_remove();
  cr_expect_eq(bb__image_write(tmp_path("late.png"), &img, NULL, &err), BB_ERR_IO);
  bb_staged_file *staged = NULL;
  cr_expect_eq(bb__image_write_staged_all_cores(tmp_path("late.exr"), &img, NULL, &staged, &err),
               BB_ERR_IO);
  bb_image *chain = NULL;
  int levels = 0;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &chain, &levels, &err), BB_OK);
  cr_expect_eq(bb__image_write_mips(tmp_path("late.tif"), chain, levels, NULL, &err), BB_ERR_IO);
  cr_expect_eq(bb__file_write(tmp_path("late.d"), "x: y\n", 5, &err), BB_ERR_IO);
  cr_expect_eq(count_entries(tmpdir, ".bb-tmp-"), 0);
  cr_expect_not(file_exists(tmp_path("late.png")));
  cr_expect_not(file_exists(tmp_path("late.tif")));
  bb_mip_chain_free(chain, levels);
  bb_image_free(&img);
}

/* ----------------------------------------------------------- hostile headers */

/* The 186-byte TIFF declaring 8192 x 8192 x 64 channels once took 16.5 GB
 * and 47 s: its read is refused from its header (64 bytes a texel, over the
 * 16 of an RGBA float image), before any allocation; its header alone is
 * described, at once. The read runs
 * in a child whose address space is capped (except under ASan, which
 * reserves terabytes), so a regression fails here instead of taking the
 * machine's memory. */
typedef struct capped_read {
  const char *path;
  int header_only;
} capped_read;

static bb_status read_with_capped_memory(const void *arg, bb_error *err) {
  const capped_read *r = arg;
#ifndef __SANITIZE_ADDRESS__
  struct rlimit rl = {(rlim_t)3 << 30, (rlim_t)3 << 30};
  setrlimit(RLIMIT_AS, &rl);
#endif
  bb_image img;
  int w, h, c;
  return r->header_only ? bb_image_read_info(r->path, &w, &h, &c, NULL, err)
                        : bb_image_read(r->path, &img, NULL, err);
}

Test(image_files, hostile_tiff_header_is_refused_before_allocating) {
  const char *path = tmp_path("hostile.tif");
  cr_assert_eq(write_hostile_tiff(path, 8192, 8192, 64), 0);
  cr_assert_eq(file_size(path), HOSTILE_TIFF_BYTES);
  for (int header_only = 0; header_only < 2; header_only++) {
    char msg[600];
    /* the child's CPU time (RUSAGE_CHILDREN grows as each is waited for) */
    struct rusage before, after;
    getrusage(RUSAGE_CHILDREN, &before);
    capped_read r = {path, header_only};
    bb_status st = run_in_child(read_with_capped_memory, &r, msg, sizeof msg);
    getrusage(RUSAGE_CHILDREN, &after);
    const double seconds = (double)(after.ru_utime.tv_sec - before.ru_utime.tv_sec) +
                           1e-6 * (double)(after.ru_utime.tv_usec - before.ru_utime.tv_usec) +
                           (double)(after.ru_stime.tv_sec - before.ru_stime.tv_sec) +
                           1e-6 * (double)(after.ru_stime.tv_usec - before.ru_stime.tv_usec);
    if (header_only) {
      cr_expect_eq(st, BB_OK, "%s", msg);
    } else {
      cr_expect_eq(st, BB_ERR_SIZE, "%s", msg);
      cr_expect(strstr(msg, "hostile.tif") && strstr(msg, "1024 MiB"), "%s", msg);
    }
    cr_expect_null(strchr(msg, '\n'), "%s", msg);
    cr_expect_lt(seconds, 5.0);
  }
}

/* 8192 x 8192 x 4 is within the byte limit (exactly 1 GiB of floats), but its
 * 52 bytes of data end in the first band: the read fails there instead of
 * decoding, and touching, all 8192 rows. */
Test(image_files, truncated_huge_tiff_fails_at_its_first_band) {
  const char *path = tmp_path("h4.tif");
  cr_assert_eq(write_hostile_tiff(path, 8192, 8192, 4), 0);
  /* The OpenImageIO module loaded first: what is measured is the read, not
   * the libraries the first image call maps (src/image/oiio_module.h). */
  cr_assert_not_null(bb__oiio_module());
  struct rusage before, after;
  getrusage(RUSAGE_SELF, &before);
  bb_image img;
  bb_error err;
  cr_assert_eq(bb_image_read(path, &img, NULL, &err), BB_ERR_FORMAT, "%s", err.message);
  getrusage(RUSAGE_SELF, &after);
  cr_assert(strstr(err.message, "truncated"), "%s", err.message);
  cr_assert_lt(strlen(err.message), 300, "one reason, not one per row: %s", err.message);
  cr_assert_lt(after.ru_maxrss - before.ru_maxrss, 256L * 1024,
               "the read touched %ld KiB", after.ru_maxrss - before.ru_maxrss);
  /* The header alone reads fine, whatever it declares. */
  int w = 0, h = 0, c = 0;
  bb_image_info info;
  cr_assert_eq(bb_image_read_info(path, &w, &h, &c, &info, &err), BB_OK, "%s",
               err.message);
  cr_assert(w == 8192 && h == 8192 && c == 4);
  cr_assert_str_eq(info.format_name, "tiff");
  bb_image_info_free(&info);
}

Test(image_files, read_header_matches_the_full_read) {
  bb_image img = make_image(13, 7, 4, 0.0f, 1.0f, 46);
  bb_write_options o = options(BB_DEPTH_16, BB_RANGE_UNIT, "made by a test");
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path("hdr.png"), &img, &o, &err), BB_OK, "%s",
               err.message);
  int w, h, c;
  bb_image_info hi, fi;
  bb_image back;
  cr_assert_eq(bb_image_read_info(tmp_path("hdr.png"), &w, &h, &c, &hi, &err), BB_OK);
  cr_assert_eq(bb_image_read(tmp_path("hdr.png"), &back, &fi, &err), BB_OK);
  cr_assert(w == back.width && h == back.height && c == back.channels);
  cr_assert_eq(hi.alpha_channel, fi.alpha_channel);
  cr_assert_eq(hi.bits_per_sample, 16);
  cr_assert_str_eq(hi.description, "made by a test");
  bb_image_info_free(&hi);
  bb_image_info_free(&fi);
  bb_image_free(&back);
  bb_image_free(&img);
  check_read_fails(tmp_path("absent.png"), BB_ERR_IO, "no such file");
}

/* --------------------------------------------------------- sanitizer hygiene */

/* The only leak suppression names Criterion's runner: a pattern on a
 * libstdc++ symbol (it was std::string::_M_assign) would hide every leaked
 * string, bumpbake's included. */
Test(image_files, leak_suppressions_name_criterion_only) {
  cr_expect_str_eq(__lsan_default_suppressions(), "leak:libcriterion.so\n");
  cr_expect_null(strstr(__lsan_default_suppressions(), "std::"));
}

/* The words of --depth, one way: each parses to its depth and back. */
Test(image_files, depth_names_round_trip_and_others_are_refused) {
  const char *names[] = {"8", "16", "half", "float"};
  const bb_depth depths[] = {BB_DEPTH_8, BB_DEPTH_16, BB_DEPTH_HALF, BB_DEPTH_FLOAT};
  for (int i = 0; i < 4; i++) {
    bb_depth d = BB_DEPTH_DEFAULT;
    cr_assert_eq(bb__depth_parse(names[i], &d, NULL), BB_OK, "%s", names[i]);
    cr_expect_eq(d, depths[i], "%s", names[i]);
    cr_expect_str_eq(bb__depth_name(d), names[i]);
  }
  cr_expect_str_eq(bb__depth_name(BB_DEPTH_DEFAULT), "default");
  cr_expect_str_eq(bb__depth_name((bb_depth)99), "unknown");
  bb_depth d = BB_DEPTH_16;
  bb_error err = {{0}};
  cr_assert_eq(bb__depth_parse("32", &d, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "depth must be one of 8, 16, half, float (got '32')");
  cr_expect_eq(d, BB_DEPTH_16, "left untouched");
  cr_expect_eq(bb__depth_parse("default", &d, NULL), BB_ERR_ARGUMENT);
  cr_expect_eq(bb__depth_parse("HALF", &d, NULL), BB_ERR_ARGUMENT, "exact case");
}
