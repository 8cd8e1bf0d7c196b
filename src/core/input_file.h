/* input_file.h: opening the files the library reads, refusing at once what
 * is not a regular file (input_file.c). */
#ifndef BB_CORE_INPUT_FILE_H
#define BB_CORE_INPUT_FILE_H

#include "bumpbake.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Opens path for reading without blocking on it: a FIFO, a device, a socket
 * or a directory is BB_ERR_IO ("PATH: is a FIFO, not a regular file"), as
 * is a missing or unreadable file ("PATH: no such file", "PATH: cannot
 * read: REASON"). On success *fd is a blocking, close-on-exec descriptor of
 * the regular file; the caller closes it. Read through the descriptor where
 * the reader allows it, so the file checked is the file read. */
bb_status bb__input_open(const char *path, int *fd, bb_error *err);

/* bb__input_open and close: for readers that can only open by name (the
 * check then narrows, not closes, the window for a swap). */
bb_status bb__input_check(const char *path, bb_error *err);

/* pread of n bytes at offset of fd, through EINTR and short reads: the
 * bytes read (fewer at the end of the file or on an error). */
size_t bb__input_read_at(int fd, void *buf, size_t n, uint64_t offset);

#ifdef __cplusplus
}
#endif

#endif /* BB_CORE_INPUT_FILE_H */
