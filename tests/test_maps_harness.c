/* test_maps_harness.c: the helpers of maps_harness.h (no tests of its own):
 * fork + exec of the binary, a temporary directory, image files. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */

#include "maps_harness.h"

#include <criterion/criterion.h>

#include <dirent.h>
#include <ftw.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static char tmpdir[64];
static char *paths[256];
static int path_count;

void harness_result_free(harness_result *r) {
  free(r->out);
  free(r->err);
  memset(r, 0, sizeof *r);
}

static char *slurp(FILE *f) {
  fflush(f);
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  cr_assert(n >= 0);
  char *buf = malloc((size_t)n + 1);
  cr_assert_not_null(buf);
  rewind(f);
  size_t got = fread(buf, 1, (size_t)n, f);
  buf[got] = '\0';
  return buf;
}

static const char *binary(void) {
  static char path[4096];
  if (!path[0]) {
    const char *bin = getenv("BB_BIN");
    if (!bin || !*bin)
      bin = "build/bumpbake";
    cr_assert(realpath(bin, path) != NULL, "BB_BIN %s not found", bin);
  }
  return path;
}

harness_result harness_run(const char *cwd, const char *const *args) {
  const char *argv[64] = {"bumpbake"};
  for (int i = 0; args[i]; i++) {
    cr_assert_lt(i, 62, "too many arguments");
    argv[i + 1] = args[i];
  }
  const char *bin = binary();
  FILE *out = tmpfile(), *err = tmpfile();
  cr_assert(out && err);
  fflush(NULL);
  pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    dup2(fileno(out), STDOUT_FILENO);
    dup2(fileno(err), STDERR_FILENO);
    if (cwd && chdir(cwd) != 0)
      _exit(126);
    execv(bin, (char *const *)argv);
    _exit(127);
  }
  int status = 0;
  cr_assert(waitpid(pid, &status, 0) == pid);
  harness_result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  fclose(out);
  fclose(err);
  return r;
}

static int remove_entry(const char *path, const struct stat *st, int flag,
                        struct FTW *ftw) {
  (void)st, (void)flag, (void)ftw;
  return remove(path);
}

void harness_setup(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/bb_maps_XXXXXX");
  cr_assert_not_null(mkdtemp(tmpdir));
}

void harness_cleanup(void) {
  if (tmpdir[0])
    nftw(tmpdir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
  tmpdir[0] = '\0';
  while (path_count > 0)
    free(paths[--path_count]);
}

const char *harness_tmpdir(void) {
  return tmpdir;
}

const char *harness_tmp(const char *name) {
  cr_assert_lt(path_count, 256);
  size_t len = strlen(tmpdir) + strlen(name) + 2;
  char *p = malloc(len);
  cr_assert_not_null(p);
  snprintf(p, len, "%s/%s", tmpdir, name);
  return paths[path_count++] = p;
}

int harness_file_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

int harness_count_lines(const char *s) {
  int n = 0;
  for (; *s; s++)
    n += *s == '\n';
  return n;
}

int harness_file_count(void) {
  DIR *d = opendir(tmpdir);
  cr_assert_not_null(d);
  int n = 0;
  for (struct dirent *e; (e = readdir(d));)
    n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  closedir(d);
  return n;
}

void harness_write(const char *path, const bb_image *img, bb_depth depth,
                   bb_range range) {
  bb_write_options o = {depth, range, NULL};
  bb_error err;
  cr_assert_eq(bb_image_write(path, img, &o, &err), BB_OK, "%s", err.message);
}

bb_image harness_read(const char *path, bb_image_info *info) {
  bb_image img;
  bb_error err;
  cr_assert_eq(bb_image_read(path, &img, info, &err), BB_OK, "%s", err.message);
  return img;
}

int harness_same_pixels(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         memcmp(a->pixels, b->pixels,
                (size_t)a->width * (size_t)a->height * (size_t)a->channels *
                    sizeof(float)) == 0;
}

double harness_max_difference(const bb_image *a, const bb_image *b) {
  cr_assert(a->width == b->width && a->height == b->height && a->channels == b->channels,
            "%dx%dx%d vs %dx%dx%d", a->width, a->height, a->channels, b->width, b->height,
            b->channels);
  double worst = 0.0;
  size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
  for (size_t i = 0; i < n; i++)
    worst = fmax(worst, fabs((double)a->pixels[i] - (double)b->pixels[i]));
  return worst;
}

void harness_expect_refusal(const char *cwd, const char *const *args, int code,
                            const char *part, int files_before, size_t case_index) {
  harness_result r = harness_run(cwd, args);
  char what[96];
  snprintf(what, sizeof what, "case %zu (%s %s)", case_index, args[0],
           args[1] ? args[1] : "");
  harness_expect_error(&r, code, part, what);
  harness_result_free(&r);
  cr_expect_eq(harness_file_count(), files_before, "%s left a file", what);
}

void harness_expect_error(const harness_result *r, int code, const char *part,
                          const char *what) {
  cr_expect_eq(r->code, code, "%s: exit %d, stderr: %s", what, r->code, r->err);
  cr_expect_eq(harness_count_lines(r->err), 1, "%s: stderr should be one line: %s", what,
               r->err);
  cr_expect(strncmp(r->err, "bumpbake", 8) == 0, "%s: %s", what, r->err);
  cr_expect(strstr(r->err, part), "%s: '%s' lacks '%s'", what, r->err, part);
  cr_expect_str_empty(r->out, "%s", what);
}
