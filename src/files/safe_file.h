/* safe_file.h: every file the library writes goes to disk this
 * way (safe_file.c), so that no failure leaves a partial file at its name. */
#ifndef BB_FILES_SAFE_FILE_H
#define BB_FILES_SAFE_FILE_H

#include "bumpbake.h"

#include <pthread.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Every writer (safe_file.c; OpenImageIO's writers reach it through
 * bb::write_staged() in oiio_write.cpp) puts bytes on disk this way, so that no
 * failure leaves a partial file at the final name:
 *
 *   bb_staged_file f;
 *   if (bb__safe_open(&f, path, err) != BB_OK) return ...;  temp created
 *   bb__safe_write(&f, bytes, n); ...          checked; errors are kept
 *   return bb__safe_commit(&f, err);           or bb__safe_discard(&f)
 *
 * - The bytes go to "DIR/.bb-tmp-XXXXXX.EXT" next to path (same
 *   filesystem, so the rename is atomic), registered for
 *   bb__tempfiles_remove() (signal handlers) while it exists.
 * - Writes are buffered; every write(2) is checked and retried on short
 *   counts. The first failure (ENOSPC, EFBIG under RLIMIT_FSIZE, EIO...) is
 *   kept and later writes return 0, so a codec that ignores a failed write
 *   cannot hide it: bb__safe_finish reports it.
 * - bb__safe_finish flushes, fsyncs and closes (checked) the temporary;
 *   bb__safe_commit finishes and renames it to path. Both remove the
 *   temporary on failure and return BB_ERR_IO with "PATH: cannot write:
 *   REASON". After finish alone the complete file waits under its temporary
 *   name (that is what bb_staged_file is): commit or discard it later.
 * - A bb_staged_file may be used from several threads (each call locks).
 * - The temporary is flock'ed from its creation until it is renamed or
 *   removed, so bb_tempfiles_sweep can tell one being written (here, or by
 *   another process or machine sharing the directory) from one a killed
 *   process left behind. */
struct bb_staged_file {
  pthread_mutex_t lock;
  int lock_ready;
  int fd;               /* -1 once closed */
  int error;            /* first errno seen, 0 when none */
  int slot;             /* registry slot for bb__tempfiles_remove, or -1 */
  int64_t pos;          /* position of the next bb__safe_write / read */
  int64_t size;         /* bytes in the file (highest byte written + 1) */
  unsigned char *buffer;
  size_t buffered;      /* bytes waiting in buffer */
  int64_t buffer_pos;   /* file offset of buffer[0] */
  char *path;           /* final name, malloc'd */
  char *temp_path;      /* temporary name, malloc'd */
  int locked;           /* 1: lock_fd holds the temporary's flock */
  int lock_fd;          /* a dup of fd, open until the temporary is renamed
                           or removed, so its lock outlives fd's close */
  /* A file staged by name in a private directory (bb__safe_open_private):
   * the directory's path, its open descriptor, the file's name in it and
   * the registry slots of both; NULL and -1 otherwise. */
  char *temp_dir;
  int dir_fd;
  const char *leaf; /* points into temp_path */
  char *registered_file; /* the file's path through temp_dir, for the registry */
  int dir_slot, file_slot;
};

/* A creation: between begin and end the calling thread holds SIGINT,
 * SIGTERM and SIGHUP off, and bb__tempfiles_remove (a signal's cleanup)
 * waits for it before it removes the registered temporaries, so a file
 * being made while the handler runs is not left behind. Every temporary
 * is made inside one; so is an encoder's file made by name in a private
 * directory. begin returns 0, or EINTR once the process is ending (then
 * make nothing, and do not call end). */
int bb__safe_creation_begin(sigset_t *held);
void bb__safe_creation_end(const sigset_t *held);

/* What stands at an output's name. A write puts a new file there by
 * rename, which would replace, not write to, anything but a regular file:
 * a device, a FIFO, a socket, a symbolic link (to anything: /dev/stdout is
 * one) or a directory. BB_OK when nothing is there or a regular file is,
 * else BB_ERR_IO "PATH: cannot write: is a FIFO, not a regular file" (a
 * directory: "is a directory"). bb__safe_open, bb__safe_open_private and
 * bb__safe_commit refuse such a name with it; the job checks every output
 * with it before baking. */
bb_status bb__safe_check_target(const char *path, bb_error *err);

/* 1 when path exists, is not a regular file, and leads (through symbolic
 * links) to a FIFO or a character device: a stream a depfile may be
 * written through (/dev/stdout on a pipe or terminal, a FIFO, /dev/null). */
int bb__safe_is_stream(const char *path);

/* Writes data through such a stream (opened without creating, truncating
 * or becoming a controlling terminal; a FIFO nobody reads is an error, not
 * a wait), every write checked, closed checked. Errors: BB_ERR_IO "PATH:
 * cannot write: REASON". */
bb_status bb__safe_write_through(const char *path, const void *data, size_t size,
                                 bb_error *err);

/* A bb_staged_file that bb__safe_discard may be called on before any open. */
void bb__safe_init(bb_staged_file *f);

/* Creates the temporary for path (f is the caller's; nothing to free on
 * failure). Errors: BB_ERR_IO (directory missing or not writable). */
bb_status bb__safe_open(bb_staged_file *f, const char *path, bb_error *err);

/* For an encoder that can only open its output by name (OpenImageIO's
 * TIFF writer appending directories): creates, next to path, a private
 * directory "DIR/.bb-tmp-XXXXXX" (mode 0700, so no other user can put a
 * link in it, and held open, so renaming it away changes nothing) and sets
 * f->temp_path to the name the encoder must write: LEAF in that directory
 * reached through its descriptor ("/proc/self/fd/N/LEAF"; the directory's
 * path where /proc is not mounted), LEAF being "staged" and path's
 * extension. Nothing exists at that name yet. Both are registered for
 * bb__tempfiles_remove. Then bb__safe_adopt, then commit or discard as for
 * bb__safe_open. Errors: BB_ERR_IO. */
bb_status bb__safe_open_private(bb_staged_file *f, const char *path, bb_error *err);

/* Makes the file the encoder wrote at f->temp_path the staged file: opened
 * without following a link, checked to be a regular file, fsynced and
 * closed (checked), as bb__safe_finish does. On failure the temporary and
 * its directory are removed and BB_ERR_IO says why. */
bb_status bb__safe_adopt(bb_staged_file *f, bb_error *err);
/* Writes at the current position / at offset; returns size, or 0 once any
 * write has failed. */
size_t bb__safe_write(bb_staged_file *f, const void *data, size_t size);
size_t bb__safe_pwrite(bb_staged_file *f, const void *data, size_t size, int64_t offset);
/* Reads back what was written (some encoders patch headers). */
size_t bb__safe_read(bb_staged_file *f, void *data, size_t size);
size_t bb__safe_pread(bb_staged_file *f, void *data, size_t size, int64_t offset);
int bb__safe_seek(bb_staged_file *f, int64_t offset); /* 0, or -1 if offset < 0 */
int64_t bb__safe_tell(bb_staged_file *f);
int64_t bb__safe_size(bb_staged_file *f);
bb_status bb__safe_finish(bb_staged_file *f, bb_error *err);
bb_status bb__safe_commit(bb_staged_file *f, bb_error *err);
/* Removes the temporary; safe after a failed open, finish or commit. */
void bb__safe_discard(bb_staged_file *f);
/* A zeroed heap bb_staged_file for the public handle API (NULL when out of
 * memory). */
bb_staged_file *bb__staged_new(void);


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Renames the staged file to its path and frees the handle (also when the
 * rename fails, which removes the temporary). Errors: BB_ERR_IO. */
bb_status bb__staged_file_commit(bb_staged_file *staged, bb_error *err);

/* Removes the staged file's temporary and frees the handle; NULL is fine. */
void bb__staged_file_discard(bb_staged_file *staged);

/* The destination path of a staged file (owned by the handle). */
const char *bb__staged_file_path(const bb_staged_file *staged);

/* Writes size bytes of data to path (a text file: a depfile, a list) the way
 * images are written: through a temporary in path's directory, flushed,
 * synced and renamed into place, so path is either untouched or whole. The
 * temporary is removed on failure, and by bb__tempfiles_remove on a signal.
 * A path that exists and is not a regular file (a device, a FIFO, a
 * symbolic link, /dev/stdout) is refused, never renamed over.
 * Errors: BB_ERR_ARGUMENT (no path, or NULL data with a size),
 * BB_ERR_MEMORY, BB_ERR_IO ("PATH: cannot write: reason"). */
bb_status bb__file_write(const char *path, const void *data, size_t size, bb_error *err);

/* Removes every temporary file a write of this process has open right now
 * (staged files included). Async-signal-safe: call it from a SIGINT or
 * SIGTERM handler, then re-raise the signal with the default action, and an
 * interrupted run leaves no temporary behind. Only files whose names this
 * library created are removed. A temporary being made on another thread at
 * that moment is waited for (those threads hold SIGINT, SIGTERM and SIGHUP
 * off while they make one), and from then on the process is taken to be
 * ending: a write that starts makes no temporary and fails (BB_ERR_IO). At
 * most 4096 temporaries are tracked at once; further ones are still removed
 * on errors, but not by this function. */
void bb__tempfiles_remove(void);

#ifdef __cplusplus
}
#endif

#endif /* BB_FILES_SAFE_FILE_H */
