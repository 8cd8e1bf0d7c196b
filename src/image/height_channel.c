/* height_channel.c: what BB_CHANNEL_AUTO means for one image (docs/conventions.md
 * "Height input", with Valve's height-in-alpha convention detected): the
 * mean of the colour, unless the colour is constant and alpha is not. */
#include "core/internal.h"
#include "image/height_channel.h"


#include <math.h>
#include <strings.h>

static const char *const CHANNEL_NAMES[] = {
    [BB_CHANNEL_AUTO] = "auto", [BB_CHANNEL_R] = "r",       [BB_CHANNEL_G] = "g",
    [BB_CHANNEL_B] = "b",       [BB_CHANNEL_A] = "a",       [BB_CHANNEL_LUMA] = "luma",
    [BB_CHANNEL_MEAN] = "mean", [BB_CHANNEL_VALVE] = "valve",
};
#define CHANNEL_COUNT ((int)(sizeof CHANNEL_NAMES / sizeof CHANNEL_NAMES[0]))

bb_status bb__channel_parse(const char *name, bb_channel *out, bb_error *err) {
  int i;
  bb_status st = bb__parse_name("channel", name, CHANNEL_NAMES, CHANNEL_COUNT, 1, &i, err);
  if (st == BB_OK) *out = (bb_channel)i;
  return st;
}

const char *bb__channel_name(bb_channel c) {
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

/* What the channel rule sees in an image. */
typedef struct channel_survey {
  int colour_varies; /* some colour channel differs from the first texel's */
  int alpha_varies;  /* alpha is finite everywhere and not constant */
  int alpha_graded;  /* ... and most texels lie between its extremes: a height
                        (a cutout mask sits at 0 or 1 but for its edges) */
  int grey;          /* one colour channel, or R = G = B at every texel */
} channel_survey;

static channel_survey survey(const bb_image *img, int colour, int alpha) {
  const size_t texels = (size_t)img->width * (size_t)img->height;
  const size_t stride = (size_t)img->channels;
  const float *first = img->pixels;
  channel_survey s = {0, 0, 0, colour == 1};
  int grey = 1, alpha_finite = 1;
  float lo = alpha >= 0 ? first[alpha] : 0.0f, hi = lo;
  for (size_t i = 0; i < texels; i++) {
    const float *t = img->pixels + i * stride;
    for (int c = 0; c < colour; c++)
      s.colour_varies |= t[c] != first[c];
    if (alpha >= 0) {
      const float a = t[alpha];
      alpha_finite &= isfinite(a);
      lo = a < lo ? a : lo;
      hi = a > hi ? a : hi;
    }
    if (colour == 3)
      grey &= t[0] == t[1] && t[1] == t[2];
  }
  if (colour == 3)
    s.grey = grey;
  s.alpha_varies = alpha >= 0 && alpha_finite && hi > lo;
  if (s.alpha_varies) {
    size_t extreme = 0;
    for (size_t i = 0; i < texels; i++) {
      const float a = img->pixels[i * stride + (size_t)alpha];
      extreme += a == lo || a == hi;
    }
    s.alpha_graded = extreme < texels / 2;
  }
  return s;
}

bb_channel bb__height_channel_noted(const bb_image *img, int alpha_channel, bb_channel channel,
                                    const char **note) {
  *note = NULL;
  if (channel != BB_CHANNEL_AUTO && channel != BB_CHANNEL_VALVE)
    return channel;
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0)
    return BB_CHANNEL_MEAN;
  const int colour = img->channels >= 3 ? 3 : 1;
  int alpha = alpha_of(img, alpha_channel);
  if (alpha >= 0 && alpha < colour)
    alpha = -1;
  if (channel == BB_CHANNEL_VALVE) {
    /* Valve's tools read alpha, and nothing else; without one, the grey
     * (recorded as the auto rule's grey) or the mean of the colour. */
    if (alpha >= 0)
      return BB_CHANNEL_A;
    *note = colour == 3 ? "no alpha channel; using the mean of R, G, B as the height"
                        : "no alpha channel; using its grey channel as the height";
    return colour == 3 ? BB_CHANNEL_MEAN : BB_CHANNEL_AUTO;
  }
  const channel_survey s = survey(img, colour, alpha);
  if (alpha >= 0 && s.alpha_varies && !s.colour_varies) {
    *note = "the colour is constant and alpha is not; using alpha as the height (Valve's "
            "convention; a channel option chooses another)";
    return BB_CHANNEL_A;
  }
  if (alpha >= 0 && s.alpha_graded && !s.grey) {
    *note = "R, G and B hold a colour and alpha a range of values; using alpha as the "
            "height (Valve's convention; channel mean takes the colour)";
    return BB_CHANNEL_A;
  }
  if (alpha >= 0 && s.alpha_varies && !s.alpha_graded && !s.grey)
    *note = "alpha looks like a mask (most texels at its extremes); using the mean of R, G, "
            "B as the height (channel a takes alpha)";
  else if (alpha >= 0 && s.alpha_varies)
    *note = "using the grey as the height; alpha varies too (channel a takes it)";
  else if (!s.grey)
    *note = "R, G and B differ (a colour image); using their mean as the height (a channel "
            "option chooses another)";
  return BB_CHANNEL_MEAN;
}

bb_channel bb__height_channel(const bb_image *img, int alpha_channel, bb_channel channel) {
  const char *note;
  return bb__height_channel_noted(img, alpha_channel, channel, &note);
}
