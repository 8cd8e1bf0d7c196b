/* texture_read.c: VTF and DDS files read as images: the container's reader lays the levels out (vtf_read.c,
 * dds_read.c), the limits of read_limits.h are checked against the level's
 * size before anything is allocated, its bytes are read through the
 * descriptor the read checked, and texels.c decodes them. */
#include "image/texture_read.h"
#include "core/input_file.h"
#include "core/internal.h"
#include "image/formats.h"
#include "image/read_limits.h"
#include "texture/texture_layout.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { MAGIC_BYTES = 88 };

static int is_vtf(const unsigned char *m, size_t n) { return n >= 4 && !memcmp(m, "VTF\0", 4); }

static int is_dds(const unsigned char *m, size_t n) { return n >= 4 && !memcmp(m, "DDS ", 4); }

int bb__texture_read_applies(const char *path) {
  if (!path)
    return 0;
  if (bb__path_has_extension(path, "vtf"))
    return 1;
  /* Only a regular file is looked into (a FIFO would block): anything else
   * goes to OpenImageIO's path, which refuses it with its reason. */
  const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return 0;
  struct stat sb;
  unsigned char m[MAGIC_BYTES];
  size_t n = 0;
  if (fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode))
    n = bb__input_read_at(fd, m, sizeof m, 0);
  close(fd);
  return is_vtf(m, n) || is_dds(m, n);
}

/* The layout of the texture open at fd, by its first bytes. */
static bb_status layout_of(int fd, const char *path, bb__texture_layout *layout, bb_error *err) {
  unsigned char m[MAGIC_BYTES];
  const size_t n = bb__input_read_at(fd, m, sizeof m, 0);
  if (n >= 4 && !memcmp(m, "DDS ", 4))
    return bb__dds_layout(fd, path, layout, err);
  return bb__vtf_layout(fd, path, layout, err); /* says "not a VTF file" when it is not one */
}

/* Opens path (checked: a regular file) and lays it out; on success the
 * caller closes *fd and frees layout->description. */
static bb_status open_layout(const char *path, int *fd, bb__texture_layout *layout,
                             bb_error *err) {
  bb_status st = bb__input_open(path, fd, err);
  if (st != BB_OK)
    return st;
  st = layout_of(*fd, path, layout, err);
  if (st != BB_OK)
    close(*fd);
  return st;
}

static void fill_info(bb__texture_layout *layout, bb_image_info *info) {
  if (!info) {
    free(layout->description);
    layout->description = NULL;
    return;
  }
  info->alpha_channel = layout->alpha_channel;
  info->is_float = layout->is_float;
  info->bits_per_sample = layout->bits_per_sample;
  snprintf(info->format_name, sizeof info->format_name, "%s", layout->container);
  info->description = layout->description;
  layout->description = NULL;
}

static int level_side(int side, int level) { return side >> level > 0 ? side >> level : 1; }

bb_status bb__texture_read_header(const char *path, int *width, int *height, int *channels,
                                  bb_image_info *info, int *level_count, bb_error *err) {
  int fd;
  bb__texture_layout layout;
  bb_status st = open_layout(path, &fd, &layout, err);
  if (st != BB_OK)
    return st;
  close(fd);
  if (width) *width = layout.width;
  if (height) *height = layout.height;
  if (channels) *channels = layout.format.channels;
  if (level_count) *level_count = layout.levels;
  fill_info(&layout, info);
  return BB_OK;
}

static bb_status read_level(int fd, const char *path, bb__texture_layout *layout, int level,
                            int first, int count, bb_image *out, bb_error *err) {
  const bb__texel_format *f = &layout->format;
  const int w = level_side(layout->width, level), h = level_side(layout->height, level);
  if (count < 0) {
    first = 0;
    count = f->channels;
  }
  const uint64_t bytes = bb__texels_bytes(f, w, h);
  /* The level's own bytes and the decoder's scratch are allocated beside
   * the floats: bb__read_check_size counts them as the file's samples. */
  const bb__image_header hd = {
      .width = w,
      .height = h,
      .channels = f->channels,
      .depth = 1,
      .file_bytes = (double)(bytes + bb__texels_scratch_bytes(f, w, h)),
      .sample_bytes = f->kind == BB__TEXELS_FLOAT                                     ? 4
                      : f->kind == BB__TEXELS_HALF || f->kind == BB__TEXELS_UNORM16 ? 2
                                                                                    : 1,
      .format = f->name};
  bb_status st = bb__read_check_size(path, &hd, count, err);
  if (st != BB_OK)
    return st;
  if (first < 0 || count < 1 || first + count > f->channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: channels %d..%d asked of a %d-channel image",
                    path, first, first + count - 1, f->channels);
  unsigned char *data = malloc((size_t)bytes);
  if (!data)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  if (bb__input_read_at(fd, data, (size_t)bytes, layout->offset[level]) != (size_t)bytes) {
    free(data);
    return bb__fail(err, BB_ERR_FORMAT, "%s: truncated %s: level %d cannot be read", path,
                    layout->container, level);
  }
  bb_error alloc_err;
  st = bb_image_alloc(out, w, h, count, &alloc_err);
  if (st != BB_OK) {
    free(data);
    return bb__fail(err, st, "%s: %s", path, alloc_err.message);
  }
  bb_error decode_err;
  st = bb__texels_decode(f, data, w, h, first, count, out->pixels, &decode_err);
  free(data);
  if (st != BB_OK)
    return bb__fail(err, st, "%s: %s", path, decode_err.message);
  return BB_OK;
}

bb_status bb__texture_read(const char *path, int first, int count, int level, bb_image *out,
                           bb_image_info *info, int *level_count, bb_error *err) {
  int fd;
  bb__texture_layout layout;
  bb_status st = open_layout(path, &fd, &layout, err);
  if (st != BB_OK)
    return st;
  if (level_count) *level_count = layout.levels;
  if (level < 0 || level >= layout.levels)
    st = bb__fail(err, BB_ERR_ARGUMENT, "%s: no mip level %d (the file has %d)", path, level,
                  layout.levels);
  else
    st = read_level(fd, path, &layout, level, first, count, out, err);
  close(fd);
  if (st == BB_OK)
    fill_info(&layout, info);
  free(layout.description);
  return st;
}
