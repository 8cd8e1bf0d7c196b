/* fuzz_load.c: image bytes -> bb_height_load, the path every command's
 * input takes (OpenImageIO's header, bumpbake's size checks, the channel
 * rule, banded decoding). The first byte picks the file extension (the
 * format OpenImageIO tries first) and the height channel rule; the rest is
 * the file. Properties: no crash, no leak, and a success is a finite
 * 1-channel height of the size the header declares. */
#include "bumpbake.h"
#include "fuzz_common.h"

#include <math.h>

static const char *const EXTENSIONS[] = {"in.png", "in.tga", "in.tif", "in.exr"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1)
    return 0;
  const char *name = EXTENSIONS[data[0] & 3];
  const bb_channel channel = (bb_channel)((data[0] >> 2) % 7);
  const char *path = fuzz_write_file(name, data + 1, size - 1);

  int width = 0, height = 0, channels = 0;
  bb_image_info info;
  bb_error err;
  bb_status header = bb_image_read_info(path, &width, &height, &channels, &info, &err);
  bb_image_info_free(&info);
  /* Past 65536 texels decoding is legitimate and bounded (up to
   * BB_MAX_READ_BYTES, which the tests check) but slow: OpenImageIO's PNG
   * reader zero-fills the whole declared image first. Such inputs would
   * drown the search in page faults, so only their header is fuzzed. */
  if (header == BB_OK && (long)width * height > (1L << 16))
    return 0;

  bb_image h;
  bb_status st = bb_height_load(path, channel, &h, &err);
  FUZZ_CHECK((st == BB_OK) == (h.pixels != NULL));
  if (st == BB_OK) {
    FUZZ_CHECK(header == BB_OK);
    FUZZ_CHECK(h.channels == 1 && h.width == width && h.height == height);
    size_t n = (size_t)h.width * (size_t)h.height;
    for (size_t i = 0; i < n; i++)
      FUZZ_CHECK(isfinite(h.pixels[i]));
  } else {
    FUZZ_CHECK(err.message[0] != '\0' && strchr(err.message, '\n') == NULL);
  }
  bb_image_free(&h);
  return 0;
}
