/* memory.c: a job's input, before it is read: what reading, baking and
 * writing it will take at the most (the bake's own ledger, bb__bake_memory,
 * with the decode before it and the encoders after it), against what the
 * machine has left, so a map too large is refused with the figures. */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "texture/texture.h"
#include "job/job_internal.h"
#include "image/formats.h"

#include <stdio.h>

/* Bytes of a sample at depth in path's format, as the encoder quantises. */
static double sample_bytes(bb_depth depth, const char *path) {
  switch (depth) {
  case BB_DEPTH_8: return 1.0;
  case BB_DEPTH_16: case BB_DEPTH_HALF: return 2.0;
  case BB_DEPTH_FLOAT: return 4.0;
  default: return bb__path_max_channels(path) == 4 ? 1.0 : 4.0; /* png/tga 8-bit; exr float */
  }
}

/* An engine texture's encoder (image/texture_write.c): the map's mip chain in
 * float, made whether it is written or not, and every level in the file's
 * format (4/3 of the top level's bytes), twice for colour blocks (range
 * fit's candidates beside cluster fit's, texture/blocks.h). */
static double texture_bytes(const bb_job *job, const char *path, const bb_map_kind_info *kind,
                            int w, int h, int channels) {
  const bb_texture_options t = bb__job_texture_of(&job->options.texture, kind->name, kind->range);
  bb_texture_format format;
  const double top = bb__texture_resolve(path, w, h, channels, &t, &format, NULL) == BB_OK
                         ? (double)bb__texture_level_bytes(format, w, h)
                         : 16.0 * w * h; /* refused by the write: the widest format */
  return (double)w * (double)h * channels * 4.0 * 4.0 / 3.0 + 2.0 * top * 4.0 / 3.0;
}

double bb__job_memory(const bb_job *job, const bb__job_item *item, int w, int h,
                      int channels) {
  const double t = (double)w * (double)h, texel = 4.0 * t;
  const bb_bake_options *o = &job->options.bake;
  /* the read: the channels the height needs (one, R G B, or R G B A to find
   * a height in alpha) decoded as floats, then the height taken out */
  const double read = ((channels < 4 ? channels : 4) + 1) * texel;
  /* the bake, holding the height until it is smoothed */
  double kept = 0.0;
  const double bake = bb__bake_memory(w, h, o, BB__BAKE_DROP_VIS | BB__BAKE_TAKE_HEIGHT, texel,
                                      &kept);
  /* the write: the maps, the slope map and its preview, and each file's
   * quantised copy (its mip chain in float too), the files encoded side by
   * side */
  double encode = 0.0;
  int kinds[BB_JOB_MAX_OUTPUTS];
  const char *paths[BB_JOB_MAX_OUTPUTS], *commands[BB_JOB_MAX_OUTPUTS];
  const int files = bb__job_map_files(item, kinds, paths, commands);
  for (int f = 0; f < files; f++) {
    const bb_map_kind_info *kind = bb_map_kind_get((bb_map_kind)kinds[f]);
    const int c = kind->channels ? kind->channels : o->basis.count;
    const double samples = t * c;
    if (bb__path_is_texture_format(paths[f])) {
      encode += texture_bytes(job, paths[f], kind, w, h, c);
      continue;
    }
    const double mips = job->options.mips ? 4.0 / 3.0 : 1.0;
    encode += samples * mips * sample_bytes(job->options.depth, paths[f]) +
              (job->options.mips ? samples * mips * 4.0 : 0.0);
  }
  if (job->slope_path)
    kept += 2 * texel, encode += 2 * t;
  if (job->valve_path) { /* Valve's RGBA file, and for -d the colour read again */
    kept += 4 * texel;
    encode += bb__path_is_texture_format(job->valve_path)
                  ? 4.0 * 4.0 * t * 4.0 / 3.0 + 4.0 * t
                  : 4.0 * t * sample_bytes(job->options.depth, job->valve_path);
    if (job->options.valve_detail)
      kept += (channels < 4 ? channels : 4) * texel + 4 * texel;
  }
  const double write = kept + encode;
  const double need = read > bake ? read : bake;
  return (need > write ? need : write) * 1.05 + 32.0 * 1024 * 1024;
}

bb_status bb__job_memory_check(const bb_job *job, const bb__job_item *item, bb_error *err) {
  int w = 0, h = 0, channels = 0;
  if (bb_image_read_info(item->input, &w, &h, &channels, NULL, NULL) != BB_OK || w <= 0 ||
      h <= 0)
    return BB_OK; /* the read says what is wrong with it */
  const double t = (double)w * (double)h;
  /* A header over the read's own limits is the read's to refuse, as a bad
   * file rather than a lack of memory. */
  if ((long long)w * h > BB_MAX_PIXELS ||
      channels * 4.0 * t > (BB_MAX_READ_BYTES > BB_MAX_READ_BYTES_PER_TEXEL * t
                                ? (double)BB_MAX_READ_BYTES
                                : BB_MAX_READ_BYTES_PER_TEXEL * t))
    return BB_OK;
  const double need = bb__job_memory(job, item, w, h, channels);
  char what[512];
  snprintf(what, sizeof what, "%s: a %d x %d bake", item->input, w, h);
  return bb__memory_check(need, what, err);
}
