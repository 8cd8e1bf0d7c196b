/* test_program.c: DOOM 3 image programs: the parser's errors and columns,
 * each operation against id Tech 4's formulas on hand-made images, and the
 * 8-bit result against an emulation of id's byte pipeline. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bumpbake.h"
#include "maps/program_internal.h"

/* --------------------------------------------------- an in-memory loader */

typedef struct named_image {
  const char *name;
  bb_image img;
} named_image;

typedef struct library {
  named_image items[4];
  int count;
  char last_path[256];
} library;

static bb_status load_from(void *user, const char *path, bb_image *img,
                           bb_image_info *info, bb_error *err) {
  library *lib = user;
  snprintf(lib->last_path, sizeof lib->last_path, "%s", path);
  for (int i = 0; i < lib->count; i++) {
    const bb_image *src = &lib->items[i].img;
    if (strcmp(lib->items[i].name, path) != 0)
      continue;
    bb_status st = bb_image_alloc(img, src->width, src->height, src->channels, err);
    if (st == BB_OK)
      memcpy(img->pixels, src->pixels,
             (size_t)src->width * (size_t)src->height * (size_t)src->channels *
                 sizeof(float));
    if (info) {
      memset(info, 0, sizeof *info);
      info->alpha_channel = -1;
    }
    return st;
  }
  snprintf(err->message, sizeof err->message, "%s: no such file", path);
  return BB_ERR_IO;
}

static void add_image(library *lib, const char *name, int w, int h, int channels,
                      const float *values) {
  named_image *it = &lib->items[lib->count++];
  it->name = name;
  cr_assert_eq(bb_image_alloc(&it->img, w, h, channels, NULL), BB_OK);
  memcpy(it->img.pixels, values,
         (size_t)w * (size_t)h * (size_t)channels * sizeof(float));
}

static void free_library(library *lib) {
  for (int i = 0; i < lib->count; i++)
    bb_image_free(&lib->items[i].img);
}

/* Runs text against lib; fails the test on any error. */
static bb_image run(library *lib, const char *text, int *is_normal) {
  bb__program *p = NULL;
  bb_error err;
  cr_assert_eq(bb__program_parse(text, &p, &err), BB_OK, "%s: %s", text, err.message);
  bb__program_options o;
  bb__program_options_init(&o);
  o.loader = load_from;
  o.loader_user = lib;
  bb_image out;
  cr_assert_eq(bb__program_run(p, &o, &out, is_normal, &err), BB_OK, "%s: %s", text,
               err.message);
  bb__program_free(p);
  return out;
}

/* The 4 x 4 height case, in id's bytes. */
static const int HEIGHT_BYTES[16] = {10, 40, 90, 200, 30, 60,  120, 250,
                                     0,  20, 80, 160, 50, 100, 150, 255};

static void add_heights(library *lib) {
  float v[16];
  for (int i = 0; i < 16; i++)
    v[i] = (float)HEIGHT_BYTES[i] / 255.0f;
  add_image(lib, "h.tga", 4, 4, 1, v);
}

static void normalize(double v[3]) {
  double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int k = 0; k < 3; k++)
    v[k] /= len;
}

/* docs/commands/program.md's heightmap formula, written out from the page. */
static void doom3_heightmap(int x, int y, double scale, double n[3]) {
  const double s = scale / 256.0;
  int x1 = (x + 1) % 4, y1 = (y + 1) % 4;
  double d1 = HEIGHT_BYTES[y * 4 + x], d2 = HEIGHT_BYTES[y * 4 + x1];
  double d3 = HEIGHT_BYTES[y1 * 4 + x], d4 = HEIGHT_BYTES[y1 * 4 + x1];
  double a[3] = {-(d2 - d1) * s, -(d3 - d1) * s, 1.0};
  double b[3] = {-(d4 - d3) * s, (d1 - d3) * s, 1.0};
  normalize(a);
  normalize(b);
  for (int k = 0; k < 3; k++)
    n[k] = a[k] + b[k];
  normalize(n);
}

Test(program, heightmap_is_doom3s_formula_on_a_4x4_case) {
  library lib = {0};
  add_heights(&lib);
  int is_normal = 0;
  bb_image out = run(&lib, "heightmap(h.tga, 4)", &is_normal);
  cr_assert_eq(is_normal, 1);
  cr_assert_eq(out.channels, 3);
  cr_assert(out.width == 4 && out.height == 4);
  for (int y = 0; y < 4; y++)
    for (int x = 0; x < 4; x++) {
      double n[3];
      doom3_heightmap(x, y, 4.0, n);
      for (int k = 0; k < 3; k++)
        cr_assert_float_eq(bb_image_texel(&out, x, y)[k], n[k], 2e-6,
                           "(%d, %d)[%d]: %g, expected %g", x, y, k,
                           (double)bb_image_texel(&out, x, y)[k], n[k]);
    }
  /* Not a trivial case: the texels lean every way. */
  cr_assert_lt(bb_image_texel(&out, 2, 0)[0], -0.3f);
  cr_assert_gt(bb_image_texel(&out, 3, 0)[0], 0.3f);
  bb_image_free(&out);
  free_library(&lib);
}

/* id's bytes: NormalizeFast (one Newton step of the 0x5f3759df guess) and
 * (byte)(n * 127 + 128), emulated here to bound the difference of an 8-bit
 * file from the engine's texture. */
static float fast_rsqrt(float x) {
  union {
    float f;
    int32_t i;
  } u = {.f = x};
  u.i = 0x5f3759df - (u.i >> 1);
  return u.f * (1.5f - 0.5f * x * u.f * u.f);
}

static void normalize_fast(float v[3]) {
  float r = fast_rsqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int k = 0; k < 3; k++)
    v[k] *= r;
}

static void id_heightmap_bytes(int x, int y, float scale, int bytes[3]) {
  const float s = scale / 256.0f;
  int x1 = (x + 1) & 3, y1 = (y + 1) & 3;
  int d1 = HEIGHT_BYTES[y * 4 + x], d2 = HEIGHT_BYTES[y * 4 + x1];
  int d3 = HEIGHT_BYTES[y1 * 4 + x], d4 = HEIGHT_BYTES[y1 * 4 + x1];
  float a[3] = {(float)-(d2 - d1) * s, (float)-(d3 - d1) * s, 1.0f};
  float b[3] = {(float)-(d4 - d3) * s, (float)(d1 - d3) * s, 1.0f};
  normalize_fast(a);
  normalize_fast(b);
  for (int k = 0; k < 3; k++)
    a[k] += b[k];
  normalize_fast(a);
  for (int k = 0; k < 3; k++)
    bytes[k] = (uint8_t)(a[k] * 127.0f + 128.0f);
}

Test(program, eight_bit_output_is_within_one_code_of_ids_bytes) {
  library lib = {0};
  add_heights(&lib);
  int is_normal = 0, differing = 0;
  bb_image out = run(&lib, "heightmap(h.tga, 4)", &is_normal);
  for (int y = 0; y < 4; y++)
    for (int x = 0; x < 4; x++) {
      int id_bytes[3];
      id_heightmap_bytes(x, y, 4.0f, id_bytes);
      for (int k = 0; k < 3; k++) {
        /* bb__image_write's 8-bit code for a normal: round(255 (0.5 + 0.5 N)). */
        double n = bb_image_texel(&out, x, y)[k];
        int code = (int)floor(255.0 * (0.5 + 0.5 * n) + 0.5);
        cr_assert_leq(abs(code - id_bytes[k]), 1, "(%d, %d)[%d]: %d vs id's %d", x, y, k,
                      code, id_bytes[k]);
        differing += code != id_bytes[k];
      }
    }
  cr_log_info("8-bit codes differing from id's by one: %d of 48", differing);
  bb_image_free(&out);
  free_library(&lib);
}

Test(program, flat_in_flat_out) {
  library lib = {0};
  float grey[9] = {0.4f, 0.4f, 0.4f, 0.4f, 0.4f, 0.4f, 0.4f, 0.4f, 0.4f};
  add_image(&lib, "grey.png", 3, 3, 1, grey);
  const char *normal_programs[] = {"heightmap(grey.png, 8)",
                                   "_flat",
                                   "addnormals(_flat, _flat)",
                                   "smoothnormals(_flat)",
                                   "SmoothNormals(heightmap(grey.png, 2))",
                                   "addnormals(heightmap(grey.png, 3), _flat)"};
  for (size_t i = 0; i < sizeof normal_programs / sizeof normal_programs[0]; i++) {
    int is_normal = 0;
    bb_image out = run(&lib, normal_programs[i], &is_normal);
    cr_assert_eq(is_normal, 1, "%s", normal_programs[i]);
    for (int t = 0; t < out.width * out.height; t++) {
      cr_assert_float_eq(out.pixels[3 * t], 0.0, 1e-6, "%s", normal_programs[i]);
      cr_assert_float_eq(out.pixels[3 * t + 1], 0.0, 1e-6, "%s", normal_programs[i]);
      cr_assert_float_eq(out.pixels[3 * t + 2], 1.0, 1e-6, "%s", normal_programs[i]);
    }
    bb_image_free(&out);
  }
  int is_normal = 1;
  bb_image out =
      run(&lib, "makeintensity(invertColor(invertColor(grey.png)))", &is_normal);
  cr_assert_eq(is_normal, 0);
  cr_assert_eq(out.channels, 4);
  for (int c = 0; c < 4; c++)
    cr_assert_float_eq(out.pixels[c], 0.4, 1e-6, "channel %d", c);
  bb_image_free(&out);
  free_library(&lib);
}

Test(program, colour_operations) {
  library lib = {0};
  float a[8] = {0.2f, 0.4f, 0.6f, 0.8f, 0.9f, 0.1f, 0.5f, 1.0f};
  float b[8] = {0.5f, 0.5f, 0.5f, 0.5f, 0.3f, 0.3f, 0.3f, 0.3f};
  add_image(&lib, "a.tga", 2, 1, 4, a);
  add_image(&lib, "b.tga", 2, 1, 4, b);
  int n;
  bb_image out = run(&lib, "add(a.tga, b.tga)", &n);
  const float added[8] = {0.7f, 0.9f, 1.0f, 1.0f, 1.0f, 0.4f, 0.8f, 1.0f};
  for (int i = 0; i < 8; i++)
    cr_assert_float_eq(out.pixels[i], added[i], 1e-6, "add [%d]", i);
  bb_image_free(&out);
  out = run(&lib, "scale(a.tga, 1, 0.5, 2, 0)", &n);
  const float scaled[8] = {0.2f, 0.2f, 1.0f, 0.0f, 0.9f, 0.05f, 1.0f, 0.0f};
  for (int i = 0; i < 8; i++)
    cr_assert_float_eq(out.pixels[i], scaled[i], 1e-6, "scale [%d]", i);
  bb_image_free(&out);
  out = run(&lib, "invertAlpha(a.tga)", &n);
  cr_assert_float_eq(out.pixels[3], 0.2, 1e-6);
  cr_assert_float_eq(out.pixels[0], 0.2, 1e-6);
  bb_image_free(&out);
  out = run(&lib, "makeAlpha(a.tga)", &n);
  cr_assert(out.pixels[0] == 1.0f && out.pixels[1] == 1.0f && out.pixels[2] == 1.0f);
  cr_assert_float_eq(out.pixels[3], 0.4, 1e-6, "mean of R, G, B");
  cr_assert_float_eq(out.pixels[7], 0.5, 1e-6);
  bb_image_free(&out);
  free_library(&lib);
}

/* A second operand of another size is drop-sampled to the first's, as id's
 * R_Dropsample does: column j w_in / w_out, row (i + 0.25) h_in / h_out. */
Test(program, second_operand_takes_the_first_ones_size) {
  library lib = {0};
  float zeros[16 * 4] = {0};
  float quad[4] = {0.1f, 0.2f, 0.3f, 0.4f};
  add_image(&lib, "big.png", 4, 4, 4, zeros);
  add_image(&lib, "small.png", 2, 2, 1, quad);
  int n;
  bb_image out = run(&lib, "add(big.png, small.png)", &n);
  cr_assert(out.width == 4 && out.height == 4);
  for (int y = 0; y < 4; y++)
    for (int x = 0; x < 4; x++)
      cr_assert_float_eq(bb_image_texel(&out, x, y)[0], quad[(y / 2) * 2 + x / 2], 1e-7,
                         "(%d, %d)", x, y);
  bb_image_free(&out);
  free_library(&lib);
}

/* id's smoothnormals: the 3 x 3 sum of (byte - 128), skipping (0, 0, 0) and
 * (128, 128, 128) texels. */
Test(program, smoothnormals_skips_empty_texels) {
  library lib = {0};
  float n[9 * 3];
  for (int i = 0; i < 9; i++) { /* every texel leans +x: (255, 128, 128) */
    n[3 * i] = 1.0f;
    n[3 * i + 1] = n[3 * i + 2] = 128.0f / 255.0f;
  }
  n[12] = n[13] = n[14] = 128.0f / 255.0f; /* the centre is (128, 128, 128) */
  add_image(&lib, "n.tga", 3, 3, 3, n);
  int is_normal;
  bb_image out = run(&lib, "smoothnormals(n.tga)", &is_normal);
  cr_assert_eq(is_normal, 1);
  for (int t = 0; t < 9; t++) {
    cr_assert_float_eq(out.pixels[3 * t], 1.0, 1e-6, "texel %d leans +x", t);
    cr_assert_float_eq(out.pixels[3 * t + 2], 0.0, 1e-6);
  }
  bb_image_free(&out);
  free_library(&lib);
}

typedef struct syntax_case {
  const char *text;
  const char *message_part;
} syntax_case;

Test(program, syntax_errors_give_the_column) {
  const syntax_case cases[] = {
      {"", "column 1: empty program"},
      {"heightmap(h.tga 4)",
       "column 17: expected ',' and the scale of heightmap, found '4'"},
      {"heightmap(h.tga, four)",
       "column 18: heightmap needs a number here, found 'four'"},
      {"heightmap(h.tga, 4", "column 19: expected ')' closing heightmap, found the end"},
      {"add(a.tga b.tga)", "column 11: expected ',' between the images"},
      {"scale(a.tga, 1, 1, 1)", "column 21: expected ',' and the next factor of scale"},
      {"a.tga b.tga", "column 7: unexpected 'b.tga' after the end of the program"},
      {"addnormals", "column 11: expected '(' after addnormals"},
      {"add(, b)", "column 5: expected an image or a function, found ','"},
      {"add(\"a.tga, b)", "column 5: unterminated"},
      {"heightmap(\"\", 4)", "column 11: empty image name"},
      {"heigthmap(h.tga, 4)",
       "unknown function 'heigthmap' at column 1 (known: heightmap, "
       "addnormals, smoothnormals, add, scale, invertAlpha, invertColor, "
       "makeIntensity, makeAlpha, and the image _flat)"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    bb__program *p = (bb__program *)1;
    bb_error err = {{0}};
    cr_expect_eq(bb__program_parse(cases[i].text, &p, &err), BB_ERR_ARGUMENT, "%s",
                 cases[i].text);
    cr_expect_null(p);
    cr_expect(strstr(err.message, cases[i].message_part), "'%s': '%s' lacks '%s'",
              cases[i].text, err.message, cases[i].message_part);
    cr_expect_null(strchr(err.message, '\n'), "one line: %s", err.message);
  }
}

Test(program, nesting_is_bounded) {
  char text[2048] = "";
  for (int i = 0; i < 70; i++)
    strcat(text, "invertColor(");
  strcat(text, "a.tga");
  for (int i = 0; i < 70; i++)
    strcat(text, ")");
  bb__program *p = NULL;
  bb_error err;
  cr_assert_eq(bb__program_parse(text, &p, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "at most 64"), "%s", err.message);
}

/* A base directory and name past 4095 bytes were cut to fit a fixed buffer,
 * and the cut path was read: here an image that exists, h.png, read for the
 * h.png.missing the program names. */
Test(program, a_path_too_long_is_an_error_not_cut) {
  static char base[4096], cut[4096];
  memset(base, 0, sizeof base);
  strcpy(base, "base");
  while (strlen(base) + strlen("/h.png") < 4095)
    strcat(base, strlen(base) + strlen("/./h.png") <= 4095 ? "/." : "x");
  strcat(strcpy(cut, base), "/h.png");
  cr_assert_eq(strlen(cut), 4095);
  library lib = {0};
  float one[1] = {0.5f};
  add_image(&lib, cut, 1, 1, 1, one);
  bb__program *p = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__program_parse("invertColor(h.png.missing)", &p, &err), BB_OK);
  bb__program_options o;
  bb__program_options_init(&o);
  o.loader = load_from;
  o.loader_user = &lib;
  o.base_dir = base;
  bb_image out;
  int is_normal;
  cr_assert_eq(bb__program_run(p, &o, &out, &is_normal, &err), BB_ERR_ARGUMENT, "read %s",
               lib.last_path);
  cr_assert(strstr(err.message, "h.png.missing: path too long"), "%s", err.message);
  cr_assert_null(out.pixels);
  bb__program_free(p);
  free_library(&lib);
}

Test(program, names_quotes_base_directory_and_missing_files) {
  library lib = {0};
  float one[1] = {0.5f};
  add_image(&lib, "base/a b,c.png", 1, 1, 1, one);
  bb__program *p = NULL;
  bb_error err;
  cr_assert_eq(bb__program_parse("INVERTCOLOR( \"a b,c.png\" )", &p, &err), BB_OK, "%s",
               err.message);
  bb__program_options o;
  bb__program_options_init(&o);
  o.loader = load_from;
  o.loader_user = &lib;
  o.base_dir = "base";
  bb_image out;
  int is_normal;
  cr_assert_eq(bb__program_run(p, &o, &out, &is_normal, &err), BB_OK, "%s", err.message);
  cr_assert_float_eq(out.pixels[0], 0.5, 1e-7);
  cr_assert_eq(out.pixels[3], 1.0f, "no alpha reads as opaque");
  bb_image_free(&out);
  bb__program_free(p);

  /* The default loader reads files; a missing one is named. */
  cr_assert_eq(bb__program_parse("heightmap(nonexistent/h_bmp.tga, 4)", &p, NULL), BB_OK);
  cr_assert_eq(bb__program_run(p, NULL, &out, &is_normal, &err), BB_ERR_IO);
  cr_assert(strstr(err.message, "nonexistent/h_bmp.tga"), "%s", err.message);
  cr_assert_null(out.pixels);
  bb__program_free(p);
  /* An absolute name is refused unless allowed; allowed, it is read. */
  cr_assert_eq(bb__program_parse("heightmap(/nonexistent/h_bmp.tga, 4)", &p, NULL), BB_OK);
  cr_assert_eq(bb__program_run(p, NULL, &out, &is_normal, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "absolute"), "%s", err.message);
  bb__program_options_init(&o);
  o.allow_outside_base = 1;
  cr_assert_eq(bb__program_run(p, &o, &out, &is_normal, &err), BB_ERR_IO);
  bb__program_free(p);
  free_library(&lib);
}

/* Where an image name is read from: base_dir joins relative names only;
 * the length is snprintf's, so a cut path can be told from a whole one. */
Test(program, image_path_joins_base_dir_for_relative_names) {
  char out[32];
  cr_assert_eq(bb__program_image_path("maps", "a.tga", out, sizeof out), 10);
  cr_assert_str_eq(out, "maps/a.tga");
  cr_assert_eq(bb__program_image_path("maps", "/abs/a.tga", out, sizeof out), 10);
  cr_assert_str_eq(out, "/abs/a.tga");
  cr_assert_eq(bb__program_image_path("", "a.tga", out, sizeof out), 5);
  cr_assert_str_eq(out, "a.tga");
  cr_assert_eq(bb__program_image_path(NULL, "a.tga", out, sizeof out), 5);
  char small[8];
  cr_assert_eq(bb__program_image_path("maps", "a.tga", small, sizeof small), 10,
               "the whole length, past cap");
}
