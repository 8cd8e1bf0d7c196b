/* test_cli_textures.c: engine textures wherever maps are written. A height
 * becomes NAME-ssbump.vtf (Valve's layout and flag), NAME.vmt and
 * NAME_normal.dds in one command; height2ssbump and normal2ssbump write
 * VTFs too; what a texture cannot hold is a usage error before the bake;
 * a batch of VTF 7.3 files is judged up to date from their provenance,
 * texture settings included; info reads a VTF's header; every reader takes
 * a VTF's pixels (bake -> .vtf -> compare, render, ssbump2normal). */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "job/job_internal.h"
#include "texture/dds.h" /* bb__dds_read_info */
#include "texture/vtf.h" /* bb__vtf_read_info */

#include <math.h>

TestSuite(cli_textures, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

/* A 64 x 64 height with relief: bumps that shadow each other. */
static void relief(const char *path, int width, int height) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, width, height, 1, NULL), BB_OK);
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
      *bb_image_texel(&h, x, y) =
          (float)(0.5 + 0.25 * sin(x * 0.4) * cos(y * 0.3) + 0.2 * sin((x + y) * 0.11));
  harness_write(path, &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
}

static char *slurp_text(const char *path) {
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s", path);
  char *text = harness_slurp(f);
  fclose(f);
  return text;
}

Test(cli_textures, one_command_makes_a_source_material_and_a_dds) {
  relief(tmp("rock.png"), 64, 64);
  char dir[256], ssbump[300], vmt[300], dds[300];
  snprintf(dir, sizeof dir, "%s", tmp("game/materials/rock"));
  cr_assert_eq(bb__directory_create(dir, NULL), BB_OK);
  snprintf(ssbump, sizeof ssbump, "%s/rock-ssbump.vtf", dir);
  snprintf(vmt, sizeof vmt, "%s/rock.vmt", dir);
  snprintf(dds, sizeof dds, "%s/rock_normal.dds", dir);
  cli_result r = RUN("bake", tmp("rock.png"), "--scale", "8", "--rays", "64", "--ssbump",
                     ssbump, "--vmt", vmt, "--normal", dds, "--vtf-version", "7.3");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "wrote material ") != NULL, "%s", r.out);
  cli_result_free(&r);

  /* Valve ships ssbumps as DXT1 with the full chain and exactly the SSBUMP flag. */
  bb_vtf_info v;
  bb_error err;
  cr_assert_eq(bb__vtf_read_info(ssbump, &v, &err), BB_OK, "%s", err.message);
  cr_expect_eq(v.version_minor, 3);
  cr_expect_eq(v.format, 13, "DXT1");
  cr_expect_eq(v.flags, BB_VTF_FLAG_SSBUMP);
  cr_expect_eq(v.mip_count, 7, "64 x 64 down to 1 x 1");
  cr_expect_eq(v.low_res_width, 16);
  cr_expect(v.description && strstr(v.description, "output=ssbump") &&
                strstr(v.description, "texture_format=default"),
            "the KVD resource holds the provenance");
  bb__vtf_info_free(&v);

  char *material = slurp_text(vmt);
  cr_expect(strstr(material, "\"$bumpmap\" \"rock/rock-ssbump\"") &&
                strstr(material, "\"$ssbump\" \"1\""),
            "%s", material);
  free(material);

  /* The DDS: BC5 with the normal flag, read back by OpenImageIO (z rebuilt). */
  bb_image n;
  bb_image_info info;
  cr_assert_eq(bb_image_read(dds, &n, &info, &err), BB_OK, "%s", err.message);
  cr_expect_eq(n.width, 64);
  cr_expect(n.channels >= 3);
  double worst = 0.0;
  for (int i = 0; i < 64 * 64; i++) {
    const float *t = n.pixels + (size_t)i * (size_t)n.channels;
    const double x = 2.0 * t[0] - 1.0, y = 2.0 * t[1] - 1.0, z = 2.0 * t[2] - 1.0;
    worst = fmax(worst, fabs(sqrt(x * x + y * y + z * z) - 1.0));
  }
  cr_expect_lt(worst, 0.05, "the decoded normals are unit vectors (worst %g)", worst);
  bb_image_free(&n);
  bb_image_info_free(&info);
}

/* Refusals come before the bake: nothing is written. */
static void expect_refused(const char *const *args, const char *part) {
  cli_result r = harness_run(args);
  harness_expect_error(&r, 2, part, args[1]);
  cli_result_free(&r);
}

Test(cli_textures, what_a_texture_cannot_hold_is_refused_first) {
  relief(tmp("odd.png"), 48, 40);
  relief(tmp("h.png"), 32, 32);
  expect_refused((const char *[]){"bake", tmp("odd.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), NULL},
                 "need a power of two on each side (resize to 64 x 32)");
  relief(tmp("not4.png"), 30, 30);
  expect_refused((const char *[]){"bake", tmp("not4.png"), "--scale", "4", "--ao",
                                  tmp("o.dds"), NULL},
                 "multiples of 4");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.dds"), "--texture-format", "bc4", NULL},
                 "format bc4 holds 1 channel");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--texture-format", "bc5", NULL},
                 "VTF has no format bc5");
  /* a name no container has: the names as --help lists them, a VTF's in
   * Valve's spelling */
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--texture-format", "dxt3", NULL},
                 "--texture-format must be one of dxt1, dxt5, bgr888, bgra8888, rgba16f "
                 "(vtf); bc1, bc3, bc4, bc5, rgba8, rgba16f, rgba32f (dds) (got 'dxt3')");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.png"), "--vmt", tmp("o.vmt"), NULL},
                 "needs a .vtf bump map");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--materials", tmp("."), NULL},
                 "give --vmt FILE");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--vmt", tmp("o.vmt"), NULL},
                 "no folder named \"materials\"");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--depth", "16", NULL},
                 "their texture format sets it");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--vtf-version", "7.9", NULL},
                 "7.2, 7.3, 7.4 or 7.5");
  expect_refused((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--ssbump",
                                  tmp("o.vtf"), "--vtf-flags", "0x4000", NULL},
                 "ENVMAP");
  cr_expect_eq(files_starting_with("o."), 0, "nothing was written");
}

Test(cli_textures, valve_commands_write_vtf) {
  relief(tmp("h.png"), 32, 32);
  cr_assert_eq(bb__directory_create(tmp("materials/x"), NULL), BB_OK);
  /* height2ssbump: RGBA (height in alpha), so DXT5 with EIGHTBITALPHA. */
  cli_result r = RUN("height2ssbump", "-r", "16", tmp("h.png"), "4", "-o",
                     tmp("materials/x/h-ssbump.vtf"), "--vmt", tmp("materials/x/h.vmt"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_vtf_info v;
  bb_error err;
  cr_assert_eq(bb__vtf_read_info(tmp("materials/x/h-ssbump.vtf"), &v, &err), BB_OK, "%s",
               err.message);
  cr_expect_eq(v.format, 15, "DXT5");
  cr_expect_eq(v.flags, BB_VTF_FLAG_SSBUMP | BB_VTF_FLAG_EIGHTBITALPHA);
  bb__vtf_info_free(&v);
  char *material = slurp_text(tmp("materials/x/h.vmt"));
  cr_expect(strstr(material, "\"x/h-ssbump\"") != NULL, "%s", material);
  free(material);

  /* normal2ssbump's weights load in Source as an ssbump. */
  r = RUN("normal", tmp("h.png"), "--scale", "4", "-o", tmp("n.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("normal2ssbump", tmp("n.png"), "-o", tmp("w.vtf"), "--nomip");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  cr_assert_eq(bb__vtf_read_info(tmp("w.vtf"), &v, &err), BB_OK, "%s", err.message);
  cr_expect_eq(v.flags, BB_VTF_FLAG_SSBUMP | BB_VTF_FLAG_NOMIP | BB_VTF_FLAG_NOLOD);
  cr_expect_eq(v.mip_count, 1);
  bb__vtf_info_free(&v);

  /* height2ssbump -n: a normal map already packed into codes, flagged NORMAL. */
  r = RUN("height2ssbump", "-n", tmp("h.png"), "4", "-o", tmp("b.vtf"), "--vtf-flags", "0xc");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  cr_assert_eq(bb__vtf_read_info(tmp("b.vtf"), &v, &err), BB_OK, "%s", err.message);
  cr_expect_eq(v.flags, BB_VTF_FLAG_NORMAL | BB_VTF_FLAG_EIGHTBITALPHA | 0xcu);
  bb__vtf_info_free(&v);
}

Test(cli_textures, a_batch_of_vtf_is_judged_by_its_provenance) {
  cr_assert_eq(bb__directory_create(tmp("in"), NULL), BB_OK);
  relief(tmp("in/a.png"), 32, 32);
  const char *base[] = {"bake", tmp("in"), "--scale", "4", "--rays", "16", "--out-dir",
                        tmp("out"), "--name", "{stem}-{kind}.vtf", "--vtf-version", "7.3"};
  const char *twice[15], *changed[15];
  memcpy(twice, base, sizeof base);
  twice[12] = NULL;
  cli_result r = harness_run(twice);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "1 baked"), "%s", r.out);
  cli_result_free(&r);
  r = harness_run(twice);
  cr_expect(strstr(r.out, "1 up to date"), "the same settings: %s", r.out);
  cli_result_free(&r);
  memcpy(changed, base, sizeof base);
  changed[12] = "--texture-format";
  changed[13] = "bgr888";
  changed[14] = NULL;
  r = harness_run(changed);
  cr_expect(strstr(r.out, "1 baked"), "another texture format rebakes: %s", r.out);
  cli_result_free(&r);
  bb_vtf_info v;
  cr_assert_eq(bb__vtf_read_info(tmp("out/a-ssbump.vtf"), &v, NULL), BB_OK);
  cr_expect_eq(v.format, 3, "BGR888");
  bb__vtf_info_free(&v);
}

Test(cli_textures, info_reads_a_vtf_header) {
  relief(tmp("h.png"), 32, 32);
  cli_result r = RUN("bake", tmp("h.png"), "--scale", "4", "--rays", "16", "--ssbump",
                     tmp("s.vtf"), "--fast-compression");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("info", tmp("s.vtf"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "vtf: version 7.2, DXT1, 6 mip levels, flags 0x08000000 (SSBUMP)"),
            "%s", r.out);
  cr_expect(strstr(r.out, "no bumpbake provenance"), "VTF 7.2 has no room for it: %s", r.out);
  cli_result_free(&r);
  r = RUN("info", "--json", tmp("s.vtf"));
  cr_expect(strstr(r.out, "\"flag_names\":[\"SSBUMP\"]") && strstr(r.out, "\"mip_count\":6"),
            "%s", r.out);
  cli_result_free(&r);
  /* Its pixels are read too: a file is the same as itself. */
  r = RUN("compare", tmp("s.vtf"), tmp("s.vtf"));
  cr_expect_eq(r.code, 0, "%s%s", r.out, r.err);
  cli_result_free(&r);
}

/* info on a DDS says what it stores: the block format or the texel
 * layout, the FourCC or DXGI code, the mips, the pixel format's flags. */
Test(cli_textures, info_reads_a_dds_header) {
  relief(tmp("h.png"), 32, 32);
  cli_result r = RUN("bake", tmp("h.png"), "--scale", "4", "--rays", "16", "--normal",
                     tmp("n.dds"), "--ssbump", tmp("s.dds"), "--fast-compression");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("bake", tmp("h.png"), "--scale", "4", "--rays", "16", "--normal", tmp("f.dds"),
          "--texture-format", "rgba16f", "--nomip");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("info", tmp("n.dds"), tmp("s.dds"), tmp("f.dds"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "dds: BC5 (FourCC ATI2), 6 mip levels, pixel format flags 0x80000004 "
                          "(FOURCC NORMAL)"),
            "%s", r.out);
  cr_expect(strstr(r.out, "dds: BC1 (FourCC DXT1), 6 mip levels"), "%s", r.out);
  cr_expect(strstr(r.out, "dds: R16G16B16A16_FLOAT (DX10 DXGI format 10), uncompressed, "
                          "1 mip level,"),
            "%s", r.out);
  cli_result_free(&r);
  r = RUN("info", "--json", tmp("n.dds"));
  cr_expect(strstr(r.out, "\"dds\":{\"format\":\"BC5\",\"fourcc\":\"ATI2\",\"dxgi_format\":0,"
                          "\"compression\":\"BC5\",\"mip_count\":6,") &&
                strstr(r.out, "\"pixel_flag_names\":[\"FOURCC\",\"NORMAL\"]"),
            "%s", r.out);
  cli_result_free(&r);
  /* the library's call refuses what its reader refuses, naming the file */
  bb_dds_info d;
  bb_error err = {{0}};
  cr_expect_eq(bb__dds_read_info(tmp("h.png"), &d, &err), BB_ERR_FORMAT);
  cr_expect(strstr(err.message, "h.png"), "%s", err.message);
}

/* A fixture of fixtures/ (BB_FIXTURES), as an absolute path. */
static const char *fixture(const char *name) {
  static char path[4096];
  const char *dir = getenv("BB_FIXTURES");
  char rel[4096];
  snprintf(rel, sizeof rel, "%s/%s", dir && *dir ? dir : "fixtures", name);
  cr_assert(realpath(rel, path) != NULL, "fixture %s not found", rel);
  return path;
}

/* The number after "key": in compare's JSON line. */
static double json_number(const char *json, const char *key) {
  char pattern[64];
  snprintf(pattern, sizeof pattern, "\"%s\":", key);
  const char *at = strstr(json, pattern);
  cr_assert_not_null(at, "%s in %s", key, json);
  return strtod(at + strlen(pattern), NULL);
}

Test(cli_textures, vtf_round_trip_within_block_error) {
  /* rock06 at 128 x 128, scale 32: rough for its size, so a 4 x 4 block
   * spans several features (the worst case of tests/texture/test_dds.c's
   * goldens). Measured 2026-12-07, max / rms in 8-bit codes against the
   * 8-bit PNG: ssbump DXT1 and DXT5 103 / 13.19, normal DXT1 70 / 8.15
   * (libsquish's cluster fit, before: 109 / 13.2 and 68 / 8.2); BGR888
   * exact; RGBA16161616F the PNG's rounding (0.5 code) and the half's
   * (2^-11). The bounds sit ~10% above. */
  const char *height = fixture("rock06_128.png");
  cli_result r = RUN("bake", height, "--scale", "32", "--rays", "32", "--ssbump", tmp("s.png"),
                     "--normal", tmp("n.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  static const struct {
    const char *map, *format, *png;
    double max, rms; /* codes */
  } cases[] = {
      {"--ssbump", "dxt1", "s.png", 114, 14.5}, {"--ssbump", "dxt5", "s.png", 114, 14.5},
      {"--normal", "dxt1", "n.png", 77, 9.0},   {"--ssbump", "bgr888", "s.png", 1e-4, 1e-4},
      {"--ssbump", "bgra8888", "s.png", 1e-4, 1e-4},
      {"--ssbump", "rgba16f", "s.png", 0.5 + 255.0 / 2048.0, 0.5 + 255.0 / 2048.0},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char name[64];
    snprintf(name, sizeof name, "%s_%s.vtf", cases[k].map + 2, cases[k].format);
    r = RUN("bake", height, "--scale", "32", "--rays", "32", cases[k].map, tmp(name),
            "--texture-format", cases[k].format, "--vtf-version", k % 2 ? "7.2" : "7.5");
    cr_assert_eq(r.code, 0, "%s", r.err);
    cli_result_free(&r);
    r = RUN("compare", "--json", tmp(name), tmp(cases[k].png));
    cr_assert(r.code == 0 || r.code == 2, "%s: %s%s", name, r.out, r.err);
    cr_expect_eq(json_number(r.out, "channels"), 3.0, "%s", r.out);
    const double max = json_number(r.out, "max_abs") * 255.0,
                 rms = json_number(r.out, "rms") * 255.0;
    cr_expect_leq(max, cases[k].max, "%s: worst %.2f codes", name, max);
    cr_expect_leq(rms, cases[k].rms, "%s: rms %.2f codes", name, rms);
    cli_result_free(&r);
  }

  /* The readers take it as any image: render from the exact VTF draws the
   * PNG's picture, bit for bit; from DXT1 a picture; ssbump2normal too. */
  r = RUN("render", "--ssbump", tmp("ssbump_bgr888.vtf"), "-o", tmp("r_vtf.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("render", "--ssbump", tmp("s.png"), "-o", tmp("r_png.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("compare", "-q", tmp("r_vtf.png"), tmp("r_png.png"));
  cr_expect_eq(r.code, 0, "the same ssbump, the same picture");
  cli_result_free(&r);
  r = RUN("render", "--ssbump", tmp("ssbump_dxt1.vtf"), "-o", tmp("r_dxt1.png"));
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("ssbump2normal", tmp("ssbump_dxt1.vtf"), "-o", tmp("n2.png"));
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("info", tmp("ssbump_dxt1.vtf"));
  cr_expect(strstr(r.out, "vtf: version 7.5, DXT1, 8 mip levels, flags 0x08000000 (SSBUMP)"),
            "%s", r.out);
  cli_result_free(&r);
  /* A broken one: one line naming it, exit 4. */
  FILE *f = fopen(tmp("cut.vtf"), "wb");
  cr_assert_not_null(f);
  fwrite("VTF\0\7\0\0\0\2\0\0\0P\0\0\0", 1, 16, f);
  fclose(f);
  r = RUN("compare", tmp("cut.vtf"), tmp("s.png"));
  harness_expect_error(&r, 4, "cut.vtf", "compare");
  cli_result_free(&r);
}
