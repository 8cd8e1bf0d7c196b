/* file_bytes.h: a whole file's bytes read into memory, and bytes written
 * as a file, each asserting it worked (the tests that take files apart
 * byte by byte: VTF, DDS, the job's writes). */
#ifndef BB_TESTS_FILE_BYTES_H
#define BB_TESTS_FILE_BYTES_H

#include <criterion/criterion.h>

#include <stdio.h>
#include <stdlib.h>

/* The bytes of path (their count in *size), malloc'd with a NUL after
 * them, so a text file is also a string. */
static inline unsigned char *file_bytes(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s", path);
  fseek(f, 0, SEEK_END);
  const long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  cr_assert(n >= 0, "%s", path);
  unsigned char *data = malloc((size_t)n + 1);
  cr_assert_not_null(data);
  cr_assert_eq(fread(data, 1, (size_t)n, f), (size_t)n, "%s", path);
  fclose(f);
  data[n] = '\0';
  *size = (size_t)n;
  return data;
}

/* Writes size bytes of data as path. */
static inline void file_bytes_write(const char *path, const unsigned char *data, size_t size) {
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f, "%s", path);
  cr_assert_eq(fwrite(data, 1, size, f), size, "%s", path);
  cr_assert_eq(fclose(f), 0, "%s", path);
}

#endif
