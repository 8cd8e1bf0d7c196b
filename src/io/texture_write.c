/* texture_write.c: bb_texture_write: a VTF or DDS file by extension, staged
 * and committed as every file the library writes. */

#include "core/internal.h"
#include "io/dds.h"
#include "io/safe_file.h"
#include "io/texture.h"
#include "io/vtf.h"

#include <stdlib.h>

/* Checks, encodes into a temporary and finishes it: on success f holds the
 * complete file under its temporary name. */
static bb_status write_finished(const char *path, const bb_image *img,
                                const bb_texture_options *options, bb_staged_file *f,
                                bb_error *err) {
  bb_texture_options defaults;
  bb_texture_options_init(&defaults);
  const bb_texture_options *o = options ? options : &defaults;
  if (!img || !img->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no image", path ? path : "texture");
  bb_texture_format format;
  bb_status st = bb__texture_resolve(path, img->width, img->height, img->channels, o,
                                     &format, err);
  if (st != BB_OK)
    return st;
  st = bb__safe_open(f, path, err);
  if (st != BB_OK)
    return st;
  st = bb__texture_container(path) == BB__CONTAINER_VTF
           ? bb__vtf_encode(f, img, o, format, err)
           : bb__dds_encode(f, img, o, format, err);
  if (st != BB_OK) {
    bb__safe_discard(f);
    return st;
  }
  return bb__safe_finish(f, err);
}

bb_status bb_texture_write(const char *path, const bb_image *img,
                           const bb_texture_options *options, bb_error *err) {
  bb_staged_file f;
  bb_status st = write_finished(path, img, options, &f, err);
  return st == BB_OK ? bb__safe_commit(&f, err) : st;
}

bb_status bb_texture_write_staged(const char *path, const bb_image *img,
                                  const bb_texture_options *options,
                                  bb_staged_file **staged, bb_error *err) {
  if (!staged)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_texture_write_staged: staged is NULL");
  *staged = NULL;
  bb_staged_file *f = bb__staged_new();
  if (!f)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path ? path : "texture");
  bb_status st = write_finished(path, img, options, f, err);
  if (st != BB_OK) {
    free(f);
    return st;
  }
  *staged = f;
  return BB_OK;
}
