/* mesh_load.c: bb__mesh_load: the import (mesh_assimp.cpp) in a child
 * process, so that whatever Assimp does with a hostile model (overflow its
 * stack on nodes nested 20,000 deep, allocate without end, loop) ends the
 * child and becomes a one-line error. The mesh comes back through a pipe
 * and is checked again before the caller sees it.
 *
 * Why a child and not a check of the file first: the depth that crashes
 * Assimp is not the nesting of brackets. A glTF's node chain is a flat
 * array of nodes naming their children by index, a Collada file can chain
 * <instance_node> references, and each of Assimp's forty-odd readers and
 * its post-processing steps recurse in their own way; only a separate
 * address space bounds them all. */
#define _GNU_SOURCE /* close_range, pipe2, F_SETPIPE_SZ, strsignal */
#include "core/internal.h"
#include "core/sanitizer_options.h"
#include "mesh/mesh_import.h"
#include "mesh/mesh_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

void bb__import_limits_default(bb__import_limits *lim) {
#ifdef BB_ASAN_BUILD
  lim->memory_bytes = 0;
#else
  lim->memory_bytes = BB_MAX_IMPORT_MEMORY;
#endif
  lim->stack_bytes = BB__IMPORT_STACK_BYTES;
  lim->cpu_seconds = BB_MAX_IMPORT_SECONDS;
  lim->wall_seconds = 4 * BB_MAX_IMPORT_SECONDS;
  lim->stall_seconds = 10;
}

/* ------------------------------------------------------------ the wire */

/* What the child answers: this header, then on success the positions
 * (3 floats per vertex), the normals when has_normals, and the indices
 * (3 uint32 per triangle), in the machine's own byte order. */
#define WIRE_MAGIC 0x6262686dU /* "bbhm" */
typedef struct wire_header {
  uint32_t magic;
  int32_t status;
  uint64_t vertices, triangles;
  uint32_t has_normals;
  char message[sizeof(((bb_error *)0)->message)];
  char note[512];
} wire_header;

/* ------------------------------------------------------------ the child */

typedef struct child_job {
  const char *path;
  bb_mesh mesh;
  char note[512];
  bb_error err;
  bb_status status;
} child_job;

static void *run_import(void *user) {
  child_job *job = user;
  job->status = bb__mesh_import(job->path, &job->mesh, job->note, sizeof job->note, &job->err);
  return NULL;
}

static int write_all(int fd, const void *data, size_t n) {
  const unsigned char *p = data;
  while (n > 0) {
    ssize_t put = write(fd, p, n);
    if (put < 0 && errno == EINTR)
      continue;
    if (put <= 0)
      return -1;
    p += put, n -= (size_t)put;
  }
  return 0;
}

/* The child keeps only its end of the pipe (as descriptor 3) and /dev/null
 * for 0, 1 and 2: Assimp prints nothing the caller should see, and no
 * other pipe of the caller's stays open in it. Returns the pipe's fd. */
static int child_descriptors(int pipe_fd) {
  int high = fcntl(pipe_fd, F_DUPFD, 3);
  int null_fd = open("/dev/null", O_RDWR);
  if (high < 0 || null_fd < 0)
    _exit(3);
  for (int fd = 0; fd < 3; fd++)
    if (fd != null_fd)
      dup2(null_fd, fd);
  if (dup2(high, 3) != 3)
    _exit(3);
  if (close_range(4, ~0U, 0) != 0) {
    long max = sysconf(_SC_OPEN_MAX);
    for (long fd = 4; fd < (max > 0 && max < 65536 ? max : 65536); fd++)
      close((int)fd);
  }
  return 3;
}

/* Signals as a fresh process has them: the caller's handlers (the CLI's,
 * which remove its staged files; a sanitizer's) must not run in the child,
 * and a closed pipe is an error to write, not a death. */
static void child_signals(void) {
  for (int s = 1; s < NSIG; s++)
    if (s != SIGKILL && s != SIGSTOP)
      signal(s, SIG_DFL);
  signal(SIGPIPE, SIG_IGN);
  sigset_t none;
  sigemptyset(&none);
  pthread_sigmask(SIG_SETMASK, &none, NULL);
}

#ifndef BB_ASAN_BUILD
/* Bytes of address space the process has now, or -1. */
static long address_space_now(void) {
  FILE *f = fopen("/proc/self/statm", "r");
  long pages = -1;
  if (f) {
    if (fscanf(f, "%ld", &pages) != 1)
      pages = -1;
    fclose(f);
  }
  long page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? pages * page : -1;
}
#endif

/* Lowers a resource limit to value (never raises the hard limit). */
static void lower_limit(int resource, rlim_t soft, rlim_t hard) {
  struct rlimit now;
  if (getrlimit(resource, &now) != 0)
    return;
  if (now.rlim_max != RLIM_INFINITY && hard > now.rlim_max)
    hard = now.rlim_max;
  if (soft > hard)
    soft = hard;
  struct rlimit want = {soft, hard};
  setrlimit(resource, &want);
}

static void child_limits(const bb__import_limits *lim) {
  lower_limit(RLIMIT_CORE, 0, 0);
  if (lim->cpu_seconds > 0)
    lower_limit(RLIMIT_CPU, (rlim_t)lim->cpu_seconds, (rlim_t)lim->cpu_seconds + 1);
#ifndef BB_ASAN_BUILD
  long now = address_space_now();
  if (lim->memory_bytes > 0 && now > 0)
    lower_limit(RLIMIT_AS, (rlim_t)now + (rlim_t)lim->memory_bytes,
                (rlim_t)now + (rlim_t)lim->memory_bytes);
#endif
}

/* The child: the import on a thread of a known stack, the answer into the
 * pipe, then _exit (no atexit handlers, no stdio buffers of the caller's
 * flushed twice). */
static void child_main(const char *path, const bb__import_limits *lim, int pipe_fd) {
  child_signals();
  int fd = child_descriptors(pipe_fd);
  child_limits(lim);
  static child_job job; /* static: the thread's stack is the bounded one */
  job.path = path;
  pthread_attr_t attr;
  pthread_t thread;
  int started = pthread_attr_init(&attr) == 0 &&
                pthread_attr_setstacksize(&attr, (size_t)lim->stack_bytes) == 0 &&
                pthread_create(&thread, &attr, run_import, &job) == 0;
  if (started)
    pthread_join(thread, NULL);
  else
    job.status = bb__fail(&job.err, BB_ERR_MEMORY, "%s: cannot start the importer's thread",
                          path);
  static wire_header h;
  h.magic = WIRE_MAGIC;
  h.status = (int32_t)job.status;
  memcpy(h.message, job.err.message, sizeof h.message);
  memcpy(h.note, job.note, sizeof h.note);
  const bb_mesh *m = &job.mesh;
  if (job.status == BB_OK) {
    h.vertices = m->vertex_count;
    h.triangles = m->triangle_count;
    h.has_normals = m->normals != NULL;
  }
  int ok = write_all(fd, &h, sizeof h) == 0;
  if (ok && job.status == BB_OK)
    ok = write_all(fd, m->positions, 3 * m->vertex_count * sizeof(float)) == 0 &&
         (!m->normals || write_all(fd, m->normals, 3 * m->vertex_count * sizeof(float)) == 0) &&
         write_all(fd, m->indices, 3 * m->triangle_count * sizeof(uint32_t)) == 0;
  _exit(ok ? 0 : 3);
}

/* ----------------------------------------------------------- the parent */

typedef struct child {
  int fd;      /* the pipe's read end, non-blocking */
  pid_t pid;
  double deadline;
  int exited;  /* reaped (or reaped by someone else: status unknown) */
  int status;  /* waitpid's, valid when exited and known */
  int known;
  int timed_out;
  int stall_seconds;    /* 0: not watched */
  long cpu_ticks;       /* the child's CPU time when last looked at */
  double moved;         /* when it last used CPU or sent bytes */
  int stalled;
} child;

/* CPU time the process has used, in clock ticks, or -1 (no /proc). */
static long cpu_ticks_of(pid_t pid) {
  char path[64], text[512];
  snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    return -1;
  ssize_t n = read(fd, text, sizeof text - 1);
  close(fd);
  if (n <= 0)
    return -1;
  text[n] = '\0';
  /* after "pid (comm) ": state is field 3, utime 14 and stime 15 */
  const char *p = strrchr(text, ')');
  unsigned long utime, stime;
  if (!p || sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &utime,
                   &stime) != 2)
    return -1;
  return (long)(utime + stime);
}

/* Whether the child has stood still (no CPU, no bytes) for stall_seconds:
 * stuck on a lock it inherited locked, not working. */
static int child_stalled(child *c) {
  if (c->stall_seconds <= 0)
    return 0;
  long ticks = cpu_ticks_of(c->pid);
  double now = bb__now_seconds();
  if (ticks < 0)
    return 0; /* cannot tell: only the deadline applies */
  if (ticks != c->cpu_ticks) {
    c->cpu_ticks = ticks;
    c->moved = now;
    return 0;
  }
  return now - c->moved > c->stall_seconds;
}

static int child_gone(child *c) {
  if (c->exited)
    return 1;
  pid_t w = waitpid(c->pid, &c->status, WNOHANG);
  if (w == c->pid)
    c->exited = c->known = 1;
  else if (w < 0 && errno == ECHILD) /* a SIGCHLD handler of the caller's reaped it */
    c->exited = 1;
  return c->exited;
}

/* Reads exactly n bytes of the answer. 0, or -1 at the end of the pipe,
 * after the child ended without closing it elsewhere, or at the deadline
 * (timed_out). */
static int read_exact(child *c, void *buf, size_t n) {
  unsigned char *p = buf;
  while (n > 0) {
    ssize_t got = read(c->fd, p, n);
    if (got > 0) {
      p += got, n -= (size_t)got;
      c->moved = bb__now_seconds();
      continue;
    }
    if (got == 0)
      return -1;
    if (errno == EINTR)
      continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK)
      return -1;
    double left = c->deadline - bb__now_seconds();
    if (left <= 0.0) {
      c->timed_out = 1;
      return -1;
    }
    /* Another thread's child may hold a copy of the write end for a moment
     * (until it closes what it does not need), so the end of the pipe is
     * also looked for as the child's exit. */
    int was_gone = c->exited;
    struct pollfd pfd = {c->fd, POLLIN, 0};
    int ready = poll(&pfd, 1, left > 0.1 ? 100 : (int)(left * 1000.0) + 1);
    if (ready == 0 && was_gone)
      return -1;
    if (ready == 0 && !child_gone(c) && child_stalled(c)) {
      c->stalled = 1;
      return -1;
    }
  }
  return 0;
}

/* Waits for the child to end (killing it first when kill_now), at most
 * until the deadline. */
static void finish(child *c, int kill_now) {
  if (kill_now && !c->exited)
    kill(c->pid, SIGKILL);
  while (!child_gone(c)) {
    if (bb__now_seconds() > c->deadline) {
      c->timed_out = 1;
      kill(c->pid, SIGKILL);
      while (waitpid(c->pid, &c->status, 0) < 0 && errno == EINTR)
        ;
      c->exited = c->known = 1;
      break;
    }
    struct timespec ms = {0, 1000000};
    nanosleep(&ms, NULL);
  }
}

/* Text from the child: NUL-terminated, printable. */
static void take_text(char *dst, size_t cap, char *src, size_t src_cap) {
  src[src_cap - 1] = '\0';
  for (char *s = src; *s; s++)
    if ((unsigned char)*s < 0x20 || (unsigned char)*s == 0x7f)
      *s = '?';
  if (dst && cap)
    snprintf(dst, cap, "%s", src);
}

/* The mesh of a successful answer, checked: counts within the limits,
 * indices in range, finite positions. */
static bb_status receive_mesh(child *c, const char *path, const wire_header *h, bb_mesh *out,
                              bb_error *err) {
  if (h->vertices < 1 || h->vertices > 3 * (uint64_t)BB_MAX_MODEL_TRIANGLES ||
      h->triangles < 1 || h->triangles > (uint64_t)BB_MAX_MODEL_TRIANGLES || h->has_normals > 1)
    return bb__fail(err, BB_ERR_FORMAT, "%s: the importer answered a malformed mesh", path);
  bb_status st = bb__mesh_alloc(out, (size_t)h->vertices, (size_t)h->triangles,
                               (int)h->has_normals, err);
  if (st != BB_OK)
    return st;
  const size_t floats = 3 * out->vertex_count * sizeof(float);
  if (read_exact(c, out->positions, floats) != 0 ||
      (out->normals && read_exact(c, out->normals, floats) != 0) ||
      read_exact(c, out->indices, 3 * out->triangle_count * sizeof(uint32_t)) != 0) {
    bb__mesh_free(out);
    return BB_ERR_IO; /* the caller words it from the child's end */
  }
  for (size_t i = 0; i < 3 * out->triangle_count; i++)
    if (out->indices[i] >= out->vertex_count) {
      bb__mesh_free(out);
      return bb__fail(err, BB_ERR_FORMAT, "%s: the importer answered a malformed mesh", path);
    }
  for (size_t i = 0; i < 3 * out->vertex_count; i++)
    if (!isfinite(out->positions[i])) {
      bb__mesh_free(out);
      return bb__fail(err, BB_ERR_FORMAT, "%s: the importer answered a malformed mesh", path);
    }
  return BB_OK;
}

/* Why a child ended without a (whole) answer, as one line. */
static bb_status child_failure(const child *c, const char *path, const bb__import_limits *lim,
                               bb_error *err) {
  if (c->timed_out)
    return bb__fail(err, BB_ERR_SIZE, "%s: the importer took more than %d s; stopped", path,
                    lim->wall_seconds);
  if (c->stalled)
    return bb__fail(err, BB_ERR_IO, "%s: the importer stood still for %d s, twice; stopped",
                    path, lim->stall_seconds);
  if (c->known && WIFSIGNALED(c->status)) {
    int sig = WTERMSIG(c->status);
    if (sig == SIGXCPU)
      return bb__fail(err, BB_ERR_SIZE, "%s: the importer took more than %d s of CPU; stopped",
                      path, lim->cpu_seconds);
    if (sig == SIGKILL)
      return bb__fail(err, BB_ERR_MEMORY, "%s: the importer was killed (out of memory?)", path);
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: not a readable model: the importer crashed (%s): the model is corrupt "
                    "or nested deeper than its %ld MiB stack allows",
                    path, strsignal(sig), lim->stack_bytes >> 20);
  }
  if (c->known && WIFEXITED(c->status) && WEXITSTATUS(c->status) != 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable model: the importer failed "
                    "(exit status %d)", path, WEXITSTATUS(c->status));
  return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable model: the importer stopped "
                  "without an answer", path);
}

/* Reads the child's answer into out (and note), or words why there is
 * none. *answered: the child sent a valid header and, on success, a valid
 * mesh. */
static bb_status receive(child *c, const char *path, const bb__import_limits *lim,
                         bb_mesh *out, char *note, size_t cap, int *answered, bb_error *err) {
  static const size_t header_size = sizeof(wire_header);
  wire_header *h = malloc(header_size);
  if (!h)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  bb_status st;
  *answered = 0;
  if (read_exact(c, h, header_size) != 0 || h->magic != WIRE_MAGIC || h->status < BB_OK ||
      h->status > BB_ERR_CANCELLED) {
    finish(c, 1);
    st = child_failure(c, path, lim, err);
  } else if (h->status != BB_OK) {
    *answered = 1;
    take_text(err ? err->message : NULL, err ? sizeof err->message : 0, h->message,
              sizeof h->message);
    st = (bb_status)h->status;
    if (st == BB_ERR_MEMORY && lim->memory_bytes > 0 && err)
      bb__fail(err, st, "%s: out of memory while reading (the importer may take %ld MiB)", path,
               lim->memory_bytes >> 20);
  } else {
    st = receive_mesh(c, path, h, out, err);
    if (st == BB_OK) {
      unsigned char extra;
      if (read_exact(c, &extra, 1) == 0 && !c->timed_out) {
        bb__mesh_free(out); /* more than it announced: not our protocol */
        st = bb__fail(err, BB_ERR_FORMAT, "%s: the importer answered a malformed mesh", path);
      } else {
        *answered = 1;
        take_text(note, cap, h->note, sizeof h->note);
      }
    } else if (st == BB_ERR_IO) {
      finish(c, 1);
      st = child_failure(c, path, lim, err);
    }
  }
  free(h);
  return st;
}

/* One child: forked, answered (or not), reaped. */
static bb_status one_child(const char *path, const bb__import_limits *lim, double deadline,
                           bb_mesh *out, char *note, size_t cap, int *answered, int *stalled,
                           bb_error *err) {
  *answered = *stalled = 0;
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot start the importer: %s", path, strerror(errno));
  fcntl(fds[0], F_SETPIPE_SZ, 1 << 20); /* fewer wake-ups for a large mesh */
  pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    child_main(path, lim, fds[1]); /* does not return */
  }
  int fork_errno = errno;
  close(fds[1]);
  if (pid < 0) {
    close(fds[0]);
    return bb__fail(err, BB_ERR_MEMORY, "%s: cannot start the importer: %s", path,
                    strerror(fork_errno));
  }
  child c;
  memset(&c, 0, sizeof c);
  c.fd = fds[0];
  c.pid = pid;
  c.deadline = deadline;
  c.stall_seconds = lim->stall_seconds;
  c.cpu_ticks = -1;
  c.moved = bb__now_seconds();
  fcntl(c.fd, F_SETFL, fcntl(c.fd, F_GETFL) | O_NONBLOCK);
  bb_status st = receive(&c, path, lim, out, note, cap, answered, err);
  finish(&c, !*answered);
  close(c.fd);
  /* A whole answer from a child that then died is no answer. */
  if (*answered && c.known && !(WIFEXITED(c.status) && WEXITSTATUS(c.status) == 0)) {
    bb__mesh_free(out);
    *answered = 0;
    st = child_failure(&c, path, lim, err);
  }
  *stalled = c.stalled;
  return st;
}

bb_status bb__mesh_load_isolated(const char *path, const bb__import_limits *lim, bb_mesh *out,
                                 char *note, size_t cap, int *clean, bb_error *err) {
  if (clean)
    *clean = 1;
  if (note && cap)
    note[0] = '\0';
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__mesh_load: out is NULL");
  memset(out, 0, sizeof *out);
  if (!path)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__mesh_load: path is NULL");
  /* The model itself first: a FIFO or a file over the limit never reaches
   * a child. */
  size_t size;
  bb_status st = bb__mesh_check_model(path, &size, err);
  if (st != BB_OK)
    return st;
  /* A child that stands still is made once more: what holds it is a lock
   * that another thread of the caller's held at the moment of the fork
   * (sanitizer runtimes' allocators do not release theirs), not the model. */
  const double deadline = bb__now_seconds() + lim->wall_seconds;
  int answered = 0, stalled = 0;
  for (int attempt = 0; attempt < 2; attempt++) {
    st = one_child(path, lim, deadline, out, note, cap, &answered, &stalled, err);
    if (!stalled)
      break;
  }
  if (clean)
    *clean = answered;
  return st;
}

bb_status bb__mesh_load_noted(const char *path, bb_mesh *out, char *note, size_t cap,
                             bb_error *err) {
  bb__import_limits lim;
  bb__import_limits_default(&lim);
  return bb__mesh_load_isolated(path, &lim, out, note, cap, NULL, err);
}

bb_status bb__mesh_load(const char *path, bb_mesh *out, bb_error *err) {
  return bb__mesh_load_noted(path, out, NULL, 0, err);
}
