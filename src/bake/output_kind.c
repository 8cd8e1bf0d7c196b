/* output_kind.c: where a bake's result keeps each map it makes, so a
 * kind's image is found without a switch per client. */
#include "bake/bake_internal.h"
#include "core/internal.h"

#include <stddef.h>

/* By bb_map_kind, for the kinds a bake makes. */
static const size_t result_offset[BB_MAP_BAKED_COUNT] = {
    [BB_MAP_NORMAL] = offsetof(bb_bake_result, normal),
    [BB_MAP_WEIGHTS] = offsetof(bb_bake_result, weights),
    [BB_MAP_SSBUMP] = offsetof(bb_bake_result, ssbump),
    [BB_MAP_AO] = offsetof(bb_bake_result, ao),
    [BB_MAP_BENT] = offsetof(bb_bake_result, bent),
    [BB_MAP_FILTERED] = offsetof(bb_bake_result, filtered),
};

const bb_image *bb__bake_result_image(const bb_bake_result *r, bb_map_kind kind) {
  if (!r || (int)kind < 0 || kind >= BB_MAP_BAKED_COUNT)
    return NULL;
  return (const bb_image *)(const void *)((const char *)r + result_offset[kind]);
}
