/* test_mesh_cli.c: `bumpbake renderbumpflat` on the hostile models of
 * test_mesh_hostile.c, as a user runs them: one line, exit 1, nothing written, and a
 * note for what a model may do without. */
#define _GNU_SOURCE /* wait4 (cli_harness.h), mkfifo */

#include "bumpbake.h"
#include "cli_harness.h"

#include <criterion/criterion.h>

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

TestSuite(mesh_cli, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

static void write_text(const char *path, const char *text) {
  write_bytes(path, text, strlen(text));
}

/* An OBJ of one triangle whose first line is `mtllib NAME`. */
static void write_obj_naming(const char *path, const char *mtl) {
  char text[512];
  snprintf(text, sizeof text, "mtllib %s\nv 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n", mtl);
  write_text(path, text);
}

/* A glTF of one triangle whose buffer is uri. */
static void write_gltf(const char *path, const char *uri) {
  char text[1024];
  snprintf(text, sizeof text,
           "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
           "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":"
           "{\"POSITION\":0}}]}],\"buffers\":[{\"uri\":\"%s\",\"byteLength\":36}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
           "\"type\":\"VEC3\",\"min\":[-1e38,-1e38,-1e38],\"max\":[1e38,1e38,1e38]}]}",
           uri);
  write_text(path, text);
}

/* Hostile models, as a user runs them: one line, exit 1,
 * nothing written, nothing of /etc/passwd printed. */
Test(mesh_cli, renderbumpflat_refuses_hostile_models_with_one_line) {
  write_gltf(tmp("passwd.gltf"), "/etc/passwd");
  cr_assert_eq(mkfifo(tmp("fifo.obj"), 0644), 0);
  cr_assert_eq(mkfifo(tmp("fifo.mtl"), 0644), 0);
  write_obj_naming(tmp("mtlfifo.obj"), "fifo.mtl");
  write_obj_naming(tmp("shadow.obj"), "../../../../etc/shadow");
  FILE *f = fopen(tmp("chain.gltf"), "w");
  cr_assert_not_null(f);
  fprintf(f, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[");
  for (int i = 0; i < 20000; i++)
    fprintf(f, "{\"children\":[%d]},", i + 1);
  fprintf(f, "{}]}");
  cr_assert_eq(fclose(f), 0);
  const struct {
    const char *model, *part;
  } cases[] = {
      {"passwd.gltf", "refers to /etc/passwd, outside the model's directory"},
      {"fifo.obj", "is a FIFO, not a regular file"},
      {"mtlfifo.obj", "refers to fifo.mtl, which is a FIFO"},
      {"shadow.obj", "refers to ../../../../etc/shadow, outside"},
      {"chain.gltf", "no triangles"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(harness_dir,
                           (const char *const[]){"renderbumpflat", cases[i].model, "-size", "8",
                                                 "8", NULL},
                           1, cases[i].part, i);
  /* A missing .mtl: rendered, with a note. */
  write_obj_naming(tmp("nomtl.obj"), "gone.mtl");
  cli_result r = RUN_IN(harness_dir, "renderbumpflat", "nomtl.obj", "-size", "8", "8", "-q");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
  cr_expect(strstr(r.err, "nomtl.obj: note: read without gone.mtl"), "%s", r.err);
  cli_result_free(&r);
  cr_expect(file_exists(tmp("nomtl_local.tga")));
}

/* A million copies of one triangle over a 64 x 64 image: more than two
 * minutes of drawing before; refused at once now. */
Test(mesh_cli, renderbumpflat_refuses_a_million_stacked_triangles_quickly) {
  FILE *f = fopen(tmp("f.obj"), "w");
  cr_assert_not_null(f);
  fputs("v 0 0 0\nv 1 0 0\nv 1 0 1\n", f);
  for (int i = 0; i < 1000000; i++)
    fputs("f 1 2 3\n", f);
  cr_assert_eq(fclose(f), 0);
  harness_expect_refusal(
      harness_dir, (const char *const[]){"renderbumpflat", "f.obj", "--size", "64", "64", NULL},
      1, "over the 256 layers a render may draw", 0);
}

/* A model twice as wide as high on square images: its texels come out
 * twice as wide as high, and a user is told so, with the size or rectangle
 * that keeps them square, even without --height and with -q; the note
 * names the model like every other note. A size of the model's shape gives
 * no note. */
Test(mesh_cli, renderbumpflat_names_the_model_in_its_note_on_stretched_texels) {
  write_text(tmp("wide.obj"), "v 0 0 0\nv 2 0 0\nv 2 0 1\nv 0 0 1\nf 1 2 3 4\n");
  cli_result r = RUN_IN(harness_dir, "renderbumpflat", "wide.obj", "-size", "8", "8", "-q");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
  cr_expect(strstr(r.err, "bumpbake: wide.obj: note: texels are 2 times as wide as high (a 2 x 1 "
                          "rectangle on 8 x 8 texels)"),
            "%s", r.err);
  cr_expect(strstr(r.err, "size 16 8, or rect 0 0 2 2, keeps them square"), "%s", r.err);
  cli_result_free(&r);
  r = RUN_IN(harness_dir, "renderbumpflat", "wide.obj", "-size", "16", "8", "-q");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.err);
  cli_result_free(&r);
}

/* A flat model's height is 0 everywhere: renderbumpflat suggested `bake
 * --scale 0`, which bake refuses; it says the model is flat instead. */
Test(mesh_cli, a_flat_model_suggests_no_scale_bake_refuses) {
  write_text(tmp("flat.obj"), "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\nf 1 3 4\n");
  cli_result r = RUN_IN(harness_dir, "renderbumpflat", "flat.obj", "--size", "16", "16",
                        "--height", "fh.png", "-o", "fn.tga");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_null(strstr(r.out, "--scale 0"), "%s", r.out);
  cr_expect(strstr(r.out, "the model is flat"), "%s", r.out);
  cli_result_free(&r);
}
