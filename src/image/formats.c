/* formats.c: the formats bumpbake writes (.png .tga .tif .tiff .exr, and
 * the engine textures .vtf .dds), the depths and channel counts each
 * holds, and the checks of a write before any encoder runs. No OpenImageIO
 * here: these are bumpbake's rules. */
#include "image/formats.h"
#include "core/file_names.h"
#include "core/internal.h"
#include "image/oiio.h"
#include "texture/texture.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

typedef struct format_rule {
  const char *ext; /* lower case, with the dot */
  bb_depth default_depth;
  unsigned allowed; /* bit (1 << bb_depth) per allowed depth */
  int max_channels;
  int holds_mips; /* tiled, mip-mapped files (OpenEXR levels, TIFF directories) */
} format_rule;

#define BIT(d) (1u << (d))

static const format_rule FORMATS[] = {
    {".png", BB_DEPTH_8, BIT(BB_DEPTH_8) | BIT(BB_DEPTH_16), 4, 0},
    {".tga", BB_DEPTH_8, BIT(BB_DEPTH_8), 4, 0},
    {".tif", BB_DEPTH_8, BIT(BB_DEPTH_8) | BIT(BB_DEPTH_16) | BIT(BB_DEPTH_FLOAT), 64, 1},
    {".tiff", BB_DEPTH_8, BIT(BB_DEPTH_8) | BIT(BB_DEPTH_16) | BIT(BB_DEPTH_FLOAT), 64, 1},
    {".exr", BB_DEPTH_FLOAT, BIT(BB_DEPTH_HALF) | BIT(BB_DEPTH_FLOAT), 64, 1},
};

void bb__extension_of(const char *path, char *out, size_t cap) {
  if (!cap) return;
  const char *dot = bb__file_extension(path);
  size_t n = 0;
  for (; dot && dot[n] && n + 1 < cap; n++) out[n] = (char)tolower((unsigned char)dot[n]);
  out[n] = '\0';
}

static const format_rule *find_format(const char *path) {
  const char *dot = bb__file_extension(path);
  if (!dot) return NULL;
  for (size_t i = 0; i < sizeof FORMATS / sizeof FORMATS[0]; i++)
    if (strcasecmp(dot, FORMATS[i].ext) == 0) return &FORMATS[i];
  return NULL;
}

/* The engine textures (texture.c) choose their samples by texture format,
 * hold 4 channels and carry their own mip chain. */
static int is_texture(const char *path) { return bb__path_is_texture_format(path); }

int bb__path_is_writable_format(const char *path) {
  return find_format(path) != NULL || is_texture(path);
}

int bb__path_supports_depth(const char *path, bb_depth depth) {
  if (is_texture(path)) return depth == BB_DEPTH_DEFAULT;
  const format_rule *f = find_format(path);
  return f && (depth == BB_DEPTH_DEFAULT ||
               ((unsigned)depth < 32 && (f->allowed & BIT((unsigned)depth)) != 0));
}

int bb__path_max_channels(const char *path) {
  if (is_texture(path)) return 4;
  const format_rule *f = find_format(path);
  return f ? f->max_channels : 0;
}

double bb__encoded_sample_bytes(const char *path, bb_depth depth) {
  const format_rule *f = find_format(path);
  if (depth == BB_DEPTH_DEFAULT)
    depth = f ? f->default_depth : BB_DEPTH_FLOAT;
  if (is_texture(path))
    return 4.0; /* a float mip chain before its blocks */
  return depth == BB_DEPTH_8 ? 1.0 : depth == BB_DEPTH_FLOAT ? 4.0 : 2.0;
}

int bb__path_holds_mips(const char *path) {
  if (is_texture(path)) return 1;
  const format_rule *f = find_format(path);
  return f && f->holds_mips;
}

int bb__path_supports_mips(const char *path) { return bb__path_holds_mips(path); }

const char *bb__exr_compression(bb_depth depth) {
  return depth == BB_DEPTH_HALF ? "piz" : "none";
}

int bb__path_resolved_depth(const char *path, bb_depth depth) {
  const format_rule *f = find_format(path);
  if (!f) return -1;
  return depth == BB_DEPTH_DEFAULT ? (int)f->default_depth : (int)depth;
}

static bb_status check_image_arg(const char *path, const bb_image *img, bb_error *err) {
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0 || img->channels <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: nothing to write (empty image)", path);
  return BB_OK;
}

/* C callers may store any int in an enum field: compare it as the int it is. */
static bb_status check_options(const char *path, const bb_write_options *o, bb_error *err) {
  int depth = (int)o->depth, range = (int)o->range;
  if (depth < (int)BB_DEPTH_DEFAULT || depth > (int)BB_DEPTH_FLOAT)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: unknown sample depth %d", path, depth);
  if (range != (int)BB_RANGE_UNIT && range != (int)BB_RANGE_SIGNED)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: unknown value range %d", path, range);
  return BB_OK;
}

static bb_status resolve_depth(const char *path, const format_rule *f, const bb_write_options *o,
                               int channels, bb_depth *depth, bb_error *err) {
  *depth = o->depth == BB_DEPTH_DEFAULT ? f->default_depth : o->depth;
  if (!(f->allowed & BIT(*depth)))
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s samples are not supported by %s files", path,
                    bb__depth_words(*depth), f->ext);
  if (channels > f->max_channels)
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s files hold at most %d channels, not %d", path,
                    f->ext, f->max_channels, channels);
  return BB_OK;
}

static const bb_write_options DEFAULT_OPTIONS = {BB_DEPTH_DEFAULT, BB_RANGE_UNIT, NULL, NULL};

void bb__texture_options_of(const bb_write_options *options, bb_texture_options *out) {
  const bb_write_options *o = options ? options : &DEFAULT_OPTIONS;
  if (o->texture) {
    *out = *o->texture;
  } else {
    bb_texture_options_init(out);
    out->map = bb__map_kind_of_output(NULL, o->range, NULL); /* no kind: by range */
  }
  if (o->description) out->description = o->description;
}

/* A texture's checks: no sample depth to choose, then bb__texture_check's. */
static bb_status texture_check(const char *path, const bb_image *top,
                               const bb_write_options *o, bb_error *err) {
  char ext[16];
  if (o->depth != BB_DEPTH_DEFAULT)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: %s samples cannot be chosen for %s files: their texture format "
                    "sets them",
                    path, bb__depth_words(o->depth), (bb__extension_of(path, ext, sizeof ext), ext));
  bb_texture_options t;
  bb__texture_options_of(o, &t);
  return bb__texture_check(path, top->width, top->height, top->channels, &t, err);
}

bb_status bb__write_check(const char *path, const bb_image *img, const bb_write_options *options,
                          bb_depth *depth, bb_error *err) {
  const bb_write_options *o = options ? options : &DEFAULT_OPTIONS;
  bb_status st = check_image_arg(path, img, err);
  if (st != BB_OK) return st;
  st = check_options(path, o, err);
  if (st != BB_OK) return st;
  *depth = BB_DEPTH_DEFAULT;
  if (is_texture(path)) return texture_check(path, img, o, err);
  const format_rule *f = find_format(path);
  if (!f) {
    char ext[sizeof err->message];
    bb__extension_of(path, ext, sizeof ext);
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: unknown output format '%s' (use .png, .tga, .tif, .tiff, .exr, .vtf "
                    "or .dds)",
                    path, ext);
  }
  return resolve_depth(path, f, o, img->channels, depth, err);
}

/* Every level must be half the one before (floored, at least 1), with the
 * same channels, as bb_mip_chain makes them and as OpenEXR's round-down
 * mode expects. */
static bb_status check_chain(const char *path, const bb_image *levels, int count, bb_error *err) {
  if (!levels || count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: nothing to write (no mip levels)", path);
  for (int k = 0; k < count; k++) {
    bb_status st = check_image_arg(path, &levels[k], err);
    if (st != BB_OK) return st;
    if (k == 0) continue;
    const bb_image *a = &levels[k - 1], *b = &levels[k];
    int w = a->width / 2 > 1 ? a->width / 2 : 1, h = a->height / 2 > 1 ? a->height / 2 : 1;
    if (b->width != w || b->height != h || b->channels != a->channels)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: mip level %d is %dx%dx%d, not %dx%dx%d (half of the level before)",
                      path, k, b->width, b->height, b->channels, w, h, a->channels);
  }
  return BB_OK;
}

bb_status bb__write_mips_check(const char *path, const bb_image *levels, int count,
                               const bb_write_options *options, bb_depth *depth,
                               bb_error *err) {
  const bb_write_options *o = options ? options : &DEFAULT_OPTIONS;
  bb_status st = check_chain(path, levels, count, err);
  if (st != BB_OK) return st;
  st = check_options(path, o, err);
  if (st != BB_OK) return st;
  *depth = BB_DEPTH_DEFAULT;
  if (is_texture(path)) return texture_check(path, &levels[0], o, err);
  const format_rule *f = find_format(path);
  if (!f || !f->holds_mips)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: mip maps need a .tif, .tiff, .exr, .vtf or .dds file", path);
  return resolve_depth(path, f, o, levels[0].channels, depth, err);
}

const char *bb__basis_channel_name(int c, int count, char out[8]) {
  if (count <= 4) return NULL;
  int width = snprintf(NULL, 0, "%d", count - 1);
  snprintf(out, 8, "B%0*d", width, c);
  return out;
}
