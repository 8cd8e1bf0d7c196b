/* image_write.c: the public image writes (bumpbake.h "writing images"):
 * what may be written checked first (formats.c), then encoded through
 * OpenImageIO into a staged temporary (oiio_write.cpp, oiio_mips.cpp), or
 * as an engine texture (texture_write.c), that is committed, or left staged
 * for the caller, or removed on any failure. */
#include "core/internal.h"
#include "image/formats.h"
#include "image/image_write.h"
#include "image/oiio_calls.h"
#include "files/safe_file.h"
#include "texture/texture.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A .vtf or .dds: the write options' texture settings, their lines added
 * to the provenance (bb__texture_provenance), levels[0] alone (given 0) or
 * the caller's chain. */
static bb_status write_texture(const char *path, const bb_image *levels, int count, int given,
                               const bb_write_options *options, bb_staged_file *f,
                               bb_error *err) {
  bb_texture_options t;
  bb__texture_options_of(options, &t);
  char *described = NULL;
  if (t.description) {
    char *lines = bb__texture_provenance(path, &t);
    const size_t n = strlen(t.description) + (lines ? strlen(lines) : 0) + 2;
    described = lines ? malloc(n) : NULL;
    if (!described) {
      free(lines);
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
    }
    const size_t len = strlen(t.description);
    snprintf(described, n, "%s%s%s", t.description,
             len && t.description[len - 1] != '\n' ? "\n" : "", lines);
    free(lines);
    t.description = described;
  }
  bb_status st = bb__texture_stage(path, levels, count, given, &t, f, err);
  free(described);
  return st;
}

static bb_status write_image(const char *path, const bb_image *img,
                             const bb_write_options *options, int threads, bb_staged_file *f,
                             bb_error *err) {
  bb_depth depth;
  bb_status st = bb__write_check(path, img, options, &depth, err);
  if (st != BB_OK) return st;
  if (bb__path_is_texture_format(path)) return write_texture(path, img, 1, 0, options, f, err);
  st = bb__oiio_write_image(path, img, depth, options ? options->range : BB_RANGE_UNIT,
                            options ? options->description : NULL, threads, NULL, f, err);
  if (st != BB_OK) bb__safe_discard(f);
  return st;
}

static bb_status write_mips(const char *path, const bb_image *levels, int count,
                            const bb_write_options *options, int threads, bb_staged_file *f,
                            bb_error *err) {
  bb_depth depth;
  bb_status st = bb__write_mips_check(path, levels, count, options, &depth, err);
  if (st != BB_OK) return st;
  if (bb__path_is_texture_format(path))
    return write_texture(path, levels, count, 1, options, f, err);
  st = bb__oiio_write_mips(path, levels, count, depth, options ? options->range : BB_RANGE_UNIT,
                           options ? options->description : NULL, threads, f, err);
  if (st != BB_OK) bb__safe_discard(f);
  return st;
}

bb_status bb__image_write(const char *path, const bb_image *img, const bb_write_options *options,
                         bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_write: path is NULL");
  bb_staged_file f;
  bb__safe_init(&f);
  bb_status st = write_image(path, img, options, 0, &f, err);
  return st == BB_OK ? bb__safe_commit(&f, err) : st;
}

bb_status bb__image_write_staged_all_cores(const char *path, const bb_image *img,
                                const bb_write_options *options, bb_staged_file **staged,
                                bb_error *err) {
  return bb__image_write_staged(path, img, options, 0, staged, err);
}

bb_status bb__image_write_staged(const char *path, const bb_image *img,
                                 const bb_write_options *options, int threads,
                                 bb_staged_file **staged, bb_error *err) {
  if (!staged) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_write_staged_all_cores: staged is NULL");
  *staged = NULL;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_write_staged_all_cores: path is NULL");
  bb_staged_file *f = bb__staged_new();
  if (!f) return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  bb_status st = write_image(path, img, options, threads, f, err);
  if (st != BB_OK) {
    free(f);
    return st;
  }
  *staged = f;
  return BB_OK;
}

bb_status bb__image_write_mips(const char *path, const bb_image *levels, int count,
                              const bb_write_options *options, bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_write_mips: path is NULL");
  bb_staged_file f;
  bb__safe_init(&f);
  bb_status st = write_mips(path, levels, count, options, 0, &f, err);
  return st == BB_OK ? bb__safe_commit(&f, err) : st;
}

bb_status bb__image_write_mips_staged_all_cores(const char *path, const bb_image *levels, int count,
                                     const bb_write_options *options,
                                     bb_staged_file **staged, bb_error *err) {
  return bb__image_write_mips_staged(path, levels, count, options, 0, staged, err);
}

bb_status bb__image_write_mips_staged(const char *path, const bb_image *levels, int count,
                                      const bb_write_options *options, int threads,
                                      bb_staged_file **staged, bb_error *err) {
  if (!staged)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_write_mips_staged_all_cores: staged is NULL");
  *staged = NULL;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_write_mips_staged_all_cores: path is NULL");
  bb_staged_file *f = bb__staged_new();
  if (!f) return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  bb_status st = write_mips(path, levels, count, options, threads, f, err);
  if (st != BB_OK) {
    free(f);
    return st;
  }
  *staged = f;
  return BB_OK;
}
