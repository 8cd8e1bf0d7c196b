/* test_untrusted.c: files every read must treat as hostile (docs: "Input
 * files are untrusted"): FIFOs and devices under an input's name. Each
 * call runs in a child with an alarm, so a regression that blocks fails
 * here instead of hanging the suite. */
#include <criterion/criterion.h>

#include "bumpbake.h"

#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char tmpdir[256];

static void make_tmpdir(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/bb-test-untrusted-XXXXXX");
  cr_assert_not_null(mkdtemp(tmpdir), "mkdtemp: %s", strerror(errno));
}

static void remove_tmpdir(void) {
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
  cr_assert_eq(system(cmd), 0);
}

TestSuite(untrusted, .init = make_tmpdir, .fini = remove_tmpdir, .timeout = 120);

static const char *tmp_path(const char *name) {
  static char buf[4][512];
  static int next = 0;
  char *p = buf[next++ % 4];
  snprintf(p, 512, "%s/%s", tmpdir, name);
  return p;
}

/* ----------------------------------------------------------- the harness */

typedef bb_status (*call_fn)(const char *path, bb_error *err);

typedef struct outcome {
  bb_status status;
  int signal;     /* the child's killing signal, or 0 */
  double seconds; /* wall-clock time of the call */
  char message[600];
} outcome;

/* Runs fn(path) in a child killed after `alarm_seconds`, and reports its
 * status, message and time. */
static outcome run_call(call_fn fn, const char *path, unsigned alarm_seconds) {
  outcome o;
  memset(&o, 0, sizeof o);
  int fds[2];
  cr_assert_eq(pipe(fds), 0);
  fflush(NULL);
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    close(fds[0]);
    alarm(alarm_seconds);
    bb_error err = {{0}};
    bb_status st = fn(path, &err);
    ssize_t n = write(fds[1], err.message, strlen(err.message));
    (void)n;
    _exit((int)st);
  }
  close(fds[1]);
  ssize_t got = read(fds[0], o.message, sizeof o.message - 1);
  o.message[got > 0 ? got : 0] = '\0';
  close(fds[0]);
  int status = 0;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  o.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  if (WIFSIGNALED(status))
    o.signal = WTERMSIG(status);
  else
    o.status = (bb_status)WEXITSTATUS(status);
  return o;
}

/* --------------------------------------------- every reader of the library */

static bb_status call_read(const char *path, bb_error *err) {
  bb_image img;
  bb_status st = bb_image_read(path, &img, NULL, err);
  bb_image_free(&img);
  return st;
}

static bb_status call_read_info(const char *path, bb_error *err) {
  int w, h, c;
  return bb_image_read_info(path, &w, &h, &c, NULL, err);
}

static bb_status call_read_mip(const char *path, bb_error *err) {
  bb_image img;
  int levels;
  bb_status st = bb_image_read_mip(path, 0, &img, NULL, &levels, err);
  bb_image_free(&img);
  return st;
}

static bb_status call_frame_count(const char *path, bb_error *err) {
  int frames;
  return bb_image_frame_count(path, &frames, err);
}

static bb_status call_basis_load(const char *path, bb_error *err) {
  bb_basis b;
  return bb_basis_load(path, &b, err);
}

static bb_status call_file_hash(const char *path, bb_error *err) {
  uint64_t h;
  return bb_file_hash(path, &h, err);
}

static const struct {
  const char *name;
  call_fn fn;
} READERS[] = {
    {"bb_image_read", call_read},       {"bb_image_read_info", call_read_info},
    {"bb_image_read_mip", call_read_mip}, {"bb_image_frame_count", call_frame_count},
    {"bb_basis_load", call_basis_load}, {"bb_file_hash", call_file_hash},
};

/* Every reader refuses path at once: BB_ERR_IO, one line naming the file
 * and saying what it is, well under a second (a FIFO with no writer used to
 * block in open() for ever, /dev/zero to be read without end). */
static void expect_refused_at_once(const char *path, const char *what) {
  for (size_t i = 0; i < sizeof READERS / sizeof READERS[0]; i++) {
    outcome o = run_call(READERS[i].fn, path, 10);
    cr_expect_eq(o.signal, 0, "%s(%s): killed by signal %d after %.1f s (it blocked)",
                 READERS[i].name, path, o.signal, o.seconds);
    if (o.signal) continue;
    cr_expect_eq(o.status, BB_ERR_IO, "%s(%s): %s", READERS[i].name, path, o.message);
    cr_expect(strstr(o.message, path) && strstr(o.message, what), "%s: '%s'", READERS[i].name,
              o.message);
    cr_expect_null(strchr(o.message, '\n'), "%s: '%s'", READERS[i].name, o.message);
    cr_expect_lt(o.seconds, 0.5, "%s(%s) took %.2f s", READERS[i].name, path, o.seconds);
  }
}

Test(untrusted, a_fifo_is_refused_by_every_reader_without_blocking) {
  const char *fifo = tmp_path("pipe.png");
  cr_assert_eq(mkfifo(fifo, 0600), 0, "mkfifo: %s", strerror(errno));
  expect_refused_at_once(fifo, "is a FIFO, not a regular file");
}

Test(untrusted, a_device_is_refused_by_every_reader) {
  const char *link = tmp_path("zero.png");
  cr_assert_eq(symlink("/dev/zero", link), 0, "symlink: %s", strerror(errno));
  expect_refused_at_once(link, "is a device, not a regular file");
}
