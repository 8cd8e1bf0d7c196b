/* test_cli_memory.c: a bake's memory estimate against the peak the bake
 * really reaches, and a bake too large for what is available refused with
 * the figures, before anything is allocated, instead of being killed. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath (cli_harness.h) */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "job/bake_rows.h"
#include "bumpbake.h"
#include "cli_harness.h"
#include "job/job_internal.h"
#include "image/image_write.h"

#include <math.h>
#include <stdint.h>

TestSuite(cli_memory, .init = harness_setup, .fini = harness_teardown);

enum { SIDE = 1536 };

/* A rough 16-bit height of SIDE x SIDE. */
static void write_height(const char *path, int side) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, side, side, 1, NULL), BB_OK);
  uint64_t s = 88172645463325252ULL;
  for (size_t i = 0; i < (size_t)side * (size_t)side; i++) {
    s ^= s << 13, s ^= s >> 7, s ^= s << 17;
    const int x = (int)(i % (size_t)side), y = (int)(i / (size_t)side);
    img.pixels[i] = (float)(0.5 + 0.3 * sin(x * 0.05) * cos(y * 0.04) +
                            0.2 * (double)(s >> 11) / 9007199254740992.0);
  }
  bb_write_options wo = {BB_DEPTH_16, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(path, &img, &wo, NULL), BB_OK);
  bb_image_free(&img);
}

/* The job's estimate for `bake input args...` as planned by the library. */
static double job_estimate(const char *input, unsigned outputs, int side) {
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 32.0f;
  o.bake.slices = 2;
  o.bake.trace.threads = 2;
  static const char *names[] = {"n.png", "w.png", "s.png", "a.png", "b.png", "f.png"};
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (outputs & BB_MAP_BIT(k)) o.paths[k] = tmp(names[k]);
  bb_job *job = NULL;
  bb_error err;
  cr_assert_eq(bb__job_plan_options(&input, 1, &o, &job, &err), BB_OK, "%s", err.message);
  const double bytes = bb__job_memory(job, &job->items[0], side, side, 1);
  bb_job_free(job);
  return bytes;
}

static long peak_kib(const char *input, unsigned outputs) {
  static const char *flags[] = {"--normal", "--weights", "--ssbump", "--ao", "--bent",
                                "--filtered"};
  static const char *names[] = {"n.png", "w.png", "s.png", "a.png", "b.png", "f.png"};
  const char *args[32] = {"bake", input, "--scale", "32", "--slices", "2", "--threads", "2",
                          "-q"};
  int n = 9;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (outputs & BB_MAP_BIT(k)) args[n++] = flags[k], args[n++] = tmp(names[k]);
  args[n] = NULL;
  cli_result r = harness_run_exec(args); /* the program's own peak, not a fork's */
  cr_assert_eq(r.code, 0, "%s", r.err);
  const long kib = r.max_rss_kib;
  cli_result_free(&r);
  return kib;
}

Test(cli_memory, the_estimate_bounds_the_peak_closely) {
  const char *big = tmp("big.png"), *tiny = tmp("tiny.png");
  write_height(big, SIDE);
  write_height(tiny, 8);
  const unsigned ssbump_ao = BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_AO);
  const unsigned sets[] = {ssbump_ao, ssbump_ao | BB_MAP_BIT(BB_MAP_NORMAL),
                           BB_MAP_BIT(BB_MAP_NORMAL), BB_MAPS_BAKED};
  const double texels = (double)SIDE * SIDE;
  for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++) {
    /* the program, its libraries and OpenImageIO's plugins: a bake of 8 x 8 */
    const long base = peak_kib(tiny, sets[i]);
    const double used = (double)(peak_kib(big, sets[i]) - base) * 1024.0;
    const double estimate = job_estimate(big, sets[i], SIDE);
    cr_expect_gt(estimate, used, "outputs 0x%x: estimate %.1f bytes a texel, used %.1f", sets[i],
                 estimate / texels, used / texels);
    cr_expect_lt(estimate, 1.35 * used + 48.0 * 1024 * 1024,
                 "outputs 0x%x: estimate %.1f bytes a texel, far over the %.1f used", sets[i],
                 estimate / texels, used / texels);
  }
}

Test(cli_memory, a_bake_over_the_memory_left_is_refused_with_the_figures) {
  const char *big = tmp("big.png");
  write_height(big, 4096);
  /* the program and OpenImageIO take 0.4-0.5 GiB of address space; 900
   * MiB leaves less than the ~0.6 GiB this bake takes */
  const run_limits lim = {-1,
#ifdef __SANITIZE_ADDRESS__
                          -1
#else
                          900L << 20
#endif
  };
#ifdef __SANITIZE_ADDRESS__
  cr_skip_test("ASan reserves terabytes of address space: no RLIMIT_AS here");
#endif
  cli_result r = harness_run_limited(
      NULL, &lim,
      (const char *[]){"bake", big, "--scale", "32", "-o", tmp("m"), NULL});
  cr_expect_eq(r.code, 1, "exit %d: %s", r.code, r.err);
  cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
  cr_expect(strstr(r.err, "big.png: a 4096 x 4096 bake needs about") &&
                strstr(r.err, "of memory;") && strstr(r.err, "is available (RLIMIT_AS)"),
            "%s", r.err);
  cr_expect_lt(r.cpu_seconds, 5.0, "refused before the bake: %.1f s of CPU", r.cpu_seconds);
  cr_expect_not(file_exists(tmp("m_ao.png")));
  cli_result_free(&r);
}
