/* test_vtf.c: VTF files byte for byte against the published layout
 * (VTFLib's VTFFormat.h, the Valve Developer Community's page): header
 * fields, flags, format codes, mip count, low-resolution image, the size
 * and place of every level smallest first; DXT1 blocks decoded by the
 * test's own decoder; the header reader on good and hostile files; the
 * Source material. */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bumpbake.h"
#include "texture/blocks.h"
#include "texture/texture_oracle.h"
#include "scratch_dir.h"
#include "file_bytes.h"
#include "core/internal.h"
#include "image/image_write.h"
#include "texture/texture.h"
#include "texture/vtf.h" /* bb__vtf_read_info */

/* A map of w x h in [0, 1]: waves, different in each channel (normal 0);
 * a field of unit normals leaning with the waves (1); or waves whose
 * colours lie on one line through RGB, which BC1 holds up to its 5:6:5
 * steps (2). */
static bb_image pattern(int w, int h, int channels, int normal) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float *t = img.pixels + ((size_t)y * (size_t)w + (size_t)x) * (size_t)channels;
      const double u = (x + 0.5) / w, v = (y + 0.5) / h;
      if (normal == 2) {
        const double a = 0.5 + 0.45 * sin(6.28 * (u + 2 * v));
        for (int c = 0; c < channels; c++)
          t[c] = (float)(c == 0 ? a : c == 1 ? 1.0 - a : 0.2 + 0.6 * a);
      } else if (normal) {
        double n[3] = {0.4 * sin(6.28 * u), 0.3 * cos(6.28 * 2 * v), 1.0};
        const double len = sqrt(n[0] * n[0] + n[1] * n[1] + 1.0);
        for (int c = 0; c < 3; c++)
          t[c] = (float)(n[c] / len);
      } else {
        for (int c = 0; c < channels; c++)
          t[c] = (float)(0.5 + 0.45 * sin(6.28 * (u * (c + 1) + v * (2 - c % 2))));
      }
    }
  return img;
}

static float f32_at(const unsigned char *p) {
  uint32_t u = oracle_u32(p);
  float v;
  memcpy(&v, &u, sizeof v);
  return v;
}

/* vtex's reflectivity, computed here from the map as the writer should. */
static void expected_reflectivity(const bb_image *img, double out[3]) {
  out[0] = out[1] = out[2] = 0;
  const size_t n = (size_t)img->width * (size_t)img->height;
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) {
      double v = img->pixels[i * (size_t)img->channels + (size_t)(img->channels == 1 ? 0 : c)];
      v = v < 0 ? 0 : v > 1 ? 1 : v;
      out[c] += pow(round(v * 255.0) / 255.0, 2.2) / (double)n;
    }
}

Test(vtf, header_byte_for_byte_7_2) {
  scratch_dir_make("bb_vtf");
  bb_image img = pattern(64, 32, 3, 0);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = BB_MAP_SSBUMP;
  o.description = "bumpbake_version=x\nscale=64\n"; /* 7.2 has no room: left out */
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(in_scratch_dir("s.vtf"), &img, &o, &err), BB_OK, "%s", err.message);
  size_t size;
  unsigned char *f = file_bytes(in_scratch_dir("s.vtf"), &size);
  cr_assert_eq(memcmp(f, "VTF\0", 4), 0, "magic");
  cr_assert_eq(oracle_u32(f + 4), 7, "major version");
  cr_assert_eq(oracle_u32(f + 8), 2, "minor version");
  cr_assert_eq(oracle_u32(f + 12), 80, "header size");
  cr_assert_eq(oracle_u16(f + 16), 64, "width");
  cr_assert_eq(oracle_u16(f + 18), 32, "height");
  cr_assert_eq(oracle_u32(f + 20), 0x08000000u, "flags: SSBUMP exactly, got 0x%08x",
               oracle_u32(f + 20));
  cr_assert_eq(oracle_u16(f + 24), 1, "frames");
  cr_assert_eq(oracle_u16(f + 26), 0, "first frame");
  cr_assert_eq(oracle_u32(f + 28), 0, "padding");
  double refl[3];
  expected_reflectivity(&img, refl);
  for (int c = 0; c < 3; c++)
    cr_assert_float_eq(f32_at(f + 32 + 4 * c), refl[c], 1e-6, "reflectivity %d: %g vs %g", c,
                       (double)f32_at(f + 32 + 4 * c), refl[c]);
  cr_assert_eq(oracle_u32(f + 44), 0, "padding");
  cr_assert_eq(f32_at(f + 48), 1.0f, "bump scale");
  cr_assert_eq(oracle_u32(f + 52), 13, "DXT1");
  cr_assert_eq(f[56], 7, "mip count: 64 x 32 down to 1 x 1");
  cr_assert_eq(oracle_u32(f + 57), 13, "low-res DXT1");
  cr_assert_eq(f[61], 16, "low-res width");
  cr_assert_eq(f[62], 8, "low-res height");
  cr_assert_eq(oracle_u16(f + 63), 1, "depth");
  for (int k = 65; k < 80; k++)
    cr_assert_eq(f[k], 0, "byte %d of the padding", k);
  /* Low-res 16 x 8 DXT1 (64 bytes) after the header, then levels smallest
   * first: 1x1, 2x1, 4x2 (one block each), 8x4 (2), 16x8 (8), 32x16 (32),
   * 64x32 (128 blocks). */
  const size_t levels[] = {8, 8, 8, 16, 64, 256, 1024};
  size_t at = 80 + 64;
  for (int k = 0; k < 7; k++)
    at += levels[k];
  cr_assert_eq(size, at, "file of %zu bytes, layout says %zu", size, at);
  int w, h;
  cr_assert_eq(oracle_vtf_level_offset(f, size, 0, &w, &h), size - 1024);
  cr_assert(w == 64 && h == 32);
  cr_assert_eq(oracle_vtf_level_offset(f, size, 6, &w, &h), 80 + 64, "1 x 1 level first");
  cr_assert(w == 1 && h == 1);

  bb_vtf_info info;
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("s.vtf"), &info, &err), BB_OK, "%s", err.message);
  cr_assert(info.version_major == 7 && info.version_minor == 2 && info.header_size == 80);
  cr_assert(info.width == 64 && info.height == 32 && info.depth == 1 && info.frames == 1);
  cr_assert_eq(info.flags, BB_VTF_FLAG_SSBUMP);
  cr_assert_str_eq(info.format_name, "DXT1");
  cr_assert(info.mip_count == 7 && info.low_res_format == 13 && info.low_res_width == 16 &&
            info.low_res_height == 8);
  cr_assert_eq(info.data_size, (long)(size - 144));
  cr_assert_null(info.description, "7.2 holds no provenance");
  bb__vtf_info_free(&info);
  free(f);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(vtf, resources_7_3_hold_the_provenance) {
  scratch_dir_make("bb_vtf");
  bb_image img = pattern(32, 32, 3, 1);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = BB_MAP_NORMAL;
  o.vtf_version = 3;
  const char *provenance =
      "bumpbake_version=0.2.0\ncommand=bumpbake bake \"a b.png\" --scale 64\nscale=64\n";
  o.description = provenance;
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(in_scratch_dir("n.vtf"), &img, &o, &err), BB_OK, "%s", err.message);
  size_t size;
  unsigned char *f = file_bytes(in_scratch_dir("n.vtf"), &size);
  cr_assert_eq(oracle_u32(f + 8), 3);
  cr_assert_eq(oracle_u32(f + 12), 80 + 3 * 8, "header size with 3 resources");
  cr_assert_eq(oracle_u32(f + 20), 0x80u, "flags: NORMAL");
  cr_assert_eq(oracle_u32(f + 68), 3, "resource count");
  /* Sorted by id, as Source's binary search needs: low-res, image, KVD. */
  cr_assert_eq(oracle_u32(f + 80), 0x01);
  cr_assert_eq(oracle_u32(f + 88), 0x30);
  cr_assert_eq(oracle_u32(f + 96), 'K' | 'V' << 8 | 'D' << 16);
  const uint32_t low = oracle_u32(f + 84), image = oracle_u32(f + 92), kvd = oracle_u32(f + 100);
  cr_assert_eq(low, 104, "low-res right after the dictionary");
  cr_assert_eq(kvd, 104 + 128, "KVD after the 16 x 16 low-res image (16 blocks)");
  const uint32_t kvd_size = oracle_u32(f + kvd);
  cr_assert_eq(image, kvd + 4 + kvd_size, "image data last");
  size_t data = 0;
  for (int s = 32; s >= 1; s /= 2)
    data += (size_t)((s + 3) / 4) * (size_t)((s + 3) / 4) * 8;
  cr_assert_eq(size, image + data);
  const char *text = (const char *)f + kvd + 4;
  /* The chunk is the KeyValues text alone: no NUL inside its size (a NUL
   * counted in it made srctools' parser stop as at an unfinished file). */
  cr_assert_null(memchr(text, '\0', kvd_size), "a NUL inside the KVD chunk");
  cr_assert(kvd_size > 2 && memcmp(text + kvd_size - 2, "}\n", 2) == 0,
            "the chunk ends with the block's brace and a newline");
  cr_assert_not_null(strstr(text, "\"bumpbake\"\n{\n"), "%s", text);
  cr_assert_not_null(strstr(text, "\t\"command\" \"bumpbake bake \\\"a b.png\\\" --scale 64\"\n"),
                     "%s", text);
  bb_vtf_info info;
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("n.vtf"), &info, &err), BB_OK, "%s", err.message);
  cr_assert_eq(info.resource_count, 3);
  cr_assert_str_eq(info.description, provenance);
  bb__vtf_info_free(&info);
  free(f);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(vtf, dxt1_blocks_are_the_codecs_and_decode_close) {
  /* Level k's bytes are what the codec makes of the mip chain's level k,
   * and the test's own decoder finds the map in them within BC1's error. */
  scratch_dir_make("bb_vtf");
  bb_image img = pattern(64, 64, 3, 2);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = BB_MAP_SSBUMP;
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(in_scratch_dir("s.vtf"), &img, &o, &err), BB_OK, "%s", err.message);
  size_t size;
  unsigned char *f = file_bytes(in_scratch_dir("s.vtf"), &size);
  bb_image *chain = NULL;
  int count = 0;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &chain, &count, NULL), BB_OK);
  cr_assert_eq(f[56], count);
  for (int k = 0; k < count; k++) {
    int w, h;
    const size_t at = oracle_vtf_level_offset(f, size, k, &w, &h);
    cr_assert(at > 0 && w == chain[k].width && h == chain[k].height);
    float *rgba = malloc((size_t)w * (size_t)h * 4 * sizeof(float));
    for (int i = 0; i < w * h; i++) {
      for (int c = 0; c < 3; c++)
        rgba[4 * i + c] = chain[k].pixels[3 * i + c];
      rgba[4 * i + 3] = 1.0f;
    }
    const size_t bytes = (size_t)((w + 3) / 4) * (size_t)((h + 3) / 4) * 8;
    unsigned char *blocks = malloc(bytes);
    cr_assert_eq(bb__blocks_compress(rgba, w, h, BB__BLOCK_BC1, BB__FIT_BEST, 1, blocks, NULL), BB_OK);
    cr_assert_eq(memcmp(blocks, f + at, bytes), 0, "level %d: the codec's blocks", k);
    unsigned char *dec = malloc((size_t)w * (size_t)h * 4);
    oracle_decode(ORACLE_BC1, f + at, w, h, dec);
    double worst = 0;
    for (int i = 0; i < w * h; i++)
      for (int c = 0; c < 3; c++) {
        const double e = fabs(dec[4 * i + c] - 255.0 * rgba[4 * i + c]);
        worst = e > worst ? e : worst;
      }
    /* Colours on one line: what is left is a block's 4 steps along it,
     * up to a sixth of the wave's range over 4 texels; measured 16.3, 22.9,
     * 21.7, 7.8, then 1.5 (5:6:5 rounding) from level 0 down. A decoder
     * that swapped channels or read indices in another order would be off
     * by 60 codes and more. */
    cr_assert_leq(worst, 25.0, "level %d: %.1f codes off", k, worst);
    free(dec);
    free(blocks);
    free(rgba);
  }
  bb_mip_chain_free(chain, count);
  free(f);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(vtf, flags_from_the_map_and_the_caller) {
  scratch_dir_make("bb_vtf");
  bb_image rgb = pattern(16, 16, 3, 0), normal = pattern(16, 16, 3, 1),
           rgba = pattern(16, 16, 4, 0);
  const struct {
    const bb_image *img;
    bb_map_kind map;
    bb_texture_format format;
    int mips;
    uint32_t extra, want;
  } cases[] = {
      {&rgb, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_DEFAULT, 1, 0, 0x08000000u},
      {&normal, BB_MAP_NORMAL, BB_TEXTURE_FORMAT_DEFAULT, 1, 0, 0x00000080u},
      {&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_DEFAULT, 1, 0, 0},
      {&rgb, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_DEFAULT, 0, 0, 0x08000300u},
      {&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_DEFAULT, 1, 0x0000000cu, 0x0000000cu},
      {&rgba, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BGRA8, 1, 0, 0x00002000u},
      {&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BGRA8, 1, 0, 0},
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.map = cases[c].map;
    o.format = cases[c].format;
    o.mips = cases[c].mips;
    o.vtf_flags = cases[c].extra;
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(in_scratch_dir("f.vtf"), cases[c].img, &o, &err), BB_OK, "%s",
                 err.message);
    size_t size;
    unsigned char *f = file_bytes(in_scratch_dir("f.vtf"), &size);
    cr_assert_eq(oracle_u32(f + 20), cases[c].want, "case %zu: flags 0x%08x, want 0x%08x", c,
                 oracle_u32(f + 20), cases[c].want);
    cr_assert_eq(f[56], cases[c].mips ? 5 : 1, "case %zu: mip count", c);
    free(f);
  }
  bb_image_free(&rgb);
  bb_image_free(&normal);
  bb_image_free(&rgba);
  scratch_dir_remove();
}

/* Every kind string the commands, the job and Python write a texture of
 * takes its map from the kind's own facts (bb_map_kind_info); Valve's
 * composites and the kinds of no map are resolved as bb__texture_options_for
 * says, the caller's own flags kept. */
Test(vtf, the_map_of_every_output_kind) {
  const uint32_t N = BB_VTF_FLAG_NORMAL;
  const struct {
    const char *kind;
    bb_range range;
    bb_map_kind map;
    uint32_t added;
  } cases[] = {
      /* the maps a bake writes, by their names */
      {"normal", BB_RANGE_SIGNED, BB_MAP_NORMAL, 0},
      {"weights", BB_RANGE_UNIT, BB_MAP_WEIGHTS, 0},
      {"ssbump", BB_RANGE_UNIT, BB_MAP_SSBUMP, 0},
      {"ao", BB_RANGE_UNIT, BB_MAP_AO, 0},
      {"bent", BB_RANGE_SIGNED, BB_MAP_BENT, 0},
      {"filtered", BB_RANGE_UNIT, BB_MAP_FILTERED, 0},
      {"slope", BB_RANGE_UNIT, BB_MAP_SLOPE, 0},
      {"plain", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      /* Valve's height2ssbump: the map, and its alpha */
      {"ssbump+height", BB_RANGE_UNIT, BB_MAP_SSBUMP, 0},
      {"ssbump+ao", BB_RANGE_UNIT, BB_MAP_SSBUMP, 0},
      {"detail-ssbump+height", BB_RANGE_UNIT, BB_MAP_SSBUMP, 0},
      {"detail-ssbump+ao", BB_RANGE_UNIT, BB_MAP_SSBUMP, 0},
      {"detail-ssbump", BB_RANGE_UNIT, BB_MAP_SSBUMP, 0},
      /* normals packed into [0, 1] already: codes, flagged */
      {"normal+height", BB_RANGE_UNIT, BB_MAP_PLAIN, N},
      {"normal+ao", BB_RANGE_UNIT, BB_MAP_PLAIN, N},
      {"normal+coverage", BB_RANGE_UNIT, BB_MAP_PLAIN, N},
      {"normal", BB_RANGE_UNIT, BB_MAP_PLAIN, N},
      {"bent", BB_RANGE_UNIT, BB_MAP_PLAIN, N},
      {"normal+coverage", BB_RANGE_SIGNED, BB_MAP_NORMAL, 0},
      /* no map of their own: by their values */
      {"height", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"colour", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"render", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"comparison", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"sheet", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"diff", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"slope_lit", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"ssbumps", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"", BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {NULL, BB_RANGE_UNIT, BB_MAP_PLAIN, 0},
      {"colour", BB_RANGE_SIGNED, BB_MAP_NORMAL, 0},
      {NULL, BB_RANGE_SIGNED, BB_MAP_NORMAL, 0},
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.vtf_flags = 0x4u; /* the caller's: kept */
    bb__texture_options_for(&o, cases[c].kind, cases[c].range);
    cr_assert_eq(o.map, cases[c].map, "%s: map %s, want %s",
                 cases[c].kind ? cases[c].kind : "NULL", bb__map_kind_name(o.map),
                 bb__map_kind_name(cases[c].map));
    cr_assert_eq(o.vtf_flags, 0x4u | cases[c].added, "%s: flags 0x%x",
                 cases[c].kind ? cases[c].kind : "NULL", (unsigned)o.vtf_flags);
  }
  bb__texture_options_for(NULL, "normal", BB_RANGE_SIGNED); /* no options: nothing */
}

/* binary16 to float, from IEEE 754 (not Imath's). */
static float half_to_float(unsigned h) {
  const int e = (h >> 10) & 31, m = h & 1023;
  double v = e == 0 ? ldexp(m, -24) : ldexp(1024 + m, e - 25);
  return (float)((h >> 15) ? -v : v);
}

/* Valve's tools write DXT1 textures under 4 texels a side (1 x 1, 2 x 2,
 * 8 x 2) as one 4 x 4 block a level covering the smaller image, as every
 * chain's smallest mips are: written, and read back at their size. */
Test(vtf, dxt1_under_4_texels_is_one_padded_block_a_level) {
  scratch_dir_make("bb_vtf");
  const int sizes[][2] = {{1, 1}, {2, 2}, {8, 2}, {2, 16}};
  for (size_t i = 0; i < sizeof sizes / sizeof *sizes; i++) {
    const int w = sizes[i][0], h = sizes[i][1];
    bb_image img = pattern(w, h, 3, 2);
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.format = BB_TEXTURE_FORMAT_BC1;
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(in_scratch_dir("s.vtf"), &img, &o, &err), BB_OK, "%d x %d: %s", w, h,
                 err.message);
    size_t size;
    unsigned char *f = file_bytes(in_scratch_dir("s.vtf"), &size);
    /* Every level a whole number of blocks; the low-res image (the top
     * level itself, at most 16 x 16) too. */
    const size_t low = (size_t)((w + 3) / 4) * (size_t)((h + 3) / 4) * 8;
    int levels = 0;
    size_t data = 0;
    for (int a = w, b = h;; a = a > 1 ? a / 2 : 1, b = b > 1 ? b / 2 : 1) {
      data += (size_t)((a + 3) / 4) * (size_t)((b + 3) / 4) * 8;
      levels++;
      if (a == 1 && b == 1)
        break;
    }
    cr_assert_eq(f[56], levels, "%d x %d: mip count", w, h);
    cr_assert(f[61] == w && f[62] == h, "low-res size");
    cr_assert_eq(size, 80 + low + data, "%d x %d: header, low-res blocks, levels", w, h);
    free(f);
    bb_image back;
    cr_assert_eq(bb_image_read(in_scratch_dir("s.vtf"), &back, NULL, &err), BB_OK, "%s", err.message);
    cr_assert(back.width == w && back.height == h, "read %d x %d", back.width, back.height);
    for (size_t k = 0; k < (size_t)w * (size_t)h * 3; k++)
      cr_assert(fabsf(back.pixels[k] - img.pixels[k]) < 0.07f, "%d x %d texel value %zu", w, h,
                k);
    bb_image_free(&back);
    bb_image_free(&img);
  }
  scratch_dir_remove();
}

Test(vtf, texel_formats) {
  /* BGR888 and BGRA8888 in Valve's byte order; RGBA16161616F halves of
   * what the engine samples (normals as 0.5 + 0.5 N); DXT5's code. */
  scratch_dir_make("bb_vtf");
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 4, NULL), BB_OK);
  for (int i = 0; i < 16; i++) {
    img.pixels[4 * i + 0] = 0.2f;
    img.pixels[4 * i + 1] = 0.4f;
    img.pixels[4 * i + 2] = 0.6f;
    img.pixels[4 * i + 3] = 0.8f;
  }
  const struct {
    bb_texture_format format;
    int code;
    size_t top;
  } cases[] = {{BB_TEXTURE_FORMAT_BGRA8, 12, 64},
               {BB_TEXTURE_FORMAT_RGBA16F, 24, 128},
               {BB_TEXTURE_FORMAT_BC3, 15, 16}};
  for (size_t c = 0; c < 3; c++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.format = cases[c].format;
    o.mips = 0;
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(in_scratch_dir("t.vtf"), &img, &o, &err), BB_OK, "%s", err.message);
    size_t size;
    unsigned char *f = file_bytes(in_scratch_dir("t.vtf"), &size);
    cr_assert_eq(oracle_u32(f + 52), (uint32_t)cases[c].code);
    cr_assert_eq(size, 80 + 8 + cases[c].top, "header, 4 x 4 low-res DXT1, one level");
    const unsigned char *t = f + 88;
    if (cases[c].format == BB_TEXTURE_FORMAT_BGRA8)
      cr_assert(t[0] == 153 && t[1] == 102 && t[2] == 51 && t[3] == 204, "B G R A: %d %d %d %d",
                t[0], t[1], t[2], t[3]);
    if (cases[c].format == BB_TEXTURE_FORMAT_RGBA16F)
      for (int k = 0; k < 4; k++)
        cr_assert_float_eq(half_to_float(oracle_u16(t + 2 * k)), 0.2f * (float)(k + 1), 2e-4);
    free(f);
  }
  /* BGR888 of a normal map: 0.5 + 0.5 N in B, G, R order. */
  bb_image n;
  cr_assert_eq(bb_image_alloc(&n, 4, 4, 3, NULL), BB_OK);
  for (int i = 0; i < 16; i++)
    n.pixels[3 * i + 0] = 0.6f, n.pixels[3 * i + 1] = 0.0f, n.pixels[3 * i + 2] = 0.8f;
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_BGR8;
  o.map = BB_MAP_NORMAL;
  o.mips = 0;
  cr_assert_eq(bb__texture_write(in_scratch_dir("n.vtf"), &n, &o, NULL), BB_OK);
  size_t size;
  unsigned char *f = file_bytes(in_scratch_dir("n.vtf"), &size);
  cr_assert_eq(oracle_u32(f + 52), 3);
  /* B: 0.5f + 0.5f * 0.8f is 0.89999998f, 229.49999 codes, so 229; G: 0.5
   * exactly, rounded half up to 128; R: 0.8, 204. */
  cr_assert(f[88] == 229 && f[89] == 128 && f[90] == 204, "%d %d %d", f[88], f[89], f[90]);
  free(f);
  bb_image_free(&n);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(vtf, same_bytes_for_any_thread_count) {
  scratch_dir_make("bb_vtf");
  bb_image img = pattern(128, 64, 3, 0);
  unsigned char *first = NULL;
  size_t first_size = 0;
  for (int threads = 1; threads <= 4; threads++) {
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.map = BB_MAP_SSBUMP;
    o.threads = threads;
    cr_assert_eq(bb__texture_write(in_scratch_dir("d.vtf"), &img, &o, NULL), BB_OK);
    size_t size;
    unsigned char *f = file_bytes(in_scratch_dir("d.vtf"), &size);
    if (!first) {
      first = f, first_size = size;
      continue;
    }
    cr_assert(size == first_size && memcmp(f, first, size) == 0, "threads %d differ", threads);
    free(f);
  }
  free(first);
  bb_image_free(&img);
  scratch_dir_remove();
}

/* Samples where the 8-bit codes change and around them: every (k + 0.5)
 * / 255 and its float neighbours, the ends, past them, signed zeros,
 * subnormals, infinities, NaN. */
static size_t awkward_samples(float *v, size_t cap) {
  size_t n = 0;
  const float odd[] = {0.0f, -0.0f, 1.0f, -1.0f, 2.0f, 1e-45f, -1e-45f, 1e-38f,
                       INFINITY, -INFINITY, NAN, -NAN, 0.5f, 1.0000001f, 0.99999994f};
  for (size_t i = 0; i < sizeof odd / sizeof odd[0] && n < cap; i++)
    v[n++] = odd[i];
  for (int k = 0; k <= 256 && n + 3 <= cap; k++) {
    const float m = (float)((k + 0.5) / 255.0);
    v[n++] = nextafterf(m, -1.0f), v[n++] = m, v[n++] = nextafterf(m, 2.0f);
  }
  return n;
}

Test(vtf, texture_bytes_are_the_scalar_codes) {
  enum { CAP = 1024 };
  float v[CAP];
  size_t n = awkward_samples(v, CAP);
  for (uint32_t s = 7; n < CAP;) { /* and a spread over -0.5 .. 1.5 */
    s ^= s << 13, s ^= s >> 17, s ^= s << 5;
    v[n++] = (float)(s % 200000u) / 100000.0f - 0.5f;
  }
  for (int unit = 0; unit <= 1; unit++)
    for (size_t start = 0; start < 4; start++) { /* every tail length */
      unsigned char got[CAP];
      bb__texture_bytes(v + start, n - start, unit, got);
      for (size_t i = start; i < n; i++) {
        const unsigned char want = bb__texture_byte(unit ? 0.5f + 0.5f * v[i] : v[i]);
        cr_assert_eq(got[i - start], want, "sample %zu (%.9g, unit %d): %d, the scalar %d", i,
                     (double)v[i], unit, got[i - start], want);
      }
    }
}

/* The reflectivity as the writer once summed it, a texel at a time
 * through the codec's view (bb__texture_texels), each channel in texel
 * order: the header's floats must be these bits. */
static void texel_sum_reflectivity(const bb_image *img, int unit_vectors, float out[3]) {
  double table[256], sum[3] = {0, 0, 0};
  for (int i = 0; i < 256; i++)
    table[i] = pow(i / 255.0, 2.2);
  const size_t n = (size_t)img->width * (size_t)img->height;
  for (size_t i = 0; i < n; i++) {
    float t[4];
    bb__texture_texels(img, unit_vectors, i, 1, t);
    for (int c = 0; c < 3; c++) {
      double u = t[c] > 0.0f ? (double)t[c] : 0.0;
      u = u < 1.0 ? u : 1.0;
      sum[c] += table[(int)(u * 255.0 + 0.5)];
    }
  }
  for (int c = 0; c < 3; c++)
    out[c] = (float)(sum[c] / (double)n);
}

Test(vtf, reflectivity_is_the_texel_by_texel_sum_bit_for_bit) {
  scratch_dir_make("bb_vtf");
  const struct {
    int channels;
    bb_map_kind map;
  } cases[] = {{1, BB_MAP_PLAIN}, {2, BB_MAP_PLAIN}, {3, BB_MAP_SSBUMP},
               {4, BB_MAP_PLAIN}, {3, BB_MAP_NORMAL}, {4, BB_MAP_NORMAL}};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    const int ch = cases[k].channels;
    const int unit = bb_map_kind_get(cases[k].map)->unit_vectors;
    bb_image img = pattern(64, 32, ch, unit);
    /* Samples on and beside the codes' edges, and out of range (finite:
     * the mip chain refuses the rest), over a third of the map. */
    float odd[1024];
    const size_t m = awkward_samples(odd, 1024);
    for (size_t i = 0, j = 0; i < (size_t)64 * 32 * (size_t)ch; i += 3)
      if (isfinite(odd[j % m]))
        img.pixels[i] = odd[j++ % m];
      else
        j++;
    bb_texture_options o;
    bb_texture_options_init(&o);
    o.map = cases[k].map;
    bb_error err = {{0}};
    cr_assert_eq(bb__texture_write(in_scratch_dir("r.vtf"), &img, &o, &err), BB_OK, "%s",
                 err.message);
    size_t size;
    unsigned char *f = file_bytes(in_scratch_dir("r.vtf"), &size);
    float want[3];
    texel_sum_reflectivity(&img, unit, want);
    for (int c = 0; c < 3; c++) {
      const float got = f32_at(f + 32 + 4 * c);
      cr_assert_eq(memcmp(&got, &want[c], sizeof got), 0,
                   "%d channels, map %d, channel %d: %.9g, the texel sum %.9g", ch,
                   (int)cases[k].map, c, (double)got, (double)want[c]);
    }
    free(f);
    bb_image_free(&img);
  }
  scratch_dir_remove();
}

static void expect_refused(const bb_image *img, bb_map_kind map, bb_texture_format format,
                           int version, uint32_t flags, const char *words) {
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.map = map;
  o.format = format;
  o.vtf_version = version;
  o.vtf_flags = flags;
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(in_scratch_dir("bad.vtf"), img, &o, &err), BB_ERR_ARGUMENT, "%s",
               err.message);
  cr_assert_not_null(strstr(err.message, words), "'%s' lacks '%s'", err.message, words);
  cr_assert_eq(bb__texture_check(in_scratch_dir("bad.vtf"), img->width, img->height, img->channels, &o,
                                NULL),
               BB_ERR_ARGUMENT);
  cr_assert_eq(access(in_scratch_dir("bad.vtf"), F_OK), -1, "nothing written");
}

Test(vtf, usage_errors) {
  scratch_dir_make("bb_vtf");
  bb_image odd = pattern(96, 80, 3, 0), tiny = pattern(2, 2, 3, 0),
           rgba = pattern(16, 16, 4, 0), ao = pattern(16, 16, 1, 0),
           rgb = pattern(16, 16, 3, 0);
  expect_refused(&odd, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_DEFAULT, 2, 0,
                 "power of two on each side (resize to 128 x 64)");
  expect_refused(&odd, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BGR8, 2, 0, "power of two");
  bb_image six = pattern(8, 6, 3, 0);
  bb_texture_options dds;
  bb_texture_options_init(&dds);
  bb_error e6 = {{0}};
  cr_assert_eq(bb__texture_write(in_scratch_dir("six.dds"), &six, &dds, &e6), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(e6.message, "block compression (bc1) needs sides that are multiples "
                                        "of 4"),
                     "%s", e6.message);
  bb_image_free(&six);
  /* A VTF's formats by Valve's names, as a modder types them. */
  expect_refused(&rgba, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BC1, 2, 0,
                 "format dxt1 holds at most 3 channels");
  expect_refused(&rgba, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BGR8, 2, 0,
                 "format bgr888 holds at most 3 channels");
  expect_refused(&ao, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BC4, 2, 0, "VTF has no format bc4");
  expect_refused(&rgb, BB_MAP_NORMAL, BB_TEXTURE_FORMAT_BC5, 2, 0, "VTF has no format bc5");
  expect_refused(&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_RGBA32F, 2, 0,
                 "VTF has no format rgba32f");
  expect_refused(&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_DEFAULT, 6, 0, "7.6");
  expect_refused(&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_DEFAULT, 1, 0, "7.1");
  expect_refused(&rgb, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_DEFAULT, 2, BB_VTF_FLAG_ENVMAP,
                 "ENVMAP");
  /* Flags that would contradict the file: readers believe them. */
  expect_refused(&rgb, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_DEFAULT, 2,
                 BB_VTF_FLAG_EIGHTBITALPHA,
                 "the EIGHTBITALPHA flag (0x00002000) says the file has alpha, and the dxt1 "
                 "file of a 3-channel image has none");
  expect_refused(&rgb, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_BC3, 2,
                 BB_VTF_FLAG_EIGHTBITALPHA, "the dxt5 file of a 3-channel image has none");
  expect_refused(&rgb, BB_MAP_SSBUMP, BB_TEXTURE_FORMAT_DEFAULT, 2, BB_VTF_FLAG_NOMIP,
                 "the NOMIP flag (0x00000100) says the file has no mip chain, and it has one");
  expect_refused(&rgba, BB_MAP_PLAIN, BB_TEXTURE_FORMAT_BGRA8, 2, 0x1000u,
                 "ONEBITALPHA flag (0x00001000) says the file has 1-bit alpha, and the "
                 "bgra8888 file has 8-bit alpha");
  /* 2 x 2 is fine uncompressed, and so is one channel in DXT1 (grey). A
   * DXT1 VTF of 1 x 1, 2 x 2, 8 x 2 is one padded block a level (as the
   * smallest mips are). */
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.format = BB_TEXTURE_FORMAT_BGR8;
  cr_assert_eq(bb__texture_write(in_scratch_dir("tiny.vtf"), &tiny, &o, NULL), BB_OK);
  cr_assert_eq(bb__texture_write(in_scratch_dir("ao.vtf"), &ao, NULL, NULL), BB_OK);
  bb_texture_format fmt;
  cr_assert_eq(bb__texture_format_parse("DXT5", &fmt, NULL), BB_OK);
  cr_assert_eq(fmt, BB_TEXTURE_FORMAT_BC3);
  cr_assert_eq(bb__texture_format_parse("rgba16161616f", &fmt, NULL), BB_OK);
  cr_assert_eq(fmt, BB_TEXTURE_FORMAT_RGBA16F);
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_format_parse("dxt9", &fmt, &err), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(err.message, "bc1"), "%s", err.message);
  cr_assert(bb__path_is_texture_format("a/B.VTF") && bb__path_is_texture_format("x.dds") &&
            !bb__path_is_texture_format("x.vtf.png") && !bb__path_is_texture_format("vtf"));
  bb_image_free(&odd);
  bb_image_free(&tiny);
  bb_image_free(&rgba);
  bb_image_free(&ao);
  bb_image_free(&rgb);
  scratch_dir_remove();
}

Test(vtf, read_info_refuses_broken_files) {
  scratch_dir_make("bb_vtf");
  bb_image img = pattern(32, 32, 3, 0);
  bb_texture_options o;
  bb_texture_options_init(&o);
  o.vtf_version = 4;
  o.description = "a=b\n";
  cr_assert_eq(bb__texture_write(in_scratch_dir("g.vtf"), &img, &o, NULL), BB_OK);
  size_t size;
  unsigned char *good = file_bytes(in_scratch_dir("g.vtf"), &size);
  bb_vtf_info info;
  bb_error err = {{0}};
  /* Truncated by one byte: the image data no longer fits. */
  file_bytes_write(in_scratch_dir("t.vtf"), good, size - 1);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("t.vtf"), &info, &err), BB_ERR_FORMAT);
  cr_assert_not_null(strstr(err.message, "truncated"), "%s", err.message);
  cr_assert_null(info.description);
  /* The low-resolution resource's offset past the end (the image data
   * still ends where the file does): the message says which part, and no
   * more than the truth ("needs 3636 bytes, the file has 3636" it was). */
  unsigned char *moved = malloc(size);
  memcpy(moved, good, size);
  cr_assert_eq(oracle_u32(moved + 80), 0x01, "the low-res entry comes first");
  const uint32_t past = (uint32_t)size + 100;
  for (int i = 0; i < 4; i++)
    moved[84 + i] = (unsigned char)(past >> (8 * i));
  file_bytes_write(in_scratch_dir("l.vtf"), moved, size);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("l.vtf"), &info, &err), BB_ERR_FORMAT);
  char want[160];
  snprintf(want, sizeof want, "low-resolution image (128 bytes at offset %u) ends past the end "
           "of the file (%zu bytes)", past, size);
  cr_expect_not_null(strstr(err.message, want), "%s", err.message);
  /* The image resource's offset past the end. */
  memcpy(moved, good, size);
  for (int i = 0; i < 4; i++)
    moved[92 + i] = (unsigned char)(past >> (8 * i));
  file_bytes_write(in_scratch_dir("i.vtf"), moved, size);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("i.vtf"), &info, &err), BB_ERR_FORMAT);
  size_t data = 0; /* DXT1, 32 x 32 down to 1 x 1 */
  for (int side = 32; side >= 1; side /= 2)
    data += (size_t)((side + 3) / 4) * (size_t)((side + 3) / 4) * 8;
  snprintf(want, sizeof want, "image data (%zu bytes at offset %u) ends past the end of the "
           "file (%zu bytes)", data, past, size);
  cr_expect_not_null(strstr(err.message, want), "%s", err.message);
  free(moved);
  /* Not a VTF; a version from the future; a resource count past the header. */
  file_bytes_write(in_scratch_dir("p.vtf"), (const unsigned char *)"\x89PNG\r\n\x1a\n........", 16);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("p.vtf"), &info, &err), BB_ERR_FORMAT);
  unsigned char *bad = malloc(size);
  memcpy(bad, good, size);
  bad[8] = 9;
  file_bytes_write(in_scratch_dir("v.vtf"), bad, size);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("v.vtf"), &info, &err), BB_ERR_FORMAT);
  memcpy(bad, good, size);
  bad[68] = 200;
  file_bytes_write(in_scratch_dir("r.vtf"), bad, size);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("r.vtf"), &info, &err), BB_ERR_FORMAT);
  cr_assert_eq(bb__vtf_read_info(in_scratch_dir("missing.vtf"), &info, &err), BB_ERR_IO);
  /* Every byte of the header and dictionary set to each of 0, 1, 0x7f,
   * 0xff in turn: OK or FORMAT, never a crash or an out-of-bounds read
   * (the sanitized build checks). */
  const unsigned char values[] = {0, 1, 0x7f, 0xff};
  for (size_t at = 0; at < 112; at++)
    for (int v = 0; v < 4; v++) {
      memcpy(bad, good, size);
      bad[at] = values[v];
      file_bytes_write(in_scratch_dir("m.vtf"), bad, size);
      bb_status st = bb__vtf_read_info(in_scratch_dir("m.vtf"), &info, &err);
      cr_assert(st == BB_OK || st == BB_ERR_FORMAT, "byte %zu = %d: %s", at, values[v],
                err.message);
      bb__vtf_info_free(&info);
    }
  free(bad);
  free(good);
  bb_image_free(&img);
  scratch_dir_remove();
}

Test(vtf, material) {
  scratch_dir_make("bb_vtf");
  char materials[160], bump[200], base[200], vmt[200];
  snprintf(materials, sizeof materials, "%s/game/materials", scratch_dir);
  snprintf(bump, sizeof bump, "%s/game/materials/./wood/wall020_height-ssbump.vtf", scratch_dir);
  snprintf(base, sizeof base, "%s/game/materials/wood/../wood/wall020.vtf", scratch_dir);
  snprintf(vmt, sizeof vmt, "%s/wall020.vmt", scratch_dir);
  bb_vmt_options o = {materials, bump, base, 1};
  bb_error err = {{0}};
  cr_assert_eq(bb_vmt_write(vmt, &o, &err), BB_OK, "%s", err.message);
  size_t size;
  char *text = (char *)file_bytes(vmt, &size);
  text[size] = '\0';
  cr_assert_str_eq(text, "// Source material written by bumpbake " BB_VERSION_STRING "\n"
                         "\"LightmappedGeneric\"\n{\n"
                         "\t\"$basetexture\" \"wood/wall020\"\n"
                         "\t\"$bumpmap\" \"wood/wall020_height-ssbump\"\n"
                         "\t\"$ssbump\" \"1\"\n}\n");
  free(text);
  /* A bump map outside the materials, not a VTF, or unquotable: refused. */
  char outside[200];
  snprintf(outside, sizeof outside, "%s/game/textures/rock.vtf", scratch_dir);
  bb_vmt_options bad = {materials, outside, NULL, 1};
  cr_assert_eq(bb_vmt_write(in_scratch_dir("x.vmt"), &bad, &err), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(err.message, "not inside the materials folder"), "%s", err.message);
  snprintf(outside, sizeof outside, "%s/game/materials/rock.tga", scratch_dir);
  cr_assert_eq(bb_vmt_write(in_scratch_dir("x.vmt"), &bad, &err), BB_ERR_ARGUMENT);
  cr_assert_not_null(strstr(err.message, "must be a .vtf"), "%s", err.message);
  snprintf(outside, sizeof outside, "%s/game/materials/a\"b.vtf", scratch_dir);
  cr_assert_eq(bb_vmt_write(in_scratch_dir("x.vmt"), &bad, &err), BB_ERR_ARGUMENT);
  bb_vmt_options none = {materials, NULL, NULL, 1};
  cr_assert_eq(bb_vmt_write(in_scratch_dir("x.vmt"), &none, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(access(in_scratch_dir("x.vmt"), F_OK), -1);
  scratch_dir_remove();
}

/* bb_vmt_write (what Python's write_vmt calls) turned the texture it names
 * into a 103-byte material, and overwrote a PNG: a material's name ends in
 * .vmt and is no other name of a texture it names, as for bake --vmt. */
Test(vtf, a_material_never_overwrites_a_texture_or_another_file) {
  scratch_dir_make("bb_vtf");
  char materials[160], bump[200], alias[200];
  snprintf(materials, sizeof materials, "%s/materials", scratch_dir);
  cr_assert_eq(mkdir(materials, 0755), 0);
  snprintf(bump, sizeof bump, "%s/materials/s.vtf", scratch_dir);
  snprintf(alias, sizeof alias, "%s/materials/s.vmt", scratch_dir);
  file_bytes_write(bump, (const unsigned char *)"VTF\0 texture", 12);
  file_bytes_write(in_scratch_dir("x.png"), (const unsigned char *)"png bytes", 9);
  bb_vmt_options o = {NULL, bump, NULL, 1};
  bb_error err = {{0}};
  cr_expect_eq(bb_vmt_write(bump, &o, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "ends in .vmt"), "%s", err.message);
  cr_expect_eq(bb_vmt_write(in_scratch_dir("x.png"), &o, &err), BB_ERR_ARGUMENT);
  cr_expect_eq(bb_vmt_write(in_scratch_dir("x.VMT.png"), &o, &err), BB_ERR_ARGUMENT);
  /* s.vmt a hard link of the texture: the same file under a .vmt name. */
  cr_assert_eq(link(bump, alias), 0);
  cr_expect_eq(bb_vmt_write(alias, &o, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "would overwrite the texture"), "%s", err.message);
  bb_vmt_options base = {NULL, in_scratch_dir("materials/t.vtf"), bump, 1};
  cr_expect_eq(bb_vmt_write(alias, &base, &err), BB_ERR_ARGUMENT);
  size_t size;
  unsigned char *bytes = file_bytes(bump, &size);
  cr_expect(size == 12 && memcmp(bytes, "VTF\0 texture", 12) == 0, "the texture was changed");
  free(bytes);
  bytes = file_bytes(in_scratch_dir("x.png"), &size);
  cr_expect(size == 9 && memcmp(bytes, "png bytes", 9) == 0, "the PNG was changed");
  free(bytes);
  /* Upper case is a .vmt too. */
  cr_expect_eq(bb_vmt_write(in_scratch_dir("materials/M.VMT"), &o, &err), BB_OK, "%s", err.message);
  scratch_dir_remove();
}

/* --vtf-version and --vtf-flags as the library reads them for every client. */
Test(vtf, version_and_flags_parse_as_the_options_take_them) {
  bb_error err;
  int minor = 0;
  const char *good[] = {"7.2", "7.5", "3", "4"};
  const int want[] = {2, 5, 3, 4};
  for (int k = 0; k < 4; k++) {
    cr_expect_eq(bb__vtf_version_parse(good[k], &minor, &err), BB_OK, "%s", good[k]);
    cr_expect_eq(minor, want[k], "%s", good[k]);
  }
  const char *bad[] = {"7.9", "7.1", "8.2", "", "7.", "3x", "seven", " 3", "+3", NULL};
  for (int k = 0; k < 10; k++) {
    cr_expect_eq(bb__vtf_version_parse(bad[k], &minor, &err), BB_ERR_ARGUMENT, "%s",
                 bad[k] ? bad[k] : "NULL");
    cr_expect(strstr(err.message, "VTF version must be 7.2, 7.3, 7.4 or 7.5"), "%s", err.message);
  }
  uint32_t flags = 0;
  cr_expect_eq(bb__vtf_flags_parse("0x08000000", &flags, &err), BB_OK);
  cr_expect_eq(flags, BB_VTF_FLAG_SSBUMP);
  cr_expect_eq(bb__vtf_flags_parse("12", &flags, &err), BB_OK);
  cr_expect_eq(flags, 12u);
  cr_expect_eq(bb__vtf_flags_parse("010", &flags, &err), BB_OK, "octal, as strtoul reads it");
  cr_expect_eq(flags, 8u);
  cr_expect_eq(bb__vtf_flags_parse("0xffffffff", &flags, &err), BB_OK);
  const char *bad_flags[] = {"-1", " -1", "+4", "0x100000000", "4k", "", NULL};
  for (int k = 0; k < 7; k++) {
    cr_expect_eq(bb__vtf_flags_parse(bad_flags[k], &flags, &err), BB_ERR_ARGUMENT, "%s",
                 bad_flags[k] ? bad_flags[k] : "NULL");
    cr_expect(strstr(err.message, "VTF flags must be a 32-bit number"), "%s", err.message);
  }
}
