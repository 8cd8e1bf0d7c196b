/* test_job.c: a bake job's plan (bb_job_plan) refusing bad options before
 * any bake. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

TestSuite(job, .init = harness_setup, .fini = harness_teardown, .timeout = 30);

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

/* The slope map's lit preview takes a light as render's --light does:
 * elevation 0..90, a finite azimuth; refused when planned, not baked. */
Test(job, slope_lit_light_is_checked_when_planned) {
  const char *input = height_file();
  bb_job_options o;
  bb_job_options_init(&o);
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
    cr_expect_eq(bb_job_plan(&input, 1, &o, &job, &err), BB_ERR_ARGUMENT, "case %zu", i);
    cr_expect_str_eq(err.message, bad[i].message);
    cr_expect_null(job);
  }
  o.slope_lit_azimuth = -400.0; /* any finite azimuth */
  for (double el = 0.0; el <= 90.0; el += 45.0) {
    o.slope_lit_elevation = el;
    bb_job *job = NULL;
    bb_error err = {{0}};
    cr_expect_eq(bb_job_plan(&input, 1, &o, &job, &err), BB_OK, "%g: %s", el, err.message);
    bb_job_free(job);
  }
}

