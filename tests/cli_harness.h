/* cli_harness.h: running bumpbake from a Criterion test (fork, then the
 * CLI's code called in the child or the binary executed: harness_start;
 * stdout and stderr captured) and a temporary directory per test.
 * Header-only: each test file that runs the CLI includes it once. */
#ifndef BB_CLI_HARNESS_H
#define BB_CLI_HARNESS_H

#include <criterion/criterion.h>

#include "cli/cli.h"

/* Under AddressSanitizer (make DEBUG=1) the executed program checks for
 * leaks at its exit; a called CLI leaves by _exit, so it checks first
 * (harness_leak_check, below). */
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#include <sanitizer/lsan_interface.h>
#include <stdint.h>
#define HARNESS_LEAK_CHECK() harness_leak_check()
#else
#define HARNESS_LEAK_CHECK() ((void)0)
#endif

#include <dirent.h>
#include <ftw.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "image/image_write.h"
#include "image/oiio_module.h"

#if defined(__SANITIZE_ADDRESS__)
/* The leak check of a called CLI, in the forked child. LeakSanitizer there
 * still lists the test process's other threads (Criterion's, the logging
 * pool OpenImageIO's dependencies start), which fork did not copy: it
 * cannot suspend them and says so for each ("Running thread N was not
 * suspended. False leaks are possible."), on stderr or in a log file
 * (ASAN_OPTIONS=log_path), for threads that are not there to run. So the
 * check reports into a file of the child's: with no leak found, that file
 * (those lines only) is dropped; with a leak, the report less those lines
 * goes to the child's stderr (the run's err, which the test sees) and the
 * check runs again, its report discarded, to end the child with the
 * sanitizer's exit code. */
static inline void harness_leak_check(void) {
  FILE *report = tmpfile();
  FILE *discard = fopen("/dev/null", "w");
  if (!report || !discard) {
    __lsan_do_leak_check();
    return;
  }
  __sanitizer_set_report_fd((void *)(intptr_t)fileno(report));
  if (!__lsan_do_recoverable_leak_check())
    return;
  rewind(report);
  char line[4096];
  while (fgets(line, sizeof line, report))
    if (!strstr(line, "was not suspended. False leaks are possible"))
      fputs(line, stderr);
  fflush(stderr);
  __sanitizer_set_report_fd((void *)(intptr_t)fileno(discard));
  __lsan_do_leak_check();
}
#endif

typedef struct cli_result {
  int code;         /* exit code, or 128 + signal when it crashed */
  char *out;        /* all of stdout, NUL-terminated */
  char *err;        /* all of stderr */
  long max_rss_kib; /* the child's peak resident memory */
  double seconds;   /* wall-clock time of the run: to print, never to assert
                       (a busy machine stretches it; assert cpu_seconds) */
  double cpu_seconds; /* the child's CPU time, user and system */
} cli_result;

static inline void cli_result_free(cli_result *r) {
  free(r->out);
  free(r->err);
  memset(r, 0, sizeof *r);
}

static inline char *harness_slurp(FILE *f) {
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

/* Absolute path of the binary (BB_BIN, default build/bumpbake), so runs
 * with another cwd find it too. */
static inline const char *harness_binary(void) {
  static char path[4096];
  if (!path[0]) {
    const char *bin = getenv("BB_BIN");
    cr_assert(realpath(bin && *bin ? bin : "build/bumpbake", path) != NULL,
              "BB_BIN not found");
  }
  return path;
}

/* Resource limits for a run; a negative value leaves that limit alone. */
typedef struct run_limits {
  long file_size_bytes;     /* RLIMIT_FSIZE: a small filesystem without root */
  long address_space_bytes; /* RLIMIT_AS: a safety net for memory tests */
} run_limits;

static const run_limits harness_no_limits = {-1, -1};

static inline void harness_set_limit(int resource, long value) {
  if (value < 0)
    return;
  struct rlimit rl = {(rlim_t)value, (rlim_t)value};
  if (setrlimit(resource, &rl) != 0)
    _exit(125);
}

/* How a run starts. HARNESS_CALL: fork, and the child calls the CLI's
 * entry (cli_main, program_entry.c, linked into this binary) and exits
 * with its code: the same code as build/bumpbake without a second exec of
 * a program that loads OpenImageIO's 260 libraries (0.25 to 0.3 s of CPU in
 * the dynamic linker each time). HARNESS_EXEC: fork and exec the binary:
 * for what is about the process itself (its peak memory, its start-up, its
 * address-space limit, signals sent to it) and for `serve`, which the test
 * binary does not link. */
typedef enum { HARNESS_CALL, HARNESS_EXEC } harness_how;

/* Number of threads of this process (/proc/self/status), 0 if unknown. */
static inline int harness_threads(void) {
  FILE *f = fopen("/proc/self/status", "r");
  if (!f)
    return 0;
  char line[256];
  int n = 0;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, "Threads: %d", &n) == 1)
      break;
  fclose(f);
  return n;
}

/* Threads of the test process when its test began (harness_setup): the
 * main one and those every process of this binary has before any test
 * code runs (Criterion's, and a logging library's idle pool that
 * OpenImageIO's dependencies start when they load); 0 before. */
static int harness_threads_at_setup;

/* Whether a run may call the CLI in a forked child: only when the test
 * has started no thread that is still alive (a fork copies no other
 * thread, so a pool the test started, OpenImageIO's or bumpbake's, would
 * be left in the child without its threads), when BB_BIN
 * names the bumpbake built beside this test binary (the CLI linked in is
 * then the one BB_BIN would run; another binary is run as it is), when
 * BB_CLI_EXEC is unset or 0 (BB_CLI_EXEC=1 runs every CLI test by exec)
 * and when the command is not serve. */
static inline int harness_may_call(const char *const *args) {
  static int same_binary = -1;
  if (same_binary < 0) {
    char self[4096], beside[4200];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    same_binary = 0;
    if (n > 0) {
      self[n] = '\0';
      char *slash = strrchr(self, '/');
      if (slash) {
        *slash = '\0';
        snprintf(beside, sizeof beside, "%s/bumpbake", self);
        char resolved[4096];
        same_binary = realpath(beside, resolved) && !strcmp(resolved, harness_binary());
      }
    }
  }
  const char *force = getenv("BB_CLI_EXEC");
  return same_binary && !(force && *force && strcmp(force, "0")) &&
         !(args[0] && !strcmp(args[0], "serve")) && harness_threads_at_setup > 0 &&
         harness_threads() == harness_threads_at_setup;
}

/* The state exec gives a program: a signal the test caught is back to its
 * default (ignored ones stay ignored, the mask is kept, as across exec). */
static inline void harness_exec_signal_state(void) {
  for (int sig = 1; sig <= SIGRTMAX; sig++) {
    struct sigaction sa;
    if (sig == SIGKILL || sig == SIGSTOP || sigaction(sig, NULL, &sa) != 0)
      continue;
    if (sa.sa_handler != SIG_IGN && sa.sa_handler != SIG_DFL)
      signal(sig, SIG_DFL);
  }
}

/* Forks and runs bumpbake with args (NULL-terminated, without argv[0]) in
 * cwd (NULL = ours) under lim, stdout and stderr to out and err, as how
 * says (HARNESS_CALL falls back to exec where harness_may_call says no): no
 * shell, so nothing is reinterpreted. Returns the pid. */
static inline pid_t harness_start(const char *cwd, const run_limits *lim,
                                  const char *const *args, FILE *out, FILE *err,
                                  harness_how how) {
  const char *argv[64] = {"bumpbake"};
  int argc = 1;
  for (int i = 0; args[i]; i++) {
    cr_assert_lt(i, 62, "too many arguments");
    argv[argc++] = args[i];
  }
  /* Resolved here, not in the child: the child may chdir first, and a
   * failed assertion there would report from a process Criterion does not
   * know. */
  const char *binary = harness_binary();
  const int call = how == HARNESS_CALL && harness_may_call(args);
  fflush(NULL);
  pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    dup2(fileno(out), STDOUT_FILENO);
    dup2(fileno(err), STDERR_FILENO);
    if (cwd && chdir(cwd) != 0)
      _exit(126);
    if (call)
      harness_exec_signal_state();
    /* The CLI keeps a signal ignored when it was ignored at its start (as
     * under nohup); a test runner started in the background by a
     * non-interactive shell ignores SIGINT, so give the child the defaults
     * an interactive user's program gets. */
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGHUP, SIG_DFL);
    harness_set_limit(RLIMIT_FSIZE, lim->file_size_bytes);
    harness_set_limit(RLIMIT_AS, lim->address_space_bytes);
    if (call) {
      /* the program's exit, less the test's atexit handlers (Criterion's) */
      int code = cli_main(argc, (char **)argv, NULL);
      fflush(NULL);
      HARNESS_LEAK_CHECK(); /* ends the child with LeakSanitizer's code on a leak */
      _exit(code);
    }
    execv(binary, (char *const *)argv);
    _exit(127);
  }
  return pid;
}

/* Forks and execs bumpbake with args: for a test that signals it. */
static inline pid_t harness_spawn(const char *cwd, const run_limits *lim,
                                  const char *const *args, FILE *out, FILE *err) {
  return harness_start(cwd, lim, args, out, err, HARNESS_EXEC);
}

/* User plus system CPU time of a rusage: what a test may bound, as no
 * load stretches it much (wall-clock time grows with every other job). */
static inline double harness_cpu_seconds(const struct rusage *u) {
  return (double)u->ru_utime.tv_sec + 1e-6 * (double)u->ru_utime.tv_usec +
         (double)u->ru_stime.tv_sec + 1e-6 * (double)u->ru_stime.tv_usec;
}

static inline double harness_seconds_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Runs bumpbake with args in cwd (NULL = ours) under lim, as how says, and
 * waits for it. */
static inline cli_result harness_run_how(const char *cwd, const run_limits *lim,
                                         const char *const *args, harness_how how) {
  FILE *out = tmpfile(), *err = tmpfile();
  cr_assert(out && err);
  double t0 = harness_seconds_now();
  pid_t pid = harness_start(cwd, lim, args, out, err, how);
  int status = 0;
  struct rusage usage;
  cr_assert(wait4(pid, &status, 0, &usage) == pid);
  cli_result r;
  r.seconds = harness_seconds_now() - t0;
  r.max_rss_kib = usage.ru_maxrss;
  r.cpu_seconds = harness_cpu_seconds(&usage);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = harness_slurp(out);
  r.err = harness_slurp(err);
  fclose(out);
  fclose(err);
  return r;
}

/* Runs bumpbake under lim: the binary when an address space is limited
 * or none is (an address-space limit and the peak memory of a memory test
 * are the program's own, not a copy of this test process), the CLI's code
 * in a forked child under a file-size limit alone (it bounds the child's
 * writes either way). */
static inline cli_result harness_run_limited(const char *cwd, const run_limits *lim,
                                             const char *const *args) {
  const int file_size_alone = lim->file_size_bytes >= 0 && lim->address_space_bytes < 0;
  return harness_run_how(cwd, lim, args, file_size_alone ? HARNESS_CALL : HARNESS_EXEC);
}

/* Runs the binary itself: for a test of its peak memory or its start. */
static inline cli_result harness_run_exec(const char *const *args) {
  return harness_run_how(NULL, &harness_no_limits, args, HARNESS_EXEC);
}

/* Runs the CLI's code in a forked child (or the binary, harness_may_call). */
static inline cli_result harness_run_in(const char *cwd, const char *const *args) {
  return harness_run_how(cwd, &harness_no_limits, args, HARNESS_CALL);
}

static inline cli_result harness_run(const char *const *args) {
  return harness_run_in(NULL, args);
}

#define RUN(...) harness_run((const char *const[]){__VA_ARGS__, NULL})
#define RUN_IN(cwd, ...) harness_run_in(cwd, (const char *const[]){__VA_ARGS__, NULL})

static inline int harness_lines(const char *s) {
  int n = 0;
  for (; *s; s++)
    n += *s == '\n';
  return n;
}

/* ------------------------------------------------- temporary directory */

static char harness_dir[64];
static char *harness_paths[256];
static int harness_path_count;

static inline int harness_remove(const char *path, const struct stat *st, int flag,
                                 struct FTW *ftw) {
  (void)st, (void)flag, (void)ftw;
  return remove(path);
}

static inline void harness_setup(void) {
  /* A called CLI reads and writes images through the OpenImageIO module,
   * which the library loads on first use (src/image/oiio_module.h): loaded
   * before the threads are counted (its libraries may start some) and
   * before the first fork, each child of the test inherits it rather than
   * loading it again, as it inherited OpenImageIO when the binary linked
   * it. */
  (void)bb__oiio_module();
  harness_threads_at_setup = harness_threads();
  snprintf(harness_dir, sizeof harness_dir, "/tmp/bb_cli_XXXXXX");
  cr_assert_not_null(mkdtemp(harness_dir));
}

static inline void harness_teardown(void) {
  if (harness_dir[0])
    nftw(harness_dir, harness_remove, 16, FTW_DEPTH | FTW_PHYS);
  harness_dir[0] = '\0';
  while (harness_path_count > 0)
    free(harness_paths[--harness_path_count]);
}

/* Path of name inside the test's directory, valid until the test ends. */
static inline const char *tmp(const char *name) {
  cr_assert_lt(harness_path_count, 256);
  size_t len = strlen(harness_dir) + strlen(name) + 2;
  char *path = malloc(len);
  cr_assert_not_null(path);
  snprintf(path, len, "%s/%s", harness_dir, name);
  return harness_paths[harness_path_count++] = path;
}

/* Writes size bytes to path (a new file); the test fails if it cannot. */
static inline void write_bytes(const char *path, const void *data, size_t size) {
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f, "cannot create %s", path);
  if (size)
    cr_assert_eq(fwrite(data, 1, size, f), size);
  cr_assert_eq(fclose(f), 0);
}

static inline int file_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

/* Number of files in the test's directory whose name starts with prefix
 * (temporary ".bb-tmp-" files included when prefix asks for them). */
static inline int files_starting_with(const char *prefix) {
  DIR *d = opendir(harness_dir);
  cr_assert_not_null(d);
  int n = 0;
  for (struct dirent *e; (e = readdir(d));)
    n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
  closedir(d);
  return n;
}

/* Expects exit code `code`, one line on stderr starting "bumpbake" and
 * holding `part`, and nothing on stdout. */
static inline void harness_expect_error(const cli_result *r, int code, const char *part,
                                        const char *what) {
  cr_expect_eq(r->code, code, "%s: exit %d, stderr: %s", what, r->code, r->err);
  cr_expect_eq(harness_lines(r->err), 1, "%s: stderr should be one line: %s", what,
               r->err);
  cr_expect(strncmp(r->err, "bumpbake", 8) == 0, "%s: %s", what, r->err);
  cr_expect(strstr(r->err, part), "%s: '%s' lacks '%s'", what, r->err, part);
  cr_expect_str_empty(r->out, "%s", what);
}

/* Runs args in cwd and expects a refusal: harness_expect_error, and the
 * test's directory holding as many files as before (no output, no
 * temporary file). case_index names the case in messages. */
static inline void harness_expect_refusal(const char *cwd, const char *const *args,
                                          int code, const char *part, size_t case_index) {
  int before = files_starting_with("");
  cli_result r = harness_run_in(cwd, args);
  char what[96];
  snprintf(what, sizeof what, "case %zu (%s %s)", case_index, args[0],
           args[1] ? args[1] : "");
  harness_expect_error(&r, code, part, what);
  cli_result_free(&r);
  cr_expect_eq(files_starting_with(""), before, "%s left a file", what);
}

/* ---------------------------------------- images (for files that include
 * bumpbake.h first) */
#ifdef BUMPBAKE_H

/* Writes img with bb__image_write; the test fails if it cannot. */
static inline void harness_write(const char *path, const bb_image *img, bb_depth depth,
                                 bb_range range) {
  bb_write_options o = {depth, range, NULL, NULL};
  bb_error err;
  cr_assert_eq(bb__image_write(path, img, &o, &err), BB_OK, "%s", err.message);
}

/* Reads a file back; the test fails if it cannot. */
static inline bb_image harness_read(const char *path, bb_image_info *info) {
  bb_image img;
  bb_error err;
  cr_assert_eq(bb_image_read(path, &img, info, &err), BB_OK, "%s", err.message);
  return img;
}

/* 1 when a and b have the same size, channels and float bits. */
static inline int harness_same_pixels(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         memcmp(a->pixels, b->pixels,
                (size_t)a->width * (size_t)a->height * (size_t)a->channels *
                    sizeof(float)) == 0;
}

/* Largest |a - b| over every sample (sizes must match). */
static inline double harness_max_difference(const bb_image *a, const bb_image *b) {
  cr_assert(a->width == b->width && a->height == b->height && a->channels == b->channels,
            "%dx%dx%d vs %dx%dx%d", a->width, a->height, a->channels, b->width, b->height,
            b->channels);
  double worst = 0.0;
  size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
  for (size_t i = 0; i < n; i++) {
    double d = (double)a->pixels[i] - (double)b->pixels[i];
    d = d < 0 ? -d : d;
    worst = d > worst ? d : worst;
  }
  return worst;
}

#endif /* BUMPBAKE_H */

#endif /* BB_CLI_HARNESS_H */
