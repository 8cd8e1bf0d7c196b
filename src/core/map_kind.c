/* map_kind.c: every kind of map, described once for every client (the
 * command line's options and JSON, Python's outputs=, the texture writer's
 * mip rule and VTF flags, the files a render reads, combine's channels). */
#include "core/internal.h"

/* In bb_map_kind order. */
static const bb_map_kind_info kinds[BB_MAP_KIND_COUNT] = {
    [BB_MAP_NORMAL] = {"normal", "the unit normal N", 3, 3, BB_RANGE_SIGNED, 0, 1,
                       BB_VTF_FLAG_NORMAL},
    [BB_MAP_WEIGHTS] = {"weights", "the basis weights sat(N.B_c)^2 / sum (normal2ssbump)", 0,
                        3, BB_RANGE_UNIT, 0, 0, BB_VTF_FLAG_SSBUMP},
    [BB_MAP_SSBUMP] = {"ssbump", "the self-shadowed bump map max(0, N.B_c) vis_c", 0, 3,
                       BB_RANGE_UNIT, 1, 0, BB_VTF_FLAG_SSBUMP},
    [BB_MAP_AO] = {"ao", "the ambient occlusion", 1, 1, BB_RANGE_UNIT, 1, 0, 0},
    [BB_MAP_BENT] = {"bent", "the bent normal normalize(sum s_c B_c)", 3, 3, BB_RANGE_SIGNED,
                     1, 1, BB_VTF_FLAG_NORMAL},
    [BB_MAP_FILTERED] = {"filtered", "the smoothed height", 1, 1, BB_RANGE_UNIT, 0, 0, 0},
    [BB_MAP_SLOPE] = {"slope", "flipcode's slope map: slope bytes / 255", 1, 1, BB_RANGE_UNIT,
                      0, 0, 0},
    [BB_MAP_PLAIN] = {"plain", "any other image: a height, a colour, a packed map", 0, 1,
                      BB_RANGE_UNIT, 0, 0, 0},
};

const bb_map_kind_info *bb_map_kind_get(bb_map_kind kind) {
  if ((int)kind < 0 || kind >= BB_MAP_KIND_COUNT)
    return NULL;
  return &kinds[kind];
}

bb_status bb_map_kind_parse(const char *name, bb_map_kind *out, bb_error *err) {
  const char *names[BB_MAP_KIND_COUNT];
  for (int k = 0; k < BB_MAP_KIND_COUNT; k++)
    names[k] = kinds[k].name;
  int k;
  bb_status st = bb__parse_name("map kind", name, names, BB_MAP_KIND_COUNT, 1, &k, err);
  if (st == BB_OK)
    *out = (bb_map_kind)k;
  return st;
}

const char *bb_map_kind_name(bb_map_kind kind) {
  const bb_map_kind_info *k = bb_map_kind_get(kind);
  return k ? k->name : "unknown";
}
