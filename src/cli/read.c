/* read.c: image reads with stderr muted. libpng, inside OpenImageIO, prints
 * its own "libpng error: ..." line on stderr for a corrupt PNG before
 * OpenImageIO returns the error we report. */
#include "read.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

int cli_mute_stderr(void) {
  fflush(stderr);
  int saved = dup(STDERR_FILENO), null_fd = open("/dev/null", O_WRONLY);
  if (saved >= 0 && null_fd >= 0)
    dup2(null_fd, STDERR_FILENO);
  if (null_fd >= 0)
    close(null_fd);
  return saved;
}

void cli_unmute_stderr(int saved) {
  if (saved < 0)
    return;
  dup2(saved, STDERR_FILENO);
  close(saved);
}

bb_status cli_read_image(const char *path, bb_image *img, bb_image_info *info, bb_error *err) {
  int saved = cli_mute_stderr();
  bb_status st = bb_image_read(path, img, info, err);
  cli_unmute_stderr(saved);
  return st;
}
