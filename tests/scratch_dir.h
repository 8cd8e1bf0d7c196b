/* scratch_dir.h: one private directory under /tmp for a test file, paths in
 * it, and its removal (with everything a test left there, without a shell).
 * A test file includes it once and calls scratch_dir_make("stem") from its
 * suite's .init and scratch_dir_remove() from its .fini. The file defines
 * _XOPEN_SOURCE 700 before its first include (mkdtemp, nftw). */
#ifndef BB_TESTS_SCRATCH_DIR_H
#define BB_TESTS_SCRATCH_DIR_H

#if !defined(_XOPEN_SOURCE) && !defined(_GNU_SOURCE)
#error "scratch_dir.h: define _XOPEN_SOURCE 700 before the first include (mkdtemp, nftw)"
#endif

#include <criterion/criterion.h>

#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char scratch_dir[64]; /* /tmp/STEM_XXXXXX */

/* Makes /tmp/STEM_XXXXXX. */
static inline void scratch_dir_make(const char *stem) {
  snprintf(scratch_dir, sizeof scratch_dir, "/tmp/%s_XXXXXX", stem);
  cr_assert_not_null(mkdtemp(scratch_dir), "mkdtemp %s: %s", scratch_dir, strerror(errno));
}

static inline int scratch_dir_remove_one(const char *path, const struct stat *st, int type,
                                         struct FTW *walk) {
  (void)st, (void)type, (void)walk;
  return remove(path) == 0 || errno == ENOENT ? 0 : -1;
}

/* Removes the directory and all it holds; asserts it went. */
static inline void scratch_dir_remove(void) {
  if (!scratch_dir[0])
    return;
  cr_assert_eq(nftw(scratch_dir, scratch_dir_remove_one, 16, FTW_DEPTH | FTW_PHYS), 0,
               "cannot remove %s: %s", scratch_dir, strerror(errno));
  scratch_dir[0] = '\0';
}

/* SCRATCH_DIR/name, in one of eight rotating buffers (so a call can take
 * several paths). */
static inline const char *in_scratch_dir(const char *name) {
  static char paths[8][512];
  static unsigned next;
  char *p = paths[next++ % 8];
  snprintf(p, sizeof paths[0], "%s/%s", scratch_dir, name);
  return p;
}

#endif
