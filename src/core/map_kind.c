/* map_kind.c: every kind of map, described once for every client (the
 * command line's options and JSON, Python's outputs=, the texture writer's
 * mip rule and VTF flags, the files a render reads, combine's channels). */
#include "core/internal.h"

#include <string.h>

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

/* --------------------------------------------------- an output's kind */

/* First parts of output kind strings that are not a kind's name, and the
 * kind they are: Valve's height2ssbump -d writes a detail ssbump (the
 * ssbump times the input's colour), stored as an ssbump. */
static const struct {
  const char *name;
  bb_map_kind kind;
} aliases[] = {{"detail-ssbump", BB_MAP_SSBUMP}};

/* The kind named by the first n characters of text (exactly, as the
 * library spells its kinds), or -1. */
static int kind_named(const char *text, size_t n) {
  for (int k = 0; k < BB_MAP_KIND_COUNT; k++)
    if (strlen(kinds[k].name) == n && strncmp(text, kinds[k].name, n) == 0)
      return k;
  for (size_t i = 0; i < sizeof aliases / sizeof aliases[0]; i++)
    if (strlen(aliases[i].name) == n && strncmp(text, aliases[i].name, n) == 0)
      return (int)aliases[i].kind;
  return -1;
}

bb_map_kind bb__map_kind_of_output(const char *kind, bb_range range,
                                   uint32_t *vtf_flags) {
  const char *text = kind ? kind : "";
  const char *plus = strchr(text, '+');
  const int k = kind_named(text, plus ? (size_t)(plus - text) : strlen(text));
  if (k < 0) /* no kind of its own: signed values are unit vectors */
    return range == BB_RANGE_SIGNED ? BB_MAP_NORMAL : BB_MAP_PLAIN;
  const bb_map_kind_info *info = &kinds[k];
  if (info->unit_vectors && range != info->range) {
    /* the vectors were packed into [0, 1] already (0.5 + 0.5 N): codes to
     * average and store as they are, in a texture flagged as the kind's */
    if (vtf_flags)
      *vtf_flags |= info->vtf_flags;
    return BB_MAP_PLAIN;
  }
  return (bb_map_kind)k;
}
