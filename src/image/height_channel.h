/* height_channel.h: the channel rule with the note it owes the user
 * (height_channel.c), and the height loader that applies it (height_load.c). */
#ifndef BB_IMAGE_HEIGHT_CHANNEL_H
#define BB_IMAGE_HEIGHT_CHANNEL_H

#include "bumpbake.h"

/* bb__height_channel, and in *note a line saying what it took when the image
 * left a choice (a colour image, an alpha that varies, no alpha for Valve's
 * rule), or NULL. The text is static. */
bb_channel bb__height_channel_noted(const bb_image *img, int alpha_channel, bb_channel channel,
                                    const char **note);

/* What bb__height_load found out about the file. */
typedef struct bb__height_loaded {
  bb_channel channel;     /* the rule's choice */
  const char *note;       /* what to tell the user of that choice, or NULL */
  int channels, bits_per_sample, is_float;
  char format_name[32];
} bb__height_loaded;

/* The height of the image file at path by the channel rule, telling which
 * channel it took and why (height_load.c): the header decides where it
 * can, and only the channels needed are decoded. Messages name the file.
 * bb__height_file_read's loader; tests call it alone. */
bb_status bb__height_load(const char *path, bb_channel channel, bb_image *height,
                          bb__height_loaded *loaded, bb_error *err);

/* Parses "r", "g", "b", "a", "luma", "mean", "auto", "valve" (any case). */
bb_status bb__channel_parse(const char *name, bb_channel *out, bb_error *err);

/* The channel the rule takes from img when asked for `channel`: channel
 * itself, except for two rules. BB_CHANNEL_AUTO reads img once and gives
 * BB_CHANNEL_A when img has an alpha channel (alpha_channel, or the last of
 * 2 or 4 channels) that varies while the colour (grey, or R, G and B) is the
 * same at every texel, or when the colour is a colour (R, G and B not all
 * equal) and alpha takes three values or more (a height, not a cutout
 * mask): Valve's convention, the height in alpha. Otherwise it gives
 * BB_CHANNEL_MEAN (for a grey image, the grey). BB_CHANNEL_VALVE gives
 * BB_CHANNEL_A whenever there is an alpha channel, else BB_CHANNEL_MEAN for
 * colour and BB_CHANNEL_AUTO (the grey) for grey. bb__height_file_read says
 * which was taken whenever the image left a choice. */
bb_channel bb__height_channel(const bb_image *img, int alpha_channel, bb_channel channel);

/* Once in bumpbake.h beside the functions that stay public there. */
/* The name bb__channel_parse accepts; "unknown" for other values. */
const char *bb__channel_name(bb_channel c);

#endif /* BB_IMAGE_HEIGHT_CHANNEL_H */
