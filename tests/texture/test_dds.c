/* test_dds.c: DDS textures read back by bb_image_read (bumpbake's DDS
 * reader, dds_read.c; OpenImageIO 2.4.7's crashes on hostile headers):
 * every format, every mip level's size, pixels within the block codec's
 * error of the uncompressed map, BC5 normal maps' z, the header's fields,
 * usage errors and thread-count determinism. The decoded blocks are checked
 * against the tests' own exact decoder (texture_oracle.h).
 *
 * The bounds are per format, in 8-bit code units against the float map
 * (normal maps as 0.5 + 0.5 N), over the goldens' maps (rock06_32, noise16,
 * bricks_clamp) and every mip level; measured values in comments, the
 * asserted bound a little above the worst (tools/bench_blocks.sh measures
 * the 1024 x 1024 rock06 maps). */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/oiio.h"
#include "bumpbake.h"
#include "texture/texture_oracle.h"
#include "scratch_dir.h"
#include "file_bytes.h"
#include "image/image_write.h"
#include "texture/texture.h"
#include "texture/dds.h" /* bb__dds_read_info */

static const char *golden(const char *name) {
  static char path[512];
  const char *fixtures = getenv("BB_FIXTURES");
  snprintf(path, sizeof path, "%s/goldens/%s", fixtures ? fixtures : "fixtures", name);
  return path;
}

static bb_image read_golden(const char *name) {
  bb_image img = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_read(golden(name), &img, NULL, &err), BB_OK, "%s", err.message);
  return img;
}

/* Worst and rms error (8-bit codes) of decoded against ref's channels, each
 * decoded channel k < channels against ref channel k (0 for a grey ref). */
typedef struct errors {
  double max, rms, z_max, angle_max;
} errors;

static errors measure(const bb_image *ref, const bb_image *dec, int channels, int normal) {
  errors e = {0, 0, 0, 0};
  double se = 0;
  size_t n = 0;
  for (size_t i = 0; i < (size_t)ref->width * (size_t)ref->height; i++) {
    const float *r = ref->pixels + i * (size_t)ref->channels;
    const float *d = dec->pixels + i * (size_t)dec->channels;
    for (int k = 0; k < channels; k++) {
      double want = r[ref->channels == 1 ? 0 : k];
      want = normal ? 0.5 + 0.5 * want : want;
      want = want < 0 ? 0 : want > 1 ? 1 : want;
      const double err = fabs((double)d[k] - want) * 255.0;
      se += err * err;
      n++;
      e.max = err > e.max ? err : e.max;
    }
    if (normal && dec->channels >= 3) {
      const double ez = fabs((double)d[2] - (0.5 + 0.5 * (double)r[2])) * 255.0;
      e.z_max = ez > e.z_max ? ez : e.z_max;
      double v[3], len = 0, dot = 0;
      for (int k = 0; k < 3; k++)
        v[k] = 2.0 * (double)d[k] - 1.0, len += v[k] * v[k];
      for (int k = 0; k < 3; k++)
        dot += v[k] / sqrt(len) * (double)r[k];
      const double a = acos(dot > 1 ? 1 : dot) * 180.0 / 3.14159265358979;
      e.angle_max = a > e.angle_max ? a : e.angle_max;
    }
  }
  e.rms = sqrt(se / (double)n);
  return e;
}

typedef struct round_trip {
  const char *golden;
  bb_map_kind map;
  bb_texture_format format;
  int channels_read;  /* channels the reader hands back */
  int compare;        /* channels compared */
  double max_bound;   /* worst error over all levels, codes */
  double rms_bound;   /* rms error of level 0, codes */
} round_trip;

/* Measured (bumpbake's codec, exact decoder; 2026-12-07): worst error
 * over every level / rms of level 0, in codes; the bounds sit ~10% above.
 * These goldens are small (128 x 128 for rock06 at scale 32) and rough,
 * so a 4 x 4 block spans several features: BC1's one line through colour
 * space cannot follow three independent ssbump channels (rms 13 codes),
 * where the 1024 x 1024 bake of tools/bench_blocks.sh loses ~3. The codec
 * fits the squared error: against libsquish's cluster fit, before it,
 * every rms is lower or equal and some worst errors higher (ao BC1 28.9
 * against 25.5). */
static const round_trip cases[] = {
    /* BC1, 5:6:5 end points, 4 colours a block: 80.4 / 8.14, 123.1 / 13.15,
     * 28.9 / 2.95 (grey ao, R, G and B compared), 125.5 / 12.61. */
    {"rock06_32_normal.exr", BB_MAP_NORMAL, BB_TEXTURE_FORMAT_BC1, 3, 3, 90, 9.0},
    {"rock06_32_ssbump.exr", BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC1, 3, 3, 136, 14.5},
    {"rock06_32_ao.exr", BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BC1, 3, 3, 32, 3.3},
    {"noise16_ssbump.exr", BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC1, 3, 3, 138, 14.0},
    /* BC3, BC1's colour (4-colour mode) and a BC4 alpha block: 123.1 /
     * 13.16 (opaque, so as BC1), 111.6 / 15.38 (4 directions, the 4th in
     * alpha). */
    {"rock06_32_ssbump.exr", BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC3, 4, 3, 136, 14.5},
    {"bricks_clamp_ssbump.exr", BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC3, 4, 4, 123, 17.0},
    /* BC4, 8-bit end points and 8 steps: 10.0 / 1.28, 5.8 / 0.79. */
    {"rock06_32_ao.exr", BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BC4, 1, 1, 11, 1.45},
    {"noise16_ao.exr", BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BC4, 1, 1, 6.5, 0.9},
    /* BC5, two BC4 blocks, x and y: 13.9 / 2.25, 11.8 / 1.87 (z below). */
    {"rock06_32_normal.exr", BB_MAP_NORMAL, BB_TEXTURE_FORMAT_BC5, 3, 2, 15.5, 2.5},
    {"noise16_normal.exr", BB_MAP_NORMAL, BB_TEXTURE_FORMAT_BC5, 3, 2, 13, 2.1},
    /* RGBA8, rounding alone: 0.5 / 0.28. */
    {"rock06_32_ssbump.exr", BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_RGBA8, 4, 3, 0.5001, 0.3},
    {"rock06_32_normal.exr", BB_MAP_NORMAL, BB_TEXTURE_FORMAT_RGBA8, 4, 3, 0.5001, 0.3},
};

Test(dds, round_trip_through_the_reader) {
  scratch_dir_make("bb_dds");
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    const round_trip *t = &cases[c];
    bb_image img = read_golden(t->golden);
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.format = t->format;
    o.map = t->map;
    char path[160];
    snprintf(path, sizeof path, "%s/%zu.dds", scratch_dir, c);
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
    bb_image *chain = NULL;
    int count = 0;
    cr_assert_eq(bb_mip_chain(&img,
                              t->map == BB_MAP_NORMAL ? BB_MIP_RENORMALIZE
                                                              : BB_MIP_AVERAGE,
                              &chain, &count, &err),
                 BB_OK);
    double worst = 0, worst_z = 0;
    for (int k = 0; k < count; k++) {
      bb_image dec = {0};
      int levels = 0;
      cr_assert_eq(bb__image_read_mip(path, k, &dec, NULL, &levels, &err), BB_OK,
                   "%s level %d: %s", t->golden, k, err.message);
      cr_assert_eq(levels, count, "%s: %d levels in the file, %d in the chain", t->golden,
                   levels, count);
      cr_assert_eq(dec.width, chain[k].width, "%s level %d width", t->golden, k);
      cr_assert_eq(dec.height, chain[k].height, "%s level %d height", t->golden, k);
      cr_assert_eq(dec.channels, t->channels_read, "%s: %d channels read", t->golden,
                   dec.channels);
      errors e = measure(&chain[k], &dec, t->compare, t->map == BB_MAP_NORMAL);
      if (k == 0)
        cr_expect_leq(e.rms, t->rms_bound, "%s %s: rms %.2f codes", t->golden,
                      bb__texture_format_name(t->format), e.rms);
      worst = e.max > worst ? e.max : worst;
      worst_z = e.z_max > worst_z ? e.z_max : worst_z;
      bb_image_free(&dec);
    }
    cr_expect_leq(worst, t->max_bound, "%s %s: max %.2f codes", t->golden,
                  bb__texture_format_name(t->format), worst);
    if (t->format == BB_TEXTURE_FORMAT_BC5)
      /* z = sqrt(1 - x^2 - y^2) magnifies x's and y's errors by |x|/z where
       * the surface is steep: measured 34.1 codes (rock06_32, the steepest)
       * and 9.5 (noise16). */
      cr_expect_leq(worst_z, 38.0, "%s: z rebuilt %.2f codes off", t->golden, worst_z);
    bb_mip_chain_free(chain, count);
    bb_image_free(&img);
  }
  scratch_dir_remove();
}

static uint32_t u32_at(const unsigned char *p) {
  return oracle_u32(p);
}

Test(dds, headers) {
  scratch_dir_make("bb_dds");
  bb_image img = read_golden("rock06_32_normal.exr");
  struct {
    bb_texture_format format;
    const char *fourcc; /* NULL: RGB masks */
    uint32_t pf_flags, dxgi;
    size_t top_bytes;
  } want[] = {
      {BB_TEXTURE_FORMAT_BC1, "DXT1", 0x4, 0, 32 * 32 * 8},
      {BB_TEXTURE_FORMAT_BC3, "DXT5", 0x4, 0, 32 * 32 * 16},
      {BB_TEXTURE_FORMAT_BC5, "ATI2", 0x80000004u, 0, 32 * 32 * 16},
      {BB_TEXTURE_FORMAT_RGBA8, NULL, 0x41, 0, 128 * 128 * 4},
      {BB_TEXTURE_FORMAT_RGBA16F, "DX10", 0x4, 10, 128 * 128 * 8},
      {BB_TEXTURE_FORMAT_RGBA32F, "DX10", 0x4, 2, 128 * 128 * 16},
  };
  for (size_t c = 0; c < sizeof want / sizeof want[0]; c++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.format = want[c].format;
    o.map = BB_MAP_NORMAL;
    char path[160];
    snprintf(path, sizeof path, "%s/h%zu.dds", scratch_dir, c);
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
    size_t size;
    unsigned char *f = file_bytes(path, &size);
    const int block = want[c].format <= BB_TEXTURE_FORMAT_BC5;
    const int dx10 = want[c].dxgi != 0;
    cr_assert_eq(memcmp(f, "DDS ", 4), 0);
    cr_assert_eq(u32_at(f + 4), 124);
    /* CAPS | HEIGHT | WIDTH | PIXELFORMAT | MIPMAPCOUNT, + LINEARSIZE or PITCH */
    cr_assert_eq(u32_at(f + 8), 0x1007u | 0x20000u | (block ? 0x80000u : 0x8u));
    cr_assert_eq(u32_at(f + 12), 128);
    cr_assert_eq(u32_at(f + 16), 128);
    cr_assert_eq(u32_at(f + 20), block ? want[c].top_bytes : want[c].top_bytes / 128);
    cr_assert_eq(u32_at(f + 28), 8, "8 levels, 128 down to 1");
    cr_assert_eq(u32_at(f + 76), 32);
    cr_assert_eq(u32_at(f + 80), want[c].pf_flags, "pixel format flags 0x%x", u32_at(f + 80));
    if (want[c].fourcc)
      cr_assert_eq(memcmp(f + 84, want[c].fourcc, 4), 0, "FourCC %.4s", (const char *)f + 84);
    else
      cr_assert(u32_at(f + 88) == 32 && u32_at(f + 92) == 0xff && u32_at(f + 96) == 0xff00 &&
                u32_at(f + 100) == 0xff0000 && u32_at(f + 104) == 0xff000000u);
    /* TEXTURE | COMPLEX | MIPMAP */
    cr_assert_eq(u32_at(f + 108), 0x1000u | 0x8u | 0x400000u);
    if (dx10) {
      cr_assert_eq(u32_at(f + 128), want[c].dxgi);
      cr_assert_eq(u32_at(f + 132), 3, "TEXTURE2D");
      cr_assert_eq(u32_at(f + 140), 1, "array size");
    }
    /* Every level, largest first, and nothing else. */
    size_t data = 0;
    for (int w = 128; w >= 1; w /= 2)
      data += block ? (size_t)((w + 3) / 4) * (size_t)((w + 3) / 4) * want[c].top_bytes /
                          (32 * 32)
                    : (size_t)w * (size_t)w * want[c].top_bytes / (128 * 128);
    cr_assert_eq(size, (dx10 ? 148 : 128) + data, "%zu bytes", size);
    free(f);
  }
  bb_image_free(&img);
  scratch_dir_remove();
}

/* binary16 to float, written from IEEE 754 (the test's own, not Imath's). */
static float half_to_float(unsigned h) {
  const int sign = (h >> 15) & 1, e = (h >> 10) & 31, m = h & 1023;
  double v = e == 0 ? ldexp(m, -24) : e == 31 ? (m ? NAN : INFINITY) : ldexp(1024 + m, e - 25);
  return (float)(sign ? -v : v);
}

Test(dds, float_formats_hold_the_values) {
  /* OpenImageIO (2.4, and its newest) reads no float DDS: the test reads the
   * levels itself, by the layout, and compares every texel. */
  scratch_dir_make("bb_dds");
  bb_image img = read_golden("noise16_ssbump.exr");
  bb_image *chain = NULL;
  int count = 0;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &chain, &count, NULL), BB_OK);
  for (int half = 0; half <= 1; half++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.format = half ? BB_TEXTURE_FORMAT_RGBA16F : BB_TEXTURE_FORMAT_RGBA32F;
    char path[160];
    snprintf(path, sizeof path, "%s/f%d.dds", scratch_dir, half);
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(path, &img, &o, &err), BB_OK, "%s", err.message);
    size_t size;
    unsigned char *f = file_bytes(path, &size);
    const unsigned char *p = f + 148;
    for (int k = 0; k < count; k++) {
      const bb_image *l = &chain[k];
      for (int i = 0; i < l->width * l->height; i++)
        for (int c = 0; c < 4; c++) {
          const float want = c < 3 ? l->pixels[3 * i + c] : 1.0f;
          float got;
          if (half) {
            got = half_to_float(oracle_u16(p));
            p += 2;
            /* nearest half: within half an ulp (2^-11 relative) */
            cr_assert_leq(fabsf(got - want), fabsf(want) * 0x1p-11f + 0x1p-25f,
                          "level %d texel %d: %g for %g", k, i, (double)got, (double)want);
          } else {
            uint32_t u = oracle_u32(p);
            memcpy(&got, &u, 4);
            p += 4;
            cr_assert_eq(got, want, "level %d texel %d", k, i);
          }
        }
    }
    cr_assert_eq((size_t)(p - f), size, "every level, nothing more");
    free(f);
  }
  bb_mip_chain_free(chain, count);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(dds, bc1_same_blocks_as_vtf_and_decoders_agree) {
  /* The DDS's BC1 level 0 and the VTF's DXT1 level 0 hold the same blocks,
   * and the reader's decoder and the test's own (both exact) give the same
   * texels, the same through either container. */
  scratch_dir_make("bb_dds");
  bb_image img = read_golden("rock06_32_ssbump.exr");
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = BB_MAP_SSBUMP;
  o.format = BB_TEXTURE_FORMAT_BC1;
  char dds[160], vtf[160];
  snprintf(dds, sizeof dds, "%s/s.dds", scratch_dir);
  snprintf(vtf, sizeof vtf, "%s/s.vtf", scratch_dir);
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(dds, &img, &o, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__texture_write(vtf, &img, &o, &err), BB_OK, "%s", err.message);
  size_t dsize, vsize;
  unsigned char *d = file_bytes(dds, &dsize), *v = file_bytes(vtf, &vsize);
  int w, h;
  size_t at = oracle_vtf_level_offset(v, vsize, 0, &w, &h);
  cr_assert(at > 0 && w == 128 && h == 128);
  cr_assert_eq(memcmp(d + 128, v + at, 32 * 32 * 8), 0, "same blocks");
  unsigned char *rgba = malloc(128 * 128 * 4);
  oracle_decode(ORACLE_BC1, v + at, 128, 128, rgba);
  bb_image dec = {0}, from_vtf = {0};
  cr_assert_eq(bb_image_read(dds, &dec, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_image_read(vtf, &from_vtf, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(dec.channels, 3, "no DDPF_ALPHAPIXELS: no alpha");
  int worst = 0;
  for (int i = 0; i < 128 * 128; i++)
    for (int c = 0; c < 3; c++) {
      const int diff = abs((int)lroundf(dec.pixels[3 * i + c] * 255.0f) - (int)rgba[4 * i + c]);
      worst = diff > worst ? diff : worst;
      cr_assert_eq(dec.pixels[3 * i + c], from_vtf.pixels[3 * i + c]);
    }
  cr_assert_eq(worst, 0, "the reader and the specification's exact decoding differ by %d",
               worst);
  bb_image_free(&dec);
  bb_image_free(&from_vtf);
  free(rgba);
  free(d);
  free(v);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(dds, same_bytes_for_any_thread_count) {
  scratch_dir_make("bb_dds");
  bb_image img = read_golden("rock06_32_normal.exr");
  unsigned char *first = NULL;
  size_t first_size = 0;
  for (int threads = 1; threads <= 3; threads++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.map = BB_MAP_NORMAL;
    o.format = BB_TEXTURE_FORMAT_BC1;
    o.threads = threads;
    char path[160];
    snprintf(path, sizeof path, "%s/t%d.dds", scratch_dir, threads);
    cr_assert_eq(bb__texture_write(path, &img, &o, NULL), BB_OK);
    size_t size;
    unsigned char *f = file_bytes(path, &size);
    if (!first) {
      first = f, first_size = size;
    } else {
      cr_assert(size == first_size && memcmp(f, first, size) == 0, "threads %d differ",
                threads);
      free(f);
    }
  }
  free(first);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(dds, non_power_of_two_mips) {
  /* 96 x 80: DDS takes any multiple of 4; levels halve down to 1 x 1
   * (48 x 40, ..., 3 x 2, 1 x 1), partial blocks below 4 texels. */
  scratch_dir_make("bb_dds");
  bb_image img = read_golden("noise16_ao.exr");
  char path[160];
  snprintf(path, sizeof path, "%s/n.dds", scratch_dir);
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(path, &img, NULL, &err), BB_OK, "%s", err.message);
  const int want[][2] = {{96, 80}, {48, 40}, {24, 20}, {12, 10}, {6, 5}, {3, 2}, {1, 1}};
  for (int k = 0; k < 7; k++) {
    bb_image dec = {0};
    int levels = 0;
    cr_assert_eq(bb__image_read_mip(path, k, &dec, NULL, &levels, &err), BB_OK, "%s",
                 err.message);
    cr_assert_eq(levels, 7);
    cr_assert(dec.width == want[k][0] && dec.height == want[k][1], "level %d: %d x %d", k,
              dec.width, dec.height);
    cr_assert_eq(dec.channels, 1, "default BC4 for one channel");
    bb_image_free(&dec);
  }
  bb_image_free(&img);
  scratch_dir_remove();
}

static void expect_refused(const char *name, const bb_image *img, bb_map_kind map,
                           bb_texture_format format, const char *words) {
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = map;
  o.format = format;
  char path[160];
  snprintf(path, sizeof path, "%s/%s", scratch_dir, name);
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(path, img, &o, &err), BB_ERR_ARGUMENT, "%s: %s", name,
               err.message);
  cr_assert_not_null(strstr(err.message, words), "%s: '%s' lacks '%s'", name, err.message,
                     words);
  cr_assert_eq(bb__texture_check(path, img->width, img->height, img->channels, &o, NULL),
               BB_ERR_ARGUMENT);
  cr_assert_eq(access(path, F_OK), -1, "%s: nothing written", name);
}

Test(dds, usage_errors) {
  scratch_dir_make("bb_dds");
  bb_image normal = read_golden("rock06_32_normal.exr");
  bb_image ssbump = read_golden("rock06_32_ssbump.exr");
  bb_image ao = read_golden("rock06_32_ao.exr");
  bb_image pit = read_golden("pit_rays64_ao.exr");
  expect_refused("a.dds", &ssbump, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC4,
                 "holds 1 channel");
  expect_refused("b.dds", &ssbump, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC5,
                 "holds at most 2 channels");
  expect_refused("c.dds", &normal, BB_MAP_NORMAL, BB_TEXTURE_FORMAT_BGR8,
                 "DDS has no format bgr888");
  expect_refused("d.dds", &ao, BB_MAP_NORMAL, BB_TEXTURE_FORMAT_DEFAULT,
                 "normal map needs 3 channels");
  expect_refused("e.dds", &pit, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BC4,
                 "multiples of 4");
  expect_refused("f.png", &ao, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_DEFAULT,
                 "not a texture file name");
  /* 65 x 65 is fine uncompressed. */
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_RGBA8;
  char path[160];
  snprintf(path, sizeof path, "%s/pit.dds", scratch_dir);
  cr_assert_eq(bb__texture_write(path, &pit, &o, NULL), BB_OK);
  /* NaN texels: BB_ERR_VALUE, nothing written. */
  ao.pixels[77] = NAN;
  snprintf(path, sizeof path, "%s/nan.dds", scratch_dir);
  cr_assert_eq(bb__texture_write(path, &ao, NULL, NULL), BB_ERR_VALUE);
  cr_assert_eq(access(path, F_OK), -1);
  bb_image_free(&normal);
  bb_image_free(&ssbump);
  bb_image_free(&ao);
  bb_image_free(&pit);
  scratch_dir_remove();
}

/* A normal map with an alpha to keep (renderbumpflat's coverage) is BC3 by
 * default, as in a VTF; BC5 would drop the alpha. */
Test(dds, a_normal_map_with_alpha_is_bc3) {
  scratch_dir_make("bb_dds");
  bb_image normal = read_golden("rock06_32_normal.exr");
  bb_image ao = read_golden("rock06_32_ao.exr");
  bb_image rgba;
  cr_assert_eq(bb_image_alloc(&rgba, normal.width, normal.height, 4, NULL), BB_OK);
  for (size_t i = 0; i < (size_t)normal.width * (size_t)normal.height; i++) {
    for (int c = 0; c < 3; c++)
      rgba.pixels[4 * i + (size_t)c] = normal.pixels[3 * i + (size_t)c];
    rgba.pixels[4 * i + 3] = ao.pixels[i];
  }
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = BB_MAP_NORMAL;
  char path[160];
  snprintf(path, sizeof path, "%s/rgba_normal.dds", scratch_dir);
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(path, &rgba, &o, &err), BB_OK, "%s", err.message);
  bb_dds_info d;
  cr_assert_eq(bb__dds_read_info(path, &d, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(d.fourcc, "DXT5");
  bb_image back = {0};
  cr_assert_eq(bb_image_read(path, &back, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(back.channels, 4);
  double worst = 0;
  for (size_t i = 0; i < (size_t)back.width * (size_t)back.height; i++)
    worst = fmax(worst, fabs(back.pixels[4 * i + 3] - ao.pixels[i]));
  cr_expect_lt(worst, 0.07, "alpha kept within BC3's error (worst %g)", worst);
  bb_image_free(&back);
  bb_image_free(&rgba);
  bb_image_free(&ao);
  bb_image_free(&normal);
}
