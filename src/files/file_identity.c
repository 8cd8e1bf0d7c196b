/* file_identity.c: whether two names are one file (file_identity.h). */
#include "files/file_identity.h"
#include "core/file_names.h"
#include "core/internal.h"

#include <limits.h>
#include <string.h>
#include <sys/stat.h>

bb__file_identity bb__file_identify(const char *path) {
  bb__file_identity id = {0};
  id.path = path;
  struct stat st;
  if (stat(path, &st) == 0) {
    id.exists = 1;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
  }
  char dir[PATH_MAX];
  bb__directory_part(path, dir, sizeof dir);
  if (stat(dir, &st) == 0) {
    id.dir_exists = 1;
    id.dir_dev = st.st_dev;
    id.dir_ino = st.st_ino;
  }
  id.name = bb__file_name(path);
  return id;
}

int bb__same_file_identity(const bb__file_identity *a, const bb__file_identity *b) {
  /* Two names of one existing file (symbolic or hard links, "./", ".."). */
  if (a->exists && b->exists)
    return a->dev == b->dev && a->ino == b->ino;
  /* Files not made yet: the same name in the same directory, however the
   * directory is spelled. */
  if (a->dir_exists && b->dir_exists)
    return a->dir_dev == b->dir_dev && a->dir_ino == b->dir_ino && strcmp(a->name, b->name) == 0;
  return strcmp(a->path, b->path) == 0;
}

bb_status bb__refuse_output_over_input(bb_error *err, const char *output, const char *input) {
  return bb__fail(err, BB_ERR_IO, "%s: would overwrite the input %s", output, input);
}
