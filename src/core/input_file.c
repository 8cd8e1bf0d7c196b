/* input_file.c: how the library opens a file it is about to read. Input
 * files are untrusted: a FIFO, a device or a directory under an image's
 * name must be refused at once, not block in open() or spin on /dev/zero. */
#include "core/input_file.h"
#include "core/internal.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* What a file that is not a regular one is, for the message. */
static const char *kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory";
  if (S_ISFIFO(mode)) return "is a FIFO, not a regular file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  return "is not a regular file";
}

bb_status bb__input_open(const char *path, int *fd_out, bb_error *err) {
  *fd_out = -1;
  if (!path || !*path) return bb__fail(err, BB_ERR_ARGUMENT, "no file name given");
  /* O_NONBLOCK: opening a FIFO with no writer returns at once instead of
   * waiting for one; it is cleared below for the regular file we keep. */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    struct stat link;
    if (errno == ENOENT && lstat(path, &link) == 0 && S_ISLNK(link.st_mode))
      return bb__fail(err, BB_ERR_IO, "%s: no such file (a symbolic link to a missing file)", path);
    if (errno == ENOENT || errno == ENOTDIR) return bb__fail(err, BB_ERR_IO, "%s: no such file", path);
    if (errno == EISDIR) return bb__fail(err, BB_ERR_IO, "%s: is a directory", path);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
  }
  struct stat st;
  if (fstat(fd, &st) != 0) {
    int e = errno;
    close(fd);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    close(fd);
    return bb__fail(err, BB_ERR_IO, "%s: %s", path, kind_of(st.st_mode));
  }
  int flags = fcntl(fd, F_GETFL);
  if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
    int e = errno;
    close(fd);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(e));
  }
  *fd_out = fd;
  return BB_OK;
}

bb_status bb__input_check(const char *path, bb_error *err) {
  int fd;
  bb_status st = bb__input_open(path, &fd, err);
  if (st == BB_OK) close(fd);
  return st;
}

size_t bb__input_read_at(int fd, void *buf, size_t n, uint64_t offset) {
  size_t done = 0;
  while (done < n) {
    ssize_t got = pread(fd, (unsigned char *)buf + done, n - done, (off_t)(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    done += (size_t)got;
  }
  return done;
}
