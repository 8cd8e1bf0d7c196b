/* renderbump_files.c: a flat render bump's normal map and height written
 * as files, together, with what made them. */
#include "core/internal.h"
#include "job/job_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Provenance of one output: the common lines, then the render's. */
static char *describe(const bb_renderbump_result *r, const bb_renderbump_options *o,
                      int normal_y_up, const char *model, uint64_t model_hash,
                      const char *command, const char *kind) {
  char *own = bb_renderbump_describe(o, r);
  if (!own)
    return NULL;
  const size_t n = strlen(own);
  char *extra = realloc(own, n + 32);
  if (!extra) {
    free(own);
    return NULL;
  }
  snprintf(extra + n, 32, "normal_y=%s\n", normal_y_up ? "up" : "down");
  const bb__job_source s = {.command = command,
                            .input = model,
                            .input_hash = model_hash,
                            .extra = extra};
  char *text = bb__job_describe(&s, kind);
  free(extra);
  return text;
}

/* Integer files hold 0.5 + 0.5 N and the coverage as it is, so RGB is
 * encoded here (BB_RANGE_SIGNED would encode alpha too); files that only
 * hold floats (EXR) store N raw, as every bumpbake normal map. */
static bb_range encode_for(const char *path, bb_image *normal) {
  if (!bb_path_supports_depth(path, BB_DEPTH_8))
    return BB_RANGE_SIGNED; /* float files store every channel raw */
  const size_t texels = (size_t)normal->width * (size_t)normal->height;
  for (size_t i = 0; i < texels; i++)
    for (int c = 0; c < 3; c++)
      normal->pixels[4 * i + (size_t)c] = 0.5f + 0.5f * normal->pixels[4 * i + (size_t)c];
  return BB_RANGE_UNIT;
}

bb_status bb_renderbump_write(const bb_renderbump_result *r, const bb_renderbump_options *o,
                              int normal_y_up, const char *model, uint64_t model_hash,
                              const char *command, const char *normal_path,
                              const char *height_path, bb_error *err) {
  if (!r || !o || !model || !normal_path || !r->normal.pixels || r->normal.channels != 4)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump write: bad arguments");
  bb_image normal = {0};
  bb_status st = bb_image_alloc(&normal, r->normal.width, r->normal.height, 4, err);
  if (st != BB_OK)
    return st;
  memcpy(normal.pixels, r->normal.pixels,
         (size_t)normal.width * (size_t)normal.height * 4 * sizeof(float));
  if (normal_y_up)
    for (size_t i = 0; i < (size_t)normal.width * (size_t)normal.height; i++)
      normal.pixels[4 * i + 1] = -normal.pixels[4 * i + 1];
  const bb_range range = encode_for(normal_path, &normal);
  char *texts[2] = {describe(r, o, normal_y_up, model, model_hash, command, "normal+coverage"),
                    height_path ? describe(r, o, normal_y_up, model, model_hash, command, "height")
                                : NULL};
  if (!texts[0] || (height_path && !texts[1])) {
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", normal_path);
  } else {
    const bb_depth height_depth =
        height_path && bb_path_supports_depth(height_path, BB_DEPTH_16) ? BB_DEPTH_16
                                                                         : BB_DEPTH_DEFAULT;
    const bb_output_file files[2] = {
        {normal_path, "normal", &normal, range, BB_DEPTH_DEFAULT, 0, texts[0], NULL, 0, NULL},
        {height_path, "height", &r->height, BB_RANGE_UNIT, height_depth, 0, texts[1], NULL, 0,
         NULL}};
    st = bb_outputs_write(files, height_path ? 2 : 1, 2, err);
  }
  free(texts[0]);
  free(texts[1]);
  bb_image_free(&normal);
  return st;
}
