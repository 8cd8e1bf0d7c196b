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

bb_status bb__map_kind_parse(const char *name, bb_map_kind *out, bb_error *err) {
  const char *names[BB_MAP_KIND_COUNT];
  for (int k = 0; k < BB_MAP_KIND_COUNT; k++)
    names[k] = kinds[k].name;
  int k;
  bb_status st = bb__parse_name("map kind", name, names, BB_MAP_KIND_COUNT, 1, &k, err);
  if (st == BB_OK)
    *out = (bb_map_kind)k;
  return st;
}

const char *bb__map_kind_name(bb_map_kind kind) {
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

/* ------------------------------------- what a map's provenance records */

/* The kinds a bake's parameters reach, by the pipeline (bake/bake.c): the
 * smoothing makes the filtered height; the scale and the normal filter the
 * normals; the basis the weights; the trace (slices, bias, inter-reflection)
 * ao; the trace's lobes (power, basis) and the normals the ssbump, and the
 * bent normal from it. normal_y flips the green of the normal and bent maps
 * after everything is made; the brightness map scales ssbump and weights
 * after bent was derived. ao is the sky's w.z over the tangent hemisphere:
 * neither the normals nor the lobes enter it, except through the light that
 * inter-reflection gathers, which is weighted by the lobes. The tests bake
 * every kind with each parameter changed and hold this table to the pixels. */
#define K(kind) (1u << (unsigned)(kind))
enum {
  FILTERED = K(BB_MAP_FILTERED),
  NORMAL = K(BB_MAP_NORMAL),
  WEIGHTS = K(BB_MAP_WEIGHTS),
  SSBUMP = K(BB_MAP_SSBUMP),
  AO = K(BB_MAP_AO),
  BENT = K(BB_MAP_BENT),
  SLOPE = K(BB_MAP_SLOPE),
  TRACED = SSBUMP | AO | BENT,
  ALL = FILTERED | NORMAL | WEIGHTS | TRACED | SLOPE
};

static const struct {
  const char *key;
  unsigned kinds;       /* the kinds whose pixels it can change */
  unsigned with_bounce; /* and those it changes with inter-reflection (a
                           "bounce" key) */
  unsigned slices;      /* those that record, without inter-reflection, only
                           the scheme and slices of the ray set's id */
} recorded[] = {
    {"scale", ALL & ~FILTERED, 0, 0},
    {"rays", TRACED, 0, 0},
    {"rayset", SSBUMP | BENT, AO, AO},
    {"filter_radius", ALL, 0, 0},
    {"filter_threshold", ALL, 0, 0},
    {"bias", TRACED, 0, 0},
    {"power", SSBUMP | BENT, AO, 0},
    {"basis", WEIGHTS | SSBUMP | BENT, AO, 0},
    {"basis_vectors", WEIGHTS | SSBUMP | BENT, AO, 0},
    {"normal_filter", NORMAL | WEIGHTS | SSBUMP | BENT, 0, 0},
    {"normal_y", NORMAL | BENT, 0, 0},
    {"addressing", ALL, 0, 0},
    {"bounce", TRACED, 0, 0},
    {"bounces", TRACED, 0, 0},
    {"bounce_albedo_map", TRACED, 0, 0},
    {"brightness", WEIGHTS | SSBUMP, 0, 0},
};
#undef K

/* The kinds of an output kind string, as bits: each '+'-separated part
 * ("ssbump+height": the ssbump and the height it carries, "height" being the
 * filtered height). 0 when a part is no kind of a bake's (renderbumpflat's
 * "coverage", a render): such a file records every key. */
static unsigned kinds_of(const char *kind) {
  unsigned bits = 0;
  for (const char *part = kind; part && *part;) {
    const size_t n = strcspn(part, "+");
    int k = kind_named(part, n);
    if (k < 0 && n == 6 && strncmp(part, "height", 6) == 0)
      k = BB_MAP_FILTERED;
    if (k < 0 || !(ALL & (1u << (unsigned)k)))
      return 0;
    bits |= 1u << (unsigned)k;
    part += n + (part[n] == '+');
  }
  return bits;
}

bb__key_use bb__map_kind_key(const char *kind, const char *key, size_t key_length,
                             int bounce) {
  const unsigned bits = kinds_of(kind);
  if (!bits || !key)
    return BB__KEY_RECORDED;
  for (size_t i = 0; i < sizeof recorded / sizeof recorded[0]; i++) {
    if (strlen(recorded[i].key) != key_length ||
        strncmp(recorded[i].key, key, key_length))
      continue;
    if ((bits & recorded[i].kinds) || (bounce && (bits & recorded[i].with_bounce)))
      return BB__KEY_RECORDED;
    return (bits & recorded[i].slices) ? BB__KEY_SLICES : BB__KEY_DROPPED;
  }
  return BB__KEY_RECORDED; /* not a bake's parameter: the version, input, channel... */
}

size_t bb__rayset_slices_length(const char *id, size_t length) {
  /* "bb-horizon-v1:a16:p1:hl2": the scheme and the slices end at the
   * second ':' */
  const char *colon = memchr(id, ':', length);
  const char *second =
      colon ? memchr(colon + 1, ':', length - (size_t)(colon + 1 - id)) : NULL;
  return second ? (size_t)(second - id) : length;
}

int bb__map_kind_records(const char *kind, const char *key, int bounce) {
  return key && bb__map_kind_key(kind, key, strlen(key), bounce) != BB__KEY_DROPPED;
}
