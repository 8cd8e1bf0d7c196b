/* fuzz_common.h: what the libFuzzer targets share: a private scratch
 * directory in /dev/shm (memory, not disk) and writing an input there. */
#ifndef BB_FUZZ_COMMON_H
#define BB_FUZZ_COMMON_H

#include <dirent.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char fuzz_scratch[64];

/* Removes the scratch directory and the files the targets left in it. */
static inline void fuzz_remove_scratch(void) {
  DIR *d = opendir(fuzz_scratch);
  if (!d)
    return;
  for (struct dirent *e; (e = readdir(d)) != NULL;) {
    char path[sizeof fuzz_scratch + 256];
    snprintf(path, sizeof path, "%s/%s", fuzz_scratch, e->d_name);
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
      unlink(path);
  }
  closedir(d);
  rmdir(fuzz_scratch);
}

/* A directory of this process, made on first use, kept for the next input
 * (libFuzzer runs millions in one process) and removed at exit. */
static inline const char *fuzz_scratch_dir(void) {
  if (!fuzz_scratch[0]) {
    snprintf(fuzz_scratch, sizeof fuzz_scratch, "/dev/shm/bb-fuzz-XXXXXX");
    if (!mkdtemp(fuzz_scratch)) {
      perror("fuzz: mkdtemp");
      abort();
    }
    atexit(fuzz_remove_scratch);
  }
  return fuzz_scratch;
}

/* Writes data to DIR/name and returns the path (static buffer). */
static inline const char *fuzz_write_file(const char *name, const uint8_t *data,
                                          size_t size) {
  static char path[128];
  snprintf(path, sizeof path, "%s/%s", fuzz_scratch_dir(), name);
  FILE *f = fopen(path, "wb");
  if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
    perror("fuzz: scratch file");
    abort();
  }
  return path;
}

/* Stops the fuzzer with a crash report when a property fails. */
#define FUZZ_CHECK(cond)                                                                 \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      fprintf(stderr, "fuzz: check failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__);    \
      abort();                                                                           \
    }                                                                                    \
  } while (0)

#endif /* BB_FUZZ_COMMON_H */
