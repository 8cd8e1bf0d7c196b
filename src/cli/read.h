/* read.h: image reads with stderr muted, so a third-party library's own
 * line about a corrupt file does not make an error two lines. */
#ifndef BB_CLI_READ_H
#define BB_CLI_READ_H

#include "bumpbake.h"

/* Mutes stderr until cli_unmute_stderr(saved) with what this returned. */
int cli_mute_stderr(void);
void cli_unmute_stderr(int saved);

/* bb_image_read with stderr muted. */
bb_status cli_read_image(const char *path, bb_image *img, bb_image_info *info, bb_error *err);

#endif /* BB_CLI_READ_H */
