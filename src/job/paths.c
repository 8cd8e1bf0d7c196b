/* paths.c: the output paths of a command, checked before any work: formats,
 * depths, channels, clashes, inputs overwritten under any spelling, and
 * directories. */
#include "core/internal.h"
#include "files/safe_file.h"
#include "image/formats.h"
#include "job/job_internal.h"
#include "image/oiio.h"
#include "texture/texture.h"

#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* ------------------------------------------------------------ path parts */

char *bb__path_with_suffix(const char *path, const char *suffix) {
  if (!path || !suffix)
    return NULL;
  const char *dot = bb__file_extension(path);
  size_t stem = dot ? (size_t)(dot - path) : strlen(path);
  size_t len = stem + strlen(suffix) + 1;
  char *out = malloc(len);
  if (out)
    snprintf(out, len, "%.*s%s", (int)stem, path, suffix);
  return out;
}

char *bb__job_prefix_path(const char *prefix, bb_map_kind kind) {
  if (!prefix || (unsigned)kind >= BB_MAP_BAKED_COUNT || !(BB_JOB_DEFAULT_MAPS & BB_MAP_BIT(kind)))
    return NULL;
  const char *name = bb_map_kind_get(kind)->name;
  const size_t len = strlen(prefix) + strlen(name) + sizeof "_.png";
  char *path = malloc(len);
  if (path)
    snprintf(path, len, "%s_%s.png", prefix, name);
  return path;
}

bb_status bb__job_map_file(const bb_job_options *o, bb_map_kind kind, char **path, bb_error *err) {
  *path = NULL;
  if ((unsigned)kind >= BB_MAP_BAKED_COUNT)
    return BB_OK;
  if (o->paths[kind])
    *path = strdup(o->paths[kind]);
  else if (o->prefix && (BB_JOB_DEFAULT_MAPS & BB_MAP_BIT(kind)))
    *path = bb__job_prefix_path(o->prefix, kind);
  else
    return BB_OK;
  return *path ? BB_OK : bb__fail(err, BB_ERR_MEMORY, "out of memory");
}

/* Valve's normal2ssbump output name: the input up to its first "_normal"
 * (any case), else up to its first '.', then "_ssbump.tga". Valve's tool
 * searches the whole path; this searches the file name only, so a directory
 * such as maps_normal/ or v1.2/ is left alone. */
char *bb__job_valve_weights_name(const char *input) {
  const char *name = bb__file_name(input);
  const char *cut = NULL;
  for (const char *p = name; *p && !cut; p++)
    if (strncasecmp(p, "_normal", 7) == 0)
      cut = p;
  if (!cut)
    cut = strchr(name, '.');
  if (!cut)
    cut = name + strlen(name);
  const size_t keep = (size_t)(cut - input);
  char *out = malloc(keep + sizeof "_ssbump.tga");
  if (out) {
    memcpy(out, input, keep);
    strcpy(out + keep, "_ssbump.tga");
  }
  return out;
}

/* ------------------------------------------------------------ same file */

int bb__same_file(const char *a, const char *b) {
  if (!a || !b)
    return 0;
  const bb__file_identity ia = bb__file_identify(a), ib = bb__file_identify(b);
  return bb__same_file_identity(&ia, &ib);
}

/* ----------------------------------------------------------- directories */

bb_status bb__directory_create(const char *path, bb_error *err) {
  if (!path || !*path)
    return bb__fail(err, BB_ERR_ARGUMENT, "no directory name given");
  char buf[PATH_MAX];
  if (strlen(path) >= sizeof buf)
    return bb__fail(err, BB_ERR_IO, "%.64s...: cannot create directory: name too long", path);
  snprintf(buf, sizeof buf, "%s", path);
  /* Each prefix ending before a '/', then the whole: mkdir -p. */
  for (char *p = buf + 1;; p++) {
    const int end = *p == '\0';
    if (*p != '/' && !end)
      continue;
    *p = '\0';
    struct stat st;
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
      return bb__fail(err, BB_ERR_IO, "%s: cannot create directory: %s", buf,
                      strerror(errno));
    if (stat(buf, &st) != 0 || !S_ISDIR(st.st_mode))
      return bb__fail(err, BB_ERR_IO, "%s: cannot create directory: a file of that name exists",
                      buf);
    if (end)
      break;
    *p = '/';
    while (p[1] == '/')
      p++;
  }
  return BB_OK;
}

bb_status bb__check_output_directory(const char *path, bb_error *err) {
  char dir[PATH_MAX];
  bb__directory_part(path, dir, sizeof dir);
  struct stat st;
  if (stat(dir, &st) != 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: directory %s: %s", path, dir,
                    strerror(errno));
  if (!S_ISDIR(st.st_mode))
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s is not a directory", path, dir);
  /* A directory, a device, a FIFO, a socket or a symbolic link would be
   * replaced by the rename that puts the output in place. */
  return bb__safe_check_target(path, err);
}

/* ---------------------------------------------------------------- checks */

/* The format rules of one image output: its extension and depth, or (late
 * is 1) its mip chain and channels, checked after its paths as they always
 * were, so the first message of several stays the same. */
bb_texture_options bb__job_texture_of(const bb_texture_options *given, const char *kind,
                                      bb_range range) {
  bb_texture_options t;
  if (given)
    t = *given;
  else
    bb_texture_options_init(&t);
  bb__texture_options_for(&t, kind, range);
  return t;
}

static bb_status check_format(const bb_output_spec *o, int late, bb_error *err) {
  char ext[17]; /* ".ext" (bb__extension_of), 15 characters of it at most */
  bb__extension_of(o->path, ext, sizeof ext);
  if (late) {
    if (o->mips && !bb__path_supports_mips(o->path))
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: --mips needs a .tif or .exr output", o->path);
    const int room = bb__path_max_channels(o->path);
    if (o->channels > room)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: %s has %d channels and %s files hold at most %d (write it as "
                      ".exr or .tif)",
                      o->path, o->kind ? o->kind : "the image", o->channels, ext, room);
    if (bb__path_is_texture_format(o->path) && o->width > 0 && o->channels > 0) {
      const bb_texture_options t = bb__job_texture_of(o->texture, o->kind, o->range);
      return bb__texture_check(o->path, o->width, o->height, o->channels, &t, err);
    }
    return BB_OK;
  }
  if (!bb__path_is_writable_format(o->path)) {
    if (!ext[0] || !ext[1]) /* none, or a bare dot */
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: no extension to choose the format by (use .png, .tga, .tif, "
                      ".tiff, .exr, .vtf or .dds)",
                      o->path);
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: unknown output format '%s' (use .png, .tga, .tif, .tiff, .exr, .vtf "
                    "or .dds)",
                    o->path, ext);
  }
  if (!bb__path_supports_depth(o->path, o->depth))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: --depth %s is not available in %s files%s",
                    o->path, bb__depth_name(o->depth), ext,
                    bb__path_is_texture_format(o->path) ? " (their texture format sets it)" : "");
  return BB_OK;
}

bb_status bb_outputs_check(const bb_output_spec *outputs, int count,
                           const char *const *reads, int read_count, bb_error *err) {
  return bb__outputs_check(outputs, count, reads, read_count, 1, err);
}

bb_status bb__outputs_check(const bb_output_spec *outputs, int count, const char *const *reads,
                            int read_count, int directories, bb_error *err) {
  if (count < 0 || (count > 0 && !outputs) || read_count < 0 || (read_count > 0 && !reads))
    return bb__fail(err, BB_ERR_ARGUMENT, "outputs check: bad arguments");
  /* Each name is looked up once; the comparisons are then in memory, so
   * the thousands of frames of an orbit check in a moment. */
  bb__file_identity *ids = malloc(((size_t)count + (size_t)read_count + 1) * sizeof *ids);
  if (!ids)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  bb__file_identity *in = ids + count;
  for (int r = 0; r < read_count; r++)
    if (reads[r])
      in[r] = bb__file_identify(reads[r]);
  bb_status st = BB_OK;
  for (int k = 0; k < count && st == BB_OK; k++) {
    const bb_output_spec *o = &outputs[k];
    if (!o->path || !*o->path) {
      st = bb__fail(err, BB_ERR_ARGUMENT, "%s: no file name given", o->kind ? o->kind : "output");
      break;
    }
    ids[k] = bb__file_identify(o->path);
    for (int j = 0; j < k && st == BB_OK; j++)
      if (bb__same_file_identity(&ids[j], &ids[k]))
        st = bb__fail(err, BB_ERR_ARGUMENT, "%s and %s would both be written to %s",
                      outputs[j].kind ? outputs[j].kind : "an output",
                      o->kind ? o->kind : "another", o->path);
    if (st == BB_OK && !o->text)
      st = check_format(o, 0, err);
    for (int r = 0; r < read_count && st == BB_OK; r++)
      if (reads[r] && bb__same_file_identity(&in[r], &ids[k]))
        st = bb__refuse_output_over_input(err, o->path, reads[r]);
    if (st == BB_OK && directories)
      st = bb__check_output_directory(o->path, err);
    if (st == BB_OK && !o->text)
      st = check_format(o, 1, err);
  }
  free(ids);
  return st;
}
