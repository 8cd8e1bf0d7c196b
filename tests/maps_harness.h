/* maps_harness.h: running the bumpbake binary from Criterion tests, with a
 * temporary directory per test (tests/test_maps_harness.c). */
#ifndef BB_MAPS_HARNESS_H
#define BB_MAPS_HARNESS_H

#include "bumpbake.h"

#include <stddef.h>

typedef struct harness_result {
  int code;  /* exit code, or 128 + signal when it crashed */
  char *out; /* all of stdout, NUL-terminated */
  char *err; /* all of stderr */
} harness_result;

/* Runs the binary named by BB_BIN (default build/bumpbake) with args
 * (NULL-terminated, without argv[0]) in cwd (NULL = ours), without a shell. */
harness_result harness_run(const char *cwd, const char *const *args);
void harness_result_free(harness_result *r);

#define HRUN(...) harness_run(NULL, (const char *const[]){__VA_ARGS__, NULL})
#define HRUN_IN(cwd, ...) harness_run(cwd, (const char *const[]){__VA_ARGS__, NULL})

/* Makes / removes the test's temporary directory; harness_tmp(name) is a
 * path inside it, valid until harness_cleanup. */
void harness_setup(void);
void harness_cleanup(void);
const char *harness_tmp(const char *name);
const char *harness_tmpdir(void);

int harness_file_exists(const char *path);
int harness_count_lines(const char *s);
/* Files in the temporary directory (temporary files included). */
int harness_file_count(void);

/* Writes img with bb_image_write (depth and range as given); reads a file
 * back (the test fails if either cannot be done). */
void harness_write(const char *path, const bb_image *img, bb_depth depth, bb_range range);
bb_image harness_read(const char *path, bb_image_info *info);

/* 1 when a and b have the same size, channels and float bits. */
int harness_same_pixels(const bb_image *a, const bb_image *b);
/* Largest |a - b| over every sample (sizes must match). */
double harness_max_difference(const bb_image *a, const bb_image *b);

/* Expects exit code `code`, one line on stderr starting "bumpbake" and
 * holding `part`, and nothing on stdout. */
void harness_expect_error(const harness_result *r, int code, const char *part,
                          const char *what);

#endif /* BB_MAPS_HARNESS_H */
