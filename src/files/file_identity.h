/* file_identity.h: whether two names are one file, the one test behind
 * every "an output may not be a file the command reads" and "two outputs
 * may not name one file" (file_identity.c). */
#ifndef BB_FILES_FILE_IDENTITY_H
#define BB_FILES_FILE_IDENTITY_H

#include "bumpbake.h"

#include <sys/types.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Which file a path names, worked out once : the file itself when
 * it exists, and the directory entry a write of it replaces (its
 * directory's device and inode and its last component) when the directory
 * exists. path and name point into the caller's string. */
typedef struct bb__file_identity {
  int exists;
  dev_t dev;
  ino_t ino;
  int dir_exists;
  dev_t dir_dev;
  ino_t dir_ino;
  const char *name;
  const char *path;
} bb__file_identity;
bb__file_identity bb__file_identify(const char *path);

/* 1 when a and b name one file: one existing file under two names (links,
 * "./", ".."), or, for files not made yet, the same name in the same
 * directory however it is spelled; else the same spelling. */
int bb__same_file_identity(const bb__file_identity *a, const bb__file_identity *b);

/* The refusal of an output that is a file the command reads: BB_ERR_IO
 * (exit 1, docs/limits.md) and "OUTPUT: would overwrite the input INPUT". */
bb_status bb__refuse_output_over_input(bb_error *err, const char *output, const char *input);

#ifdef __cplusplus
}
#endif

#endif
