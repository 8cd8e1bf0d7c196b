/* test_texture_read.c: VTF and DDS files read back through bb_image_read
 * and friends (bumpbake's own readers; tests/texture/test_dds.c checks the DDS
 * bumpbake writes).
 *
 * - Every format and version bumpbake writes, with and without mips: each
 *   level read (bb__image_read_mip) against the tests' own decoding of the
 *   same bytes (texture_oracle.h, exact arithmetic): texel formats bit for
 *   bit (8-bit codes / 255, half floats), block formats too (the reader
 *   decodes blocks by the same exact rules).
 * - Channels: alpha read when the header's flags say the texture has it.
 * - Hand-made hostile headers: one line naming the file, never a crash,
 *   sizes refused before anything is allocated (sparse files declaring
 *   4 Gi texels).
 * The round trip against the baked PNG, within block error, is in
 * tests/cli/test_cli_textures.c. */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include <criterion/criterion.h>

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "job/job_internal.h"
#include "bumpbake.h"
#include "texture/texture_oracle.h"
#include "scratch_dir.h"
#include "file_bytes.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "texture/vtf.h" /* bb__vtf_read_info */

static void make_scratch_dir(void) { scratch_dir_make("bb_texread"); }

TestSuite(texture_read, .init = make_scratch_dir, .fini = scratch_dir_remove);

static void put_u16(unsigned char *p, unsigned v) {
  p[0] = (unsigned char)(v & 0xff);
  p[1] = (unsigned char)(v >> 8);
}

static void put_u32(unsigned char *p, uint32_t v) {
  for (int k = 0; k < 4; k++)
    p[k] = (unsigned char)(v >> (8 * k));
}

/* Waves, different in each channel, in [0.05, 0.95]. */
static bb_image pattern(int w, int h, int channels) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < channels; c++) {
        const double u = (x + 0.5) / w, v = (y + 0.5) / h;
        img.pixels[((size_t)y * (size_t)w + (size_t)x) * (size_t)channels + (size_t)c] =
            (float)(0.5 + 0.45 * sin(6.28 * (u * (c + 1) + v * (2 - c % 2))));
      }
  return img;
}

/* binary16 to float, from IEEE 754 (the test's own, not Imath's). */
static float half_to_float(unsigned h) {
  const int sign = (h >> 15) & 1, e = (h >> 10) & 31, m = h & 1023;
  double v = e == 0 ? ldexp(m, -24) : e == 31 ? (m ? NAN : INFINITY) : ldexp(1024 + m, e - 25);
  return (float)(sign ? -v : v);
}

/* Texel i channel c of a level of Valve format `code` at p, as the oracle
 * reads it; rgba: the level's block decoding (block formats). */
static float oracle_texel(int code, const unsigned char *p, const unsigned char *rgba, size_t i,
                          int c) {
  switch (code) {
  case 3: return (float)p[3 * i + (size_t)(2 - c)] / 255.0f;
  case 12: return (float)p[4 * i + (size_t)(c < 3 ? 2 - c : 3)] / 255.0f;
  case 24: return half_to_float(oracle_u16(p + 8 * i + 2 * (size_t)c));
  default: return (float)rgba[4 * i + (size_t)c] / 255.0f;
  }
}

typedef struct vtf_case {
  bb_texture_format format;
  int code;      /* Valve's */
  int channels;  /* of the image written, and so read */
  double bound;  /* against the oracle, in codes (floats: exact) */
} vtf_case;

static const vtf_case VTF_CASES[] = {
    {BB_TEXTURE_FORMAT_BC1, 13, 3, 0},        {BB_TEXTURE_FORMAT_BC3, 15, 3, 0},
    {BB_TEXTURE_FORMAT_BC3, 15, 4, 0},        {BB_TEXTURE_FORMAT_BGR8, 3, 3, 0},
    {BB_TEXTURE_FORMAT_BGRA8, 12, 3, 0},      {BB_TEXTURE_FORMAT_BGRA8, 12, 4, 0},
    {BB_TEXTURE_FORMAT_RGBA16F, 24, 3, 0},    {BB_TEXTURE_FORMAT_RGBA16F, 24, 4, 0},
};

Test(texture_read, vtf_every_format_version_and_level) {
  for (size_t k = 0; k < sizeof VTF_CASES / sizeof VTF_CASES[0]; k++) {
    const vtf_case *t = &VTF_CASES[k];
    bb_image img = pattern(32, 16, t->channels);
    for (int version = 2; version <= 5; version++)
      for (int mips = 0; mips <= 1; mips++) {
        bb_texture_options o;
        bb_texture_options_init(&o);
        o.format = t->format;
        o.vtf_version = version;
        o.mips = mips;
        o.fast = 1;
        o.description = "key=value";
        const char *path = in_scratch_dir("t.vtf");
        bb_error err = {{0}};
        cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
        size_t size;
        unsigned char *file = file_bytes(path, &size);
        const int want_levels = mips ? 6 : 1; /* 32 x 16 down to 1 x 1 */
        for (int level = 0; level < want_levels; level++) {
          bb_image got;
          bb_image_info info;
          int levels = 0;
          cr_assert_eq(bb__image_read_mip(path, level, &got, &info, &levels, &err), BB_OK,
                       "format %d 7.%d mips %d level %d: %s", t->code, version, mips, level,
                       err.message);
          cr_assert_eq(levels, want_levels);
          int w, h;
          const size_t at = oracle_vtf_level_offset(file, size, level, &w, &h);
          cr_assert_neq(at, 0u);
          cr_assert(got.width == w && got.height == h && got.channels == t->channels,
                    "%d x %d x %d", got.width, got.height, got.channels);
          cr_assert_str_eq(info.format_name, "vtf");
          cr_assert_eq(info.alpha_channel, t->channels == 4 ? 3 : -1);
          cr_assert_eq(info.is_float, t->code == 24);
          /* 7.3 and up carry the provenance (and the texture settings). */
          cr_assert_eq(info.description != NULL && strstr(info.description, "key=value") != NULL,
                       version >= 3);
          unsigned char *rgba = malloc((size_t)w * (size_t)h * 4);
          if (t->code == 13 || t->code == 15)
            oracle_decode(t->code == 13 ? ORACLE_BC1 : ORACLE_BC3, file + at, w, h, rgba);
          for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            for (int c = 0; c < t->channels; c++) {
              const float want = oracle_texel(t->code, file + at, rgba, i, c);
              const float have = got.pixels[i * (size_t)t->channels + (size_t)c];
              cr_assert_leq(fabs((double)have - (double)want) * 255.0, t->bound + 1e-4,
                            "format %d 7.%d level %d texel %zu channel %d: %g, oracle %g",
                            t->code, version, level, i, c, (double)have, (double)want);
            }
          free(rgba);
          bb_image_free(&got);
          bb_image_info_free(&info);
        }
        /* A level past the last is an argument error, the count still told. */
        bb_image none;
        int levels = 0;
        cr_assert_eq(bb__image_read_mip(path, want_levels, &none, NULL, &levels, &err),
                     BB_ERR_ARGUMENT);
        cr_assert_eq(levels, want_levels);
        cr_assert_null(none.pixels);
        free(file);
      }
    bb_image_free(&img);
  }
}

Test(texture_read, vtf_header_agrees_with_the_pixels_and_channels_can_be_picked) {
  bb_image img = pattern(16, 16, 4);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_BGRA8;
  const char *path = in_scratch_dir("h.vtf");
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
  int w, h, c;
  bb_image_info info;
  cr_assert_eq(bb_image_read_info(path, &w, &h, &c, &info, &err), BB_OK, "%s", err.message);
  cr_assert(w == 16 && h == 16 && c == 4 && info.alpha_channel == 3 && info.bits_per_sample == 8);
  bb_image_info_free(&info);
  int frames = 0;
  cr_assert_eq(bb__image_frame_count(path, &frames, &err), BB_OK, "%s", err.message);
  cr_assert_eq(frames, 1);
  /* A height read by the channel rule: the alpha channel alone. */
  bb_image a;
  cr_assert_eq(bb__height_file_read(path, BB_CHANNEL_A, 0, NULL, NULL, &a, NULL, &err), BB_OK,
               "%s", err.message);
  cr_assert_eq(a.channels, 1);
  for (int i = 0; i < 256; i++)
    cr_assert_leq(fabsf(a.pixels[i] - img.pixels[4 * i + 3]), 0.5f / 255.0f + 1e-6f);
  bb_image_free(&a);
  bb_image_free(&img);
}

Test(texture_read, dds_with_a_dx10_header) {
  /* OpenImageIO 2.4 refuses these; bumpbake's own reader takes them. */
  bb_image img = pattern(16, 8, 3);
  bb_image *chain = NULL;
  int count = 0;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &chain, &count, NULL), BB_OK);
  for (int half = 0; half <= 1; half++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.format = half ? BB_TEXTURE_FORMAT_RGBA16F : BB_TEXTURE_FORMAT_RGBA32F;
    const char *path = in_scratch_dir(half ? "f16.dds" : "f32.dds");
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
    for (int level = 0; level < count; level++) {
      bb_image got;
      bb_image_info info;
      int levels = 0;
      cr_assert_eq(bb__image_read_mip(path, level, &got, &info, &levels, &err), BB_OK, "%s",
                   err.message);
      cr_assert_eq(levels, count);
      cr_assert_str_eq(info.format_name, "dds");
      cr_assert(info.is_float && info.bits_per_sample == (half ? 16 : 32));
      const bb_image *l = &chain[level];
      cr_assert(got.width == l->width && got.height == l->height && got.channels == 4);
      for (int i = 0; i < l->width * l->height; i++)
        for (int c = 0; c < 4; c++) {
          const float want = c < 3 ? l->pixels[3 * i + c] : 1.0f;
          const float have = got.pixels[4 * i + c];
          if (half)
            cr_assert_leq(fabsf(have - want), fabsf(want) * 0x1p-11f + 0x1p-25f);
          else
            cr_assert_eq(have, want, "level %d texel %d", level, i);
        }
      bb_image_free(&got);
      bb_image_info_free(&info);
    }
  }
  bb_mip_chain_free(chain, count);
  bb_image_free(&img);
}

/* ------------------------------------------------------ hostile headers */

/* Reading path fails with one line that names it (header and pixels). */
static void expect_refused(const char *path, const char *what) {
  bb_image img;
  bb_error err = {{0}};
  bb_status st = bb_image_read(path, &img, NULL, &err);
  cr_assert_neq(st, BB_OK, "%s: read", what);
  cr_assert_null(img.pixels);
  cr_assert_not_null(strstr(err.message, path), "%s: %s", what, err.message);
  cr_assert_null(strchr(err.message, '\n'), "%s: %s", what, err.message);
  int levels = 0;
  st = bb__image_read_mip(path, 0, &img, NULL, &levels, &err);
  cr_assert_neq(st, BB_OK, "%s: read_mip", what);
  cr_assert_not_null(strstr(err.message, path), "%s: %s", what, err.message);
}

/* A valid 16 x 16 BGR888 VTF of version 7.minor with mips, as bytes. */
static unsigned char *valid_vtf(int minor, size_t *size) {
  bb_image img = pattern(16, 16, 3);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_BGR8;
  o.vtf_version = minor;
  const char *path = in_scratch_dir("valid.vtf");
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
  return file_bytes(path, size);
}

Test(texture_read, hostile_vtf_headers) {
  size_t size;
  unsigned char *v2 = valid_vtf(2, &size);
  const unsigned char *base = v2;
  unsigned char *f = malloc(size);
  const char *path = in_scratch_dir("bad.vtf");
#define CASE(what, edit)                                                                       \
  do {                                                                                         \
    memcpy(f, base, size);                                                                     \
    edit;                                                                                      \
    file_bytes_write(path, f, size);                                                                      \
    expect_refused(path, what);                                                                \
  } while (0)
  CASE("unread format (P8)", put_u32(f + 52, 7));
  CASE("unknown format", put_u32(f + 52, 0x7fffffff));
  CASE("mip count past the chain", f[56] = 6);
  CASE("mip count 0", f[56] = 0);
  CASE("mip count 255", f[56] = 255);
  CASE("volume", f[63] = 2);
  CASE("zero width", f[16] = f[17] = 0);
  CASE("header size past the end", put_u32(f + 12, 0xfffffff0u));
  CASE("version 7.9", put_u32(f + 8, 9));
  CASE("65535 x 65535 RGBA32323232F", (f[16] = f[17] = f[18] = f[19] = 0xff, put_u32(f + 52, 29), f[56] = 1));
  CASE("64 frames", f[24] = 64);
  /* The last level (the largest, written last) cut short by one byte. */
  file_bytes_write(path, v2, size - 1);
  expect_refused(path, "truncated last level");
  file_bytes_write(path, v2, 40);
  expect_refused(path, "truncated header");
  file_bytes_write(path, (const unsigned char *)"not a texture at all, not at all", 33);
  expect_refused(path, "not a VTF");
  free(v2);
  free(f);

  /* 7.3+: the resource dictionary. */
  unsigned char *v3 = valid_vtf(3, &size);
  f = malloc(size);
  memcpy(f, v3, size);
  file_bytes_write(path, f, size);
  bb_image ok;
  bb_error err = {{0}};
  cr_assert_eq(bb_image_read(path, &ok, NULL, &err), BB_OK, "%s", err.message);
  bb_image_free(&ok);
  base = v3;
  CASE("resource count huge", put_u32(f + 68, 0xffffffffu));
  CASE("resource count 33", put_u32(f + 68, 33));
  CASE("image resource past the end", put_u32(f + 80 + 8 + 4, 0x7ffffff0u));
  CASE("image resource at the end", put_u32(f + 80 + 8 + 4, (uint32_t)size));
  CASE("no image resource", put_u32(f + 80 + 8, 0x31));
  CASE("low-res resource past the end", put_u32(f + 80 + 4, 0xfffffff0u));
  free(v3);
  free(f);
#undef CASE
}

/* The header's declared data size is levels x frames x faces: 32768^3
 * RGBA32323232F texels (2^49 bytes a frame) x 32768 frames is 2^64, which
 * wrapped to 0 in 64 bits and passed the "truncated" check, so info
 * answered for a 200-byte file declaring 16 EiB. */
Test(texture_read, vtf_declared_size_product_does_not_wrap) {
  size_t size;
  unsigned char *f = valid_vtf(2, &size);
  put_u16(f + 16, 32768);
  put_u16(f + 18, 32768);
  put_u16(f + 24, 32768); /* frames */
  put_u32(f + 52, 29);    /* RGBA32323232F */
  f[56] = 1;              /* one level */
  put_u16(f + 63, 32768); /* depth */
  const char *path = in_scratch_dir("wraps.vtf");
  file_bytes_write(path, f, size);
  bb_vtf_info info;
  bb_error err = {{0}};
  cr_assert_eq(bb__vtf_read_info(path, &info, &err), BB_ERR_FORMAT, "%s", err.message);
  cr_assert_not_null(strstr(err.message, "truncated VTF"), "%s", err.message);
  cr_assert_not_null(strstr(err.message, path), "%s", err.message);
  cr_assert_null(strchr(err.message, '\n'), "%s", err.message);
  expect_refused(path, "declared size wrapping to 0");
  /* one frame of the same is refused too, by the plain check */
  put_u16(f + 24, 1);
  file_bytes_write(path, f, size);
  cr_assert_eq(bb__vtf_read_info(path, &info, &err), BB_ERR_FORMAT, "%s", err.message);
  free(f);
}

Test(texture_read, hostile_sizes_are_refused_before_allocating) {
  /* Headers declaring 65535 x 65535 (VTF, I8) and 65536 x 65536 (DDS, R8)
   * over sparse files long enough to hold them: the texel limit refuses
   * them before any byte is read or allocated. */
  unsigned char h[148];
  memset(h, 0, sizeof h);
  memcpy(h, "VTF", 4);
  put_u32(h + 4, 7);
  put_u32(h + 8, 2);
  put_u32(h + 12, 80);
  h[16] = h[17] = h[18] = h[19] = 0xff;
  put_u32(h + 52, 5); /* I8 */
  h[56] = 1;
  put_u32(h + 57, 0xffffffffu); /* no low-resolution image */
  h[63] = 1;
  const char *path = in_scratch_dir("huge.vtf");
  file_bytes_write(path, h, 80);
  cr_assert_eq(truncate(path, 80 + 65535LL * 65535LL), 0);
  expect_refused(path, "65535 x 65535 VTF");
  bb_image img;
  bb_error err = {{0}};
  cr_assert_eq(bb_image_read(path, &img, NULL, &err), BB_ERR_SIZE, "%s", err.message);
  cr_assert_not_null(strstr(err.message, "over the maximum"), "%s", err.message);

  memset(h, 0, sizeof h);
  memcpy(h, "DDS ", 4);
  put_u32(h + 4, 124);
  put_u32(h + 8, 0x1007);
  put_u32(h + 12, 65536);
  put_u32(h + 16, 65536);
  put_u32(h + 76, 32);
  put_u32(h + 80, 4);
  memcpy(h + 84, "DX10", 4);
  put_u32(h + 128, 61); /* R8_UNORM */
  put_u32(h + 132, 3);
  put_u32(h + 140, 1);
  path = in_scratch_dir("huge.dds");
  file_bytes_write(path, h, 148);
  cr_assert_eq(truncate(path, 148 + 65536LL * 65536LL), 0);
  cr_assert_eq(bb_image_read(path, &img, NULL, &err), BB_ERR_SIZE, "%s", err.message);
  cr_assert_not_null(strstr(err.message, "over the maximum"), "%s", err.message);
}

Test(texture_read, hostile_dx10_dds_headers) {
  bb_image img = pattern(16, 16, 3);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_RGBA16F;
  const char *valid = in_scratch_dir("valid.dds");
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(valid, &img, &o, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
  size_t size;
  unsigned char *v = file_bytes(valid, &size);
  unsigned char *f = malloc(size);
  const char *path = in_scratch_dir("bad.dds");
#define CASE(what, edit)                                                                       \
  do {                                                                                         \
    memcpy(f, v, size);                                                                        \
    edit;                                                                                      \
    file_bytes_write(path, f, size);                                                                      \
    expect_refused(path, what);                                                                \
  } while (0)
  CASE("width 2^31", put_u32(f + 16, 0x80000000u));
  CASE("height 0", put_u32(f + 12, 0));
  CASE("mip count 100", put_u32(f + 28, 100));
  CASE("mip count 2^32 - 1", put_u32(f + 28, 0xffffffffu));
  CASE("BC7 (not read)", put_u32(f + 128, 98));
  CASE("3D texture", put_u32(f + 132, 4));
  CASE("depth 2", put_u32(f + 24, 2));
  CASE("larger than the file", (put_u32(f + 12, 64), put_u32(f + 16, 64)));
#undef CASE
  file_bytes_write(path, v, size - 1);
  expect_refused(path, "truncated last level");
  file_bytes_write(path, v, 100);
  expect_refused(path, "truncated header");
  free(v);
  free(f);
}

Test(texture_read, legacy_dds_mip_count_past_its_size) {
  /* OpenImageIO's DDS reader walks every level before the one it seeks:
   * a 16 x 16 file declaring 65029 levels took minutes to count (the
   * fuzzer's find). bumpbake's own DDS reader refuses it in one line. */
  bb_image img = pattern(16, 16, 3);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_BC1;
  const char *path = in_scratch_dir("mips.dds");
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
  size_t size;
  unsigned char *f = file_bytes(path, &size);
  int levels = 0;
  bb_image level;
  cr_assert_eq(bb__image_read_mip(path, 4, &level, NULL, &levels, &err), BB_OK, "%s",
               err.message);
  cr_assert(levels == 5 && level.width == 1 && level.height == 1);
  bb_image_free(&level);
  put_u32(f + 28, 65029);
  file_bytes_write(path, f, size);
  expect_refused(path, "65029 mip levels");
  cr_assert_eq(bb_image_read_info(path, NULL, NULL, NULL, NULL, &err), BB_ERR_FORMAT);
  cr_assert_not_null(strstr(err.message, "65029 mip levels"), "%s", err.message);
  free(f);
}

/* A hand-made VTF of 8 x 8 BGR888 texels, 4 levels, `frames` frames, as
 * Valve's layout has it (levels smallest first, each holding every frame),
 * version 7.minor; 7.3+ with an inline CRC resource ahead of the image, as
 * vtex writes one. Texel i of frame f at level k holds B = 10 k + f, G =
 * i, R = 200. *size receives the file's size; malloc'd. */
static unsigned char *layered_vtf(int minor, int frames, size_t *size) {
  const int levels = 4;
  size_t data = 0;
  for (int k = 0; k < levels; k++)
    data += (size_t)(8 >> k) * (size_t)(8 >> k) * 3 * (size_t)frames;
  const size_t header = minor >= 3 ? 80 + 2 * 8 : 80;
  unsigned char *f = calloc(1, header + data);
  memcpy(f, "VTF", 4);
  put_u32(f + 4, 7);
  put_u32(f + 8, (uint32_t)minor);
  put_u32(f + 12, (uint32_t)header);
  f[16] = 8, f[18] = 8;
  f[24] = (unsigned char)frames;
  put_u32(f + 52, 3); /* BGR888 */
  f[56] = (unsigned char)levels;
  put_u32(f + 57, 0xffffffffu); /* no low-resolution image */
  f[63] = 1;
  if (minor >= 3) {
    put_u32(f + 68, 2);
    memcpy(f + 80, "CRC\x02", 4); /* inline: its value is the data field */
    put_u32(f + 84, 0x12345678u);
    put_u32(f + 88, 0x30);
    put_u32(f + 92, (uint32_t)header);
  }
  unsigned char *p = f + header;
  for (int k = levels - 1; k >= 0; k--)
    for (int fr = 0; fr < frames; fr++)
      for (int i = 0; i < (8 >> k) * (8 >> k); i++, p += 3)
        p[0] = (unsigned char)(10 * k + fr), p[1] = (unsigned char)i, p[2] = 200;
  *size = header + data;
  return f;
}

Test(texture_read, frame_0_of_every_level_of_an_animated_vtf) {
  const char *path = in_scratch_dir("frames.vtf");
  for (int minor = 2; minor <= 5; minor += 3)
    for (int frames = 1; frames <= 3; frames += 2) {
      size_t size;
      unsigned char *f = layered_vtf(minor, frames, &size);
      file_bytes_write(path, f, size);
      for (int k = 0; k < 4; k++) {
        bb_image img;
        int levels = 0;
        bb_error err = {{0}};
        cr_assert_eq(bb__image_read_mip(path, k, &img, NULL, &levels, &err), BB_OK,
                     "7.%d, %d frames, level %d: %s", minor, frames, k, err.message);
        cr_assert(levels == 4 && img.width == 8 >> k && img.channels == 3);
        for (int i = 0; i < img.width * img.height; i++) {
          cr_assert_float_eq(img.pixels[3 * i + 0], 200.0f / 255.0f, 1e-7f);
          cr_assert_float_eq(img.pixels[3 * i + 1], (float)i / 255.0f, 1e-7f);
          cr_assert_float_eq(img.pixels[3 * i + 2], (float)(10 * k) / 255.0f, 1e-7f,
                             "7.%d, %d frames, level %d texel %d: not frame 0's", minor,
                             frames, k, i);
        }
        bb_image_free(&img);
      }
      /* The last frame of the top level cut short: refused. */
      file_bytes_write(path, f, size - 1);
      expect_refused(path, "truncated last frame");
      free(f);
    }
}

/* A legacy DDS header (no DX10) of w x h, one level, pixel format flags,
 * FourCC or bit count and masks, then `data` bytes of a pattern. */
static unsigned char *legacy_dds(uint32_t w, uint32_t h, uint32_t pf_flags, const char *fourcc,
                                 uint32_t bits, const uint32_t masks[4], size_t data,
                                 size_t *size) {
  unsigned char *f = calloc(1, 128 + data);
  memcpy(f, "DDS ", 4);
  put_u32(f + 4, 124);
  put_u32(f + 8, 0x1007);
  put_u32(f + 12, h);
  put_u32(f + 16, w);
  put_u32(f + 76, 32);
  put_u32(f + 80, pf_flags);
  if (fourcc)
    memcpy(f + 84, fourcc, 4);
  put_u32(f + 88, bits);
  for (int c = 0; c < 4; c++)
    put_u32(f + 92 + 4 * c, masks ? masks[c] : 0);
  put_u32(f + 108, 0x1000);
  for (size_t i = 0; i < data; i++)
    f[128 + i] = (unsigned char)(i * 37 + 11);
  *size = 128 + data;
  return f;
}

Test(texture_read, legacy_dds_headers_openimageio_crashed_or_hung_on) {
  /* OpenImageIO 2.4.7 divided by zero on DXT2 and DXT4 (the fuzzer's find)
   * and looped for ever on a zero mask: bumpbake's reader takes DXT2/DXT4
   * as DXT3/DXT5 (premultiplied colour, read as stored) and refuses masks
   * it cannot use, in one line. */
  const char *path = in_scratch_dir("legacy.dds");
  size_t size;
  for (int k = 0; k < 2; k++) {
    unsigned char *f = legacy_dds(16, 16, 0x4, k ? "DXT4" : "DXT2", 0, NULL, 16 * 16, &size);
    file_bytes_write(path, f, size);
    bb_image img;
    bb_error err = {{0}};
    cr_assert_eq(bb_image_read(path, &img, NULL, &err), BB_OK, "%s", err.message);
    cr_assert(img.width == 16 && img.channels == 4);
    bb_image_free(&img);
    free(f);
  }
  const uint32_t zero[4] = {0, 0, 0, 0}, gap[4] = {0xf0f, 0xf0, 0xf000, 0},
                 rgb565[4] = {0xf800, 0x7e0, 0x1f, 0}, la[4] = {0xff, 0, 0, 0xff00};
  struct {
    const char *what;
    uint32_t flags, bits;
    const uint32_t *masks;
    int ok, channels;
  } cases[] = {
      {"RGB, zero masks", 0x40, 32, zero, 0, 0},
      {"RGB, a mask with a gap", 0x40, 16, gap, 0, 0},
      {"RGB, 7 bits", 0x40, 7, rgb565, 0, 0},
      {"RGB, 0 bits", 0x40, 0, rgb565, 0, 0},
      {"no format at all", 0, 0, zero, 0, 0},
      {"RGB 565", 0x40, 16, rgb565, 1, 3},
      {"luminance and alpha", 0x20001, 16, la, 1, 2},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    unsigned char *f =
        legacy_dds(16, 16, cases[k].flags, NULL, cases[k].bits, cases[k].masks, 16 * 16 * 4, &size);
    file_bytes_write(path, f, size);
    if (cases[k].ok) {
      bb_image img;
      bb_error err = {{0}};
      cr_assert_eq(bb_image_read(path, &img, NULL, &err), BB_OK, "%s: %s", cases[k].what,
                   err.message);
      cr_assert_eq(img.channels, cases[k].channels, "%s", cases[k].what);
      /* 565: the first texel's bytes 11, 48 as R 5, G 6, B 5 bits. */
      if (cases[k].bits == 16 && cases[k].channels == 3) {
        const unsigned v = 11u | 48u << 8;
        cr_assert_float_eq(img.pixels[0], (float)((v >> 11) & 31) / 31.0f, 1e-6f);
        cr_assert_float_eq(img.pixels[1], (float)((v >> 5) & 63) / 63.0f, 1e-6f);
        cr_assert_float_eq(img.pixels[2], (float)(v & 31) / 31.0f, 1e-6f);
      }
      bb_image_free(&img);
    } else {
      expect_refused(path, cases[k].what);
    }
    free(f);
  }
  unsigned char *f = legacy_dds(16, 16, 0x4, "BC7X", 0, NULL, 256, &size);
  file_bytes_write(path, f, size);
  expect_refused(path, "unknown FourCC");
  free(f);
  /* A DDS under another name is still read by bumpbake's reader. */
  f = legacy_dds(16, 16, 0x4, "DXT1", 0, NULL, 128, &size);
  path = in_scratch_dir("really_a_dds.png");
  file_bytes_write(path, f, size);
  bb_image img;
  bb_image_info info;
  bb_error err = {{0}};
  cr_assert_eq(bb_image_read(path, &img, &info, &err), BB_OK, "%s", err.message);
  cr_assert_str_eq(info.format_name, "dds");
  bb_image_free(&img);
  bb_image_info_free(&info);
  free(f);
}
