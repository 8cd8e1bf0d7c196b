/* test_map_memory.c: bb_command_map, normal2ssbump's, ssbump2normal's and
 * combine's run on images in memory: the map bb_command_run writes (to a
 * float EXR, the values as they are) bit for bit, from the images the run
 * reads, decoded as it decodes them; and its refusals. */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include "bumpbake.h"
#include "command_words.h"
#include "pattern_image.h"
#include "image/image_write.h"

#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static char dir[] = "/tmp/bb_map_memory_XXXXXX";
static char paths[4][96];

/* A file in the test's folder. */
static const char *at(int i, const char *name) {
  snprintf(paths[i], sizeof paths[i], "%s/%s", dir, name);
  return paths[i];
}

static void setup(void) {
  strcpy(dir, "/tmp/bb_map_memory_XXXXXX");
  cr_assert_not_null(mkdtemp(dir));
}

static void teardown(void) {
  const char *names[] = {"n.exr", "a.exr", "b.png", "m.exr", "out.exr"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
    char p[128];
    snprintf(p, sizeof p, "%s/%s", dir, names[i]);
    unlink(p);
  }
  rmdir(dir);
}

static void write_file(const char *path, const bb_image *img, bb_depth depth) {
  bb_write_options o;
  memset(&o, 0, sizeof o);
  o.depth = depth;
  bb_error err = {{0}};
  cr_assert_eq(bb__image_write(path, img, &o, &err), BB_OK, "%s", err.message);
}

static bb_image read_back(const char *path, bb_image_info *info) {
  bb_image img = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_read(path, &img, info, &err), BB_OK, "%s", err.message);
  return img;
}

/* The run's output (words plus -o out.exr) against mem, bit for bit. */
static void expect_run_writes(const char *name, const char *const *words, const bb_image *mem) {
  const char *all[16];
  int n = 0;
  while (words[n])
    all[n] = words[n], n++;
  all[n++] = "--output";
  all[n++] = at(3, "out.exr");
  all[n] = NULL;
  bb_command *c = command(name, all);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  bb_command_result r = {0};
  cr_assert_eq(bb_command_run(c, NULL, &r, &err), BB_OK, "%s", err.message);
  bb_image file = read_back(paths[3], NULL);
  cr_assert_eq(file.width, mem->width);
  cr_assert_eq(file.height, mem->height);
  cr_assert_eq(file.channels, mem->channels, "%s: channels", name);
  const size_t count = (size_t)mem->width * (size_t)mem->height * (size_t)mem->channels;
  cr_expect_eq(memcmp(file.pixels, mem->pixels, count * sizeof(float)), 0,
               "%s: the run's pixels", name);
  bb_image_free(&file);
  bb_command_result_free(&r);
  bb_command_free(c);
}

/* The same command's options, checked in memory (no output, no files). */
static bb_command *in_memory(const char *name, const char *const *words) {
  bb_command *c = command(name, words);
  bb_command_set_in_memory(c, 0);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  return c;
}

TestSuite(cmd_map, .init = setup, .fini = teardown);

/* normal2ssbump --normal-y up: OpenGL normals, flipped in memory as the
 * run's decode flips them. */
Test(cmd_map, normal2ssbump_in_memory_is_the_runs_weights) {
  bb_image n = pattern_image(24, 16, 3, -0.6f, 0.6f, 0.f);
  for (size_t i = 0; i < 24 * 16; i++)
    n.pixels[3 * i + 2] = 0.8f;
  write_file(at(0, "n.exr"), &n, BB_DEPTH_FLOAT);
  bb_image_info info = {0};
  bb_image values = read_back(paths[0], &info);
  bb_image normals = {0};
  bb_error err = {{0}}; /* as the run decodes, but +Y left up */
  cr_assert_eq(bb_normal_map_decode(&values, info.is_float, 0, 1, &normals, &err), BB_OK);
  const char *words[] = {"--normal-y", "up", NULL};
  bb_command *c = in_memory("normal2ssbump", words);
  bb_image mem = {0};
  cr_assert_eq(bb_command_map(c, &normals, NULL, NULL, BB_DEPTH_DEFAULT, NULL, &mem, &err), BB_OK,
               "%s", err.message);
  cr_expect_eq(access(at(3, "out.exr"), F_OK), -1, "nothing written in memory");
  const char *run[] = {paths[0], "--normal-y", "up", NULL};
  expect_run_writes("normal2ssbump", run, &mem);
  /* the green read as +Y up: not the weights of the same normals +Y down */
  bb_command_free(c);
  const char *none[] = {NULL};
  c = in_memory("normal2ssbump", none);
  bb_image down = {0};
  cr_assert_eq(bb_command_map(c, &normals, NULL, NULL, BB_DEPTH_DEFAULT, NULL, &down, &err),
               BB_OK);
  cr_expect_neq(memcmp(down.pixels, mem.pixels, 24 * 16 * 3 * sizeof(float)), 0);
  bb_image_free(&down);
  bb_image_free(&mem);
  bb_command_free(c);
  bb_image_free(&normals);
  bb_image_free(&values);
  bb_image_info_free(&info);
  bb_image_free(&n);
}

Test(cmd_map, ssbump2normal_in_memory_is_the_runs_normals) {
  bb_image w = pattern_image(20, 12, 3, 0.05f, 0.6f, 0.f);
  write_file(at(0, "a.exr"), &w, BB_DEPTH_FLOAT);
  bb_image ssbump = read_back(paths[0], NULL);
  const char *words[] = {"--kind", "weights", "--normal-y", "up", NULL};
  bb_command *c = in_memory("ssbump2normal", words);
  bb_image mem = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_command_map(c, &ssbump, NULL, NULL, BB_DEPTH_DEFAULT, NULL, &mem, &err), BB_OK,
               "%s", err.message);
  cr_expect_eq(mem.channels, 3);
  const char *run[] = {paths[0], "--kind", "weights", "--normal-y", "up", NULL};
  expect_run_writes("ssbump2normal", run, &mem);
  bb_image_free(&mem);
  bb_command_free(c);
  bb_image_free(&ssbump);
  bb_image_free(&w);
}

/* combine --detail with an 8-bit B: its flat texel as the file stores it
 * (b_depth 8), so a flat B leaves A unchanged; the exact flat would not. */
Test(cmd_map, combine_detail_in_memory_takes_Bs_depth) {
  bb_image a = pattern_image(16, 16, 3, 0.1f, 0.9f, 0.f);
  write_file(at(0, "a.exr"), &a, BB_DEPTH_FLOAT);
  bb_image flat = pattern_image(16, 16, 3, 0.0f, 0.0f, 0.f);
  for (size_t i = 0; i < 16 * 16 * 3; i++)
    flat.pixels[i] = 1.0f / sqrtf(3.0f); /* stored as 147 of 255 */
  write_file(at(1, "b.png"), &flat, BB_DEPTH_8);
  bb_image va = read_back(paths[0], NULL), vb = read_back(paths[1], NULL);
  const char *words[] = {"--detail", "1", NULL};
  bb_command *c = in_memory("combine", words);
  bb_image mem = {0}, exact = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_command_map(c, &va, &vb, NULL, BB_DEPTH_8, NULL, &mem, &err), BB_OK, "%s",
               err.message);
  cr_expect_eq(memcmp(mem.pixels, va.pixels, 16 * 16 * 3 * sizeof(float)), 0,
               "a flat 8-bit detail leaves A bit for bit");
  cr_assert_eq(bb_command_map(c, &va, &vb, NULL, BB_DEPTH_DEFAULT, NULL, &exact, &err), BB_OK);
  cr_expect_neq(memcmp(exact.pixels, va.pixels, 16 * 16 * 3 * sizeof(float)), 0,
                "147/255 is not the exact flat");
  const char *run[] = {paths[0], paths[1], "--detail", "1", NULL};
  expect_run_writes("combine", run, &mem);
  bb_image_free(&exact);
  bb_image_free(&mem);
  bb_command_free(c);
  bb_image_free(&va);
  bb_image_free(&vb);
  bb_image_free(&flat);
  bb_image_free(&a);
}

/* combine --mask of normals +Y up: the mask's T, the normals flipped in
 * and out as the run decodes and writes them. */
Test(cmd_map, combine_mask_of_normals_in_memory_is_the_runs_map) {
  bb_image n1 = pattern_image(16, 8, 3, -0.5f, 0.5f, 0.f),
           n2 = pattern_image(16, 8, 3, -0.3f, 0.7f, 0.f);
  bb_image t = pattern_image(16, 8, 1, -0.2f, 1.2f, 0.f);
  write_file(at(0, "n.exr"), &n1, BB_DEPTH_FLOAT);
  write_file(at(1, "a.exr"), &n2, BB_DEPTH_FLOAT);
  write_file(at(2, "m.exr"), &t, BB_DEPTH_FLOAT);
  bb_image_info i1 = {0}, i2 = {0};
  bb_image v1 = read_back(paths[0], &i1), v2 = read_back(paths[1], &i2);
  bb_image mask = read_back(paths[2], NULL);
  bb_image d1 = {0}, d2 = {0};
  bb_error err = {{0}}; /* as the run decodes them, not renormalised (+Y left up) */
  cr_assert_eq(bb_normal_map_decode(&v1, i1.is_float, 0, 0, &d1, &err), BB_OK);
  cr_assert_eq(bb_normal_map_decode(&v2, i2.is_float, 0, 0, &d2, &err), BB_OK);
  const char *words[] = {"--mask", "(array)", "--kind", "normal", "--normal-y", "up", NULL};
  bb_command *c = in_memory("combine", words);
  bb_image mem = {0};
  cr_assert_eq(bb_command_map(c, &d1, &d2, &mask, BB_DEPTH_DEFAULT, NULL, &mem, &err), BB_OK,
               "%s", err.message);
  const char *run[] = {paths[0], paths[1],  "--mask",     paths[2], "--kind",
                       "normal", "--normal-y", "up", NULL};
  expect_run_writes("combine", run, &mem);
  bb_image_free(&mem);
  bb_command_free(c);
  bb_image_free(&d1);
  bb_image_free(&d2);
  bb_image_free(&v1);
  bb_image_free(&v2);
  bb_image_free(&mask);
  bb_image_info_free(&i1);
  bb_image_info_free(&i2);
  bb_image_free(&n1);
  bb_image_free(&n2);
  bb_image_free(&t);
}

Test(cmd_map, refusals_name_what_is_wrong) {
  bb_image a = pattern_image(8, 8, 3, 0.1f, 0.9f, 0.f), out = {0};
  bb_error err = {{0}};
  const char *none[] = {NULL};
  const char *mix[] = {"--mix", "0.5", NULL};
  bb_command *c = command("combine", mix);
  bb_command_set_in_memory(c, 0);
  cr_expect_eq(bb_command_map(c, &a, &a, NULL, BB_DEPTH_DEFAULT, NULL, &out, &err),
               BB_ERR_ARGUMENT, "unchecked");
  cr_expect_str_eq(err.message, "combine: the command is not checked for images in memory");
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_map(c, &a, NULL, NULL, BB_DEPTH_DEFAULT, NULL, &out, &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "combine: B, the second map, is needed");
  /* --mix: a mask given is not used (all 1 would give B) */
  bb_image ones = pattern_image(8, 8, 1, 0.0f, 0.0f, 0.f), mixed = {0}, masked = {0};
  for (size_t i = 0; i < 8 * 8; i++)
    ones.pixels[i] = 1.0f;
  bb_image other = pattern_image(8, 8, 3, 0.9f, 0.2f, 0.f);
  cr_assert_eq(bb_command_map(c, &a, &other, NULL, BB_DEPTH_DEFAULT, NULL, &mixed, &err), BB_OK);
  cr_assert_eq(bb_command_map(c, &a, &other, &ones, BB_DEPTH_DEFAULT, NULL, &masked, &err),
               BB_OK);
  cr_expect_eq(memcmp(mixed.pixels, masked.pixels, 8 * 8 * 3 * sizeof(float)), 0);
  bb_image_free(&mixed);
  bb_image_free(&masked);
  cr_expect_eq(bb_command_map(c, &a, &other, NULL, (bb_depth)9, NULL, &mixed, &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "combine: no depth 9");
  bb_command_free(c);
  const char *masking[] = {"--mask", "(array)", NULL};
  c = in_memory("combine", masking);
  cr_expect_eq(bb_command_map(c, &a, &other, NULL, BB_DEPTH_DEFAULT, NULL, &mixed, &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "combine: the mask is needed");
  bb_image_free(&other);
  bb_image_free(&ones);
  cr_expect_eq(bb_command_map(c, &a, &a, NULL, BB_DEPTH_DEFAULT, NULL, NULL, &err),
               BB_ERR_ARGUMENT);
  cr_expect_null(out.pixels);
  bb_command_free(c);
  /* checked for files, not for memory */
  const char *files[] = {"a.png", "b.png", "--mix", "0.5", "--output", "c.png", NULL};
  c = command("combine", files);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_map(c, &a, &a, NULL, BB_DEPTH_DEFAULT, NULL, &out, &err),
               BB_ERR_ARGUMENT);
  bb_command_free(c);
  /* a command that makes no map */
  const char *flat[] = {"_flat", NULL};
  c = in_memory("program", flat);
  cr_expect_eq(bb_command_map(c, &a, NULL, NULL, BB_DEPTH_DEFAULT, NULL, &out, &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "program makes no map of images in memory");
  bb_command_free(c);
  /* the operator's own refusal: another basis' map */
  bb_image six = pattern_image(8, 8, 6, 0.1f, 0.9f, 0.f);
  c = in_memory("ssbump2normal", none);
  cr_expect_eq(bb_command_map(c, &six, NULL, NULL, BB_DEPTH_DEFAULT, NULL, &out, &err),
               BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "6 channels"), "%s", err.message);
  bb_command_free(c);
  bb_image_free(&six);
  bb_image_free(&a);
}
