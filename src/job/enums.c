/* enums.c: the library's enums as the options' words: each parsed by its
 * own parser (with its aliases) and named by its own _name function, so a
 * word list is never typed twice. Below the commands, so that the job
 * writes a bake's options with the words the commands read
 * (bake_rows.c). */
#include "job/bake_rows.h"
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "image/height_channel.h"
#include "image/oiio.h"
#include "mesh/mesh_internal.h"
#include "render/render_internal.h"
#include "texture/texture.h"

#include <string.h>

#define ENUM_WORDS(stem, type, parser, namer)                                           \
  const char *bb__name_##stem(int i) { return namer((type)i); }                          \
  bb_status bb__parse_##stem(const char *text, long long *value, bb_error *err) {         \
    type v;                                                                              \
    const bb_status st = parser(text, &v, err);                                          \
    if (st == BB_OK)                                                                     \
      *value = (long long)v;                                                             \
    return st;                                                                           \
  }

_Static_assert(sizeof(bb_normal_filter) == sizeof(int), "enums are stored as int");

ENUM_WORDS(normal_filter, bb_normal_filter, bb__normal_filter_parse, bb__normal_filter_name)
ENUM_WORDS(channel, bb_channel, bb__channel_parse, bb__channel_name)
ENUM_WORDS(texture_format, bb_texture_format, bb__texture_format_parse, bb__texture_format_name)
ENUM_WORDS(render_mode, bb_render_mode, bb__render_mode_parse, bb__render_mode_name)
ENUM_WORDS(albedo_mode, bb_albedo_mode, bb__albedo_mode_parse, bb__albedo_mode_name)
ENUM_WORDS(axis, bb_axis, bb__axis_parse, bb__axis_name)

/* --depth: "default" is no word of its own */
const char *bb__name_depth(int i) { return bb__depth_name((bb_depth)i); }
bb_status bb__parse_depth(const char *text, long long *value, bb_error *err) {
  bb_depth d;
  const bb_status st = bb__depth_parse(text, &d, err);
  if (st == BB_OK)
    *value = (long long)d;
  return st;
}

const char *bb__name_normal_y(int i) { return i == 0 ? "down" : i == 1 ? "up" : NULL; }
bb_status bb__parse_normal_y(const char *text, long long *value, bb_error *err) {
  int up = 0;
  const bb_status st = bb__normal_y_parse(text, &up, err);
  if (st == BB_OK)
    *value = up;
  return st;
}

/* A kind the option does not take, refused in the words of the kinds it
 * takes ("map kind must be one of ssbump, weights (got 'ao')"). */
static bb_status kind_refused(unsigned kinds, const char *text, bb_error *err) {
  const char *names[BB_MAP_KIND_COUNT];
  for (int i = 0; i < BB_MAP_KIND_COUNT; i++)
    names[i] = (kinds & BB_MAP_BIT(i)) ? bb__map_kind_name((bb_map_kind)i) : NULL;
  int k = 0;
  if (bb__parse_name("map kind", text, names, BB_MAP_KIND_COUNT, 1, &k, err) == BB_OK)
    return bb__fail(err, BB_ERR_ARGUMENT, "map kind '%.64s' is not one of these", text);
  return BB_ERR_ARGUMENT;
}

/* Map kinds as words: the library's names and parser (bb__map_kind_name,
 * bb__map_kind_parse), each option taking its own kinds; "" names a kind the
 * option does not take. */
#define KIND_WORDS(stem, kinds)                                                         \
  const char *bb__name_##stem(int i) {                                                   \
    if (i < 0 || i >= BB_MAP_KIND_COUNT)                                                 \
      return NULL;                                                                       \
    return ((kinds) & BB_MAP_BIT(i)) ? bb__map_kind_name((bb_map_kind)i) : "";            \
  }                                                                                      \
  bb_status bb__parse_##stem(const char *text, long long *value, bb_error *err) {         \
    bb_map_kind k;                                                                       \
    if (bb__map_kind_parse(text, &k, NULL) != BB_OK || !((kinds) & BB_MAP_BIT(k)))        \
      return kind_refused(kinds, text, err);                                             \
    *value = (long long)k;                                                               \
    return BB_OK;                                                                        \
  }

/* combine --kind: the maps combine's operators know */
KIND_WORDS(map_kind, BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_WEIGHTS) |
                         BB_MAP_BIT(BB_MAP_AO) | BB_MAP_BIT(BB_MAP_NORMAL))
/* --maps: the bake's maps */
KIND_WORDS(output_kind, BB_MAPS_BAKED)

/* ssbump2normal --kind: what a basis map holds */
KIND_WORDS(ssbump_kind, BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_WEIGHTS))
