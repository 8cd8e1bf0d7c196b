/* height_file.c: a height map file read the way every bake reads it: the
 * bytes hashed before they are decoded, the channel rule applied and said,
 * and what the file's format or depth will cost the maps said too. */
#include "core/input_file.h"
#include "core/internal.h"
#include "image/height_channel.h"
#include "job/job_internal.h"
#include "image/formats.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* One code of an integer height file is 1 / max code of h, so S / max code
 * texels of displacement. Past about an eighth of a texel the steps between
 * codes show as rings in the normals of a smooth slope, through the default
 * smoothing (an 8-bit dome: faint at scale 32, plain at 64, strong at 128;
 * none at 16). */
#define TERRACE_STEP_TEXELS 0.12

static void say(bb_note_fn note, void *user, const char *path, const char *text) {
  if (note && text)
    note(user, path, text);
}

/* Notes about what the file itself will cost the maps. */
static void note_input(const bb__height_loaded *info, float height_scale, bb_note_fn note,
                       void *user, const char *path) {
  if (strcmp(info->format_name, "jpeg") == 0)
    say(note, user, path,
        "a JPEG height: its 8 x 8 blocks of lossy compression show in the maps; a lossless "
        "height (PNG, TIFF, EXR) avoids them");
  if (!info->is_float && info->bits_per_sample > 0 && info->bits_per_sample < 16 &&
      height_scale > 0.0f) {
    const double max_code = ldexp(1.0, info->bits_per_sample) - 1.0;
    const double step = (double)height_scale / max_code;
    if (step > TERRACE_STEP_TEXELS) {
      char text[256];
      snprintf(text, sizeof text,
               "%d-bit heights: one code is %.2g texels of height at scale %g, which shows as "
               "terraces on smooth slopes; a 16-bit height avoids them",
               info->bits_per_sample, step, (double)height_scale);
      say(note, user, path, text);
    }
  }
}

bb_status bb__height_file_read(const char *path, bb_channel channel, float height_scale,
                              bb_note_fn note, void *note_user, bb_image *height,
                              bb_height_source *source, bb_error *err) {
  if (!height)
    return bb__fail(err, BB_ERR_ARGUMENT, "height file read: height is NULL");
  memset(height, 0, sizeof *height);
  bb_height_source local;
  if (!source)
    source = &local;
  memset(source, 0, sizeof *source);
  /* The bytes are hashed before they are decoded: provenance must never
   * pair a newer file's hash with an older file's pixels. The header is
   * read first, so a file that is missing, no regular file or no image is
   * refused as the image reader says it, before its bytes are all read. */
  bb_status st = bb_image_read_info(path, NULL, NULL, NULL, NULL, err);
  if (st == BB_OK)
    st = bb_file_hash(path, &source->file_hash, err);
  if (st != BB_OK)
    return st;
  bb__height_loaded loaded;
  st = bb__height_load(path, channel, height, &loaded, err);
  if (st != BB_OK)
    return st;
  source->channel = loaded.channel;
  source->channels = loaded.channels;
  source->grey = loaded.channels - (loaded.channels == 2 || loaded.channels == 4) < 3;
  source->bits_per_sample = loaded.bits_per_sample;
  source->is_float = loaded.is_float;
  snprintf(source->format_name, sizeof source->format_name, "%s", loaded.format_name);
  source->height_hash = bb__image_hash(height);
  say(note, note_user, path, loaded.note);
  note_input(&loaded, height_scale, note, note_user, path);
  return BB_OK;
}

const char *bb_height_source_channel(const bb_height_source *source) {
  if (!source)
    return "unknown";
  /* The mean of one colour channel is that channel. */
  if (source->grey && (source->channel == BB_CHANNEL_MEAN || source->channel == BB_CHANNEL_LUMA ||
                       source->channel == BB_CHANNEL_AUTO))
    return "grey";
  return bb__channel_name(source->channel);
}

bb_depth bb__depth_like_input(int bits_per_sample, int is_float, const char *path) {
  /* The closest the format holds, from the input's own depth downwards. */
  static const bb_depth float_order[] = {BB_DEPTH_FLOAT, BB_DEPTH_HALF, BB_DEPTH_16};
  static const bb_depth half_order[] = {BB_DEPTH_HALF, BB_DEPTH_FLOAT, BB_DEPTH_16};
  static const bb_depth int16_order[] = {BB_DEPTH_16, BB_DEPTH_FLOAT};
  const bb_depth *order = NULL;
  size_t n = 0;
  if (is_float && bits_per_sample <= 16)
    order = half_order, n = 3;
  else if (is_float)
    order = float_order, n = 3;
  else if (bits_per_sample > 8)
    order = int16_order, n = 2;
  for (size_t i = 0; i < n; i++)
    if (bb__path_supports_depth(path, order[i]))
      return order[i];
  return BB_DEPTH_DEFAULT;
}
