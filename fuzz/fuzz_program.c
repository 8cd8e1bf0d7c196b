/* fuzz_program.c: DOOM 3 image programs (bb__program_parse, bb__program_run)
 * over real small image files: the text is the input; the images it can
 * name (a.png, b.tga, c.exr, d.tif, e.png of other sizes) are written once
 * into the scratch directory, its base. Properties: no crash, leak, hang or
 * overflow; a program that runs gives finite values, 3 channels for a normal
 * map and 4 otherwise; a refusal is one of the documented statuses; no
 * name reads outside the base. */
#include "bumpbake.h"
#include "maps/program_internal.h"
#include "fuzz_common.h"
#include "image/image_write.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Small real files of several formats and sizes, once per process. */
static void write_images(void) {
  static int done;
  if (done)
    return;
  done = 1;
  static const struct {
    const char *name;
    int w, h, c;
    bb_depth depth;
  } files[] = {{"a.png", 8, 8, 1, BB_DEPTH_16},
               {"b.tga", 8, 8, 4, BB_DEPTH_8},
               {"c.exr", 8, 8, 3, BB_DEPTH_HALF},
               {"d.tif", 8, 8, 2, BB_DEPTH_16},
               {"e.png", 5, 3, 3, BB_DEPTH_8}};
  for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
    bb_image img;
    if (bb_image_alloc(&img, files[f].w, files[f].h, files[f].c, NULL) != BB_OK)
      abort();
    size_t n = (size_t)files[f].w * (size_t)files[f].h * (size_t)files[f].c;
    for (size_t i = 0; i < n; i++)
      img.pixels[i] = (float)((i * 37 + f * 11) % 64) / 63.0f;
    char path[256];
    snprintf(path, sizeof path, "%s/%s", fuzz_scratch_dir(), files[f].name);
    const bb_write_options wo = {files[f].depth, BB_RANGE_UNIT, NULL, NULL};
    if (bb__image_write(path, &img, &wo, NULL) != BB_OK)
      abort();
    bb_image_free(&img);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > 4096)
    return 0;
  write_images();
  char *text = malloc(size + 1);
  if (!text)
    abort();
  memcpy(text, data, size);
  text[size] = '\0';
  bb__program *p = NULL;
  bb_error err = {{0}};
  if (bb__program_parse(text, &p, &err) == BB_OK) {
    bb__program_options o;
    bb__program_options_init(&o);
    o.base_dir = fuzz_scratch_dir();
    bb_image out = {0};
    int is_normal = 0;
    bb_status st = bb__program_run(p, &o, &out, &is_normal, &err);
    if (st == BB_OK) {
      FUZZ_CHECK(out.channels == (is_normal ? 3 : 4));
      const size_t n = (size_t)out.width * (size_t)out.height * (size_t)out.channels;
      for (size_t i = 0; i < n; i++)
        FUZZ_CHECK(isfinite(out.pixels[i]));
    } else {
      FUZZ_CHECK(st == BB_ERR_ARGUMENT || st == BB_ERR_IO || st == BB_ERR_FORMAT ||
                 st == BB_ERR_SIZE || st == BB_ERR_VALUE);
      FUZZ_CHECK(out.pixels == NULL);
    }
    bb_image_free(&out);
    bb__program_free(p);
  }
  free(text);
  return 0;
}
