/* vtf.c: Valve Texture Format files: written (7.2 to 7.5, one frame, one
 * face) and their headers read, for `info` and for the pixel reader
 * (vtf_read.c).
 *
 * The layout, from VTFLib's VTFFormat.h (Neil Jedrzejewski and Ryan Gregg,
 * github.com/NeilJed/VTFLib) and the Valve Developer Community's "Valve
 * Texture Format" page, which agree with Valve's vtf.cpp (Source SDK):
 * all little-endian, fields packed (no padding but the named one):
 *
 *   0  char[4]  "VTF\0"
 *   4  u32[2]   version 7, minor
 *  12  u32      header size (80 for 7.2; 7.3+: 80 + 8 x resources)
 *  16  u16      width, u16 height (of the top level)
 *  20  u32      flags (TEXTUREFLAGS_*)
 *  24  u16      frames, u16 first frame
 *  28  u8[4]    padding
 *  32  f32[3]   reflectivity
 *  44  u8[4]    padding
 *  48  f32      bump scale
 *  52  u32      high-resolution image format (IMAGE_FORMAT_*)
 *  56  u8       mip count
 *  57  u32      low-resolution image format (DXT1 = 13)
 *  61  u8       low-resolution width, u8 height
 *  63  u16      depth (7.2+)
 *  65  u8[3]    padding, 68 u32 resource count (7.3+), 72 u8[8] padding
 *  80           7.3+: resource entries { u8 id[3], u8 flags, u32 data }
 *
 * then the low-resolution image, then (7.3+) resource data chunks, then the
 * image data: every mip level, smallest first (each level: frames, faces,
 * slices). 7.2 and older have no resources, and so no room for provenance;
 * 7.3 and up carry it in a "KVD" (key-value data) resource, text that
 * Source's tools read as KeyValues: "bumpbake" { "key" "value" ... }.
 * Valve's engine finds resources by binary search on the 24-bit id, so the
 * dictionary is sorted: low-res (0x01), image (0x30), KVD. */

#include "core/input_file.h"
#include "core/internal.h"
#include "texture/texture.h"
#include "texture/vtf.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { HEADER_BYTES = 80, RESOURCE_BYTES = 8, MAX_RESOURCES = 32 };
enum {
  RSRC_LOW_RES = 0x01,
  RSRC_IMAGE = 0x30,
  RSRC_KVD = 'K' | ('V' << 8) | ('D' << 16),
  RSRC_NO_DATA_CHUNK = 0x02 /* in the flags byte: data is the value itself */
};

static void put_u16(unsigned char *p, unsigned v) {
  p[0] = (unsigned char)(v & 0xff);
  p[1] = (unsigned char)((v >> 8) & 0xff);
}

static void put_u32(unsigned char *p, uint32_t v) {
  for (int k = 0; k < 4; k++)
    p[k] = (unsigned char)((v >> (8 * k)) & 0xff);
}

static void put_f32(unsigned char *p, float v) {
  uint32_t u;
  memcpy(&u, &v, sizeof u);
  put_u32(p, u);
}

static int vtf_code(bb_texture_format format) {
  switch (format) {
  case BB_TEXTURE_FORMAT_BC1: return BB__VTF_DXT1;
  case BB_TEXTURE_FORMAT_BC3: return BB__VTF_DXT5;
  case BB_TEXTURE_FORMAT_BGR8: return BB__VTF_BGR888;
  case BB_TEXTURE_FORMAT_BGRA8: return BB__VTF_BGRA8888;
  case BB_TEXTURE_FORMAT_RGBA16F: return BB__VTF_RGBA16161616F;
  default: return -1;
  }
}

/* vtex's and VTFLib's reflectivity: per channel, the mean over the top
 * level of (code / 255)^2.2, code the texel's 8-bit value (as the block
 * codec sees the texel: bb__texture_texels, a grey map's value in all
 * three, a normal map's 0.5 + 0.5 n).
 *
 * A row's samples are turned into codes first, four at a time
 * (bb__texture_bytes), then the codes' powers are summed texel by texel in
 * the order the sums always took: the bits of the texel-at-a-time loop
 * this replaces, which cost about 95 instructions a texel (100 M of a
 * 1024 x 1024 VTF write, on one thread before the levels were
 * compressed). 0, or -1 out of memory. */
static int reflectivity(const bb_image *top, bb_map_kind map, float out[3]) {
  const int unit_vectors = bb_map_kind_get(map)->unit_vectors;
  double table[256];
  for (int i = 0; i < 256; i++)
    table[i] = pow(i / 255.0, 2.2);
  const size_t ch = (size_t)top->channels, w = (size_t)top->width;
  /* Texel x's channel c has its code at from[c] + step[c] x of the row's
   * codes; a 2-channel map's third channel is a 0 (0.5 in a normal map),
   * its code kept after the row's (at w ch). */
  const size_t from[3] = {0, ch >= 2 ? 1 : 0, ch >= 3 ? 2 : ch == 2 ? w * ch : 0};
  const size_t step[3] = {ch, ch, ch == 2 ? 0 : ch};
  unsigned char *codes = malloc(w * ch + 1);
  if (!codes)
    return -1;
  double sum[3] = {0, 0, 0};
  codes[w * ch] = bb__texture_byte(unit_vectors ? 0.5f : 0.0f);
  for (int y = 0; y < top->height; y++) {
    bb__texture_bytes(top->pixels + (size_t)y * w * ch, w * ch, unit_vectors, codes);
    for (size_t x = 0; x < w; x++)
      for (int c = 0; c < 3; c++)
        sum[c] += table[codes[from[c] + step[c] * x]];
  }
  free(codes);
  const double n = (double)w * (double)top->height;
  for (int c = 0; c < 3; c++)
    out[c] = (float)(sum[c] / n);
  return 0;
}

/* The provenance as a KeyValues block, "bumpbake" { "key" "value" ... },
 * '"' and '\' escaped with '\'. malloc'd and NUL-terminated, but *size
 * leaves the NUL out: the chunk is the text alone, as KeyValues readers
 * take a buffer of known size (Valve's LoadFromBuffer; srctools' parser
 * stops at a NUL inside the text as at an unfinished file). */
static char *kvd_text(const char *description, size_t *size) {
  const size_t n = strlen(description);
  /* Each character may double, and each line adds a tab, four quotes, a
   * space and a newline. */
  const size_t cap = 32 + 2 * n + 8 * (n + 1);
  char *out = malloc(cap);
  if (!out)
    return NULL;
  size_t k = 0;
  k += (size_t)snprintf(out + k, cap - k, "\"bumpbake\"\n{\n");
  for (const char *line = description; *line;) {
    const char *end = strchr(line, '\n');
    if (!end)
      end = line + strlen(line);
    const char *eq = memchr(line, '=', (size_t)(end - line));
    if (end > line) {
      out[k++] = '\t';
      for (int part = 0; part < 2; part++) {
        const char *a = part == 0 ? line : (eq ? eq + 1 : end);
        const char *b = part == 0 ? (eq ? eq : end) : end;
        out[k++] = '"';
        for (const char *c = a; c < b; c++) {
          if (*c == '"' || *c == '\\')
            out[k++] = '\\';
          out[k++] = *c;
        }
        out[k++] = '"';
        if (part == 0)
          out[k++] = ' ';
      }
      out[k++] = '\n';
    }
    line = *end ? end + 1 : end;
  }
  k += (size_t)snprintf(out + k, cap - k, "}\n");
  *size = k;
  return out;
}

bb_status bb__vtf_encode(bb_staged_file *f, const bb_image *chain, int levels,
                         const bb_image *low, const bb_texture_options *o,
                         bb_texture_format format, bb_error *err) {
  const char *path = f->path;
  const bb_image *img = &chain[0];
  bb_status st = BB_OK;
  if (!low)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no low-resolution level", path);
  const size_t low_bytes = bb__texture_level_bytes(BB_TEXTURE_FORMAT_BC1, low->width, low->height);

  uint32_t flags = o->vtf_flags;
  flags |= bb_map_kind_get(o->map)->vtf_flags;
  if (!o->mips)
    flags |= BB_VTF_FLAG_NOMIP | BB_VTF_FLAG_NOLOD;
  if (img->channels == 4 && bb__texture_format_has_alpha(format))
    flags |= BB_VTF_FLAG_EIGHTBITALPHA;

  uint64_t data_bytes = 0;
  for (int k = 0; k < levels; k++)
    data_bytes += bb__texture_level_bytes(format, chain[k].width, chain[k].height);

  char *kvd = NULL;
  size_t kvd_bytes = 0;
  const int resources = o->vtf_version >= 3 ? (o->description ? 3 : 2) : 0;
  if (resources == 3 && !(kvd = kvd_text(o->description, &kvd_bytes)))
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  const uint32_t header_size = (uint32_t)(HEADER_BYTES + RESOURCE_BYTES * resources);
  const uint64_t low_at = header_size;
  const uint64_t kvd_at = low_at + low_bytes;
  const uint64_t image_at = kvd_at + (kvd ? 4 + kvd_bytes : 0);
  if (image_at + data_bytes > UINT32_MAX) {
    free(kvd);
    return bb__fail(err, BB_ERR_SIZE, "%s: %llu bytes do not fit a VTF's 32-bit offsets",
                    path, (unsigned long long)(image_at + data_bytes));
  }

  unsigned char header[HEADER_BYTES + RESOURCE_BYTES * MAX_RESOURCES];
  memset(header, 0, sizeof header);
  memcpy(header, "VTF", 4);
  put_u32(header + 4, 7);
  put_u32(header + 8, (uint32_t)o->vtf_version);
  put_u32(header + 12, header_size);
  put_u16(header + 16, (unsigned)img->width);
  put_u16(header + 18, (unsigned)img->height);
  put_u32(header + 20, flags);
  put_u16(header + 24, 1); /* frames */
  put_u16(header + 26, 0); /* first frame */
  float refl[3];
  if (reflectivity(&chain[0], o->map, refl) != 0) {
    free(kvd);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  for (int c = 0; c < 3; c++)
    put_f32(header + 32 + 4 * c, refl[c]);
  put_f32(header + 48, 1.0f); /* bump scale */
  put_u32(header + 52, (uint32_t)vtf_code(format));
  header[56] = (unsigned char)levels;
  put_u32(header + 57, BB__VTF_DXT1);
  header[61] = (unsigned char)low->width;
  header[62] = (unsigned char)low->height;
  put_u16(header + 63, 1); /* depth */
  if (resources) {
    put_u32(header + 68, (uint32_t)resources);
    unsigned char *e = header + HEADER_BYTES;
    put_u32(e, RSRC_LOW_RES);
    put_u32(e + 4, (uint32_t)low_at);
    put_u32(e + 8, RSRC_IMAGE);
    put_u32(e + 12, (uint32_t)image_at);
    if (kvd) {
      put_u32(e + 16, RSRC_KVD);
      put_u32(e + 20, (uint32_t)kvd_at);
    }
  }

  /* The low-resolution image, then the levels, smallest first, as the
   * file holds them; the levels are compressed in one job, largest first. */
  unsigned char *low_blocks = malloc(low_bytes);
  unsigned char *data = malloc(data_bytes ? (size_t)data_bytes : 1);
  unsigned char **at = malloc((size_t)levels * sizeof *at);
  if (!low_blocks || !data || !at)
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  if (st == BB_OK) {
    size_t offset = (size_t)data_bytes;
    for (int k = 0; k < levels; k++) {
      offset -= bb__texture_level_bytes(format, chain[k].width, chain[k].height);
      at[k] = data + offset;
    }
    st = bb__texture_encode(low, o->map, BB_TEXTURE_FORMAT_BC1, o->fast, 1, low_blocks, err);
  }
  if (st == BB_OK)
    st = bb__texture_encode_levels(chain, levels, o->map, format, o->fast, o->threads, at, err);
  if (st == BB_OK) {
    bb__safe_write(f, header, header_size);
    bb__safe_write(f, low_blocks, low_bytes);
    if (kvd) {
      unsigned char size[4];
      put_u32(size, (uint32_t)kvd_bytes);
      bb__safe_write(f, size, 4);
      bb__safe_write(f, kvd, kvd_bytes);
    }
    bb__safe_write(f, data, (size_t)data_bytes);
  }
  /* Write errors are kept by f and reported when the caller finishes it. */
  free(at);
  free(data);
  free(low_blocks);
  free(kvd);
  return st;
}

/* ------------------------------------------------------------- reading */

static uint32_t get_u32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static unsigned get_u16(const unsigned char *p) {
  return (unsigned)p[0] | (unsigned)p[1] << 8;
}

static float get_f32(const unsigned char *p) {
  uint32_t u = get_u32(p);
  float v;
  memcpy(&v, &u, sizeof v);
  return v;
}

/* Valve's formats: name, bytes a texel (texel formats) or a 4 x 4 block
 * (block: 1), from VTFLib's table. */
static const struct {
  const char *name;
  int bytes, block;
} vtf_formats[] = {
    {"RGBA8888", 4, 0},      {"ABGR8888", 4, 0},       {"RGB888", 3, 0},
    {"BGR888", 3, 0},        {"RGB565", 2, 0},         {"I8", 1, 0},
    {"IA88", 2, 0},          {"P8", 1, 0},             {"A8", 1, 0},
    {"RGB888_BLUESCREEN", 3, 0}, {"BGR888_BLUESCREEN", 3, 0}, {"ARGB8888", 4, 0},
    {"BGRA8888", 4, 0},      {"DXT1", 8, 1},           {"DXT3", 16, 1},
    {"DXT5", 16, 1},         {"BGRX8888", 4, 0},       {"BGR565", 2, 0},
    {"BGRX5551", 2, 0},      {"BGRA4444", 2, 0},       {"DXT1_ONEBITALPHA", 8, 1},
    {"BGRA5551", 2, 0},      {"UV88", 2, 0},           {"UVWQ8888", 4, 0},
    {"RGBA16161616F", 8, 0}, {"RGBA16161616", 8, 0},   {"UVLX8888", 4, 0},
    {"R32F", 4, 0},          {"RGB323232F", 12, 0},    {"RGBA32323232F", 16, 0},
    {"NV_DST16", 2, 0},      {"NV_DST24", 4, 0},       {"NV_INTZ", 4, 0},
    {"NV_RAWZ", 4, 0},       {"ATI_DST16", 2, 0},      {"ATI_DST24", 4, 0},
    {"NV_NULL", 4, 0},       {"ATI2N", 16, 1},         {"ATI1N", 8, 1},
};
enum { VTF_FORMAT_COUNT = (int)(sizeof vtf_formats / sizeof vtf_formats[0]) };

/* Bytes of a w x h x d level of Valve format code, or 0 if unknown. */
static uint64_t level_bytes(int code, uint64_t w, uint64_t h, uint64_t d) {
  if (code < 0 || code >= VTF_FORMAT_COUNT)
    return 0;
  if (vtf_formats[code].block)
    return (w + 3) / 4 * ((h + 3) / 4) * d * (uint64_t)vtf_formats[code].bytes;
  return w * h * d * (uint64_t)vtf_formats[code].bytes;
}

void bb__vtf_info_free(bb_vtf_info *info) {
  if (!info)
    return;
  free(info->description);
  info->description = NULL;
}

/* Reads size bytes at offset; 0 on success. */
static int read_at(int fd, void *data, size_t size, off_t offset) {
  unsigned char *p = data;
  while (size > 0) {
    ssize_t n = pread(fd, p, size, offset);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
      return -1;
    p += n;
    size -= (size_t)n;
    offset += n;
  }
  return 0;
}

/* Appends s[0..n) to out at *k, undoing the writer's '\' escapes; out has
 * room for n more bytes. */
static void unescape(const char *s, size_t n, char *out, size_t *k) {
  for (size_t i = 0; i < n; i++) {
    if (s[i] == '\\' && i + 1 < n)
      i++;
    out[(*k)++] = s[i];
  }
}

/* The next quoted string of text[*at..len): its bounds, escapes kept;
 * skips blanks, braces and // comments. 0 when none is left. */
static int next_string(const char *text, size_t len, size_t *at, size_t *start, size_t *end) {
  size_t i = *at;
  for (;;) {
    while (i < len && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' ||
                       text[i] == '\n' || text[i] == '{' || text[i] == '}'))
      i++;
    if (i + 1 < len && text[i] == '/' && text[i + 1] == '/') {
      while (i < len && text[i] != '\n')
        i++;
      continue;
    }
    break;
  }
  if (i >= len || text[i] != '"')
    return 0;
  size_t j = i + 1;
  while (j < len && text[j] != '"') {
    if (text[j] == '\\' && j + 1 < len)
      j++;
    j++;
  }
  if (j >= len)
    return 0;
  *start = i + 1;
  *end = j;
  *at = j + 1;
  return 1;
}

/* "key=value" lines from a KVD chunk bumpbake wrote ("bumpbake" { ... });
 * NULL for any other text (a KVD of another tool). */
static char *kvd_description(const char *text, size_t len) {
  const char *nul = memchr(text, '\0', len);
  if (nul)
    len = (size_t)(nul - text);
  size_t at = 0, a, b;
  if (!next_string(text, len, &at, &a, &b) || b - a != 8 || memcmp(text + a, "bumpbake", 8))
    return NULL;
  char *out = malloc(len + 1);
  if (!out)
    return NULL;
  size_t k = 0, c, d;
  while (next_string(text, len, &at, &a, &b) && next_string(text, len, &at, &c, &d)) {
    unescape(text + a, b - a, out, &k);
    out[k++] = '=';
    unescape(text + c, d - c, out, &k);
    out[k++] = '\n';
  }
  out[k] = '\0';
  return out;
}

bb_status bb__vtf_read_header(int fd, const char *path, bb_vtf_info *info,
                              uint64_t *image_offset, bb_error *err) {
  memset(info, 0, sizeof *info);
  bb_status st = BB_OK;
  struct stat sb;
  unsigned char h[HEADER_BYTES + RESOURCE_BYTES * MAX_RESOURCES];
  memset(h, 0, sizeof h);
  if (fstat(fd, &sb) != 0) {
    st = bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    goto done;
  }
  const uint64_t file_size = (uint64_t)sb.st_size;
  if (file_size < 16 || read_at(fd, h, 16, 0) != 0 || memcmp(h, "VTF\0", 4) != 0) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: not a VTF file", path);
    goto done;
  }
  info->version_major = (int)get_u32(h + 4);
  const uint32_t minor = get_u32(h + 8);
  const uint32_t header_size = get_u32(h + 12);
  if (info->version_major != 7 || minor > 5) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF version %u.%u is not known (7.0 to 7.5 are)",
                  path, get_u32(h + 4), minor);
    goto done;
  }
  info->version_minor = (int)minor;
  info->header_size = (int)(header_size > INT32_MAX ? INT32_MAX : header_size);
  /* The fields each version has: 63 bytes up to 7.1, 65 in 7.2, 72 from
   * 7.3 on (the resource count), plus its resource entries. */
  const uint32_t fields = minor <= 1 ? 63 : minor == 2 ? 65 : 72;
  if (header_size < fields || header_size > file_size) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF header size %u does not fit (file of %llu bytes)",
                  path, header_size, (unsigned long long)file_size);
    goto done;
  }
  const size_t head = header_size < sizeof h ? header_size : sizeof h;
  if (read_at(fd, h, head, 0) != 0) {
    st = bb__fail(err, BB_ERR_IO, "%s: cannot read its header", path);
    goto done;
  }
  info->width = (int)get_u16(h + 16);
  info->height = (int)get_u16(h + 18);
  info->flags = get_u32(h + 20);
  info->frames = (int)get_u16(h + 24);
  info->first_frame = (int)get_u16(h + 26);
  for (int c = 0; c < 3; c++)
    info->reflectivity[c] = get_f32(h + 32 + 4 * c);
  info->bump_scale = get_f32(h + 48);
  info->format = (int)get_u32(h + 52);
  info->mip_count = h[56];
  info->low_res_format = (int)get_u32(h + 57);
  info->low_res_width = h[61];
  info->low_res_height = h[62];
  info->depth = minor >= 2 ? (int)get_u16(h + 63) : 1;
  snprintf(info->format_name, sizeof info->format_name, "%s",
           info->format >= 0 && info->format < VTF_FORMAT_COUNT ? vtf_formats[info->format].name
                                                                 : "unknown");
  if (info->width == 0 || info->height == 0) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF of %d x %d texels", path, info->width,
                  info->height);
    goto done;
  }

  /* Where the low-resolution and image data start: after the header, or
   * where 7.3+'s dictionary says. */
  uint64_t low_at = header_size, image_at = 0, kvd_at = 0;
  const int has_low = info->low_res_format >= 0 && info->low_res_format < VTF_FORMAT_COUNT &&
                      info->low_res_width > 0 && info->low_res_height > 0;
  const uint64_t low_bytes =
      has_low ? level_bytes(info->low_res_format, (uint64_t)info->low_res_width,
                            (uint64_t)info->low_res_height, 1)
              : 0;
  if (!has_low)
    info->low_res_format = -1;
  int found_image = 0, found_low = 0;
  if (minor >= 3) {
    const uint32_t n = get_u32(h + 68);
    if (n > MAX_RESOURCES || (uint64_t)HEADER_BYTES + (uint64_t)RESOURCE_BYTES * n > header_size) {
      st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF resource count %u does not fit its header",
                    path, n);
      goto done;
    }
    info->resource_count = (int)n;
    for (uint32_t r = 0; r < n; r++) {
      const unsigned char *e = h + HEADER_BYTES + RESOURCE_BYTES * r;
      const uint32_t id = get_u32(e) & 0x00ffffffu, data = get_u32(e + 4);
      const int inline_data = (e[3] & RSRC_NO_DATA_CHUNK) != 0;
      if (id == RSRC_LOW_RES)
        low_at = data, found_low = 1;
      else if (id == RSRC_IMAGE)
        image_at = data, found_image = 1;
      else if (id == RSRC_KVD && !inline_data)
        kvd_at = data;
    }
    if (!found_image) {
      st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF without an image resource", path);
      goto done;
    }
    if (!found_low && has_low) {
      st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF without its low-resolution resource", path);
      goto done;
    }
  } else {
    image_at = low_at + low_bytes;
  }

  /* The image data: every level of every frame and face. */
  const int faces = !(info->flags & BB_VTF_FLAG_ENVMAP)        ? 1
                    : (minor < 5 && info->first_frame != 0xffff) ? 7
                                                                 : 6;
  uint64_t data = 0;
  uint64_t w = (uint64_t)info->width, hh = (uint64_t)info->height,
           d = (uint64_t)(info->depth > 0 ? info->depth : 1);
  for (int k = 0; k < info->mip_count; k++) {
    data += level_bytes(info->format, w, hh, d);
    w = w > 1 ? w / 2 : 1, hh = hh > 1 ? hh / 2 : 1, d = d > 1 ? d / 2 : 1;
  }
  if (level_bytes(info->format, 1, 1, 1) == 0) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: unknown VTF image format %d", path, info->format);
    goto done;
  }
  /* One frame's levels fit 64 bits (65535^3 x 16 x 8/7 < 2^53), their
   * product with frames x faces may not: 32768^3 x 16 x 32768 frames
   * wraps to 0 and would pass the check below. Past the file's size it
   * is truncated, whatever the product. */
  const uint64_t copies = (uint64_t)(info->frames > 0 ? info->frames : 1) * (uint64_t)faces;
  if (data > file_size / copies) {
    st = bb__fail(err, BB_ERR_FORMAT,
                  "%s: truncated VTF: its header declares %llu bytes of image data a frame "
                  "x %llu frames and faces, the file has %llu bytes",
                  path, (unsigned long long)data, (unsigned long long)copies,
                  (unsigned long long)file_size);
    goto done;
  }
  data *= copies;
  info->data_size = (long)data;
  /* Each part said where it lies: the low-resolution image and the image
   * data are checked apart (a low-resolution resource past the end once
   * gave "needs 3636 bytes, the file has 3636"). */
  if (has_low && low_at + low_bytes > file_size) {
    st = bb__fail(err, BB_ERR_FORMAT,
                  "%s: truncated VTF: its low-resolution image (%llu bytes at offset %llu) "
                  "ends past the end of the file (%llu bytes)",
                  path, (unsigned long long)low_bytes, (unsigned long long)low_at,
                  (unsigned long long)file_size);
    goto done;
  }
  if (image_at > file_size || data > file_size - image_at) {
    st = bb__fail(err, BB_ERR_FORMAT,
                  "%s: truncated VTF: its image data (%llu bytes at offset %llu) ends past "
                  "the end of the file (%llu bytes)",
                  path, (unsigned long long)data, (unsigned long long)image_at,
                  (unsigned long long)file_size);
    goto done;
  }

  if (image_offset)
    *image_offset = image_at;

  /* Provenance: a KVD chunk, { u32 size, text }, that bumpbake wrote. */
  if (kvd_at) {
    unsigned char size_bytes[4];
    if (kvd_at + 4 > file_size || read_at(fd, size_bytes, 4, (off_t)kvd_at) != 0) {
      st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF KVD resource past the end of the file", path);
      goto done;
    }
    const uint32_t size = get_u32(size_bytes);
    if (size > (1u << 20) || kvd_at + 4 + size > file_size) {
      st = bb__fail(err, BB_ERR_FORMAT, "%s: VTF KVD resource of %u bytes does not fit", path,
                    size);
      goto done;
    }
    char *text = malloc((size_t)size + 1);
    if (!text) {
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
      goto done;
    }
    if (read_at(fd, text, size, (off_t)(kvd_at + 4)) != 0) {
      free(text);
      st = bb__fail(err, BB_ERR_IO, "%s: cannot read its KVD resource", path);
      goto done;
    }
    info->description = kvd_description(text, size);
    free(text);
  }
done:
  if (st != BB_OK)
    bb__vtf_info_free(info);
  return st;
}

bb_status bb__vtf_read_info(const char *path, bb_vtf_info *info, bb_error *err) {
  if (!info)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__vtf_read_info: info is NULL");
  memset(info, 0, sizeof *info);
  if (!path)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb__vtf_read_info: path is NULL");
  int fd;
  bb_status st = bb__input_open(path, &fd, err);
  if (st != BB_OK)
    return st;
  st = bb__vtf_read_header(fd, path, info, NULL, err);
  close(fd);
  return st;
}

const char *bb__vtf_flag_name(int bit) {
  /* Source SDK 2013, public/vtf/vtf.h, CompiledVtfFlags. */
  static const char *const names[32] = {
      "POINTSAMPLE", "TRILINEAR",   "CLAMPS",      "CLAMPT",         "ANISOTROPIC",
      "HINT_DXT5",   "SRGB",        "NORMAL",      "NOMIP",          "NOLOD",
      "ALL_MIPS",    "PROCEDURAL",  "ONEBITALPHA", "EIGHTBITALPHA",  "ENVMAP",
      "RENDERTARGET", "DEPTHRENDERTARGET", "NODEBUGOVERRIDE", "SINGLECOPY", "PRE_SRGB",
      NULL,          NULL,          NULL,          "NODEPTHBUFFER",  NULL,
      "CLAMPU",      "VERTEXTEXTURE", "SSBUMP",    NULL,             "BORDER",
      NULL,          NULL};
  return bit >= 0 && bit < 32 ? names[bit] : NULL;
}
