/* test_job.c: a bake job's plan (bb__job_plan_options) refusing bad options before
 * any bake. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "job/bake_rows.h"
#include "bumpbake.h"
#include "bumpbake_cluster.h"
#include "cli_harness.h"
#include "bake/bake_internal.h"
#include "job/job_internal.h"
#include "file_bytes.h"
#include "trace/basis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

TestSuite(job, .init = harness_setup, .fini = harness_teardown, .timeout = 300);

/* A small height file in the test's directory. */
static const char *height_file(void) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  for (int i = 0; i < 64; i++)
    h.pixels[i] = (float)(i % 5) / 4.0f;
  harness_write(tmp("h.png"), &h, BB_DEPTH_DEFAULT, BB_RANGE_UNIT);
  bb_image_free(&h);
  return tmp("h.png");
}

/* Every job records the command line that made it (a command's plan
 * names it, spelled by bb_command_text): a plan of options alone, with no
 * line to record, is refused. */
Test(job, a_plan_without_its_command_line_is_refused) {
  const char *input = height_file();
  bb_job_options o;
  bb__job_options_init(&o);
  o.bake.height_scale = 4.0f;
  o.paths[BB_MAP_NORMAL] = tmp("n.png");
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_expect_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "job plan: no command line to record (plan it through its command)");
  cr_expect_null(job);
  o.command_options = "--scale 4"; /* a batch's options alone: a line */
  cr_expect_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  bb_job_free(job);
}

/* The slope map's lit preview takes a light as render's --light does:
 * elevation 0..90, a finite azimuth; refused when planned, not baked. */
Test(job, slope_lit_light_is_checked_when_planned) {
  const char *input = height_file();
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 4.0f;
  o.slope_path = tmp("s.png");
  o.slope_lit = 1;
  o.slope_lit_azimuth = 30.0;
  const struct {
    double azimuth, elevation;
    const char *message;
  } bad[] = {{30.0, 120.0, "--lit elevation must be in 0..90 (got 120)"},
             {30.0, -1.0, "--lit elevation must be in 0..90 (got -1)"},
             {30.0, NAN, "--lit elevation must be in 0..90 (got nan)"},
             {INFINITY, 45.0, "--lit azimuth must be finite (got inf)"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    o.slope_lit_azimuth = bad[i].azimuth;
    o.slope_lit_elevation = bad[i].elevation;
    bb_job *job = NULL;
    bb_error err = {{0}};
    cr_expect_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_ERR_ARGUMENT, "case %zu", i);
    cr_expect_str_eq(err.message, bad[i].message);
    cr_expect_null(job);
  }
  o.slope_lit_azimuth = -400.0; /* any finite azimuth */
  for (double el = 0.0; el <= 90.0; el += 45.0) {
    o.slope_lit_elevation = el;
    bb_job *job = NULL;
    bb_error err = {{0}};
    cr_expect_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%g: %s", el, err.message);
    bb_job_free(job);
  }
}

/* A bake of height_file() at scale 4 with 16 rays, forced, its outputs
 * to name. */
static bb_job_options small_bake(void) {
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 4.0f;
  o.bake.rays = 16;
  o.force = 1;
  return o;
}

/* bb_job_bake_item (bumpbake serve's bake): the maps bb_job_run_item
 * would write, kept instead, with the kinds asked besides; nothing written. */
Test(job, bake_item_keeps_the_maps_run_item_writes) {
  const char *input = height_file();
  bb_job_options o = small_bake();
  o.paths[BB_MAP_SSBUMP] = tmp("s.exr"); /* float: the bits themselves */
  o.paths[BB_MAP_AO] = tmp("ao.exr");
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  bb_bake_result kept;
  cr_assert_eq(bb_job_bake_item(job, 0, BB_MAP_BIT(BB_MAP_BENT), NULL, NULL, &kept, &err),
               BB_OK, "%s", err.message);
  cr_expect_eq(access(tmp("s.exr"), F_OK), -1, "bake_item wrote a file");
  cr_expect_not_null(kept.bent.pixels, "the kind asked besides");
  cr_expect_null(kept.weights.pixels, "a kind not asked");
  cr_expect_eq(bb_job_report_get(job, 0)->width, 8);
  cr_assert_eq(bb_job_run_item(job, 0, NULL, NULL), BB_OK);
  const struct {
    const char *path;
    const bb_image *img;
  } maps[] = {{tmp("s.exr"), &kept.ssbump}, {tmp("ao.exr"), &kept.ao}};
  for (int m = 0; m < 2; m++) {
    bb_image written;
    cr_assert_eq(bb_image_read(maps[m].path, &written, NULL, &err), BB_OK, "%s", err.message);
    cr_assert_eq(written.width * written.height * written.channels,
                 maps[m].img->width * maps[m].img->height * maps[m].img->channels);
    cr_expect_eq(memcmp(written.pixels, maps[m].img->pixels,
                        sizeof(float) * (size_t)(written.width * written.height * written.channels)),
                 0, "%s differs from the maps kept", maps[m].path);
    bb_image_free(&written);
  }
  bb_bake_result_free(&kept);
  bb_job_free(job);
}

/* bb_job_write_item (serve's "write"): the files of the maps bake_item
 * kept, byte for byte the ones bb_job_run_item writes after its own bake
 * (8-bit PNGs, a float EXR, the slope map and its lit preview, provenance
 * in each), with kinds asked besides in the maps given. */
Test(job, write_item_writes_run_items_bytes_from_the_maps_kept) {
  const char *input = height_file();
  bb_job_options o = small_bake();
  o.paths[BB_MAP_SSBUMP] = tmp("s.png");
  o.paths[BB_MAP_NORMAL] = tmp("n.png");
  o.paths[BB_MAP_AO] = tmp("ao.exr");
  o.slope_path = tmp("slope.png");
  o.slope_lit = 1;
  o.command = "bumpbake bake h.png --scale 4 --rays 16 ...";
  const char *files[] = {tmp("s.png"), tmp("n.png"), tmp("ao.exr"), tmp("slope.png"),
                         tmp("slope_lit.png")};
  enum { FILES = sizeof files / sizeof files[0] };
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  bb_bake_result kept;
  cr_expect_eq(bb_job_write_item(job, 0, &(bb_bake_result){0}, &err), BB_ERR_ARGUMENT,
               "not baked yet");
  cr_assert_eq(bb_job_bake_item(job, 0, BB_MAPS_BAKED, NULL, NULL, &kept, &err), BB_OK, "%s",
               err.message);
  bb_bake_result missing = kept;
  memset(&missing.ao, 0, sizeof missing.ao);
  cr_expect_eq(bb_job_write_item(job, 0, &missing, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "no ao of 8 x 8"), "%s", err.message);
  cr_assert_eq(bb_job_write_item(job, 0, &kept, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_job_report_get(job, 0)->outcome, BB_JOB_BAKED);
  unsigned char *written[FILES];
  size_t sizes[FILES];
  for (int k = 0; k < FILES; k++) {
    written[k] = file_bytes(files[k], &sizes[k]);
    cr_assert_eq(remove(files[k]), 0);
  }
  bb_bake_result_free(&kept);
  cr_assert_eq(bb_job_run_item(job, 0, NULL, NULL), BB_OK);
  for (int k = 0; k < FILES; k++) {
    size_t size;
    unsigned char *again = file_bytes(files[k], &size);
    cr_expect(size == sizes[k] && memcmp(again, written[k], size) == 0,
              "%s: bb_job_write_item's bytes differ from bb_job_run_item's", files[k]);
    free(again);
    free(written[k]);
  }
  bb_job_free(job);
}

/* bb_job_provenance (the provenance bumpbake serve's page shows): the
 * text the file of that kind records, the maps the bake read (brightness)
 * named by their hashes; for a kind the job does not write, the ray set
 * its bake traced besides. NULL before the bake and for no input. */
Test(job, provenance_is_what_the_file_records) {
  const char *input = height_file();
  bb_job_options o = small_bake();
  o.brightness_file = input; /* a map of the maps' size */
  o.paths[BB_MAP_SSBUMP] = tmp("p.png");
  o.command = "bumpbake bake h.png --scale 4 --rays 16 --brightness h.png --ssbump p.png";
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  cr_expect_null(bb_job_provenance(job, 0, "ssbump"), "not baked yet");
  cr_assert_eq(bb_job_run_item(job, 0, NULL, NULL), BB_OK);
  char *text = bb_job_provenance(job, 0, "ssbump");
  cr_assert_not_null(text);
  bb_image_info info = {0};
  cr_assert_eq(bb_image_read_info(tmp("p.png"), NULL, NULL, NULL, &info, &err), BB_OK, "%s",
               err.message);
  cr_expect_str_eq(text, info.description ? info.description : "(none)");
  cr_expect(strstr(text, "\nbrightness=") != NULL, "%s", text);
  bb_image_info_free(&info);
  free(text);
  cr_expect_null(bb_job_provenance(job, 1, "ssbump"));
  cr_expect_null(bb_job_provenance(NULL, 0, "ssbump"));
  bb_job_free(job);

  o.brightness_file = NULL;
  o.paths[BB_MAP_SSBUMP] = NULL;
  o.paths[BB_MAP_NORMAL] = tmp("n.png");
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  bb_bake_result kept;
  cr_assert_eq(bb_job_bake_item(job, 0, BB_MAPS_BAKED, NULL, NULL, &kept, &err), BB_OK, "%s",
               err.message);
  text = bb_job_provenance(job, 0, "ssbump");
  cr_assert_not_null(text);
  char rayset[96];
  snprintf(rayset, sizeof rayset, "\nrayset=%s\n", kept.rayset_id);
  cr_expect(kept.rayset_id[0] && strstr(text, rayset), "%s", text);
  cr_expect(strstr(text, "\noutput=ssbump\n") && !strstr(text, "brightness="), "%s", text);
  free(text);
  bb_bake_result_free(&kept);
  bb_job_free(job);
}

/* bb_command_report_json: the object `bake --json` prints of an input (its
 * line, bb_job_report_lines), with a status when asked (serve's
 * "written"). */
Test(job, report_json_is_the_lines_object) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new("bake", &c, &err), BB_OK);
  cr_assert_eq(bb_command_add_input(c, height_file(), &err), BB_OK);
  const char *set[][2] = {{"scale", "4"}, {"rays", "16"}, {"ssbump", tmp("j.png")},
                          {"json", NULL}};
  for (size_t i = 0; i < sizeof set / sizeof set[0]; i++)
    cr_assert_eq(bb_command_set(c, set[i][0], set[i][1], &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  bb_job *job = NULL;
  cr_assert_eq(bb_command_plan(c, NULL, &job, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_job_run_item(job, 0, NULL, NULL), BB_OK);
  const bb_job_report *r = bb_job_report_get(job, 0);
  char *json = bb_command_report_json(c, r, NULL);
  char *lines = bb_job_report_lines(c, r, 0, NULL);
  cr_assert(json && lines);
  cr_expect_eq(strlen(lines), strlen(json) + 1);
  cr_expect_eq(strncmp(lines, json, strlen(json)), 0, "%s\n%s", json, lines);
  free(json);
  json = bb_command_report_json(c, r, "written");
  char head[4200];
  snprintf(head, sizeof head, "{\"input\":\"%s\",\"status\":\"written\",\"width\":8,", r->input);
  cr_expect_eq(strncmp(json, head, strlen(head)), 0, "%s", json);
  cr_expect_null(bb_command_report_json(NULL, r, NULL));
  free(json);
  free(lines);
  bb_job_free(job);
  bb_command_free(c);
}

/* The maps of input 0 of a job of these slices and basis, baked through
 * context (NULL: cold). */
static bb_bake_result bake_with(const char *input, int slices, const char *basis,
                                bb_bake_context *context) {
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 4.0f;
  o.bake.slices = slices;
  o.bake.bounce_albedo = 0.5; /* the bounce reads the ray set too */
  o.bake.trace.threads = 2;
  cr_assert_eq(bb__basis_parse(basis, &o.bake.basis, NULL), BB_OK);
  o.paths[BB_MAP_SSBUMP] = tmp("s.png");
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  bb_job_use_context(job, context);
  bb_bake_result r;
  cr_assert_eq(bb_job_bake_item(job, 0, BB_MAPS_BAKED, NULL, NULL, &r, &err), BB_OK, "%s",
               err.message);
  bb_job_free(job);
  return r;
}

static void expect_same_maps(const bb_bake_result *a, const bb_bake_result *b, const char *what) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    const bb_image *x = bb__bake_result_image(a, (bb_map_kind)k);
    const bb_image *y = bb__bake_result_image(b, (bb_map_kind)k);
    if (!x || !x->pixels) {
      cr_expect(!y || !y->pixels, "%s: kind %d", what, k);
      continue;
    }
    cr_assert(y && y->pixels && x->width == y->width && x->channels == y->channels,
              "%s: kind %d", what, k);
    cr_expect_eq(memcmp(x->pixels, y->pixels,
                        sizeof(float) * (size_t)x->width * (size_t)x->height *
                            (size_t)x->channels),
                 0, "%s: kind %d differs from a cold bake's", what, k);
  }
  cr_expect_str_eq(a->rayset_id, b->rayset_id, "%s", what);
}

/* A bake through a context (serve's warm bakes: the ray set kept, the
 * buffers reused) is a cold bake's bits, the second one too, and a change
 * of slices or basis builds the ray set of the new ones. */
Test(job, a_warm_bake_is_a_cold_bakes_bits) {
  const char *input = height_file();
  bb_bake_context *context = NULL;
  cr_assert_eq(bb_bake_context_new(&context, NULL), BB_OK);
  bb_bake_result cold = bake_with(input, 8, "hl2", NULL);
  for (int round = 0; round < 2; round++) {
    bb_bake_result warm = bake_with(input, 8, "hl2", context);
    expect_same_maps(&cold, &warm, round ? "the second warm bake" : "the first warm bake");
    bb_bake_result_free(&warm);
  }
  cr_expect_eq(bb__context_rayset_builds(context), 1, "the ray set was built once");
  bb_bake_result_free(&cold);
  const struct {
    int slices;
    const char *basis;
  } changes[] = {{12, "hl2"}, {12, "hl2+z"}, {8, "hl2"}};
  for (int c = 0; c < 3; c++) {
    cold = bake_with(input, changes[c].slices, changes[c].basis, NULL);
    bb_bake_result warm = bake_with(input, changes[c].slices, changes[c].basis, context);
    expect_same_maps(&cold, &warm, changes[c].basis);
    cr_expect_eq(bb__context_rayset_builds(context), 2 + c);
    bb_bake_result_free(&cold);
    bb_bake_result_free(&warm);
  }
  bb_bake_context_free(context);
}

static int cancel_at_once(void *user, long done, long total) {
  (void)user, (void)done, (void)total;
  return 1;
}

/* A cancelled bake keeps nothing and says so. */
Test(job, bake_item_cancelled_keeps_nothing) {
  const char *input = height_file();
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 4.0f;
  o.paths[BB_MAP_SSBUMP] = tmp("s.png");
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  bb_bake_result kept;
  cr_expect_eq(bb_job_bake_item(job, 0, 0u, cancel_at_once, NULL, &kept, &err),
               BB_ERR_CANCELLED);
  cr_expect_null(kept.ssbump.pixels);
  cr_expect_eq(bb_job_bake_item(job, 0, 1u << 30, NULL, NULL, &kept, &err), BB_ERR_ARGUMENT);
  cr_expect_eq(bb_job_bake_item(job, 1, 0u, NULL, NULL, &kept, &err), BB_ERR_ARGUMENT);
  bb_job_free(job);
}

/* -o PREFIX's names, one rule for bake and serve; a name's leading dot is
 * no extension (as Python's os.path.splitext). */
Test(job, prefix_and_suffix_names) {
  static const struct {
    bb_map_kind kind;
    const char *want; /* NULL: -o does not write it */
  } cases[] = {{BB_MAP_NORMAL, "out/r_normal.png"}, {BB_MAP_SSBUMP, "out/r_ssbump.png"},
               {BB_MAP_AO, "out/r_ao.png"},         {BB_MAP_BENT, NULL},
               {BB_MAP_FILTERED, NULL},             {BB_MAP_SLOPE, NULL}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    char *got = bb__job_prefix_path("out/r", cases[i].kind);
    if (cases[i].want)
      cr_expect_str_eq(got ? got : "(null)", cases[i].want);
    else
      cr_expect_null(got, "kind %d", (int)cases[i].kind);
    free(got);
  }
  cr_expect_null(bb__job_prefix_path(NULL, BB_MAP_NORMAL));
  static const char *const suffixed[][3] = {{"rock.png", "-ssbump.tga", "rock-ssbump.tga"},
                                            {"a.b/rock", "_x", "a.b/rock_x"},
                                            {"d/.png", "", "d/.png"},
                                            {"d/.hidden.png", "", "d/.hidden"},
                                            {"rock.tar.png", "", "rock.tar"}};
  for (size_t i = 0; i < sizeof suffixed / sizeof suffixed[0]; i++) {
    char *got = bb__path_with_suffix(suffixed[i][0], suffixed[i][1]);
    cr_expect_str_eq(got ? got : "(null)", suffixed[i][2], "%s", suffixed[i][0]);
    free(got);
  }
}

/* The progress of a job's input as a caller sees it: each call's stage
 * (bb_job_stage) and figures. */
typedef struct stage_log {
  bb_job *job;
  int calls, bake_calls, compress_calls;
  long last_done, total;
  int backwards; /* a compress call whose done fell */
} stage_log;

static int log_stage(void *user, long done, long total) {
  stage_log *l = user;
  const char *stage = bb_job_stage(l->job);
  l->calls++;
  if (stage && !strcmp(stage, "bake")) {
    l->bake_calls++;
  } else if (stage && !strcmp(stage, "compress")) {
    if (l->compress_calls++ && done < l->last_done)
      l->backwards = 1;
    l->last_done = done, l->total = total;
  }
  return 0;
}

Test(job, block_compression_is_a_stage_of_its_own) {
  /* An 8 x 8 height written as a VTF (DXT1, mips 8 to 1: 2 + 1 + 1 + 1
   * rows of blocks, and the 8 x 8 low-resolution image's 2) and a DDS ao
   * (BC4, 2 + 1 + 1 + 1): after the bake's calls, the compress stage's,
   * their total the 12 rows, done rising to it; its seconds a part of the
   * write's. Without an engine texture: no such stage, no seconds. */
  const char *input = height_file();
  for (int textures = 1; textures >= 0; textures--) {
    bb_job_options o;
    bb__job_options_init(&o);
    o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
    o.bake.height_scale = 4.0f;
    o.bake.rays = 16;
    o.paths[BB_MAP_SSBUMP] = textures ? tmp("s.vtf") : tmp("s.png");
    o.paths[BB_MAP_AO] = textures ? tmp("ao.dds") : tmp("ao.png");
    o.force = 1;
    bb_job *job = NULL;
    bb_error err = {{0}};
    cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
    stage_log l = {job, 0, 0, 0, 0, 0, 0};
    cr_assert_eq(bb_job_run_item(job, 0, log_stage, &l), BB_OK);
    cr_expect_null(bb_job_stage(job), "no stage once run");
    const bb_job_report *r = bb_job_report_get(job, 0);
    cr_expect_gt(l.bake_calls, 0);
    if (textures) {
      cr_expect_gt(l.compress_calls, 0);
      cr_expect_eq(l.total, 12, "rows of blocks: %ld", l.total);
      cr_expect_eq(l.last_done, 12, "done at the end: %ld", l.last_done);
      cr_expect_not(l.backwards);
      cr_expect(r->seconds_compress > 0 && r->seconds_compress <= r->seconds_write,
                "compress %g s of write %g s", r->seconds_compress, r->seconds_write);
    } else {
      cr_expect_eq(l.compress_calls, 0);
      cr_expect_eq(r->seconds_compress, 0.0);
    }
    bb_job_free(job);
  }
}

/* A 16-bit height of w x h with a bump at (bx, by), written to path. */
static void bump_file(const char *path, int w, int h, int bx, int by) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      const double d2 = (x - bx) * (x - bx) + (y - by) * (y - by);
      img.pixels[y * w + x] =
          (float)(0.3 + 0.2 * sin(0.4 * x) * cos(0.3 * y) + 0.3 * exp(-d2 / 2.0));
    }
  harness_write(path, &img, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&img);
}

/* bumpbake serve's way: the bakes of a job through a context that keeps
 * (bb_bake_context_keep) bake a changed file again where it changed, and
 * keep the maps a job without a context makes. */
Test(job, bake_item_through_a_keeping_context_is_the_whole_bake) {
  const char *input = tmp("edited.png");
  bump_file(input, 48, 40, 10, 10);
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 16.0f;
  o.paths[BB_MAP_SSBUMP] = tmp("e_ssbump.exr");
  o.force = 1;
  bb_bake_context *context = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_bake_context_new(&context, &err), BB_OK);
  bb_bake_context_keep(context, 1);
  for (int edit = 0; edit < 3; edit++) {
    if (edit > 0)
      bump_file(input, 48, 40, 10 + 3 * edit, 10 + edit);
    bb_job *job = NULL, *cold = NULL;
    cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
    cr_assert_eq(bb__job_plan_options(&input, 1, &o, &cold, &err), BB_OK, "%s", err.message);
    bb_job_use_context(job, context);
    bb_bake_result kept, whole;
    cr_assert_eq(bb_job_bake_item(job, 0, BB_MAPS_BAKED, NULL, NULL, &kept, &err), BB_OK,
                 "%s", err.message);
    cr_assert_eq(bb_job_bake_item(cold, 0, BB_MAPS_BAKED, NULL, NULL, &whole, &err),
                 BB_OK, "%s", err.message);
    const bb_region changed = bb_bake_context_changed(context);
    if (edit > 0) {
      cr_expect(bb__context_last_local(context), "edit %d was baked whole", edit);
      cr_expect(changed.x0 <= 10 && changed.x0 + changed.width > 10 + 3 * edit &&
                    changed.y0 <= 10 && changed.y0 + changed.height > 10 + edit,
                "edit %d: %dx%d at (%d, %d) changed", edit, changed.width, changed.height,
                changed.x0, changed.y0);
    }
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
      const bb_image *a = bb__bake_result_image(&kept, (bb_map_kind)k);
      const bb_image *b = bb__bake_result_image(&whole, (bb_map_kind)k);
      cr_assert_eq(a->pixels != NULL, b->pixels != NULL);
      if (a->pixels)
        cr_expect(
            memcmp(a->pixels, b->pixels,
                   (size_t)a->width * (size_t)a->height * (size_t)a->channels * 4) == 0,
            "edit %d: map %d differs from the job's without a context", edit, k);
    }
    cr_expect_null(kept.vis.pixels, "the job's bake lets vis go, as without a context");
    bb_bake_result_free(&kept);
    bb_bake_result_free(&whole);
    bb_job_free(job);
    bb_job_free(cold);
  }
  bb_bake_context_free(context);
}
