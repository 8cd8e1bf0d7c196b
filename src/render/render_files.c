/* render_files.c: what a render reads from files and what its pictures
 * record of them: the map files checked and decoded for their kind, the
 * provenance keys of a render, and the names of an orbit's frames. */
#include "core/file_names.h"
#include "core/internal.h"
#include "render/render_internal.h"
#include "trace/basis.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What a file of each kind a render reads holds, for the message that
 * refuses one of too few channels; NULL: a kind a render does not read. */
static const char *const channels_why[BB_MAP_KIND_COUNT] = {
    [BB_MAP_NORMAL] = "X, Y, Z",
    [BB_MAP_SSBUMP] = "R, G, B = the basis B0, B1, B2",
    [BB_MAP_AO] = "grey",
    [BB_MAP_BENT] = "X, Y, Z",
    [BB_MAP_SLOPE] = "flipcode's slope byte, as bake --slope writes",
};

bb_status bb_render_map_read(const char *path, bb_map_kind kind, int normal_y_up,
                             const bb_image *like, bb_image *out, uint64_t *hash,
                             bb_error *err) {
  if (!out || (int)kind < 0 || kind >= BB_MAP_KIND_COUNT || !channels_why[kind])
    return bb__fail(err, BB_ERR_ARGUMENT, "render map read: bad arguments");
  memset(out, 0, sizeof *out);
  bb_image raw = {0};
  bb_image_info info;
  bb_status st = bb_image_read(path, &raw, &info, err);
  if (st != BB_OK)
    return st;
  bb_error why = {{0}};
  const bb_map_kind_info *k = bb_map_kind_get(kind);
  const int channels = k->file_channels;
  const int is_float = info.is_float;
  if (kind == BB_MAP_SSBUMP)
    st = bb__basis_map_check(&raw, info.description, &why);
  bb_image_info_free(&info);
  if (st != BB_OK)
    bb__fail(err, st, "%s: %s", path, why.message);
  else if (raw.channels < channels)
    st = bb__fail(err, BB_ERR_ARGUMENT, "%s: %d channel%s; %s %s map needs %d (%s)", path,
                  raw.channels, raw.channels == 1 ? "" : "s",
                  (kind == BB_MAP_AO || kind == BB_MAP_SSBUMP) ? "an" : "a",
                  k->name, channels, channels_why[kind]);
  else if (like && (raw.width != like->width || raw.height != like->height))
    st = bb__fail(err, BB_ERR_ARGUMENT, "%s: %dx%d, but the other maps are %dx%d", path,
                  raw.width, raw.height, like->width, like->height);
  if (st == BB_OK && k->unit_vectors) {
    st = bb_normal_map_decode(&raw, is_float, normal_y_up, 1, out, &why);
    if (st != BB_OK)
      bb__fail(err, st, "%s: %s", path, why.message);
    bb_image_free(&raw);
  } else if (st == BB_OK) {
    *out = raw;
  } else {
    bb_image_free(&raw);
  }
  if (st == BB_OK && hash) /* of the map as decoded */
    *hash = bb__image_hash(out);
  return st;
}

/* Appends "key=value\n" to *text (growing it); 0, or -1 when out of memory. */
static int add_line(char **text, size_t *length, const char *key, const char *value) {
  const size_t add = strlen(key) + strlen(value) + 2;
  char *grown = realloc(*text, *length + add + 1);
  if (!grown)
    return -1;
  snprintf(grown + *length, add + 1, "%s=%s\n", key, value);
  *text = grown;
  *length += add;
  return 0;
}

char *bb__render_provenance(const bb_render_sources *s, const bb_render_options *o) {
  if (!s || !o)
    return NULL;
  char *text = NULL;
  size_t length = 0;
  int failed = 0;
  if (s->height) {
    failed |= add_line(&text, &length, "render_from", "height");
  } else {
    failed |= add_line(&text, &length, "render_from", "maps");
    if (s->maps[BB_MAP_NORMAL] || s->maps[BB_MAP_BENT])
      failed |= add_line(&text, &length, "map_normal_y", s->maps_normal_y_up ? "up" : "down");
    for (int m = 0; m < BB_MAP_KIND_COUNT; m++)
      if (s->maps[m]) {
        char key[32];
        snprintf(key, sizeof key, "map_%s", bb__map_kind_name((bb_map_kind)m));
        failed |= add_line(&text, &length, key, bb__file_name(s->maps[m]));
      }
  }
  if (s->albedo) {
    char hash[32];
    snprintf(hash, sizeof hash, "%016" PRIx64, s->albedo_hash);
    failed |= add_line(&text, &length, "albedo", bb__file_name(s->albedo));
    failed |= add_line(&text, &length, "albedo_hash", hash);
  }
  char *options = bb__render_options_describe(o);
  if (!options)
    failed = 1;
  else {
    const size_t n = strlen(options);
    char *grown = failed ? NULL : realloc(text, length + n + 1);
    if (grown) {
      memcpy(grown + length, options, n + 1);
      text = grown;
      length += n;
    } else {
      failed = 1;
    }
    free(options);
  }
  if (!failed && s->frames) {
    char frame[64];
    snprintf(frame, sizeof frame, "%d/%d", s->frame, s->frames);
    failed |= add_line(&text, &length, "frame", frame);
  }
  if (failed) {
    free(text);
    return NULL;
  }
  return text;
}

char *bb__render_frame_path(const char *output, int frame, int frames) {
  if (!output)
    return NULL;
  const char *dot = bb__file_extension(output);
  size_t stem = dot ? (size_t)(dot - output) : strlen(output);
  size_t len = strlen(output) + 8;
  char *path = malloc(len);
  if (path)
    snprintf(path, len, frames > 1000 ? "%.*s_%04d%s" : "%.*s_%03d%s", (int)stem, output,
             frame % 10000, dot ? dot : "");
  return path;
}
