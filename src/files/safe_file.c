/* safe_file.c: the one way bumpbake puts bytes on disk (see internal.h).
 *
 * A file is written to a temporary ".bb-tmp-XXXXXX.EXT" in its destination
 * directory (same filesystem, so the final rename is atomic), through a
 * buffer whose every write(2) is checked and retried on short counts. The
 * first error is kept; later writes do nothing. Finishing flushes, fsyncs
 * and closes (checked) the file; committing renames it into place. Any
 * failure removes the temporary, so the final name never holds a partial
 * file, and a full disk is an error, never a silent truncation.
 *
 * Temporaries being written are listed in a fixed table that a signal
 * handler can walk (bb__tempfiles_remove): only lock-free atomics, unlink(2),
 * rmdir(2) and clock_gettime(2) are used there, all async-signal-safe. */

#include "core/file_names.h"
#include "core/internal.h"
#include "files/safe_file.h"
#include "bumpbake_cluster.h"
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* ------------------------------------------------- temporary-file registry */

/* Slots of temporaries that exist right now. A slot is FREE, being FILLED
 * by its owner, or LIVE (its path is complete and may be unlinked). */
/* Enough for every frame of the longest orbit (3600) staged at once; the
 * table is zero pages until used. */
enum { TEMP_SLOTS = 4096 };
enum { SLOT_FREE = 0, SLOT_FILLED, SLOT_LIVE };
static atomic_int slot_state[TEMP_SLOTS];
static char slot_path[TEMP_SLOTS][PATH_MAX];
static int slot_is_dir[TEMP_SLOTS]; /* a private directory (bb__safe_open_private) */

/* Lists path (a file, or a directory when is_dir) for bb__tempfiles_remove;
 * returns its slot, or -1 when the table is full (it then loses only its
 * signal-time cleanup). */
static int register_path(const char *path, int is_dir) {
  size_t n = strlen(path);
  if (n >= PATH_MAX)
    return -1;
  for (int i = 0; i < TEMP_SLOTS; i++) {
    int expected = SLOT_FREE;
    if (atomic_compare_exchange_strong(&slot_state[i], &expected, SLOT_FILLED)) {
      memcpy(slot_path[i], path, n + 1);
      slot_is_dir[i] = is_dir;
      atomic_store_explicit(&slot_state[i], SLOT_LIVE, memory_order_release);
      return i;
    }
  }
  return -1;
}

static void unregister_temp(int slot) {
  if (slot >= 0)
    atomic_store_explicit(&slot_state[slot], SLOT_FREE, memory_order_release);
}

static int register_temp(const char *path) { return register_path(path, 0); }

/* A name is registered before its file exists, so the handler's walk never
 * misses a file; but a walk that unlinks the name while another thread's
 * open(2) is making it would miss the file that open then leaves (seen as a
 * temporary left after SIGTERM under load). So every name is made into a
 * file inside a creation: the thread holds SIGINT, SIGTERM and SIGHUP off,
 * so the handler never runs on it there, and counts itself in `creating`;
 * bb__tempfiles_remove first says the process is ending (`closing`), after
 * which no creation starts, then waits for those in flight, then walks.
 * (Each side stores before it loads, sequentially consistent: one of the
 * two always sees the other.) */
static atomic_int creating;
static atomic_int closing;

int bb__safe_creation_begin(sigset_t *held) {
  sigset_t fatal;
  sigemptyset(&fatal);
  sigaddset(&fatal, SIGINT);
  sigaddset(&fatal, SIGTERM);
  sigaddset(&fatal, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &fatal, held);
  atomic_fetch_add(&creating, 1);
  if (atomic_load(&closing)) {
    bb__safe_creation_end(held);
    return EINTR;
  }
  return 0;
}

void bb__safe_creation_end(const sigset_t *held) {
  atomic_fetch_sub(&creating, 1);
  pthread_sigmask(SIG_SETMASK, held, NULL);
}

void bb__tempfiles_remove(void) {
  int saved_errno = errno; /* a handler must leave errno as it found it */
  atomic_store(&closing, 1);
  /* A creation is an open(2), a mkdir(2) or a mip chain's encoding. The
   * bound only matters to a handler of another signal run on a creating
   * thread, which would otherwise wait for itself. */
  struct timespec start, now;
  clock_gettime(CLOCK_MONOTONIC, &start);
  while (atomic_load(&creating) > 0) {
    clock_gettime(CLOCK_MONOTONIC, &now);
    if (now.tv_sec - start.tv_sec > 10)
      break;
  }
  /* Files first, then the private directories they emptied. */
  for (int pass = 0; pass < 2; pass++)
    for (int i = 0; i < TEMP_SLOTS; i++)
      if (atomic_load_explicit(&slot_state[i], memory_order_acquire) == SLOT_LIVE &&
          slot_is_dir[i] == pass)
        (void)(pass ? rmdir(slot_path[i]) : unlink(slot_path[i]));
  errno = saved_errno;
}

/* ------------------------------------------------------------ file names */

/* The extension of path's last component, with its dot, or "". */
static const char *extension_of(const char *path) {
  const char *dot = bb__file_extension(path);
  return dot ? dot : "";
}

/* "DIR/.bb-tmp-" + 6 random characters + ext (the extension of path, so a
 * writer that picks its format by name sees the right one; "" for a
 * directory), malloc'd. */
static char *temp_name(const char *path, const char *ext, uint64_t *seed) {
  static const char ALNUM[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  const char *base = bb__file_name(path);
  size_t dir_len = (size_t)(base - path);
  size_t len = dir_len + sizeof ".bb-tmp-XXXXXX" + strlen(ext);
  char *name = malloc(len);
  if (!name)
    return NULL;
  /* splitmix64: a fresh, well mixed value per call. */
  uint64_t z = (*seed += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  char random[7];
  for (int i = 0; i < 6; i++, z /= 62)
    random[i] = ALNUM[z % 62];
  random[6] = '\0';
  snprintf(name, len, "%.*s.bb-tmp-%s%s", (int)dir_len, path, random, ext);
  return name;
}

static uint64_t fresh_seed(void) {
  static atomic_uint_fast64_t calls;
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^ ((uint64_t)getpid() << 16) ^
         (atomic_fetch_add(&calls, 1) * 0xD1B54A32D192ED03ull);
}

/* ---------------------------------------------------- what is at a name */

static const char *kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISREG(mode)) return "a regular file";
  return "a special file";
}

bb_status bb__safe_check_target(const char *path, bb_error *err) {
  struct stat named, target;
  if (!path || lstat(path, &named) != 0 || S_ISREG(named.st_mode))
    return BB_OK; /* nothing there (or nothing to say yet): the write tells */
  if (S_ISDIR(named.st_mode))
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: is a directory", path);
  if (!S_ISLNK(named.st_mode))
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: is %s, not a regular file", path,
                    kind_of(named.st_mode));
  return bb__fail(err, BB_ERR_IO,
                  "%s: cannot write: is a symbolic link (to %s), not a regular file; name "
                  "the file itself",
                  path, stat(path, &target) == 0 ? kind_of(target.st_mode) : "nothing");
}

int bb__safe_is_stream(const char *path) {
  struct stat named, target;
  return path && lstat(path, &named) == 0 && !S_ISREG(named.st_mode) &&
         stat(path, &target) == 0 && (S_ISFIFO(target.st_mode) || S_ISCHR(target.st_mode));
}

bb_status bb__safe_write_through(const char *path, const void *data, size_t size,
                                 bb_error *err) {
  /* O_NONBLOCK: a FIFO without a reader fails (ENXIO) instead of waiting;
   * cleared for the writes. */
  int fd = open(path, O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  int error = fd < 0 ? errno : 0;
  struct stat st;
  if (!error && fstat(fd, &st) != 0)
    error = errno;
  else if (!error && !S_ISFIFO(st.st_mode) && !S_ISCHR(st.st_mode))
    error = EINVAL; /* swapped since it was checked */
  int flags = error ? 0 : fcntl(fd, F_GETFL);
  if (!error && (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0))
    error = errno;
  const unsigned char *bytes = data;
  while (!error && size > 0) {
    const ssize_t n = write(fd, bytes, size);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
      error = n < 0 ? errno : ENOSPC;
    else
      bytes += n, size -= (size_t)n;
  }
  if (fd >= 0 && close(fd) != 0 && !error && errno != EINTR)
    error = errno;
  if (error == ENXIO)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: no process reads the FIFO", path);
  if (error)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, strerror(error));
  return BB_OK;
}

/* ------------------------------------------------------------ low level */

/* Writes all of data at offset, retrying short counts and EINTR. Returns 0,
 * or the errno of the failure (ENOSPC for a write that made no progress). */
static int write_fully(int fd, const unsigned char *data, size_t size, int64_t offset) {
  while (size > 0) {
    ssize_t n = pwrite(fd, data, size, (off_t)offset);
    if (n < 0) {
      if (errno == EINTR)
        continue;
      return errno;
    }
    if (n == 0)
      return ENOSPC;
    data += n;
    size -= (size_t)n;
    offset += n;
  }
  return 0;
}

static void note_error(bb_staged_file *f, int error) {
  if (!f->error)
    f->error = error;
}

static void flush_buffer(bb_staged_file *f) {
  if (f->buffered && !f->error)
    note_error(f, write_fully(f->fd, f->buffer, f->buffered, f->buffer_pos));
  f->buffered = 0;
}

static void grow_size(bb_staged_file *f, int64_t end) {
  if (end > f->size)
    f->size = end;
}

/* Closes the descriptor once; the result of close(2) counts as a write. */
static void close_fd(bb_staged_file *f) {
  if (f->fd < 0)
    return;
  if (close(f->fd) != 0 && errno != EINTR)
    note_error(f, errno);
  f->fd = -1;
}

/* Removes the temporary (and its private directory), forgets them and
 * frees everything f owns. */
static void release(bb_staged_file *f, int remove_temp) {
  if (f->fd >= 0) {
    close(f->fd);
    f->fd = -1;
  }
  if (f->dir_fd >= 0) {
    if (remove_temp && f->leaf) unlinkat(f->dir_fd, f->leaf, 0);
  } else if (remove_temp && f->temp_path) {
    unlink(f->temp_path);
  }
  if (f->temp_dir) rmdir(f->temp_dir); /* empty once its file is gone or renamed */
  /* The locks go last, after the rename, unlink or rmdir: a sweep never
   * sees a temporary of ours unlocked. */
  if (f->dir_fd >= 0) {
    close(f->dir_fd);
    f->dir_fd = -1;
  }
  if (f->locked) close(f->lock_fd);
  f->locked = 0;
  unregister_temp(f->slot);
  unregister_temp(f->file_slot);
  unregister_temp(f->dir_slot);
  f->slot = f->file_slot = f->dir_slot = -1;
  free(f->buffer);
  free(f->temp_path);
  free(f->path);
  free(f->temp_dir);
  free(f->registered_file);
  f->buffer = NULL;
  f->temp_path = f->path = f->temp_dir = f->registered_file = NULL;
  f->leaf = NULL;
  if (f->lock_ready)
    pthread_mutex_destroy(&f->lock);
  f->lock_ready = 0;
}

/* ----------------------------------------------------------------- open */

enum { BUFFER_BYTES = 1 << 16 };

/* Locks the temporary just created as fd under name, for
 * bb_tempfiles_sweep: 0 when this process now holds the lock on the file
 * that name names, EEXIST when a sweep got to it first (it removes what it
 * locks: try another name), or another errno. The lock goes with a dup of
 * fd into *lock_fd, which stays open until the temporary is renamed or
 * removed; with lock_fd NULL, with fd itself. */
static int lock_temp(int fd, const char *name, int *lock_fd) {
  if (flock(fd, LOCK_EX | LOCK_NB) != 0)
    return errno == EWOULDBLOCK ? EEXIST : (errno == ENOLCK || errno == EINVAL ? ENOLCK : errno);
  struct stat ours, named;
  if (fstat(fd, &ours) != 0 || stat(name, &named) != 0 || ours.st_dev != named.st_dev ||
      ours.st_ino != named.st_ino)
    return EEXIST; /* swept between the open and the lock */
  if (!lock_fd) return 0; /* the lock goes with fd itself */
  *lock_fd = fcntl(fd, F_DUPFD_CLOEXEC, 0);
  return *lock_fd >= 0 ? 0 : errno;
}

/* Creates the temporary with O_EXCL and locks it. Its name is registered
 * before the file exists, so no instant passes in which a signal could
 * leave it behind; a name that already exists is unregistered and another
 * tried. A filesystem without locks (ENOLCK) still gets its temporary,
 * unlocked: a sweep there may take it for an orphan, which only a sweep run
 * while it is written can do. */
static int create_temp(bb_staged_file *f) {
  uint64_t seed = fresh_seed();
  for (int attempt = 0; attempt < 100; attempt++) {
    char *name = temp_name(f->path, extension_of(f->path), &seed);
    if (!name)
      return ENOMEM;
    sigset_t held;
    if (bb__safe_creation_begin(&held) != 0) {
      free(name);
      return EINTR;
    }
    int slot = register_temp(name);
    /* 0666 less the umask, as for any new file (mkstemp would make 0600,
     * and the rename keeps the mode). */
    int fd = open(name, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    int error = fd >= 0 ? lock_temp(fd, name, &f->lock_fd) : errno;
    if (error == ENOLCK)
      error = 0;
    else if (!error)
      f->locked = 1;
    if (error) {
      if (fd >= 0)
        close(fd); /* a sweep's: not ours to remove */
      unregister_temp(slot);
    }
    bb__safe_creation_end(&held);
    if (!error) {
      f->fd = fd;
      f->slot = slot;
      f->temp_path = name;
      return 0;
    }
    free(name);
    if (error != EEXIST)
      return error;
  }
  return EEXIST;
}

void bb__safe_init(bb_staged_file *f) {
  memset(f, 0, sizeof *f);
  f->fd = f->dir_fd = -1;
  f->slot = f->file_slot = f->dir_slot = -1;
}

bb_status bb__safe_open(bb_staged_file *f, const char *path, bb_error *err) {
  bb__safe_init(f);
  if (!path || !*path)
    return bb__fail(err, BB_ERR_ARGUMENT, "no output path");
  f->path = malloc(strlen(path) + 1);
  f->buffer = malloc(BUFFER_BYTES);
  if (!f->path || !f->buffer) {
    release(f, 0);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  strcpy(f->path, path);
  if (bb__safe_check_target(path, err) != BB_OK) {
    release(f, 0);
    return BB_ERR_IO;
  }
  if (pthread_mutex_init(&f->lock, NULL) != 0) {
    release(f, 0);
    return bb__fail(err, BB_ERR_MEMORY, "%s: cannot create a lock", path);
  }
  f->lock_ready = 1;
  int error = create_temp(f);
  if (error) {
    release(f, 0);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, strerror(error));
  }
  return BB_OK;
}

/* Creates the private directory with mkdir (which never follows a link and
 * fails on any existing name), registered before it exists, opens it
 * without following a link and locks it as create_temp locks a file:
 * f->dir_fd, f->temp_dir and f->dir_slot. A directory a sweep removed or
 * locked first (it removes what it locks) is given up for another name. */
static int create_private_dir(bb_staged_file *f) {
  uint64_t seed = fresh_seed();
  for (int attempt = 0; attempt < 100; attempt++) {
    char *name = temp_name(f->path, "", &seed);
    if (!name) return ENOMEM;
    sigset_t held;
    if (bb__safe_creation_begin(&held) != 0) {
      free(name);
      return EINTR;
    }
    int slot = register_path(name, 1);
    int error = mkdir(name, 0700) == 0 ? 0 : errno;
    int fd = -1;
    if (!error) {
      /* Swapped for a link or another's directory in between: refused. */
      fd = open(name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
      struct stat st;
      if (fd < 0)
        error = errno == ENOENT ? EEXIST : errno;
      else if (fstat(fd, &st) != 0 || st.st_uid != geteuid() || (st.st_mode & 077) != 0)
        error = EPERM;
      else if ((error = lock_temp(fd, name, NULL)) == ENOLCK)
        error = 0; /* no locks here: unlocked, as create_temp's files */
    }
    if (error) {
      if (fd >= 0) close(fd);
      unregister_temp(slot);
    }
    bb__safe_creation_end(&held);
    if (!error) {
      f->temp_dir = name;
      f->dir_slot = slot;
      f->dir_fd = fd;
      return 0;
    }
    free(name);
    if (error != EEXIST) return error;
  }
  return EEXIST;
}

bb_status bb__safe_open_private(bb_staged_file *f, const char *path, bb_error *err) {
  bb__safe_init(f);
  if (!path || !*path) return bb__fail(err, BB_ERR_ARGUMENT, "no output path");
  f->path = malloc(strlen(path) + 1);
  if (!f->path) return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  strcpy(f->path, path);
  if (bb__safe_check_target(path, err) != BB_OK) {
    release(f, 0);
    return BB_ERR_IO;
  }
  int error = create_private_dir(f);
  if (!error) {
    const char *ext = extension_of(path);
    char through_fd[64];
    snprintf(through_fd, sizeof through_fd, "/proc/self/fd/%d", f->dir_fd);
    struct stat st;
    /* The name through the descriptor reaches this directory whatever
     * happens to its path; without /proc the path has to do. */
    const char *dir = stat(through_fd, &st) == 0 && S_ISDIR(st.st_mode) ? through_fd : f->temp_dir;
    size_t dir_len = strlen(dir), reg_len = strlen(f->temp_dir), leaf_len = strlen("/staged") + strlen(ext);
    f->temp_path = malloc(dir_len + leaf_len + 1);
    f->registered_file = malloc(reg_len + leaf_len + 1);
    if (!f->temp_path || !f->registered_file) {
      error = ENOMEM;
    } else {
      sprintf(f->temp_path, "%s/staged%s", dir, ext);
      sprintf(f->registered_file, "%s/staged%s", f->temp_dir, ext);
      f->leaf = f->temp_path + dir_len + 1;
      f->file_slot = register_temp(f->registered_file);
    }
  }
  if (error) {
    release(f, 1);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, strerror(error));
  }
  if (pthread_mutex_init(&f->lock, NULL) != 0) {
    release(f, 1);
    return bb__fail(err, BB_ERR_MEMORY, "%s: cannot create a lock", path);
  }
  f->lock_ready = 1;
  return BB_OK;
}

bb_status bb__safe_adopt(bb_staged_file *f, bb_error *err) {
  int error = 0;
  int fd = openat(f->dir_fd, f->leaf, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  struct stat st;
  if (fd < 0)
    error = errno;
  else if (fstat(fd, &st) != 0)
    error = errno;
  else if (!S_ISREG(st.st_mode))
    error = EINVAL;
  /* A full disk may only show at fsync (delayed allocation) or close (NFS). */
  else if (fsync(fd) != 0)
    error = errno;
  if (fd >= 0 && close(fd) != 0 && !error && errno != EINTR) error = errno;
  if (error) {
    bb_status status =
        bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", f->path, strerror(error));
    release(f, 1);
    return status;
  }
  return BB_OK;
}

/* ------------------------------------------------------- reads and writes */

/* Buffered write at offset; the caller holds the lock. */
static size_t write_at(bb_staged_file *f, const void *data, size_t size, int64_t offset) {
  if (f->error || f->fd < 0)
    return 0;
  if (size == 0)
    return 0;
  if (offset < 0 || (uint64_t)offset > (uint64_t)INT64_MAX - size) {
    note_error(f, EINVAL);
    return 0;
  }
  /* The buffer holds bytes contiguous from buffer_pos; anything else (a
   * seek back, a big block) flushes it first. */
  if (f->buffered && offset != f->buffer_pos + (int64_t)f->buffered)
    flush_buffer(f);
  if (size >= BUFFER_BYTES) {
    flush_buffer(f);
    if (!f->error)
      note_error(f, write_fully(f->fd, data, size, offset));
  } else {
    if (f->buffered + size > BUFFER_BYTES)
      flush_buffer(f);
    if (!f->buffered)
      f->buffer_pos = offset;
    memcpy(f->buffer + f->buffered, data, size);
    f->buffered += size;
  }
  if (f->error)
    return 0;
  grow_size(f, offset + (int64_t)size);
  return size;
}

size_t bb__safe_write(bb_staged_file *f, const void *data, size_t size) {
  pthread_mutex_lock(&f->lock);
  size_t n = write_at(f, data, size, f->pos);
  f->pos += (int64_t)n;
  pthread_mutex_unlock(&f->lock);
  return n;
}

size_t bb__safe_pwrite(bb_staged_file *f, const void *data, size_t size, int64_t offset) {
  pthread_mutex_lock(&f->lock);
  size_t n = write_at(f, data, size, offset);
  pthread_mutex_unlock(&f->lock);
  return n;
}

size_t bb__safe_pread(bb_staged_file *f, void *data, size_t size, int64_t offset) {
  pthread_mutex_lock(&f->lock);
  flush_buffer(f); /* what was written must be what is read back */
  size_t done = 0;
  while (!f->error && f->fd >= 0 && done < size && offset >= 0) {
    ssize_t n = pread(f->fd, (unsigned char *)data + done, size - done,
                      (off_t)(offset + (int64_t)done));
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
      break;
    done += (size_t)n;
  }
  pthread_mutex_unlock(&f->lock);
  return done;
}

size_t bb__safe_read(bb_staged_file *f, void *data, size_t size) {
  size_t n = bb__safe_pread(f, data, size, bb__safe_tell(f));
  pthread_mutex_lock(&f->lock);
  f->pos += (int64_t)n;
  pthread_mutex_unlock(&f->lock);
  return n;
}

int bb__safe_seek(bb_staged_file *f, int64_t offset) {
  if (offset < 0)
    return -1;
  pthread_mutex_lock(&f->lock);
  f->pos = offset;
  pthread_mutex_unlock(&f->lock);
  return 0;
}

int64_t bb__safe_tell(bb_staged_file *f) {
  pthread_mutex_lock(&f->lock);
  int64_t pos = f->pos;
  pthread_mutex_unlock(&f->lock);
  return pos;
}

int64_t bb__safe_size(bb_staged_file *f) {
  pthread_mutex_lock(&f->lock);
  int64_t size = f->size;
  pthread_mutex_unlock(&f->lock);
  return size;
}

/* -------------------------------------------------------- finish, commit */

bb_status bb__safe_finish(bb_staged_file *f, bb_error *err) {
  if (f->fd < 0 && !f->error && f->temp_path)
    return BB_OK; /* finished before */
  if (!f->temp_path)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: nothing to finish",
                    f->path ? f->path : "?");
  flush_buffer(f);
  /* A full disk may only show at fsync (delayed allocation) or close (NFS). */
  if (!f->error && fsync(f->fd) != 0)
    note_error(f, errno);
  close_fd(f);
  if (f->error) {
    bb_status st =
        bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", f->path, strerror(f->error));
    release(f, 1);
    return st;
  }
  return BB_OK;
}

/* Makes the rename itself durable. It has already happened and cannot be
 * undone, so a directory that refuses fsync (some filesystems do) is not an
 * error of the write. */
static void sync_directory_of(const char *path) {
  const char *base = bb__file_name(path);
  char dir[PATH_MAX];
  if (base == path)
    snprintf(dir, sizeof dir, ".");
  else
    snprintf(dir, sizeof dir, "%.*s", (int)(base - path), path);
  int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    (void)fsync(fd);
    close(fd);
  }
}

bb_status bb__safe_commit(bb_staged_file *f, bb_error *err) {
  bb_status st = bb__safe_finish(f, err);
  if (st != BB_OK)
    return st;
  /* Checked at open; again here, as what stands at the name may have
   * changed while the file was encoded. */
  if (bb__safe_check_target(f->path, err) != BB_OK) {
    release(f, 1);
    return BB_ERR_IO;
  }
  if (f->dir_fd >= 0 ? renameat(f->dir_fd, f->leaf, AT_FDCWD, f->path) != 0
                     : rename(f->temp_path, f->path) != 0) {
    st = bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", f->path, strerror(errno));
    release(f, 1);
    return st;
  }
  sync_directory_of(f->path);
  release(f, 0);
  return BB_OK;
}

void bb__safe_discard(bb_staged_file *f) {
  if (f)
    release(f, 1);
}

/* ------------------------------------------------------- orphans */

/* ".bb-tmp-" and six characters of temp_name's alphabet, then anything (the
 * extension). */
static int is_temp_name(const char *name) {
  if (strncmp(name, ".bb-tmp-", 8) != 0)
    return 0;
  for (int i = 8; i < 14; i++) {
    const char c = name[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')))
      return 0;
  }
  return name[14] == '\0' || name[14] == '.';
}

/* Empties a private directory (bb__safe_open_private) whose writer is gone,
 * open as fd: its staged file, whatever the encoder named "staged*". */
static void empty_private_dir(int fd) {
  const int listing = fcntl(fd, F_DUPFD_CLOEXEC, 0);
  DIR *d = listing >= 0 ? fdopendir(listing) : NULL;
  if (!d) {
    if (listing >= 0) close(listing);
    return;
  }
  for (struct dirent *e; (e = readdir(d)) != NULL;)
    if (strncmp(e->d_name, "staged", 6) == 0) unlinkat(fd, e->d_name, 0);
  closedir(d);
}

/* Removes dir/name when it is a temporary nobody holds (a file, or a
 * private directory and its staged file): 1 removed, 0 left (held, gone,
 * neither, or a directory holding something else), -1 failed (errno). */
static int sweep_one(const char *dir, const char *name) {
  char path[PATH_MAX];
  if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path)
    return 0;
  int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return errno == ENOENT || errno == ELOOP ? 0 : -1;
  int removed = 0;
  struct stat held, named;
  if (flock(fd, LOCK_EX | LOCK_NB) == 0 && fstat(fd, &held) == 0 &&
      lstat(path, &named) == 0 && held.st_dev == named.st_dev && held.st_ino == named.st_ino) {
    /* Locked by us, it is still the file at that name: its writer is gone. */
    if (S_ISREG(held.st_mode)) {
      if (unlink(path) == 0)
        removed = 1;
      else if (errno != ENOENT)
        removed = -1;
    } else if (S_ISDIR(held.st_mode) && name[14] == '\0' && held.st_uid == geteuid()) {
      empty_private_dir(fd);
      if (rmdir(path) == 0)
        removed = 1;
      else if (errno != ENOENT && errno != ENOTEMPTY && errno != EEXIST)
        removed = -1;
    }
  }
  const int saved = errno;
  close(fd); /* drops the lock */
  errno = saved;
  return removed;
}

bb_status bb_tempfiles_sweep(const char *dir, int *removed, bb_error *err) {
  if (removed)
    *removed = 0;
  if (!dir || !*dir)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_tempfiles_sweep: no directory");
  DIR *d = opendir(dir);
  if (!d)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read the directory: %s", dir, strerror(errno));
  bb_status st = BB_OK;
  int count = 0;
  for (struct dirent *e; (e = readdir(d)) != NULL;) {
    if (!is_temp_name(e->d_name))
      continue;
    const int r = sweep_one(dir, e->d_name);
    if (r > 0)
      count++;
    else if (r < 0 && st == BB_OK)
      st = bb__fail(err, BB_ERR_IO, "%s/%s: cannot remove a left-over temporary: %s", dir,
                    e->d_name, strerror(errno));
  }
  closedir(d);
  if (removed)
    *removed = count;
  return st;
}

/* ------------------------------------------------------ public handles */

bb_staged_file *bb__staged_new(void) {
  bb_staged_file *f = malloc(sizeof *f);
  if (f) bb__safe_init(f);
  return f;
}

const char *bb__staged_file_path(const bb_staged_file *staged) {
  return staged ? staged->path : NULL;
}

bb_status bb__staged_file_commit(bb_staged_file *staged, bb_error *err) {
  if (!staged)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__staged_file_commit: NULL");
  bb_status st = bb__safe_commit(staged, err);
  free(staged);
  return st;
}

void bb__staged_file_discard(bb_staged_file *staged) {
  if (!staged)
    return;
  bb__safe_discard(staged);
  free(staged);
}

bb_status bb__file_write(const char *path, const void *data, size_t size, bb_error *err) {
  if (!data && size)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__file_write: no data");
  bb_staged_file f;
  bb_status st = bb__safe_open(&f, path, err);
  if (st != BB_OK)
    return st;
  bb__safe_write(&f, data, size); /* an error is kept, and reported by the commit */
  return bb__safe_commit(&f, err);
}
