/* output_kind.c: the maps a bake can make, described once for every client
 * (the command line's options and JSON, Python's outputs=). */
#include "core/internal.h"


#include <stddef.h>
#include <string.h>

/* In bb_output_kind order; result_offset says where bb_bake_result keeps
 * each, so a kind's image is found without a switch per client. */
static const struct {
  bb_output_kind_info info;
  size_t result_offset;
} kinds[BB_OUTPUT_KIND_COUNT] = {
    {{"normal", "the unit normal N", 3, BB_RANGE_SIGNED, 0},
     offsetof(bb_bake_result, normal)},
    {{"weights", "the basis weights sat(N.B_c)^2 / sum (normal2ssbump)", 0, BB_RANGE_UNIT, 0},
     offsetof(bb_bake_result, weights)},
    {{"ssbump", "the self-shadowed bump map max(0, N.B_c) vis_c", 0, BB_RANGE_UNIT, 1},
     offsetof(bb_bake_result, ssbump)},
    {{"ao", "the ambient occlusion", 1, BB_RANGE_UNIT, 1}, offsetof(bb_bake_result, ao)},
    {{"bent", "the bent normal normalize(sum s_c B_c)", 3, BB_RANGE_SIGNED, 1},
     offsetof(bb_bake_result, bent)},
    {{"filtered", "the smoothed height", 1, BB_RANGE_UNIT, 0},
     offsetof(bb_bake_result, filtered)},
};

const bb_output_kind_info *bb_output_kind_get(bb_output_kind kind) {
  if ((int)kind < 0 || kind >= BB_OUTPUT_KIND_COUNT)
    return NULL;
  return &kinds[kind].info;
}

bb_status bb_output_kind_parse(const char *name, bb_output_kind *out, bb_error *err) {
  const char *names[BB_OUTPUT_KIND_COUNT];
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
    names[k] = kinds[k].info.name;
  int k;
  bb_status st = bb__parse_name("map", name, names, BB_OUTPUT_KIND_COUNT, 0, &k, err);
  if (st == BB_OK)
    *out = (bb_output_kind)k;
  return st;
}

const bb_image *bb_bake_result_image(const bb_bake_result *r, bb_output_kind kind) {
  if (!r || (int)kind < 0 || kind >= BB_OUTPUT_KIND_COUNT)
    return NULL;
  return (const bb_image *)(const void *)((const char *)r + kinds[kind].result_offset);
}
