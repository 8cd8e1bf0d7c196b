/* test_renderbump_run.c: renderbumpflat run by the library
 * (bb_command_renderbump, bb_command_run) and its files and compare's diff
 * through the job: what is written and recorded, nothing in memory, a
 * failed write leaving the old files, the outputs checked against the
 * inputs before any work. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */

#include <criterion/criterion.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bumpbake.h"
#include "command_words.h"
#include "file_bytes.h"
#include "scratch_dir.h"
#include "image/image_write.h"
#include "job/job_internal.h"
#include "mesh/mesh_internal.h"

static void setup(void) {
  scratch_dir_make("bb_rbf_run");
}
static void teardown(void) {
  scratch_dir_remove();
}

TestSuite(renderbump_run, .init = setup, .fini = teardown, .timeout = 120);

/* A square pyramid whose apex faces the viewer along -y: a height that is
 * not flat. */
static const char *pyramid(void) {
  const char *path = in_scratch_dir("pyramid.obj");
  static const char text[] = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0.5 -0.5 0.5\n"
                             "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
  file_bytes_write(path, (const unsigned char *)text, sizeof text - 1);
  return path;
}

/* c checked and run by bb_command_renderbump, which must succeed. */
static void render_checked(bb_command *c, bb_renderbump_result *render,
                           bb_command_result *written) {
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_renderbump(c, NULL, render, written, &err), BB_OK, "%s",
               err.message);
}

static int exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

static int temporaries(void) {
  DIR *d = opendir(scratch_dir);
  cr_assert_not_null(d);
  int n = 0;
  for (struct dirent *e; (e = readdir(d));)
    n += strncmp(e->d_name, ".bb-tmp-", 8) == 0;
  closedir(d);
  return n;
}

Test(renderbump_run, writes_both_files_with_provenance_and_hands_back_the_render) {
  const char *model = pyramid();
  char normal[512], height[512];
  snprintf(normal, sizeof normal, "%s", in_scratch_dir("n.tga"));
  snprintf(height, sizeof height, "%s", in_scratch_dir("h.png"));
  bb_command *c = command("renderbumpflat",
                          (const char *const[]){model, "--size", "16 16", "--output",
                                                normal, "--height", height, NULL});
  bb_renderbump_result render;
  bb_command_result written;
  render_checked(c, &render, &written);
  bb_error err = {{0}};
  cr_assert_eq(written.file_count, 2);
  cr_expect_str_eq(written.files[0].kind, "normal");
  cr_expect_str_eq(written.files[0].path, normal);
  cr_expect_str_eq(written.files[1].kind, "height");
  cr_expect_str_eq(written.files[1].path, height);
  cr_expect_eq(render.triangles, 4);
  cr_expect_eq(render.vertices, 5);
  cr_expect_eq(render.normal.width, 16);
  cr_expect(render.height_scale > 0);
  bb_mesh mesh = {0};
  cr_assert_eq(bb__mesh_load(model, &mesh, &err), BB_OK, "%s", err.message);
  cr_expect_eq(render.model_hash, bb__mesh_hash(&mesh));
  bb__mesh_free(&mesh);
  /* the height 16-bit where the format holds it; each file's kind recorded */
  int w, h, ch;
  bb_image_info info = {0};
  cr_assert_eq(bb_image_read_info(height, &w, &h, &ch, &info, &err), BB_OK, "%s",
               err.message);
  cr_expect_eq(info.bits_per_sample, 16);
  cr_assert_not_null(info.description);
  cr_expect(strstr(info.description, "\noutput=height\n"), "%s", info.description);
  cr_expect(strstr(info.description, "command=bumpbake renderbumpflat "), "%s",
            info.description);
  bb_image_info_free(&info);
  cr_assert_eq(bb_image_read_info(normal, &w, &h, &ch, &info, &err), BB_OK, "%s",
               err.message);
  cr_expect_eq(info.bits_per_sample, 8);
  cr_expect(strstr(info.description, "\noutput=normal+coverage\n"), "%s",
            info.description);
  bb_image_info_free(&info);
  bb_renderbump_result_free(&render);
  bb_command_result_free(&written);
  /* bb_command_run runs the same and says what it wrote */
  cr_assert_eq(bb_command_run(c, NULL, &written, &err), BB_OK, "%s", err.message);
  cr_expect_eq(written.file_count, 2);
  bb_command_result_free(&written);
  bb_command_free(c);
}

Test(renderbump_run, in_memory_writes_nothing) {
  const char *model = pyramid();
  bb_command *c =
      command("renderbumpflat", (const char *const[]){model, "--size", "8 8", NULL});
  bb_command_set_in_memory(c, 0);
  bb_renderbump_result render;
  bb_command_result written;
  render_checked(c, &render, &written);
  cr_expect_eq(written.file_count, 0);
  cr_expect_eq(render.height.width, 8);
  cr_expect_not(exists(in_scratch_dir("pyramid_local.tga")));
  bb_renderbump_result_free(&render);
  bb_command_free(c);
  /* in memory the input count is not checked: the run asks for its model */
  c = command("renderbumpflat", (const char *const[]){NULL});
  bb_command_set_in_memory(c, 0);
  bb_error none = {{0}};
  cr_assert_eq(bb_command_check(c, &none), BB_OK, "%s", none.message);
  cr_expect_eq(bb_command_renderbump(c, NULL, &render, &written, &none), BB_ERR_ARGUMENT);
  cr_expect_str_eq(none.message, "renderbumpflat: a MODEL is needed");
  bb_command_free(c);
  /* files are refused in memory */
  bb_error err = {{0}};
  c = command("renderbumpflat",
              (const char *const[]){model, "--output", in_scratch_dir("n.png"), NULL});
  bb_command_set_in_memory(c, 0);
  cr_expect_eq(bb_command_check(c, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--output is about files: not for images in memory");
  bb_command_free(c);
}

/* The height cannot be put in place (its name became a directory after the
 * check): the normal map is not replaced either, and no temporary stays. */
Test(renderbump_run, a_failed_write_leaves_the_old_files) {
  const char *model = pyramid();
  char normal[512], height[512];
  snprintf(normal, sizeof normal, "%s", in_scratch_dir("n.png"));
  snprintf(height, sizeof height, "%s", in_scratch_dir("h.tif"));
  const char *const first[] = {model,  "--size",   "8 8",  "--output",
                               normal, "--height", height, NULL};
  bb_command *c = command("renderbumpflat", first);
  bb_error err = {{0}};
  bb_command_result written;
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_run(c, NULL, &written, &err), BB_OK, "%s", err.message);
  bb_command_result_free(&written);
  bb_command_free(c);
  size_t old_size;
  unsigned char *old = file_bytes(normal, &old_size);

  const char *const second[] = {model,  "--size",   "16 8", "--output",
                                normal, "--height", height, NULL};
  c = command("renderbumpflat", second);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(unlink(height), 0);
  cr_assert_eq(mkdir(height, 0700), 0);
  bb_renderbump_result render;
  cr_expect_eq(bb_command_renderbump(c, NULL, &render, &written, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, height), "%s", err.message);
  cr_expect_eq(written.file_count, 0);
  cr_expect_null(render.normal.pixels);
  size_t size;
  unsigned char *now = file_bytes(normal, &size);
  cr_expect(size == old_size && memcmp(now, old, size) == 0,
            "the normal map was replaced");
  cr_expect_eq(temporaries(), 0);
  free(now);
  free(old);
  bb_command_free(c);
}

Test(renderbump_run, refuses_other_and_unchecked_commands) {
  const char *model = pyramid();
  bb_renderbump_result render;
  bb_command_result written;
  bb_error err = {{0}};
  bb_command *c = command("renderbumpflat", (const char *const[]){model, NULL});
  cr_expect_eq(bb_command_renderbump(c, NULL, &render, &written, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "not checked"), "%s", err.message);
  bb_command_free(c);
  c = command("info", (const char *const[]){model, NULL});
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_renderbump(c, NULL, &render, &written, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "info is not renderbumpflat");
  bb_command_free(c);
}

/* ------------------------------------------------------- compare's diff */

static void grey_png(const char *path, float value) {
  bb_image img;
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 1, &err), BB_OK);
  for (int i = 0; i < 16; i++)
    img.pixels[i] = value * (float)(i % 3);
  cr_assert_eq(bb__image_write(path, &img, NULL, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
}

Test(renderbump_run, the_diff_is_checked_against_the_inputs_and_its_format) {
  char a[512], b[512], over[512];
  snprintf(a, sizeof a, "%s", in_scratch_dir("a.png"));
  snprintf(b, sizeof b, "%s", in_scratch_dir("b.png"));
  snprintf(over, sizeof over, "%s/./b.png", scratch_dir);
  grey_png(a, 0.25f);
  grey_png(b, 0.5f);
  bb_error err = {{0}};
  bb_command *c = command("compare", (const char *const[]){a, b, "--diff", over, NULL});
  cr_expect_eq(bb_command_check(c, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, ": would overwrite the input "), "%s",
            err.message);
  bb_command_free(c);
  /* a GIF is no animation here: refused as bb__image_write refuses it */
  c = command("compare",
              (const char *const[]){a, b, "--diff", in_scratch_dir("d.gif"), NULL});
  cr_expect_eq(bb_command_check(c, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "unknown output format '.gif'"), "%s", err.message);
  bb_command_free(c);
  /* and so for a map command's output, before the map is made */
  c = command("normal2ssbump",
              (const char *const[]){a, "--output", in_scratch_dir("w.gif"), NULL});
  cr_expect_eq(bb_command_check(c, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "unknown output format '.gif'"), "%s", err.message);
  bb_command_free(c);
}

/* The diff's depth is the command's data: float and raw in .exr, the
 * format's own (8-bit, scaled to a maximum of 1) elsewhere; no provenance. */
Test(renderbump_run, the_diff_is_float_in_exr_and_scaled_elsewhere) {
  char a[512], b[512], exr[512], png[512];
  snprintf(a, sizeof a, "%s", in_scratch_dir("a.png"));
  snprintf(b, sizeof b, "%s", in_scratch_dir("b.png"));
  snprintf(exr, sizeof exr, "%s", in_scratch_dir("d.exr"));
  snprintf(png, sizeof png, "%s", in_scratch_dir("d.png"));
  grey_png(a, 0.25f);
  grey_png(b, 0.5f);
  const char *diffs[2] = {exr, png};
  for (int k = 0; k < 2; k++) {
    bb_compare_report r;
    bb_error err = {{0}};
    cr_assert_eq(bb__compare_files(a, b, NULL, diffs[k], &r, &err), BB_OK, "%s",
                 err.message);
    cr_expect(r.diff_written, "%s", r.diff_error.message);
    bb__compare_report_free(&r);
    bb_image img;
    bb_image_info info = {0};
    cr_assert_eq(bb_image_read(diffs[k], &img, &info, &err), BB_OK, "%s", err.message);
    cr_expect_eq(info.is_float, k == 0);
    cr_expect_null(info.description, "%s", diffs[k]);
    float max = 0;
    for (int i = 0; i < 16; i++)
      max = img.pixels[i] > max ? img.pixels[i] : max;
    /* the largest difference, 1 - 0.5 in 8-bit codes (255 - 128), kept in
     * the EXR and made white in the PNG */
    cr_expect_float_eq(max, k == 0 ? 127.0f / 255 : 1.0f, 1e-6, "%s: %g", diffs[k], max);
    bb_image_free(&img);
    bb_image_info_free(&info);
  }
}
