/* test_sweep.c: bb_tempfiles_sweep removes the temporaries of killed
 * writers and nothing else: not a temporary being written, here or in
 * another process, nor a file that only looks like one. */
#include <criterion/criterion.h>

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bumpbake.h"
#include "image/oiio_module.h"
#include "bumpbake_cluster.h"
#include "files/safe_file.h"
#include "image/image_write.h"

static char dir[256];

static void make_dir(void) {
  snprintf(dir, sizeof dir, "/tmp/bb-test-sweep-XXXXXX");
  cr_assert_not_null(mkdtemp(dir), "mkdtemp: %s", strerror(errno));
}

static void remove_dir(void) {
  DIR *d = opendir(dir);
  if (!d) return;
  for (struct dirent *e; (e = readdir(d));) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    if (unlink(path) != 0) { /* a private directory and its staged file */
      char inner[600];
      snprintf(inner, sizeof inner, "%s/staged.tif", path);
      unlink(inner);
      rmdir(path);
    }
  }
  closedir(d);
  rmdir(dir);
}

/* Names in dir starting with ".bb-tmp-". */
static int temporaries(void) {
  int n = 0;
  DIR *d = opendir(dir);
  cr_assert_not_null(d);
  for (struct dirent *e; (e = readdir(d));) n += strncmp(e->d_name, ".bb-tmp-", 8) == 0;
  closedir(d);
  return n;
}

static bb_image small(void) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 8, 8, 1, NULL), BB_OK);
  for (int i = 0; i < 64; i++) img.pixels[i] = (float)i / 64.0f;
  return img;
}

/* A child that stages a file and then dies by SIGKILL (what an OOM kill or
 * a worker's loss does): its temporary stays behind, unlocked. Returns
 * when it is dead. */
static void killed_writer(const char *path) {
  /* The OpenImageIO module loaded once here (src/image/oiio_module.h), so
   * each child inherits it, as it inherited OpenImageIO when the binary
   * linked it, rather than loading it again (and inside its limits). */
  cr_assert_not_null(bb__oiio_module());
  const pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    bb_image img = small();
    bb_staged_file *f = NULL;
    if (bb__image_write_staged_all_cores(path, &img, NULL, &f, NULL) != BB_OK) _exit(3);
    raise(SIGKILL);
    _exit(4);
  }
  int status = 0;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  cr_assert(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL, "status %d", status);
}

/* A mip-mapped TIFF staged through a private directory (OpenImageIO's
 * TIFF writer opens its file by name): *f, to commit or discard. */
static bb_status stage_tiff_mips(const char *path, bb_staged_file **f) {
  bb_image img = small(), *levels = NULL;
  int count = 0;
  bb_status st = bb_mip_chain(&img, BB_MIP_AVERAGE, &levels, &count, NULL);
  if (st == BB_OK) st = bb__image_write_mips_staged_all_cores(path, levels, count, NULL, f, NULL);
  bb_mip_chain_free(levels, count);
  bb_image_free(&img);
  return st;
}

/* A child that stages a mip-mapped TIFF and dies by SIGKILL: its private
 * directory, with the file in it, stays behind. */
static void killed_private_writer(const char *path) {
  /* The OpenImageIO module loaded once here (src/image/oiio_module.h), so
   * each child inherits it, as it inherited OpenImageIO when the binary
   * linked it, rather than loading it again (and inside its limits). */
  cr_assert_not_null(bb__oiio_module());
  const pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    bb_staged_file *f = NULL;
    if (stage_tiff_mips(path, &f) != BB_OK) _exit(3);
    raise(SIGKILL);
    _exit(4);
  }
  int status = 0;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  cr_assert(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL, "status %d", status);
}

/* A child that stages a file and waits on a pipe before committing it: a
 * writer alive in another process. */
static pid_t live_writer(const char *path, int *go) {
  /* The OpenImageIO module loaded once here (src/image/oiio_module.h), so
   * each child inherits it, as it inherited OpenImageIO when the binary
   * linked it, rather than loading it again (and inside its limits). */
  cr_assert_not_null(bb__oiio_module());
  int up[2], down[2];
  cr_assert_eq(pipe(up), 0);
  cr_assert_eq(pipe(down), 0);
  const pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    close(up[0]), close(down[1]);
    bb_image img = small();
    bb_staged_file *f = NULL;
    if (bb__image_write_staged_all_cores(path, &img, NULL, &f, NULL) != BB_OK) _exit(3);
    char c = 'r';
    if (write(up[1], &c, 1) != 1 || read(down[0], &c, 1) != 1) _exit(5);
    _exit(bb__staged_file_commit(f, NULL) == BB_OK ? 0 : 6);
  }
  close(up[1]), close(down[0]);
  char c;
  cr_assert_eq(read(up[0], &c, 1), 1, "the writer is staged");
  close(up[0]);
  *go = down[1];
  return pid;
}

Test(sweep, removes_only_what_killed_writers_left, .init = make_dir, .fini = remove_dir) {
  char path[512], other[512], fake[512], look[512];
  snprintf(path, sizeof path, "%s/killed.png", dir);
  killed_writer(path);
  killed_writer(path);
  cr_assert_eq(temporaries(), 2, "each killed writer left its temporary");
  cr_assert_eq(access(path, F_OK), -1, "and nothing at the final name");

  /* alive: one staged here, one in another process */
  snprintf(other, sizeof other, "%s/here.png", dir);
  bb_image img = small();
  bb_staged_file *mine = NULL;
  cr_assert_eq(bb__image_write_staged_all_cores(other, &img, NULL, &mine, NULL), BB_OK);
  snprintf(look, sizeof look, "%s/there.exr", dir);
  int go = -1;
  const pid_t there = live_writer(look, &go);
  /* and names that are not the library's temporaries */
  snprintf(fake, sizeof fake, "%s/.bb-tmp-short.png", dir);
  FILE *f = fopen(fake, "w");
  cr_assert_not_null(f);
  fclose(f);
  cr_assert_eq(temporaries(), 5);

  int removed = -1;
  bb_error err;
  cr_assert_eq(bb_tempfiles_sweep(dir, &removed, &err), BB_OK, "%s", err.message);
  cr_assert_eq(removed, 2);
  cr_assert_eq(temporaries(), 3, "the two live temporaries and the look-alike stay");

  /* the live writers still commit */
  cr_assert_eq(bb__staged_file_commit(mine, &err), BB_OK, "%s", err.message);
  char c = 'g';
  cr_assert_eq(write(go, &c, 1), 1);
  close(go);
  int status = 0;
  cr_assert_eq(waitpid(there, &status, 0), there);
  cr_assert(WIFEXITED(status) && WEXITSTATUS(status) == 0, "status %d", status);
  cr_assert_eq(access(other, F_OK), 0);
  cr_assert_eq(access(look, F_OK), 0);
  cr_assert_eq(temporaries(), 1, "the look-alike alone");
  cr_assert_eq(bb_tempfiles_sweep(dir, &removed, &err), BB_OK);
  cr_assert_eq(removed, 0);
  bb_image_free(&img);
}

Test(sweep, refuses_a_missing_directory) {
  bb_error err;
  int removed = 7;
  cr_assert_eq(bb_tempfiles_sweep("/nonexistent/bb-sweep", &removed, &err), BB_ERR_IO);
  cr_assert(strstr(err.message, "/nonexistent/bb-sweep: cannot read the directory"), "%s",
            err.message);
  cr_assert_eq(removed, 0);
  cr_assert_eq(bb_tempfiles_sweep(NULL, NULL, &err), BB_ERR_ARGUMENT);
}

Test(sweep, removes_the_private_directories_killed_writers_left, .init = make_dir,
     .fini = remove_dir) {
  char path[512], live[512], inner[600];
  snprintf(path, sizeof path, "%s/killed.tif", dir);
  killed_private_writer(path);
  cr_assert_eq(temporaries(), 1, "the killed writer left its private directory");
  DIR *d = opendir(dir);
  cr_assert_not_null(d);
  for (struct dirent *e; (e = readdir(d));)
    if (strncmp(e->d_name, ".bb-tmp-", 8) == 0) {
      snprintf(inner, sizeof inner, "%s/%s/staged.tif", dir, e->d_name);
      cr_assert_eq(access(inner, F_OK), 0, "with the file in it: %s", inner);
    }
  closedir(d);
  /* one being written here stays */
  snprintf(live, sizeof live, "%s/live.tif", dir);
  bb_staged_file *mine = NULL;
  cr_assert_eq(stage_tiff_mips(live, &mine), BB_OK);
  cr_assert_eq(temporaries(), 2);

  int removed = -1;
  bb_error err;
  cr_assert_eq(bb_tempfiles_sweep(dir, &removed, &err), BB_OK, "%s", err.message);
  cr_assert_eq(removed, 1);
  cr_assert_eq(temporaries(), 1, "the live writer's directory stays");
  cr_assert_eq(bb__staged_file_commit(mine, &err), BB_OK, "%s", err.message);
  cr_assert_eq(temporaries(), 0);
  cr_assert_eq(access(live, F_OK), 0);
}
