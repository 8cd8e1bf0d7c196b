/* check_bake.c: a golden check of a batch baked in memory: each input baked
 * once (bb_job_bake_item), each of its maps made into what reading the
 * file the batch would write gives back (bb__image_as_read: the same codes,
 * the same floats), compared with the golden there, with the provenance
 * the batch would record; with an update, the maps that did not pass
 * written as the batch writes them, and no other file touched. */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "image/oiio.h"
#include "job/check.h"
#include "job/job_internal.h"
#include "texture/texture.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* An engine texture's map (.vtf, .dds) as read back: its blocks are made
 * by writing it, so it is written to a private temporary directory (never
 * beside the golden), read and removed. */
static bb_status texture_as_read(const bb_job *job, const char *path, const char *kind,
                                 const bb_image *img, bb_range range, bb_depth depth,
                                 const char *description, bb_image *out, bb_error *err) {
  const char *tmp = getenv("TMPDIR");
  char dir[PATH_MAX - 256], file[PATH_MAX];
  if ((size_t)snprintf(dir, sizeof dir, "%s/bb-check-XXXXXX",
                       tmp && *tmp ? tmp : "/tmp") >= sizeof dir ||
      !mkdtemp(dir))
    return bb__fail(err, BB_ERR_IO, "%s: cannot make a temporary directory: %s", path,
                    strerror(errno));
  snprintf(file, sizeof file, "%s/%s", dir, bb__file_name(path));
  const bb_output_file f = {file,        kind,
                            img,         range,
                            depth,       job->options.mips,
                            description, NULL,
                            0,           &job->options.texture};
  bb_status st = bb_outputs_write(&f, 1, job->options.texture.threads, err);
  if (st == BB_OK)
    st = bb_image_read(file, out, NULL, err);
  unlink(file);
  rmdir(dir);
  return st;
}

/* The golden at path as a side of a case: read, or why it is not (no file:
 * EXTRA; a link out of the golden tree, not a regular file, unreadable:
 * UNREADABLE). */
static bb_check_status read_golden(const char *root, const char *path, bb_image *img,
                                   bb_image_info *info, char *why, size_t cap) {
  struct stat s;
  if (lstat(path, &s) != 0) {
    snprintf(why, cap, "no golden at %s", path);
    return errno == ENOENT ? BB_CHECK_EXTRA : BB_CHECK_UNREADABLE;
  }
  if (S_ISLNK(s.st_mode)) {
    char real_root[PATH_MAX];
    const char *refused = bb__check_real_root(root, real_root)
                              ? bb__check_link_refusal(real_root, path)
                              : "its tree has no real path";
    if (refused) {
      snprintf(why, cap, "%s: %s", path, refused);
      return BB_CHECK_UNREADABLE;
    }
  }
  bb_error e = {{0}};
  if (bb_image_read(path, img, info, &e) != BB_OK) {
    snprintf(why, cap, "%s", e.message);
    return BB_CHECK_UNREADABLE;
  }
  return BB_CHECK_PASS;
}

/* The case of map kind of input i, decided; *update gets its bit when the
 * golden should be written. */
static bb_status map_case(bb_check *c, int i, int kind, const bb_bake_result *result,
                          bb__check_case **out, unsigned *update, bb_error *err) {
  bb_job *job = bb__check_job(c);
  const char *path = job->items[i].paths[kind];
  const bb_map_kind_info *info = bb_map_kind_get((bb_map_kind)kind);
  const char *root = bb__check_setup_of(c)->golden;
  size_t skip = strlen(job->out_dir);
  while (skip > 1 && job->out_dir[skip - 1] == '/')
    skip--;
  const double t0 = bb__now_seconds();
  bb__check_case *k =
      bb__check_case_new(path + skip + 1, path, job->items[i].input, info->name);
  char *description = bb__job_map_description(job, i, result, kind);
  if (!k || !description) {
    bb__check_case_free(k);
    free(description);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  const bb_depth depth = bb__job_map_depth(job, i, kind);
  bb_image fresh = {0}, golden = {0};
  bb_image_info golden_info = {0};
  bb_error e = {{0}};
  char why[sizeof e.message + 64] = "";
  const bb_image *map = bb__bake_result_image(result, (bb_map_kind)kind);
  bb_status made = bb__path_is_texture_format(path)
                       ? texture_as_read(job, path, info->name, map, info->range, depth,
                                         description, &fresh, &e)
                       : bb__image_as_read(path, map, depth, info->range, &fresh, &e);
  bb_check_status status = BB_CHECK_PASS;
  if (made != BB_OK) {
    status = BB_CHECK_UNREADABLE;
    snprintf(why, sizeof why, "%s", e.message);
  } else {
    status = read_golden(root, path, &golden, &golden_info, why, sizeof why);
  }
  /* A float file of a unit-vector map holds raw [-1, 1] values. */
  const int stored_float = bb__path_resolved_depth(path, depth) >= BB_DEPTH_HALF;
  const bb__check_sides sides = {golden.pixels ? &golden : NULL,
                                 fresh.pixels ? &fresh : NULL,
                                 golden_info.description,
                                 description,
                                 golden_info.is_float && info->range == BB_RANGE_SIGNED,
                                 stored_float && info->range == BB_RANGE_SIGNED};
  bb_status st =
      bb__check_decide(c, k, &sides, status, status == BB_CHECK_PASS ? NULL : why, err);
  bb_image_free(&fresh);
  bb_image_free(&golden);
  bb_image_info_free(&golden_info);
  free(description);
  k->pub.seconds = bb__now_seconds() - t0;
  if (st != BB_OK) {
    bb__check_case_free(k);
    return st;
  }
  /* A map that could not be made is not written either. */
  if (k->pub.status != BB_CHECK_PASS && made == BB_OK)
    *update |= BB_MAP_BIT(kind);
  *out = k;
  return BB_OK;
}

/* The cases of an input that did not bake: one per map, with its reason. */
static bb_status unbaked_cases(bb_check *c, int i, const bb_error *why,
                               bb_check_case_fn each, void *user, bb_error *err) {
  bb_job *job = bb__check_job(c);
  size_t skip = strlen(job->out_dir);
  while (skip > 1 && job->out_dir[skip - 1] == '/')
    skip--;
  bb_status st = BB_OK;
  for (int k = 0; k < BB_MAP_BAKED_COUNT && st == BB_OK; k++) {
    const char *path = job->items[i].paths[k];
    if (!path)
      continue;
    bb__check_case *kc = bb__check_case_new(path + skip + 1, path, job->items[i].input,
                                            bb__map_kind_name((bb_map_kind)k));
    const bb__check_sides none = {0};
    st = kc ? bb__check_decide(c, kc, &none, BB_CHECK_UNREADABLE, why->message, err)
            : bb__fail(err, BB_ERR_MEMORY, "out of memory");
    if (st == BB_OK)
      st = bb__check_add(c, kc, each, user, err);
    else
      bb__check_case_free(kc);
  }
  return st;
}

bb_status bb_check_run_input(bb_check *c, int i, bb_progress_fn progress,
                             void *progress_user, bb_check_case_fn each, void *user,
                             bb_error *err) {
  bb_job *job = c ? bb__check_job(c) : NULL;
  if (!job || i < 0 || i >= job->count)
    return bb__fail(err, BB_ERR_ARGUMENT, "check: no input %d to bake", i);
  bb_bake_result result;
  bb_error why = {{0}};
  bb_status st = bb_job_bake_item(job, i, 0u, progress, progress_user, &result, &why);
  if (st == BB_ERR_CANCELLED) {
    if (err)
      *err = why;
    return st;
  }
  /* an input that would not bake (unreadable, too large for the memory)
   * leaves its maps uncompared: cases that say why */
  if (st != BB_OK)
    return unbaked_cases(c, i, &why, each, user, err);
  bb__check_case *cases[BB_MAP_BAKED_COUNT] = {0};
  unsigned update = 0;
  for (int k = 0; k < BB_MAP_BAKED_COUNT && st == BB_OK; k++)
    if (job->items[i].paths[k])
      st = map_case(c, i, k, &result, &cases[k], &update, err);
  if (st == BB_OK && bb__check_setup_of(c)->update && update) {
    bb_error e = {{0}};
    const int written = bb__job_write_maps(job, i, &result, update, &e) == BB_OK;
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      if (cases[k] && (update & BB_MAP_BIT(k))) {
        cases[k]->pub.updated = written;
        if (!written && !cases[k]->update_error &&
            !(cases[k]->update_error = strdup(e.message)))
          st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
      }
  }
  bb_bake_result_free(&result);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    if (cases[k] && st == BB_OK)
      st = bb__check_add(c, cases[k], each, user, err);
    else
      bb__check_case_free(cases[k]);
    cases[k] = NULL;
  }
  return st;
}
