/* renderbump_files.c: a flat render bump's normal map and height as the
 * job checks and writes them (output.c): together or neither, each with
 * what made it. */
#include "core/internal.h"
#include "job/job_internal.h"
#include "image/formats.h"
#include "mesh/mesh_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Files that hold integers store 0.5 + 0.5 N and the coverage as it is, so
 * RGB is encoded by the write (BB_RANGE_SIGNED would encode alpha too);
 * files that only hold floats (EXR) store N raw, as every bumpbake normal
 * map. */
int bb__renderbump_outputs(const char *normal_path, const char *height_path,
                           bb__job_output out[2]) {
  const int integers = normal_path && bb__path_supports_depth(normal_path, BB_DEPTH_8);
  out[0] = (bb__job_output){.path = normal_path,
                            .kind = "normal",
                            .range = integers ? BB_RANGE_UNIT : BB_RANGE_SIGNED,
                            .depth = BB_DEPTH_DEFAULT};
  if (!height_path)
    return 1;
  out[1] = (bb__job_output){.path = height_path,
                            .kind = "height",
                            .range = BB_RANGE_UNIT,
                            .depth = bb__path_supports_depth(height_path, BB_DEPTH_16)
                                         ? BB_DEPTH_16
                                         : BB_DEPTH_DEFAULT};
  return 2;
}

/* The render's own provenance lines (bb__renderbump_describe's) and
 * normal_y, malloc'd; NULL when out of memory. */
static char *render_lines(const bb_renderbump_result *r, const bb_renderbump_options *o,
                          int normal_y_up) {
  char *own = bb__renderbump_describe(o, r);
  if (!own)
    return NULL;
  const size_t n = strlen(own);
  char *extra = realloc(own, n + 32);
  if (!extra) {
    free(own);
    return NULL;
  }
  snprintf(extra + n, 32, "normal_y=%s\n", normal_y_up ? "up" : "down");
  return extra;
}

bb_status bb__renderbump_write(const bb_renderbump_result *r, const bb_renderbump_options *o,
                              int normal_y_up, const char *model, uint64_t model_hash,
                              const char *command, const char *normal_path,
                              const char *height_path, bb_error *err) {
  if (!r || !o || !model || !normal_path || !r->normal.pixels || r->normal.channels != 4)
    return bb__fail(err, BB_ERR_ARGUMENT, "renderbump write: bad arguments");
  bb__job_output out[2];
  const int count = bb__renderbump_outputs(normal_path, height_path, out);
  bb_image normal = {0};
  bb_status st = bb_image_alloc(&normal, r->normal.width, r->normal.height, 4, err);
  if (st != BB_OK)
    return st;
  const size_t texels = (size_t)normal.width * (size_t)normal.height;
  memcpy(normal.pixels, r->normal.pixels, texels * 4 * sizeof(float));
  for (size_t i = 0; i < texels; i++) {
    float *p = normal.pixels + 4 * i;
    if (normal_y_up)
      p[1] = -p[1];
    if (out[0].range == BB_RANGE_UNIT)
      for (int c = 0; c < 3; c++)
        p[c] = 0.5f + 0.5f * p[c];
  }
  char *extra = render_lines(r, o, normal_y_up);
  if (!extra) {
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", normal_path);
  } else {
    const bb__job_source source = {.command = command,
                                   .input = model,
                                   .input_hash = model_hash,
                                   .extra = extra};
    const bb__job_file files[2] = {{&out[0], &normal, &source, "normal+coverage"},
                                   {&out[1], &r->height, &source, NULL}};
    st = bb__job_write_set(files, count, err);
  }
  free(extra);
  bb_image_free(&normal);
  return st;
}
