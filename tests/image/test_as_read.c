/* test_as_read.c: bb__image_as_read against a real write and read, bit for
 * bit, in every format and depth bumpbake writes, unit and signed values,
 * 1, 3, 4 and 6 channels, values out of range and NaN: what a golden check
 * of a bake compares must be what the file would hold. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */

#include "bumpbake.h"
#include "image/oiio.h"
#include "scratch_dir.h"
#include "image/image_write.h"

#include <math.h>
#include <string.h>

TestSuite(as_read, .init = NULL, .timeout = 120);

static void values(bb_image *img, int w, int h, int channels, int seed) {
  cr_assert_eq(bb_image_alloc(img, w, h, channels, NULL), BB_OK);
  const size_t n = (size_t)w * (size_t)h * (size_t)channels;
  for (size_t i = 0; i < n; i++)
    img->pixels[i] = (float)(1.3 * sin(0.37 * (double)i + seed) - 0.1);
  img->pixels[3] = NAN; /* quantised to 0; kept as NaN in float files */
  img->pixels[5] = 1e-9f;
  img->pixels[7] = 65504.5f;
}

Test(as_read, matches_a_write_and_a_read_bit_for_bit) {
  scratch_dir_make("bb_as_read");
  static const struct {
    const char *ext;
    bb_depth depth;
    int channels;
  } cases[] = {{"png", BB_DEPTH_8, 1},        {"png", BB_DEPTH_8, 3},
               {"png", BB_DEPTH_8, 4},        {"png", BB_DEPTH_16, 3},
               {"png", BB_DEPTH_16, 4},       {"tga", BB_DEPTH_8, 3},
               {"tga", BB_DEPTH_8, 4},        {"tif", BB_DEPTH_8, 3},
               {"tif", BB_DEPTH_16, 6},       {"tif", BB_DEPTH_FLOAT, 3},
               {"tiff", BB_DEPTH_DEFAULT, 1}, {"exr", BB_DEPTH_HALF, 3},
               {"exr", BB_DEPTH_FLOAT, 6},    {"exr", BB_DEPTH_DEFAULT, 1}};
  int compared = 0;
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
    for (int range = BB_RANGE_UNIT; range <= BB_RANGE_SIGNED; range++) {
      bb_image img;
      values(&img, 13, 7, cases[c].channels, (int)c);
      char name[64];
      snprintf(name, sizeof name, "m%zu_%d.%s", c, range, cases[c].ext);
      const char *path = in_scratch_dir(name);
      const bb_write_options wo = {cases[c].depth, (bb_range)range, NULL, NULL};
      bb_error err = {{0}};
      if (!isfinite(img.pixels[7]) || cases[c].depth == BB_DEPTH_HALF)
        img.pixels[7] = 3.25f; /* half holds up to 65504 */
      cr_assert_eq(bb__image_write(path, &img, &wo, &err), BB_OK, "%s: %s", name,
                   err.message);
      bb_image back, made;
      cr_assert_eq(bb_image_read(path, &back, NULL, &err), BB_OK, "%s", err.message);
      cr_assert_eq(
          bb__image_as_read(path, &img, cases[c].depth, (bb_range)range, &made, &err),
          BB_OK, "%s: %s", name, err.message);
      cr_assert(back.width == made.width && back.height == made.height &&
                    back.channels == made.channels,
                "%s: %dx%dx%d read, %dx%dx%d made", name, back.width, back.height,
                back.channels, made.width, made.height, made.channels);
      const size_t n = (size_t)back.width * (size_t)back.height * (size_t)back.channels;
      for (size_t i = 0; i < n; i++) {
        uint32_t a, b;
        memcpy(&a, &back.pixels[i], 4);
        memcpy(&b, &made.pixels[i], 4);
        cr_expect(a == b || (isnan(back.pixels[i]) && isnan(made.pixels[i])),
                  "%s sample %zu: read %.9g, made %.9g", name, i, (double)back.pixels[i],
                  (double)made.pixels[i]);
      }
      compared++;
      bb_image_free(&img);
      bb_image_free(&back);
      bb_image_free(&made);
    }
  cr_assert_eq(compared, 28);
  scratch_dir_remove();
}

Test(as_read, refuses_textures_and_unknown_extensions) {
  bb_image img, out;
  values(&img, 4, 4, 3, 0);
  bb_error err = {{0}};
  cr_assert_eq(
      bb__image_as_read("m.vtf", &img, BB_DEPTH_DEFAULT, BB_RANGE_UNIT, &out, &err),
      BB_ERR_FORMAT);
  cr_assert_eq(
      bb__image_as_read("m.dds", &img, BB_DEPTH_DEFAULT, BB_RANGE_UNIT, &out, &err),
      BB_ERR_FORMAT);
  cr_assert_eq(
      bb__image_as_read("m.jpg", &img, BB_DEPTH_DEFAULT, BB_RANGE_UNIT, &out, &err),
      BB_ERR_FORMAT);
  cr_assert_null(out.pixels);
  bb_image_free(&img);
}
