/* fuzz_load.c: image bytes -> every read of the library, the path every
 * command's input takes (the checked descriptor, the header probes,
 * OpenImageIO's readers, bumpbake's size checks, the channel rule, banded
 * decoding, frames; VTF and DX10 DDS files through bumpbake's own texture
 * reader). The first byte's low 5 bits pick the file extension (modulo the
 * 17 of EXTENSIONS: the format OpenImageIO tries first, every other reader
 * then gets its turn by content; .vtf goes to the VTF reader), its top 3
 * bits the height channel rule; the rest is the file. Properties: no crash, no leak, no unit slower than `make fuzz`'s
 * -timeout or allocating past its -malloc_limit_mb, every failure one line,
 * and a success a finite 1-channel height of the size the header declares. */
#include "bumpbake.h"
#include "image/height_channel.h"
#include "fuzz_common.h"
#include "image/oiio.h"

#include <math.h>

/* Every format the seed corpus holds a valid file of (make_seeds.c), PSD
 * read-only. */
static const char *const EXTENSIONS[17] = {
    "in.png", "in.tga", "in.tif", "in.exr", "in.jpg", "in.bmp", "in.pnm", "in.gif", "in.hdr",
    "in.dpx", "in.jp2", "in.webp", "in.sgi", "in.ico", "in.psd", "in.dds", "in.vtf"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1)
    return 0;
  const char *name = EXTENSIONS[(data[0] & 31) % 17];
  const bb_channel channel = (bb_channel)((data[0] >> 5) % 7);
  const char *path = fuzz_write_file(name, data + 1, size - 1);

  int width = 0, height = 0, channels = 0;
  bb_image_info info;
  bb_error err;
  bb_status header = bb_image_read_info(path, &width, &height, &channels, &info, &err);
  bb_image_info_free(&info);
  if (header != BB_OK) {
    FUZZ_CHECK(err.message[0] != '\0' && strchr(err.message, '\n') == NULL);
    return 0;
  }
  /* Past 65536 texels decoding is legitimate and bounded (up to
   * BB_MAX_READ_BYTES, which the tests check) but slow: such inputs would
   * drown the search in page faults, so only their header is fuzzed. */
  if ((long)width * height > (1L << 16))
    return 0;

  bb_image h;
  bb_status st = bb__height_load(path, channel, &h, &(bb__height_loaded){0}, &err);
  FUZZ_CHECK((st == BB_OK) == (h.pixels != NULL));
  if (st == BB_OK) {
    FUZZ_CHECK(h.channels == 1 && h.width == width && h.height == height);
    size_t n = (size_t)h.width * (size_t)h.height;
    for (size_t i = 0; i < n; i++)
      FUZZ_CHECK(isfinite(h.pixels[i]));
  } else {
    FUZZ_CHECK(err.message[0] != '\0' && strchr(err.message, '\n') == NULL);
  }
  bb_image_free(&h);

  /* Frames and mip levels: further subimages and levels, each opened. */
  int frames = 0, levels = 0;
  if (bb__image_frame_count(path, &frames, &err) == BB_OK) {
    FUZZ_CHECK(frames >= 1);
  } else {
    FUZZ_CHECK(err.message[0] != '\0' && strchr(err.message, '\n') == NULL);
  }
  bb_image level;
  st = bb__image_read_mip(path, 1, &level, NULL, &levels, &err);
  FUZZ_CHECK((st == BB_OK) == (level.pixels != NULL));
  FUZZ_CHECK(st != BB_OK || levels >= 2);
  bb_image_free(&level);
  return 0;
}
