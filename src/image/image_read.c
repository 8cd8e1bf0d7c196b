/* image_read.c: the public image reads (bumpbake.h "reading images") and
 * bb__image_read_channels / bb__image_level_count (image/oiio.h): arguments
 * checked, outputs cleared, OpenImageIO called (oiio_read.cpp), and
 * whatever a failed read made freed. */
#include "core/internal.h"
#include "image/formats.h"
#include "image/oiio.h"
#include "image/oiio_calls.h"
#include "texture/texture.h"
#include "texture/vtf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* OpenImageIO has no VTF reader: its header is read here (vtf.c), and its
 * pixels are not read at all. */
static bb_status refuse_vtf_pixels(const char *path, bb_error *err) {
  return bb__fail(err, BB_ERR_FORMAT,
                  "%s: VTF textures are written, not read, by bumpbake (info reads their "
                  "header; compare the image they were made from)",
                  path);
}

/* A VTF's header as bb_image_read_info reports an image's. */
static bb_status read_vtf_info(const char *path, int *width, int *height, int *channels,
                               bb_image_info *info, bb_error *err) {
  bb_vtf_info v;
  bb_status st = bb_vtf_read_info(path, &v, err);
  if (st != BB_OK) return st;
  const int alpha = v.format == BB__VTF_DXT5 || v.format == BB__VTF_BGRA8888 ||
                    v.format == BB__VTF_RGBA16161616F ||
                    (v.flags & BB_VTF_FLAG_EIGHTBITALPHA) != 0;
  if (width) *width = v.width;
  if (height) *height = v.height;
  if (channels) *channels = alpha ? 4 : 3;
  if (info) {
    info->alpha_channel = alpha ? 3 : -1;
    info->is_float = v.format == BB__VTF_RGBA16161616F;
    info->bits_per_sample = info->is_float ? 16 : 8;
    snprintf(info->format_name, sizeof info->format_name, "vtf");
    info->description = v.description;
    v.description = NULL;
  }
  bb_vtf_info_free(&v);
  return BB_OK;
}

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
  if (bb__texture_container(path) == BB__CONTAINER_VTF) return refuse_vtf_pixels(path, err);
  return finish_read(bb__oiio_read(path, 0, -1, 0, out, info, NULL, err), out, info);
}

bb_status bb__image_read_channels(const char *path, int first_channel, int channel_count,
                                  bb_image *out, bb_image_info *info, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_channels: out is NULL");
  memset(out, 0, sizeof *out);
  clear_info(info);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_channels: path is NULL");
  if (channel_count < 1) return bb__fail(err, BB_ERR_ARGUMENT, "%s: no channel to read", path);
  if (bb__texture_container(path) == BB__CONTAINER_VTF) return refuse_vtf_pixels(path, err);
  return finish_read(bb__oiio_read(path, first_channel, channel_count, 0, out, info, NULL, err),
                     out, info);
}

bb_status bb_image_read_mip(const char *path, int level, bb_image *out, bb_image_info *info,
                            int *level_count, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_mip: out is NULL");
  memset(out, 0, sizeof *out);
  clear_info(info);
  if (level_count) *level_count = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_mip: path is NULL");
  if (bb__texture_container(path) == BB__CONTAINER_VTF) return refuse_vtf_pixels(path, err);
  int levels = 0; /* counted whatever the caller asks: a level past the last is an error */
  bb_status st = bb__oiio_read(path, 0, -1, level, out, info, &levels, err);
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
  if (bb__texture_container(path) == BB__CONTAINER_VTF)
    return read_vtf_info(path, width, height, channels, info, err);
  bb_status st = bb__oiio_read_header(path, width, height, channels, info, err);
  if (st != BB_OK) bb_image_info_free(info);
  return st;
}

bb_status bb_image_frame_count(const char *path, int *frames, bb_error *err) {
  if (!path || !frames)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_frame_count: NULL argument");
  *frames = 0;
  return bb__oiio_frame_count(path, frames, err);
}

bb_status bb__image_level_count(const char *path, int *levels, bb_error *err) {
  *levels = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_level_count: path is NULL");
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

int bb_path_is_readable_format(const char *path) {
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
