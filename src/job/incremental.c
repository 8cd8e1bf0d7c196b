/* incremental.c: what lets a build skip a bake whose outputs are current:
 * the hash of an input file's bytes and the header-only check of an output.
 *
 * An output is current when its stored provenance says it was made from the
 * same input bytes, by this bumpbake version, with every parameter that
 * affects pixels as now, and its file holds the depth and mip levels asked
 * for. Anything less certain (no provenance, cut provenance, a file that
 * will not open) counts as stale: a needless re-bake costs time, a wrong
 * skip leaves a wrong map.
 */

#include "bake/bake_internal.h"
#include "core/input_file.h"
#include "core/internal.h"
#include "image/oiio.h"
#include "files/provenance.h"
#include "trace/rayset.h"
#include "job/job_internal.h"
#include "texture/texture.h"
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ------------------------------------------------------------------ hash */

#define FNV64_PRIME 0x100000001b3ULL
enum { HASH_BLOCK_BYTES = 1 << 16 };

static uint64_t fnv1a_bytes(uint64_t h, const unsigned char *p, size_t n) {
  for (size_t i = 0; i < n; i++) {
    h ^= p[i];
    h *= FNV64_PRIME;
  }
  return h;
}

bb_status bb_file_hash(const char *path, uint64_t *hash, bb_error *err) {
  if (!path || !hash)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_file_hash: NULL argument");
  *hash = 0;
  /* Only regular files are hashed: a FIFO would block, a device never end. */
  int fd;
  bb_error why;
  if (bb__input_open(path, &fd, &why) != BB_OK) {
    const size_t n = bb__message_names(why.message, path);
    const char *reason =
        n && why.message[n + 1] == ' ' ? why.message + n + 2 : why.message;
    /* "cannot read: " once: the open's own reason may already say it. */
    if (strncmp(reason, "cannot read: ", 13) == 0)
      reason += 13;
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, reason);
  }
  FILE *f = fdopen(fd, "rb");
  if (!f) {
    int e = errno;
    close(fd);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(e));
  }
  unsigned char *block = malloc(HASH_BLOCK_BYTES);
  if (!block) {
    fclose(f);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  uint64_t h = BB__FNV64_OFFSET;
  size_t got;
  while ((got = fread(block, 1, HASH_BLOCK_BYTES, f)) > 0)
    h = fnv1a_bytes(h, block, got);
  int read_error = ferror(f) ? errno : 0;
  free(block);
  fclose(f);
  if (read_error)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(read_error));
  *hash = h;
  return BB_OK;
}

/* ----------------------------------------------------------------- check */

void bb__bake_rayset_id(const bb_bake_options *o, char *out, size_t cap) {
  if (!out || !cap)
    return;
  out[0] = '\0';
  bb_bake_options prepared;
  if (!o || !(o->outputs & BB_MAPS_TRACED) || bb__bake_prepare(o, &prepared, NULL) != BB_OK)
    return;
  bb__rayset_id(prepared.slices, o->power, &o->basis, out, cap);
}

/* The depth a file's samples have, as bb__image_write would have asked for
 * it; -1 for anything it does not write. */
static int depth_of(const bb_image_info *info) {
  if (info->is_float)
    return info->bits_per_sample == 16 ? BB_DEPTH_HALF
           : info->bits_per_sample == 32 ? BB_DEPTH_FLOAT
                                         : -1;
  return info->bits_per_sample == 8 ? BB_DEPTH_8 : info->bits_per_sample == 16 ? BB_DEPTH_16 : -1;
}

/* Writes why an output is not current into reason (may be NULL). */
static void say(char *reason, size_t cap, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static void say(char *reason, size_t cap, const char *fmt, ...) {
  if (!reason || !cap)
    return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(reason, cap, fmt, ap);
  va_end(ap);
}

/* The provenance the header holds against the one expected: 1 when every
 * key that matters agrees. */
static int provenance_matches(const bb_image_info *info, const char *want, char *reason,
                              size_t cap) {
  static const char *const ignored[] = {"command", "input", "input_hash", NULL};
  switch (bb__provenance_classify(info->description)) {
  case BB_PROVENANCE_NONE:
    say(reason, cap, "no bumpbake provenance");
    return 0;
  case BB_PROVENANCE_DAMAGED:
    say(reason, cap, "its provenance is damaged");
    return 0;
  case BB_PROVENANCE_INTACT:
    break;
  }
  return !bb__provenance_mismatch(info->description, want, ignored, reason, cap);
}

/* Depth and mip levels of the file against what writing it would give. */
static int layout_matches(const char *path, const bb_image_info *info, bb_depth depth,
                          int mip_mapped, char *reason, size_t cap) {
  int want = bb__path_resolved_depth(path, depth), have = depth_of(info);
  if (want < 0 || have != want) {
    say(reason, cap, "%s samples; %s asked", bb__depth_words(have),
        bb__depth_words(want));
    return 0;
  }
  int levels = 0;
  bb_error why;
  if (bb__image_level_count(path, &levels, &why) != BB_OK) {
    say(reason, cap, "%s", why.message);
    return 0;
  }
  if ((levels > 1) != (mip_mapped != 0)) {
    say(reason, cap, "%s; %s asked", levels > 1 ? "mip-mapped" : "one level",
        mip_mapped ? "mip-mapped" : "one level");
    return 0;
  }
  return 1;
}

bb_status bb__output_check(const char *path, const bb_provenance *expected, bb_depth depth,
                          int mip_mapped, bb_output_state *state, char *reason, size_t cap,
                          bb_error *err) {
  if (reason && cap)
    reason[0] = '\0';
  if (!path || !expected || !state)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__output_check: NULL argument");
  if (depth < BB_DEPTH_DEFAULT || depth > BB_DEPTH_FLOAT)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__output_check: unknown depth %d", (int)depth);
  *state = BB_OUTPUT_STALE;
  struct stat st;
  if (stat(path, &st) != 0 && errno == ENOENT) {
    *state = BB_OUTPUT_MISSING;
    say(reason, cap, "no such file");
    return BB_OK;
  }
  if (!expected->input_file_hash) {
    say(reason, cap, "the input file's hash is not known");
    return BB_OK;
  }
  char *want = bb__provenance_format(expected);
  if (!want)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  bb_image_info info;
  bb_error why;
  if (bb_image_read_info(path, NULL, NULL, NULL, &info, &why) != BB_OK) {
    say(reason, cap, "%s", why.message);
  } else {
    /* A texture's layout (format, mips, VTF flags) is in its provenance. */
    if (provenance_matches(&info, want, reason, cap) &&
        (bb__path_is_texture_format(path) ||
         layout_matches(path, &info, depth, mip_mapped, reason, cap)))
      *state = BB_OUTPUT_CURRENT;
    bb_image_info_free(&info);
  }
  free(want);
  return BB_OK;
}
