/* height_channel.c: what BB_CHANNEL_AUTO means for one image (docs/conventions.md
 * "Height input", with Valve's height-in-alpha convention detected): the
 * mean of the colour, unless the colour is constant and alpha is not. */
#include "core/internal.h"


#include <strings.h>

static const char *const CHANNEL_NAMES[] = {
    [BB_CHANNEL_AUTO] = "auto", [BB_CHANNEL_R] = "r",       [BB_CHANNEL_G] = "g",
    [BB_CHANNEL_B] = "b",       [BB_CHANNEL_A] = "a",       [BB_CHANNEL_LUMA] = "luma",
    [BB_CHANNEL_MEAN] = "mean",
};
#define CHANNEL_COUNT ((int)(sizeof CHANNEL_NAMES / sizeof CHANNEL_NAMES[0]))

bb_status bb_channel_parse(const char *name, bb_channel *out, bb_error *err) {
  int i;
  bb_status st = bb__parse_name("channel", name, CHANNEL_NAMES, CHANNEL_COUNT, 1, &i, err);
  if (st == BB_OK) *out = (bb_channel)i;
  return st;
}

const char *bb_channel_name(bb_channel c) {
  if ((int)c < 0 || (int)c >= CHANNEL_COUNT) return "unknown";
  return CHANNEL_NAMES[c];
}

/* Index of the alpha channel: the file's, else the last channel of a grey +
 * alpha or RGBA image (TGA does not always flag its alpha); -1 if none. */
static int alpha_of(const bb_image *img, int alpha_channel) {
  if (alpha_channel >= 0)
    return alpha_channel < img->channels ? alpha_channel : -1;
  return img->channels == 2 || img->channels == 4 ? img->channels - 1 : -1;
}

/* 1 when the colour channels (0 .. colour-1) are constant over the image
 * and channel alpha is not. */
static int height_is_in_alpha(const bb_image *img, int colour, int alpha) {
  const size_t texels = (size_t)img->width * (size_t)img->height;
  const size_t stride = (size_t)img->channels;
  const float *first = img->pixels;
  int alpha_varies = 0;
  for (size_t i = 1; i < texels; i++) {
    const float *t = img->pixels + i * stride;
    for (int c = 0; c < colour; c++)
      if (t[c] != first[c])
        return 0;
    alpha_varies |= t[alpha] != first[alpha];
  }
  return alpha_varies;
}

bb_channel bb_height_channel(const bb_image *img, int alpha_channel, bb_channel channel) {
  if (channel != BB_CHANNEL_AUTO)
    return channel;
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0)
    return BB_CHANNEL_MEAN;
  const int colour = img->channels >= 3 ? 3 : 1;
  const int alpha = alpha_of(img, alpha_channel);
  if (alpha >= colour && height_is_in_alpha(img, colour, alpha))
    return BB_CHANNEL_A;
  return BB_CHANNEL_MEAN;
}
