/* image_read.c: the public image reads (bumpbake.h "reading images") and
 * bb__image_read_channels / bb__image_level_count (image/oiio.h): arguments
 * checked, outputs cleared, OpenImageIO called (oiio_read.cpp) or, for the
 * engine textures (VTF, which it cannot read, and DDS, which it cannot read
 * safely), texture_read.c, and whatever a failed read made freed. */
#include "core/internal.h"
#include "image/formats.h"
#include "image/oiio.h"
#include "image/oiio_calls.h"
#include "image/texture_read.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void clear_info(bb_image_info *info) {
  if (!info) return;
  memset(info, 0, sizeof *info);
  info->alpha_channel = -1;
}

void bb_image_info_free(bb_image_info *info) {
  if (!info) return;
  free(info->description);
  info->description = NULL;
}

/* A failed read leaves nothing allocated. */
static bb_status finish_read(bb_status st, bb_image *out, bb_image_info *info) {
  if (st != BB_OK) {
    bb_image_free(out);
    bb_image_info_free(info);
  }
  return st;
}

bb_status bb_image_read(const char *path, bb_image *out, bb_image_info *info, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read: out is NULL");
  memset(out, 0, sizeof *out);
  clear_info(info);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read: path is NULL");
  if (bb__texture_read_applies(path))
    return finish_read(bb__texture_read(path, 0, -1, 0, out, info, NULL, err), out, info);
  return finish_read(bb__oiio_read(path, 0, -1, 0, out, info, NULL, err), out, info);
}

bb_status bb__image_read_channels(const char *path, int first_channel, int channel_count,
                                  bb_image *out, bb_image_info *info, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_channels: out is NULL");
  memset(out, 0, sizeof *out);
  clear_info(info);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_channels: path is NULL");
  if (channel_count < 1) return bb__fail(err, BB_ERR_ARGUMENT, "%s: no channel to read", path);
  if (bb__texture_read_applies(path))
    return finish_read(
        bb__texture_read(path, first_channel, channel_count, 0, out, info, NULL, err), out, info);
  return finish_read(bb__oiio_read(path, first_channel, channel_count, 0, out, info, NULL, err),
                     out, info);
}

bb_status bb__image_read_mip(const char *path, int level, bb_image *out, bb_image_info *info,
                            int *level_count, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_mip: out is NULL");
  memset(out, 0, sizeof *out);
  clear_info(info);
  if (level_count) *level_count = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_mip: path is NULL");
  int levels = 0; /* counted whatever the caller asks: a level past the last is an error */
  bb_status st = bb__texture_read_applies(path)
                     ? bb__texture_read(path, 0, -1, level, out, info, &levels, err)
                     : bb__oiio_read(path, 0, -1, level, out, info, &levels, err);
  if (level_count) *level_count = levels;
  return finish_read(st, out, info);
}

bb_status bb_image_read_info(const char *path, int *width, int *height, int *channels,
                             bb_image_info *info, bb_error *err) {
  clear_info(info);
  if (width) *width = 0;
  if (height) *height = 0;
  if (channels) *channels = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_info: path is NULL");
  bb_status st = bb__texture_read_applies(path)
                     ? bb__texture_read_header(path, width, height, channels, info, NULL, err)
                     : bb__oiio_read_header(path, width, height, channels, info, err);
  if (st != BB_OK) bb_image_info_free(info);
  return st;
}

bb_status bb__image_frame_count(const char *path, int *frames, bb_error *err) {
  if (!path || !frames)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_frame_count: NULL argument");
  *frames = 0;
  if (bb__texture_read_applies(path)) { /* frame 0 is what is read */
    bb_status st = bb__texture_read_header(path, NULL, NULL, NULL, NULL, NULL, err);
    if (st == BB_OK) *frames = 1;
    return st;
  }
  return bb__oiio_frame_count(path, frames, err);
}

bb_status bb__image_level_count(const char *path, int *levels, bb_error *err) {
  *levels = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_level_count: path is NULL");
  if (bb__texture_read_applies(path))
    return bb__texture_read_header(path, NULL, NULL, NULL, NULL, levels, err);
  return bb__oiio_level_count(path, levels, err);
}

/* Whether ext (without its dot) is one of the extensions of OpenImageIO's
 * list: "tiff:tif,tiff;png:png;...", a format, then its extensions. */
static int list_holds(const char *list, const char *ext) {
  const size_t n = strlen(ext);
  for (const char *pos = list; *pos;) {
    const char *end = strchr(pos, ';');
    if (!end) end = pos + strlen(pos);
    const char *colon = memchr(pos, ':', (size_t)(end - pos));
    for (const char *at = colon ? colon + 1 : pos; at < end;) {
      const char *comma = memchr(at, ',', (size_t)(end - at));
      if (!comma) comma = end;
      if ((size_t)(comma - at) == n && memcmp(at, ext, n) == 0) return 1;
      at = comma + 1;
    }
    pos = *end ? end + 1 : end;
  }
  return 0;
}

int bb__path_is_readable_format(const char *path) {
  if (!path) return 0;
  char ext[256];
  bb__extension_of(path, ext, sizeof ext);
  if (strlen(ext) < 2 || strlen(ext) + 1 >= sizeof ext) return 0;
  char *list = bb__oiio_extension_list();
  if (!list) return 0;
  int found = list_holds(list, ext + 1);
  free(list);
  return found;
}
