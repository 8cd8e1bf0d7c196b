/* height_load.c: heights from images and files by the channel rule
 * (docs/conventions.md "Height input"): which channel becomes h. */

#include "core/internal.h"
#include "image/height_channel.h"
#include "image/oiio.h"
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* How one height texel is made from a source texel. */
typedef enum {
  PICK_ONE,  /* copy channel `index` */
  PICK_MEAN, /* (R + G + B) / 3 in double */
  PICK_LUMA  /* Rec. 709 luma in double */
} pick_kind;

typedef struct {
  pick_kind kind;
  int index;
} pick;

/* Index of the alpha channel: the file's, else the last channel of a grey +
 * alpha or RGBA image (formats such as TGA do not always flag their alpha). */
static int alpha_index(int channels, int alpha_channel) {
  if (alpha_channel >= 0) return alpha_channel;
  if (channels == 2 || channels == 4) return channels - 1;
  return -1;
}

/* Resolves the requested channel against an image layout (channel count and
 * alpha index). Grey images (1 channel, or grey + alpha) have no G or B, but
 * their R, luma and mean are the grey itself. */
static bb_status resolve_pick(int channels, int alpha_channel, bb_channel channel, pick *p,
                              bb_error *err) {
  const int colour = channels >= 3;
  p->kind = PICK_ONE;
  p->index = 0;
  switch (channel) {
  case BB_CHANNEL_AUTO:
  case BB_CHANNEL_VALVE: /* resolved by bb__height_channel before this */
  case BB_CHANNEL_MEAN:
    if (colour) p->kind = PICK_MEAN;
    return BB_OK;
  case BB_CHANNEL_LUMA:
    if (colour) p->kind = PICK_LUMA;
    return BB_OK;
  case BB_CHANNEL_R:
    return BB_OK;
  case BB_CHANNEL_G:
  case BB_CHANNEL_B:
    if (!colour)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "channel '%s' asked of a grey image (%d channel%s) with no %s",
                      bb__channel_name(channel), channels, channels == 1 ? "" : "s",
                      channel == BB_CHANNEL_G ? "green" : "blue");
    p->index = channel == BB_CHANNEL_G ? 1 : 2;
    return BB_OK;
  case BB_CHANNEL_A:
    p->index = alpha_index(channels, alpha_channel);
    if (p->index < 0 || p->index >= channels)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "channel 'a' asked of an image with no alpha (%d channels)", channels);
    return BB_OK;
  }
  return bb__fail(err, BB_ERR_ARGUMENT, "unknown height channel %d", (int)channel);
}

static float pick_value(const float *texel, pick p) {
  switch (p.kind) {
  case PICK_MEAN:
    return (float)(((double)texel[0] + (double)texel[1] + (double)texel[2]) / 3.0);
  case PICK_LUMA:
    return (float)(0.2126 * texel[0] + 0.7152 * texel[1] + 0.0722 * texel[2]);
  case PICK_ONE:
    break;
  }
  return texel[p.index];
}

/* Fails with the first non-finite height of a 1-channel image. */
static bb_status check_finite(const bb_image *height, bb_error *err) {
  if (bb__image_all_finite(height))
    return BB_OK;
  for (int y = 0; y < height->height; y++)
    for (int x = 0; x < height->width; x++) {
      float h = *bb_image_texel(height, x, y);
      if (!isfinite(h))
        return bb__fail(err, BB_ERR_VALUE, "height at texel (%d, %d) is %s", x, y,
                        isnan(h) ? "NaN" : "infinite");
    }
  return BB_OK;
}

bb_status bb_height_from_image(const bb_image *img, int alpha_channel, bb_channel channel,
                               bb_image *height, bb_error *err) {
  if (!height) return bb__fail(err, BB_ERR_ARGUMENT, "bb_height_from_image: height is NULL");
  memset(height, 0, sizeof *height);
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0 || img->channels <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_height_from_image: empty image");
  if (alpha_channel >= img->channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "alpha channel %d of a %d-channel image",
                    alpha_channel, img->channels);
  pick p;
  channel = bb__height_channel(img, alpha_channel, channel); /* auto: mean or alpha */
  bb_status st = resolve_pick(img->channels, alpha_channel, channel, &p, err);
  if (st != BB_OK) return st;
  st = bb_image_alloc(height, img->width, img->height, 1, err);
  if (st != BB_OK) return st;

  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++)
      *bb_image_texel(height, x, y) = pick_value(bb_image_texel(img, x, y), p);
  st = check_finite(height, err);
  if (st != BB_OK) bb_image_free(height);
  return st;
}

/* 1 when R = G = B at every texel of a 3-channel image. */
static int is_grey(const bb_image *rgb) {
  const size_t n = (size_t)rgb->width * (size_t)rgb->height;
  for (size_t i = 0; i < n; i++) {
    const float *t = rgb->pixels + 3 * i;
    if (t[0] != t[1] || t[1] != t[2])
      return 0;
  }
  return 1;
}

/* The height of a file whose pick was resolved from its header: only the
 * channels the pick needs are decoded (one, or R, G, B for a mean or luma),
 * so a file with many channels costs no more than a grey one. *grey
 * receives whether decoded R, G, B were all equal (1 when one channel was
 * read). */
static bb_status load_picked(const char *path, pick p, bb_image *height, int *grey,
                             bb_error *err) {
  const int first = p.kind == PICK_ONE ? p.index : 0;
  const int count = p.kind == PICK_ONE ? 1 : 3;
  bb_image part;
  *grey = 1;
  bb_status st = bb__image_read_channels(path, first, count, &part, NULL, err);
  if (st != BB_OK) return st;
  bb_error local;
  if (count == 1) {
    st = check_finite(&part, &local);
    if (st == BB_OK) {
      *height = part; /* already the height: no copy */
      return BB_OK;
    }
  } else {
    *grey = is_grey(&part);
    bb_channel rule = p.kind == PICK_LUMA ? BB_CHANNEL_LUMA : BB_CHANNEL_MEAN;
    st = bb_height_from_image(&part, -1, rule, height, &local);
  }
  bb_image_free(&part);
  if (st != BB_OK) bb__fail(err, st, "%s: %s", path, local.message);
  return st;
}

/* The height of the whole decoded image: for the cases where the rule
 * looks at the pixels (bb__height_channel). */
static bb_status load_whole(const char *path, bb_channel channel, bb_image *height,
                            bb__height_loaded *loaded, bb_error *err) {
  bb_image img;
  bb_image_info info;
  /* bb_image_read's messages already name the file. */
  bb_status st = bb_image_read(path, &img, &info, err);
  if (st != BB_OK) return st;
  loaded->channel = bb__height_channel_noted(&img, info.alpha_channel, channel, &loaded->note);
  bb_error local;
  st = bb_height_from_image(&img, info.alpha_channel, loaded->channel, height, &local);
  if (st != BB_OK) bb__fail(err, st, "%s: %s", path, local.message);
  bb_image_free(&img);
  bb_image_info_free(&info);
  return st;
}

bb_status bb__height_load(const char *path, bb_channel channel, bb_image *height,
                          bb__height_loaded *loaded, bb_error *err) {
  if (!height) return bb__fail(err, BB_ERR_ARGUMENT, "height load: height is NULL");
  memset(height, 0, sizeof *height);
  memset(loaded, 0, sizeof *loaded);
  int channels = 0;
  bb_image_info info;
  /* The header says which channels the rule needs; the I/O layer's
   * messages already name the file. */
  bb_status st = bb_image_read_info(path, NULL, NULL, &channels, &info, err);
  if (st != BB_OK) return st;
  const int alpha_channel = info.alpha_channel;
  loaded->channels = channels;
  loaded->bits_per_sample = info.bits_per_sample;
  loaded->is_float = info.is_float;
  snprintf(loaded->format_name, sizeof loaded->format_name, "%s", info.format_name);
  bb_image_info_free(&info);
  const int alpha = alpha_index(channels, alpha_channel);
  /* Auto on an image with alpha looks at the pixels (is the height in
   * alpha?): that case decodes every channel. */
  if (channel == BB_CHANNEL_AUTO && alpha >= 0)
    return load_whole(path, channel, height, loaded, err);
  /* Valve's rule and auto without alpha are decided by the header. */
  loaded->channel = channel;
  if (channel == BB_CHANNEL_VALVE && alpha >= 0)
    loaded->channel = BB_CHANNEL_A;
  else if (channel == BB_CHANNEL_VALVE) {
    loaded->channel = channels >= 3 ? BB_CHANNEL_MEAN : BB_CHANNEL_AUTO;
    loaded->note = channels >= 3 ? "no alpha channel; using the mean of R, G, B as the height"
                                 : "no alpha channel; using its grey channel as the height";
  }
  pick p;
  bb_error local;
  st = resolve_pick(channels, alpha_channel, loaded->channel, &p, &local);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, local.message);
  int grey = 1;
  st = load_picked(path, p, height, &grey, err);
  if (st == BB_OK && channel == BB_CHANNEL_AUTO) {
    loaded->channel = BB_CHANNEL_MEAN;
    if (!grey)
      loaded->note = "R, G and B differ (a colour image); using their mean as the height (a "
                     "channel option chooses another)";
  }
  return st;
}
