/* height_channel.h: the channel rule with the note it owes the user
 * (height_channel.c). */
#ifndef BB_IO_HEIGHT_CHANNEL_H
#define BB_IO_HEIGHT_CHANNEL_H

#include "bumpbake.h"

/* bb_height_channel, and in *note a line saying what it took when the image
 * left a choice (a colour image, an alpha that varies, no alpha for Valve's
 * rule), or NULL. The text is static. */
bb_channel bb__height_channel_noted(const bb_image *img, int alpha_channel, bb_channel channel,
                                    const char **note);

#endif /* BB_IO_HEIGHT_CHANNEL_H */
