/* texture.c: what the VTF and DDS writers share: formats, checks, the mip
 * chain and the encoding of a level (see texture.h). */

#include "core/file_names.h"
#include "core/internal.h"
#include "texture/blocks.h"
#include "texture/texture.h"

/* Imath's C half conversion (round to nearest even, as OpenEXR's), header
 * only: no lookup table, so nothing to link. */
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>

#include <errno.h>
#include <stdint.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ------------------------------------------------------------- formats */

typedef struct format_info {
  const char *name;  /* first name: bb__texture_format_name */
  int block;         /* a bb__block_format + 1, or 0 for texel formats */
  int texel_bytes;   /* texel formats: bytes a texel */
  int max_channels;  /* channels of the image it holds (bc5: 2, or 3 of a normal map) */
  int exact;         /* 1: exactly max_channels (bc4) */
  int has_alpha;
  int vtf, dds;      /* 1 when the container has it */
  const char *vtf_name; /* Valve's name, as --texture-format takes it for a .vtf
                           (dxt1, dxt5), where it differs */
} format_info;

/* In bb_texture_format order, DEFAULT first. */
static const format_info formats[] = {
    {"default", 0, 0, 4, 0, 0, 1, 1, NULL},
    {"bc1", 1 + BB__BLOCK_BC1, 0, 3, 0, 0, 1, 1, "dxt1"},
    {"bc3", 1 + BB__BLOCK_BC3, 0, 4, 0, 1, 1, 1, "dxt5"},
    {"bc4", 1 + BB__BLOCK_BC4, 0, 1, 1, 0, 0, 1, NULL},
    {"bc5", 1 + BB__BLOCK_BC5, 0, 2, 0, 0, 0, 1, NULL},
    {"bgr888", 0, 3, 3, 0, 0, 1, 0, NULL},
    {"bgra8888", 0, 4, 4, 0, 1, 1, 0, NULL},
    {"rgba8", 0, 4, 4, 0, 1, 0, 1, NULL},
    {"rgba16f", 0, 8, 4, 0, 1, 1, 1, NULL},
    {"rgba32f", 0, 16, 4, 0, 1, 0, 1, NULL},
};
enum { FORMAT_COUNT = (int)(sizeof formats / sizeof formats[0]) };

/* Every name bb__texture_format_parse takes, and the format it names. */
static const struct {
  const char *name;
  bb_texture_format format;
} format_names[] = {
    {"default", BB_TEXTURE_FORMAT_DEFAULT}, {"bc1", BB_TEXTURE_FORMAT_BC1},
    {"dxt1", BB_TEXTURE_FORMAT_BC1},        {"bc3", BB_TEXTURE_FORMAT_BC3},
    {"dxt5", BB_TEXTURE_FORMAT_BC3},        {"bc4", BB_TEXTURE_FORMAT_BC4},
    {"bc5", BB_TEXTURE_FORMAT_BC5},         {"bgr888", BB_TEXTURE_FORMAT_BGR8},
    {"bgra8888", BB_TEXTURE_FORMAT_BGRA8},  {"rgba8", BB_TEXTURE_FORMAT_RGBA8},
    {"rgba16f", BB_TEXTURE_FORMAT_RGBA16F}, {"rgba16161616f", BB_TEXTURE_FORMAT_RGBA16F},
    {"rgba32f", BB_TEXTURE_FORMAT_RGBA32F},
};
enum { NAME_COUNT = (int)(sizeof format_names / sizeof format_names[0]) };

static const format_info *info_of(bb_texture_format format) {
  return (int)format >= 0 && (int)format < FORMAT_COUNT ? &formats[format] : NULL;
}

/* The format's name in messages about a file of container c: Valve's for a
 * VTF (dxt1, as a Source modder types it), the DDS one otherwise (bc1). */
static const char *name_in(const format_info *f, bb__container c) {
  return c == BB__CONTAINER_VTF && f->vtf_name ? f->vtf_name : f->name;
}

bb_status bb__texture_format_parse(const char *name, bb_texture_format *out, bb_error *err) {
  const char *names[NAME_COUNT];
  for (int k = 0; k < NAME_COUNT; k++)
    names[k] = format_names[k].name;
  int k;
  bb_status st = bb__parse_name("texture format", name, names, NAME_COUNT, 1, &k, err);
  if (st == BB_OK && out)
    *out = format_names[k].format;
  return st;
}

bb_status bb__vtf_version_parse(const char *text, int *minor, bb_error *err) {
  /* "7.3" as Valve writes it, or the minor number alone. */
  const char *m = text && strncmp(text, "7.", 2) == 0 ? text + 2 : text;
  char *end = NULL;
  /* A digit first: strtol would also take spaces and a sign. */
  const int digits = m && m[0] >= '0' && m[0] <= '9';
  const long v = digits ? strtol(m, &end, 10) : 0;
  if (!digits || *end || v < 2 || v > 5)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "VTF version must be 7.2, 7.3, 7.4 or 7.5 (got '%.64s')", text ? text : "");
  if (minor) *minor = (int)v;
  return BB_OK;
}

bb_status bb__vtf_flags_parse(const char *text, uint32_t *flags, bb_error *err) {
  char *end = NULL;
  errno = 0;
  /* A digit first: strtoul would also take spaces and a sign. */
  const int digits = text && text[0] >= '0' && text[0] <= '9';
  const unsigned long v = digits ? strtoul(text, &end, 0) : 0;
  if (!digits || *end || errno || v > 0xffffffffUL)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "VTF flags must be a 32-bit number, e.g. 0x4 (got '%.64s')", text ? text : "");
  if (flags) *flags = (uint32_t)v;
  return BB_OK;
}

const char *bb__texture_format_name(bb_texture_format format) {
  const format_info *f = info_of(format);
  return f ? f->name : "unknown";
}

int bb__texture_format_has_alpha(bb_texture_format format) {
  const format_info *f = info_of(format);
  return f ? f->has_alpha : 0;
}

size_t bb__texture_level_bytes(bb_texture_format format, int width, int height) {
  const format_info *f = info_of(format);
  if (!f || format == BB_TEXTURE_FORMAT_DEFAULT || width <= 0 || height <= 0)
    return 0;
  if (f->block)
    return bb__blocks_size((bb__block_format)(f->block - 1), width, height);
  return (size_t)width * (size_t)height * (size_t)f->texel_bytes;
}

long bb__texture_block_rows(const char *path, int width, int height, int channels,
                            const bb_texture_options *options) {
  bb_texture_format format;
  bb_error ignored;
  if (bb__texture_resolve(path, width, height, channels, options, &format, &ignored) != BB_OK)
    return 0;
  const format_info *f = info_of(format);
  if (!f || !f->block)
    return 0;
  const int mips = options ? options->mips : 1;
  long rows = 0;
  int low = bb__texture_container(path) != BB__CONTAINER_VTF; /* 1: found, or none */
  for (int w = width, h = height, k = 0;; k++) {
    if (k == 0 || mips)
      rows += (h + 3) / 4;
    if (!low && w <= 16 && h <= 16) /* the low-resolution image: DXT1 */
      rows += (h + 3) / 4, low = 1;
    if ((w == 1 && h == 1) || (!mips && low))
      break;
    w = w / 2 > 1 ? w / 2 : 1, h = h / 2 > 1 ? h / 2 : 1;
  }
  return rows;
}

void bb_texture_options_init(bb_texture_options *o) {
  if (!o)
    return;
  memset(o, 0, sizeof *o);
  o->format = BB_TEXTURE_FORMAT_DEFAULT;
  o->map = BB_MAP_PLAIN;
  o->mips = 1;
  o->vtf_version = 2;
}

/* ------------------------------------------------------------- checks */

bb__container bb__texture_container(const char *path) {
  const char *dot = bb__file_extension(path);
  if (!dot)
    return BB__CONTAINER_NONE;
  if (strcasecmp(dot, ".vtf") == 0)
    return BB__CONTAINER_VTF;
  if (strcasecmp(dot, ".dds") == 0)
    return BB__CONTAINER_DDS;
  return BB__CONTAINER_NONE;
}

int bb__path_is_texture_format(const char *path) {
  return bb__texture_container(path) != BB__CONTAINER_NONE;
}

static int is_power_of_two(int n) {
  return n > 0 && (n & (n - 1)) == 0;
}

/* The power of two nearest n (ties up), for the message. */
static int nearest_power_of_two(int n) {
  int p = 1;
  while (p < n && p < (1 << 30))
    p <<= 1;
  return p - n <= n - p / 2 ? p : p / 2;
}

/* The names of the container's formats, "bc1, bc3, ...", into buf. */
static void container_formats(bb__container c, char *buf, size_t cap) {
  buf[0] = '\0';
  size_t used = 0;
  for (int k = 1; k < FORMAT_COUNT; k++) {
    if (!(c == BB__CONTAINER_VTF ? formats[k].vtf : formats[k].dds))
      continue;
    int n = snprintf(buf + used, cap - used, "%s%s", used ? ", " : "",
                     name_in(&formats[k], c));
    if (n < 0 || (size_t)n >= cap - used)
      break;
    used += (size_t)n;
  }
}

static bb_texture_format default_format(bb__container c, bb_map_kind map, int channels) {
  if (c == BB__CONTAINER_VTF)
    return channels == 4 ? BB_TEXTURE_FORMAT_BC3 : BB_TEXTURE_FORMAT_BC1;
  /* BC5 keeps x and y (z rebuilt); a normal map with an alpha to keep
   * (renderbumpflat's coverage) is BC3, as in a VTF */
  if (bb_map_kind_get(map)->unit_vectors && channels < 4)
    return BB_TEXTURE_FORMAT_BC5;
  switch (channels) {
  case 1: return BB_TEXTURE_FORMAT_BC4;
  case 2: return BB_TEXTURE_FORMAT_BC5;
  case 3: return BB_TEXTURE_FORMAT_BC1;
  default: return BB_TEXTURE_FORMAT_BC3;
  }
}

/* The flags that say what a VTF holds (alpha, a mip chain) are the
 * writer's: one added by the caller that the file would contradict is
 * refused, as readers (the engine, VTFLib, `info`) believe the flags. */
static bb_status check_vtf_flags(const char *path, int width, int height, int channels,
                                 const bb_texture_options *o, bb_texture_format fmt,
                                 bb_error *err) {
  const format_info *f = info_of(fmt);
  const int alpha = channels == 4 && f->has_alpha; /* as vtf.c sets EIGHTBITALPHA */
  const uint32_t extra = o->vtf_flags;
  if (extra & BB_VTF_FLAG_ONEBITALPHA)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: the ONEBITALPHA flag (0x%08x) says the file has 1-bit alpha, and "
                    "the %s file has %s",
                    path, BB_VTF_FLAG_ONEBITALPHA, name_in(f, BB__CONTAINER_VTF),
                    alpha ? "8-bit alpha" : "none");
  if ((extra & BB_VTF_FLAG_EIGHTBITALPHA) && !alpha)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: the EIGHTBITALPHA flag (0x%08x) says the file has alpha, and the %s "
                    "file of a %d-channel image has none",
                    path, BB_VTF_FLAG_EIGHTBITALPHA, name_in(f, BB__CONTAINER_VTF), channels);
  if ((extra & BB_VTF_FLAG_NOMIP) && o->mips && (width > 1 || height > 1))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: the NOMIP flag (0x%08x) says the file has no mip chain, and it has "
                    "one: write it without mips (--nomip), which sets the flag",
                    path, BB_VTF_FLAG_NOMIP);
  return BB_OK;
}

bb_status bb__texture_resolve(const char *path, int width, int height, int channels,
                              const bb_texture_options *options, bb_texture_format *format,
                              bb_error *err) {
  bb_texture_options defaults;
  bb_texture_options_init(&defaults);
  const bb_texture_options *o = options ? options : &defaults;
  if (!path)
    return bb__fail(err, BB_ERR_ARGUMENT, "texture: no path");
  const bb__container c = bb__texture_container(path);
  const char *kind = c == BB__CONTAINER_VTF ? "VTF" : "DDS";
  if (c == BB__CONTAINER_NONE)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: not a texture file name (.vtf or .dds)", path);
  if (!bb_map_kind_get(o->map))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: unknown texture map kind %d", path, (int)o->map);
  const format_info *f = info_of(o->format);
  if (!f)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: unknown texture format %d", path,
                    (int)o->format);
  if (!bb__range_holds(&bb__range_threads, o->threads)) {
    char who[600];
    snprintf(who, sizeof who, "%s: threads", path);
    return bb__range_check(&bb__range_threads, o->threads, who, err);
  }
  if (c == BB__CONTAINER_VTF) {
    if (o->vtf_version < 2 || o->vtf_version > 5)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: VTF version 7.%d is not written (7.2 to 7.5 are)", path,
                      o->vtf_version);
    if (o->vtf_flags & BB_VTF_FLAG_ENVMAP)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: the ENVMAP flag (0x%08x) makes a cube map, and one face is "
                      "written",
                      path, BB_VTF_FLAG_ENVMAP);
  }
  if (width <= 0 || height <= 0 || width > BB_MAX_DIMENSION || height > BB_MAX_DIMENSION)
    return bb__fail(err, BB_ERR_SIZE, "%s: bad image size %d x %d", path, width, height);
  if (channels < 1 || channels > 4)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: a %s texture holds at most 4 channels (the image has %d)", path,
                    kind, channels);
  if (bb_map_kind_get(o->map)->unit_vectors && channels < 3)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: a normal map needs 3 channels (the image has %d)", path, channels);
  bb_texture_format fmt = o->format == BB_TEXTURE_FORMAT_DEFAULT
                              ? default_format(c, o->map, channels)
                              : o->format;
  f = info_of(fmt);
  if (!(c == BB__CONTAINER_VTF ? f->vtf : f->dds)) {
    char names[128];
    container_formats(c, names, sizeof names);
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: %s has no format %s (it has %s)", path, kind,
                    name_in(f, c), names);
  }
  const int holds = fmt == BB_TEXTURE_FORMAT_BC5 && bb_map_kind_get(o->map)->unit_vectors
                        ? 3
                        : f->max_channels;
  if (channels > holds || (f->exact && channels != holds))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: format %s holds %s%d channel%s, and the %s has %d", path,
                    name_in(f, c),
                    f->exact ? "" : "at most ", holds, holds == 1 ? "" : "s",
                    bb_map_kind_get(o->map)->unit_vectors ? "normal map" : "image", channels);
  if (c == BB__CONTAINER_VTF) {
    bb_status st = check_vtf_flags(path, width, height, channels, o, fmt, err);
    if (st != BB_OK)
      return st;
    if (!is_power_of_two(width) || !is_power_of_two(height))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: %d x %d: Source textures need a power of two on each side "
                      "(resize to %d x %d)",
                      path, width, height, nearest_power_of_two(width),
                      nearest_power_of_two(height));
    if (width > 32768 || height > 32768)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: %d x %d: a VTF side is at most 32768",
                      path, width, height);
  }
  /* A VTF stores a side under 4 texels (1 or 2: a power of two) as one
   * padded 4 x 4 block, as Valve's tools write the smallest mips and 1 x 1
   * and 2 x 2 textures; a DDS's top level needs whole blocks (Direct3D). */
  const int padded_vtf = c == BB__CONTAINER_VTF && (width < 4 || height < 4);
  if (f->block && !padded_vtf && (width % 4 != 0 || height % 4 != 0))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: %d x %d: block compression (%s) needs sides that are multiples of 4",
                    path, width, height, name_in(f, c));
  if (format)
    *format = fmt;
  return BB_OK;
}

bb_status bb__texture_check(const char *path, int width, int height, int channels,
                           const bb_texture_options *options, bb_error *err) {
  return bb__texture_resolve(path, width, height, channels, options, NULL, err);
}

/* ------------------------------------------------------------- encoding */

void bb__texture_texels(const bb_image *img, int unit_vectors, size_t i, size_t n,
                        float *rgba) {
  const size_t ch = (size_t)img->channels;
  const float *t = img->pixels + i * ch;
  float *o = rgba;
  switch (img->channels) {
  case 1:
    for (size_t x = 0; x < n; x++)
      o[4 * x] = o[4 * x + 1] = o[4 * x + 2] = t[x], o[4 * x + 3] = 1.0f;
    break;
  case 2:
    for (size_t x = 0; x < n; x++)
      o[4 * x] = t[2 * x], o[4 * x + 1] = t[2 * x + 1], o[4 * x + 2] = 0.0f,
              o[4 * x + 3] = 1.0f;
    break;
  case 3:
    for (size_t x = 0; x < n; x++)
      o[4 * x] = t[3 * x], o[4 * x + 1] = t[3 * x + 1], o[4 * x + 2] = t[3 * x + 2],
              o[4 * x + 3] = 1.0f;
    break;
  default:
    for (size_t x = 0; x < n; x++)
      memcpy(o + 4 * x, t + ch * x, 4 * sizeof(float));
    break;
  }
  if (unit_vectors)
    for (size_t x = 0; x < n; x++)
      for (size_t c = 0; c < 3; c++)
        o[4 * x + c] = 0.5f + 0.5f * o[4 * x + c];
}

/* Four samples at a time in doubles, two to a register, each lane's
 * operations those of bb__texture_byte: max(v, 0) (maxpd gives its second
 * operand for a NaN, as v > 0 ? v : 0 does), min(u, 1), u 255 + 0.5, then
 * truncated. */
void bb__texture_bytes(const float *v, size_t n, int unit_vectors, unsigned char *out) {
  size_t i = 0;
#if defined(__SSE2__)
  const __m128 half = _mm_set1_ps(0.5f);
  const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0), scale = _mm_set1_pd(255.0),
                round = _mm_set1_pd(0.5);
  for (; i + 4 <= n; i += 4) {
    __m128 f = _mm_loadu_ps(v + i);
    if (unit_vectors)
      f = _mm_add_ps(half, _mm_mul_ps(half, f));
    __m128d lo = _mm_cvtps_pd(f), hi = _mm_cvtps_pd(_mm_movehl_ps(f, f));
    lo = _mm_min_pd(_mm_max_pd(lo, zero), one);
    hi = _mm_min_pd(_mm_max_pd(hi, zero), one);
    lo = _mm_add_pd(_mm_mul_pd(lo, scale), round);
    hi = _mm_add_pd(_mm_mul_pd(hi, scale), round);
    const __m128i k = _mm_unpacklo_epi64(_mm_cvttpd_epi32(lo), _mm_cvttpd_epi32(hi));
    const __m128i b = _mm_packus_epi16(_mm_packs_epi32(k, k), _mm_setzero_si128());
    const uint32_t four = (uint32_t)_mm_cvtsi128_si32(b);
    memcpy(out + i, &four, 4);
  }
#endif
  for (; i < n; i++)
    out[i] = bb__texture_byte(unit_vectors ? 0.5f + 0.5f * v[i] : v[i]);
}

static void put_u16(unsigned char *p, uint16_t v) {
  p[0] = (unsigned char)(v & 0xff);
  p[1] = (unsigned char)(v >> 8);
}

static void put_f32(unsigned char *p, float v) {
  uint32_t u;
  memcpy(&u, &v, sizeof u);
  for (int k = 0; k < 4; k++)
    p[k] = (unsigned char)((u >> (8 * k)) & 0xff);
}

/* The block codec's view of a level: its texels as the engine samples them. */
typedef struct level_source {
  const bb_image *level;
  int unit_vectors; /* bb_map_kind_info.unit_vectors */
} level_source;

/* A block's texels, a row at a time. */
static void level_texels(const void *source, int x0, int y0, int w, int h, float rgba[64]) {
  const level_source *s = source;
  const size_t width = (size_t)s->level->width;
  for (int y = 0; y < h; y++)
    bb__texture_texels(s->level, s->unit_vectors, (size_t)(y0 + y) * width + (size_t)x0,
                       (size_t)w, rgba + 16 * y);
}

/* One level in a texel format, texel by texel. */
static void encode_texels(const bb_image *level, int unit_vectors, bb_texture_format format,
                          int texel_bytes, unsigned char *out) {
  const size_t n = (size_t)level->width * (size_t)level->height;
  unsigned char *p = out;
  for (size_t i = 0; i < n; i++) {
    float t[4];
    bb__texture_texels(level, unit_vectors, i, 1, t);
    switch (format) {
    case BB_TEXTURE_FORMAT_BGR8:
      p[0] = bb__texture_byte(t[2]), p[1] = bb__texture_byte(t[1]), p[2] = bb__texture_byte(t[0]);
      break;
    case BB_TEXTURE_FORMAT_BGRA8:
      p[0] = bb__texture_byte(t[2]), p[1] = bb__texture_byte(t[1]), p[2] = bb__texture_byte(t[0]), p[3] = bb__texture_byte(t[3]);
      break;
    case BB_TEXTURE_FORMAT_RGBA8:
      for (int c = 0; c < 4; c++)
        p[c] = bb__texture_byte(t[c]);
      break;
    case BB_TEXTURE_FORMAT_RGBA16F:
      for (int c = 0; c < 4; c++)
        put_u16(p + 2 * c, imath_float_to_half(t[c]));
      break;
    default: /* BB_TEXTURE_FORMAT_RGBA32F */
      for (int c = 0; c < 4; c++)
        put_f32(p + 4 * c, t[c]);
      break;
    }
    p += texel_bytes;
  }
}

bb_status bb__texture_encode_levels(const bb_image *levels, int count, bb_map_kind map,
                                    bb_texture_format format, int fast, int threads,
                                    unsigned char *const *out, bb_error *err) {
  const format_info *f = info_of(format);
  const bb_map_kind_info *kind = bb_map_kind_get(map);
  if (!f || !kind || format == BB_TEXTURE_FORMAT_DEFAULT || count < 1 || !levels || !out)
    return bb__fail(err, BB_ERR_ARGUMENT, "texture: bad levels, kind or format");
  for (int k = 0; k < count; k++)
    if (!levels[k].pixels || !out[k])
      return bb__fail(err, BB_ERR_ARGUMENT, "texture: bad level %d", k);
  if (!f->block) {
    for (int k = 0; k < count; k++)
      encode_texels(&levels[k], kind->unit_vectors, format, f->texel_bytes, out[k]);
    return BB_OK;
  }
  level_source *sources = malloc((size_t)count * sizeof *sources);
  bb__block_image *images = malloc((size_t)count * sizeof *images);
  bb_status st = BB_OK;
  if (!sources || !images) {
    st = bb__fail(err, BB_ERR_MEMORY, "texture: out of memory");
  } else {
    for (int k = 0; k < count; k++) {
      sources[k] = (level_source){&levels[k], kind->unit_vectors};
      images[k] = (bb__block_image){levels[k].width, levels[k].height,
                                    (bb__block_format)(f->block - 1), level_texels,
                                    &sources[k], out[k]};
    }
    st = bb__blocks_compress_images(images, count, fast ? BB__FIT_QUICK : BB__FIT_BEST,
                                    threads, NULL, NULL, err);
  }
  free(images);
  free(sources);
  return st;
}

bb_status bb__texture_encode(const bb_image *level, bb_map_kind map,
                             bb_texture_format format, int fast, int threads,
                             unsigned char *out, bb_error *err) {
  if (!level)
    return bb__fail(err, BB_ERR_ARGUMENT, "texture: bad level or format");
  return bb__texture_encode_levels(level, 1, map, format, fast, threads, &out, err);
}

/* ----------------------------------------------------- maps, provenance */

/* The map of an output kind string, as the library reads every one
 * (bb__map_kind_of_output: core/map_kind.c). */
void bb__texture_options_for(bb_texture_options *o, const char *kind, bb_range range) {
  if (o)
    o->map = bb__map_kind_of_output(kind, range, &o->vtf_flags);
}

char *bb__texture_provenance(const char *path, const bb_texture_options *options) {
  const bb__container c = bb__texture_container(path);
  if (c == BB__CONTAINER_NONE)
    return NULL;
  bb_texture_options defaults;
  bb_texture_options_init(&defaults);
  const bb_texture_options *o = options ? options : &defaults;
  char text[256];
  int n = snprintf(text, sizeof text,
                   "texture=%s\ntexture_format=%s\ntexture_mips=%d\ntexture_fit=%s",
                   c == BB__CONTAINER_VTF ? "vtf" : "dds", bb__texture_format_name(o->format),
                   o->mips ? 1 : 0, o->fast ? "range" : "cluster");
  if (c == BB__CONTAINER_VTF && n > 0 && (size_t)n < sizeof text)
    snprintf(text + n, sizeof text - (size_t)n, "\nvtf_version=7.%d\nvtf_flags=0x%08x",
             o->vtf_version, (unsigned)o->vtf_flags);
  return strdup(text);
}
