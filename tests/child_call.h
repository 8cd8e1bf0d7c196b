/* child_call.h: one library call run in a forked child, so that a call that
 * blocks, crashes or takes the machine's memory fails the test instead of
 * the test run: the child has an alarm and, outside AddressSanitizer builds
 * (which reserve terabytes), an address-space limit. Header-only. */
#ifndef BB_TESTS_CHILD_CALL_H
#define BB_TESTS_CHILD_CALL_H

#include <criterion/criterion.h>

#include "bumpbake.h"
#include "image/oiio_module.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef bb_status (*child_call_fn)(const char *path, bb_error *err);

typedef struct child_outcome {
  bb_status status;
  int signal;       /* the child's killing signal, or 0 */
  double seconds;   /* wall-clock time of the call: to print, never to assert */
  double cpu_seconds; /* the child's CPU time, user and system: to assert */
  long max_rss_kib; /* the child's peak resident memory */
  char message[600];
} child_outcome;

#if defined(__SANITIZE_ADDRESS__)
#define CHILD_CALL_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CHILD_CALL_ASAN 1
#endif
#endif

/* Runs fn(path) in a child killed after alarm_seconds, its address space
 * capped at address_space_bytes (0: no cap), and reports its status,
 * message, time and memory. */
static inline child_outcome child_call(child_call_fn fn, const char *path,
                                       unsigned alarm_seconds, long address_space_bytes) {
  child_outcome o;
  memset(&o, 0, sizeof o);
  /* The OpenImageIO module loaded once here (src/image/oiio_module.h), so
   * each child inherits it, as it inherited OpenImageIO when the binary
   * linked it, rather than loading it again (and inside its limits). */
  cr_assert_not_null(bb__oiio_module());
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
#ifndef CHILD_CALL_ASAN
    if (address_space_bytes > 0) {
      struct rlimit rl = {(rlim_t)address_space_bytes, (rlim_t)address_space_bytes};
      setrlimit(RLIMIT_AS, &rl);
    }
#else
    (void)address_space_bytes;
#endif
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
  struct rusage usage;
  cr_assert_eq(wait4(pid, &status, 0, &usage), pid);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  o.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  o.max_rss_kib = usage.ru_maxrss;
  o.cpu_seconds = (double)usage.ru_utime.tv_sec + 1e-6 * (double)usage.ru_utime.tv_usec +
                  (double)usage.ru_stime.tv_sec + 1e-6 * (double)usage.ru_stime.tv_usec;
  if (WIFSIGNALED(status))
    o.signal = WTERMSIG(status);
  else
    o.status = (bb_status)WEXITSTATUS(status);
  return o;
}

#endif /* BB_TESTS_CHILD_CALL_H */
