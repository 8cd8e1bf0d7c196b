/* test_trace_input.c: what a checked command's bake traces, built from the
 * command alone (bb_command_trace_input, a split trace's worker), is what
 * the bake's own stages build from its height and options, bit for bit;
 * a file whose bytes changed, and a command that traces nothing, are
 * refused; a basis of vectors set on the command (bb_command_set_basis) is
 * the one traced. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */

#include "job/job_internal.h"
#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "bumpbake_cluster.h"
#include "cmd/cmd_internal.h"
#include "image/image_write.h"
#include "scratch_dir.h"

#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

static void make_scratch_dir(void) { scratch_dir_make("bb_trace_input"); }

TestSuite(trace_input, .init = make_scratch_dir, .fini = scratch_dir_remove, .timeout = 120);

static const char *height_file(void) {
  static char path[512];
  snprintf(path, sizeof path, "%s/h.png", scratch_dir);
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 37, 29, 1, NULL), BB_OK);
  for (int y = 0; y < 29; y++)
    for (int x = 0; x < 37; x++)
      img.pixels[y * 37 + x] = (float)(0.5 + 0.3 * sin(0.7 * x) * cos(0.45 * y) +
                                       0.15 * sin(0.05 * x * y));
  bb_write_options o = {BB_DEPTH_16, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(path, &img, &o, NULL), BB_OK);
  bb_image_free(&img);
  return path;
}

/* A bake command of words ("--scale", "12", ...; a flag's value NULL). */
static bb_command *bake(const char *command, const char *input, const char *const (*options)[2],
                        int check) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new(command, &c, &err), BB_OK, "%s", err.message);
  if (input)
    cr_assert_eq(bb_command_add_input(c, input, &err), BB_OK, "%s", err.message);
  for (int i = 0; options[i][0]; i++)
    cr_assert_eq(bb_command_set(c, options[i][0], options[i][1], &err), BB_OK, "%s: %s",
                 options[i][0], err.message);
  if (check)
    cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  return c;
}

static uint64_t hash_of(const char *path) {
  uint64_t h = 0;
  cr_assert_eq(bb_file_hash(path, &h, NULL), BB_OK);
  return h;
}

/* The horizons of every slice of (p, rs), one image each (freed by the caller). */
static void horizons(const bb_pyramid *p, const bb_rayset *rs, bb_image *out) {
  bb_trace_options o = {.bias_texels = 0.55, .threads = 1};
  const int n = bb_rayset_slice_count(rs);
  for (int s = 0; s < n; s++) {
    bb_error err = {{0}};
    cr_assert_eq(bb_trace_horizons(p, rs, &o, &s, 1, &out[s], &err), BB_OK, "%s",
                 err.message);
  }
}

/* The command's trace input against the bake stages' own of its height and
 * options (the command's bake, with basis in place of --basis's when not NULL). */
static void assert_the_bakes_input(const bb_command *c, const char *path,
                                   const bb_basis *basis) {
  bb_error err = {{0}};
  bb_pyramid *p = NULL, *ref_p = NULL;
  bb_rayset *rs = NULL, *ref_rs = NULL;
  cr_assert_eq(bb_command_trace_input(c, 2, hash_of(path), &p, &rs, &err), BB_OK, "%s",
               err.message);
  bb_image height;
  cr_assert_eq(bb__height_file_read(path, c->options.job.channel,
                                   c->options.job.bake.height_scale, NULL, NULL, &height, NULL,
                                   &err),
               BB_OK, "%s", err.message);
  bb_bake_options o = c->options.job.bake;
  o.outputs = BB_MAPS_TRACED;
  o.trace.threads = 1;
  if (basis)
    o.basis = *basis;
  cr_assert_eq(bb__bake_trace_input(&height, &o, &ref_p, &ref_rs, &err), BB_OK, "%s",
               err.message);
  bb_image_free(&height);
  cr_assert_str_eq(bb_rayset_id(rs), bb_rayset_id(ref_rs));
  const int n = bb_rayset_slice_count(rs);
  cr_assert_eq(n, bb_rayset_slice_count(ref_rs));
  cr_assert_eq(bb_rayset_lobe_count(rs), bb_rayset_lobe_count(ref_rs));
  bb_image mine[64], theirs[64];
  cr_assert(n <= 64);
  horizons(p, rs, mine);
  horizons(ref_p, ref_rs, theirs);
  float highest = 0.0f;
  for (int s = 0; s < n; s++) {
    const size_t count = (size_t)mine[s].width * (size_t)mine[s].height;
    cr_assert(mine[s].width == 37 && mine[s].height == 29);
    cr_assert(memcmp(mine[s].pixels, theirs[s].pixels, count * sizeof(float)) == 0,
              "slice %d's horizons differ", s);
    for (size_t i = 0; i < count; i++)
      highest = fmaxf(highest, mine[s].pixels[i]);
    bb_image_free(&mine[s]);
    bb_image_free(&theirs[s]);
  }
  cr_assert_gt(highest, 0.0f, "nothing rises: a test that cannot fail");
  bb_pyramid_free(p);
  bb_pyramid_free(ref_p);
  bb_rayset_free(rs);
  bb_rayset_free(ref_rs);
}

Test(trace_input, is_what_the_bake_stages_build_of_the_commands_options) {
  const char *path = height_file();
  const char *const options[][2] = {{"scale", "12"},       {"slices", "6"},
                                    {"basis", "dirs:5"},   {"clamp", NULL},
                                    {"filter-radius", "2"}, {"power", "2"},
                                    {"normal", "n.png"},   {NULL, NULL}};
  bb_command *c = bake("bake", path, options, 1);
  assert_the_bakes_input(c, path, NULL);
  /* rays, not slices: round(sqrt(rays)) slices, the bake's rule */
  const char *const by_rays[][2] = {{"scale", "12"}, {"rays", "49"}, {"ao", "a.png"},
                                    {NULL, NULL}};
  bb_command *r = bake("bake", path, by_rays, 1);
  bb_pyramid *p = NULL;
  bb_rayset *rs = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_trace_input(r, 0, hash_of(path), &p, &rs, &err), BB_OK, "%s",
               err.message);
  cr_assert_eq(bb_rayset_slice_count(rs), 7);
  bb_pyramid_free(p);
  bb_rayset_free(rs);
  bb_command_free(r);
  bb_command_free(c);
}

Test(trace_input, refuses_other_bytes_and_what_traces_nothing) {
  const char *path = height_file();
  const char *const options[][2] = {{"scale", "12"}, {"slices", "4"}, {"ao", "a.png"},
                                    {NULL, NULL}};
  bb_error err = {{0}};
  bb_pyramid *p = (bb_pyramid *)&err;
  bb_rayset *rs = (bb_rayset *)&err;
  bb_command *c = bake("bake", path, options, 1);
  cr_assert_eq(bb_command_trace_input(c, 1, hash_of(path) ^ 1, &p, &rs, &err), BB_ERR_IO);
  cr_assert(strstr(err.message, "h.png: the file changed while it was baked"), "%s",
            err.message);
  cr_assert(p == NULL && rs == NULL, "a refusal leaves something allocated");
  cr_assert_eq(bb_command_trace_input(c, -1, hash_of(path), &p, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "threads"), "%s", err.message);
  bb_command_free(c);

  c = bake("bake", path, options, 0); /* not checked */
  cr_assert_eq(bb_command_trace_input(c, 1, hash_of(path), &p, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "bake: the command is not checked for files");
  bb_command_free(c);

  const char *const normal_options[][2] = {{"scale", "12"}, {"output", "n.png"}, {NULL, NULL}};
  c = bake("normal", path, normal_options, 1);
  cr_assert_eq(bb_command_trace_input(c, 1, hash_of(path), &p, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "normal traces nothing");
  bb_command_free(c);

  const char *const batch[][2] = {{"scale", "12"}, {"out-dir", "out"}, {NULL, NULL}};
  c = bake("bake", path, batch, 0);
  cr_assert_eq(bb_command_add_input(c, path, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_trace_input(c, 1, hash_of(path), &p, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "bake: a trace's input is of one height file (got 2)");
  bb_command_free(c);
  cr_assert_eq(bb_command_trace_input(NULL, 1, 0, &p, &rs, &err), BB_ERR_ARGUMENT);
}

Test(trace_input, traces_the_basis_of_vectors_set_on_the_command) {
  const char *path = height_file();
  const double v[4][3] = {{0.6, 0.0, 0.8}, {0.0, 0.6, 0.8}, {-0.6, 0.0, 0.8}, {0.0, 0.0, 1.0}};
  bb_basis vectors;
  cr_assert_eq(bb_basis_from_vectors(v, 4, &vectors, NULL), BB_OK);
  const char *const options[][2] = {{"scale", "12"}, {"slices", "4"}, {"ssbump", "s.png"},
                                    {NULL, NULL}};
  bb_error err = {{0}};
  bb_command *c = bake("bake", path, options, 0);
  cr_assert_eq(bb_command_set_basis(c, &vectors, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "bake: set a basis of vectors after the check");
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  bb_basis downwards = vectors;
  downwards.vector[0][2] = -0.8;
  cr_assert_eq(bb_command_set_basis(c, &downwards, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(c->options.job.bake.basis.count, 3, "a refused basis was kept");
  cr_assert_eq(bb_command_set_basis(c, &vectors, &err), BB_OK, "%s", err.message);
  cr_assert_eq(c->options.job.bake.basis.count, 4);
  cr_assert_str_eq(c->options.job.bake.basis.name, vectors.name);
  assert_the_bakes_input(c, path, &vectors);
  bb_pyramid *p = NULL;
  bb_rayset *rs = NULL;
  cr_assert_eq(bb_command_trace_input(c, 1, hash_of(path), &p, &rs, &err), BB_OK);
  cr_assert_eq(bb_rayset_lobe_count(rs), 4);
  bb_pyramid_free(p);
  bb_rayset_free(rs);
  /* checked again (a default set by a cluster): still the vectors */
  cr_assert_eq(bb_command_set(c, "threads", "2", &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(c->options.job.bake.basis.count, 4);
  bb_command_free(c);

  const char *const named[][2] = {{"scale", "12"}, {"basis", "hl2+z"}, {"ssbump", "s.png"},
                                  {NULL, NULL}};
  c = bake("bake", path, named, 1);
  cr_assert_eq(bb_command_set_basis(c, &vectors, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "bake: --basis is given: a basis of vectors goes in its place");
  bb_command_set_spelling(c, BB_SPELLING_KEYWORDS);
  cr_assert_eq(bb_command_set_basis(c, &vectors, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "bake: basis is given: a basis of vectors goes in its place");
  bb_command_free(c);
  const char *const none[][2] = {{NULL, NULL}};
  c = bake("info", NULL, none, 0);
  cr_assert_eq(bb_command_set_basis(c, &vectors, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "info takes no --basis");
  bb_command_free(c);
}
