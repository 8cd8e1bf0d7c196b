/* test_cli_bounce.c: bake's inter-reflection and brightness maps and
 * render's relief view, run as a program: the options reach the library
 * through the job, the maps are inputs (refused as outputs, listed in
 * depfiles), and what each changes is what the library promises. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"

#include <math.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

TestSuite(cli_bounce, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

#define FAST "--scale", "6", "--slices", "8", "--filter-radius", "2"

/* Pits and ridges: enough relief for light to bounce. */
static void height_file(const char *path) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 24, 24, 1, NULL), BB_OK);
  for (int i = 0; i < 24 * 24; i++)
    h.pixels[i] = (float)(0.5 + 0.4 * sin(0.8 * (i % 24)) * cos(0.6 * (i / 24)));
  harness_write(path, &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
}

static void grey_file(const char *path, float value) {
  bb_image g;
  cr_assert_eq(bb_image_alloc(&g, 24, 24, 1, NULL), BB_OK);
  for (int i = 0; i < 24 * 24; i++)
    g.pixels[i] = value;
  harness_write(path, &g, BB_DEPTH_FLOAT, BB_RANGE_UNIT);
  bb_image_free(&g);
}

static void run_ok(const char *const *args) {
  cli_result r = harness_run(args);
  cr_assert_eq(r.code, 0, "%s %s: %s", args[0], args[1], r.err);
  cli_result_free(&r);
}

Test(cli_bounce, bounce_lightens_ao_and_zero_changes_nothing) {
  height_file(tmp("h.png"));
  run_ok((const char *[]){"bake", tmp("h.png"), FAST, "--ao", tmp("a0.exr"), NULL});
  run_ok((const char *[]){"bake", tmp("h.png"), FAST, "--bounce", "0", "--ao", tmp("z.exr"), NULL});
  run_ok((const char *[]){"bake", tmp("h.png"), FAST, "--bounce", "0.6", "--ao", tmp("b.exr"), NULL});
  bb_image a0 = harness_read(tmp("a0.exr"), NULL), z = harness_read(tmp("z.exr"), NULL);
  bb_image b = harness_read(tmp("b.exr"), NULL);
  cr_expect_eq(memcmp(a0.pixels, z.pixels, 24 * 24 * sizeof(float)), 0,
               "--bounce 0 changed a pixel");
  double gained = 0;
  for (int i = 0; i < 24 * 24; i++) {
    cr_expect(b.pixels[i] >= a0.pixels[i] && b.pixels[i] <= 1.0f, "texel %d", i);
    gained += b.pixels[i] - a0.pixels[i];
  }
  cr_expect_gt(gained, 0.0, "the bounce added no light");
  bb_image_free(&a0);
  bb_image_free(&z);
  bb_image_free(&b);
}

/* --json gives the bounce as docs/commands/bake.md says: rho and the
 * bounces asked among the parameters, its seconds among the stages (a
 * bounce bake's stages left most of its time out); none without it. */
Test(cli_bounce, json_gives_the_bounce_and_its_seconds) {
  height_file(tmp("h.png"));
  cli_result r = harness_run((const char *[]){"bake", tmp("h.png"), FAST, "--bounce", "0.6",
                                              "--bounces", "2", "--ao", tmp("b.exr"), "--json",
                                              NULL});
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "\"threads\":") && strstr(r.out, ",\"bounce\":0.6,\"bounces\":2}"),
            "%s", r.out);
  const char *seconds = strstr(r.out, "\"seconds\":{");
  cr_assert_not_null(seconds, "%s", r.out);
  double trace = -1, bounce = -1;
  const char *t = strstr(seconds, "\"trace\":");
  cr_assert_not_null(t, "%s", r.out);
  cr_expect_eq(sscanf(t, "\"trace\":%lf,\"bounce\":%lf", &trace, &bounce), 2, "%s", r.out);
  cr_expect_gt(bounce, 0.0, "%s", r.out);
  cli_result_free(&r);
  r = harness_run((const char *[]){"bake", tmp("h.png"), FAST, "--ao", tmp("a.exr"), "--json",
                                   NULL});
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(!strstr(r.out, "bounce"), "no bounce, no key: %s", r.out);
  cli_result_free(&r);
}

/* A brightness of 0.5 halves an ssbump that nothing clips; the maps are
 * inputs: an output over one is refused, and the depfile lists them. */
Test(cli_bounce, brightness_and_albedo_maps_are_inputs) {
  height_file(tmp("h.png"));
  grey_file(tmp("half.exr"), 0.5f);
  grey_file(tmp("albedo.exr"), 0.4f);
  run_ok((const char *[]){"bake", tmp("h.png"), FAST, "--ssbump", tmp("s.exr"), NULL});
  run_ok((const char *[]){"bake", tmp("h.png"), FAST, "--brightness", tmp("half.exr"),
                          "--bounce-albedo", tmp("albedo.exr"), "--ssbump", tmp("sb.exr"),
                          "--depfile", tmp("d.d"), NULL});
  run_ok((const char *[]){"bake", tmp("h.png"), FAST, "--brightness", tmp("half.exr"),
                          "--ssbump", tmp("sh.exr"), NULL});
  bb_image s = harness_read(tmp("s.exr"), NULL), sh = harness_read(tmp("sh.exr"), NULL);
  for (int i = 0; i < 24 * 24 * 3; i++)
    cr_expect_float_eq(sh.pixels[i], 0.5f * s.pixels[i], 1e-6, "value %d", i);
  bb_image_free(&s);
  bb_image_free(&sh);
  FILE *f = fopen(tmp("d.d"), "r");
  cr_assert_not_null(f);
  char *text = harness_slurp(f);
  fclose(f);
  cr_expect(strstr(text, "half.exr") && strstr(text, "albedo.exr"), "depfile: %s", text);
  free(text);
  const char *over[] = {"bake", tmp("h.png"), FAST, "--brightness", tmp("half.exr"), "--ssbump",
                        tmp("half.exr"), NULL};
  harness_expect_refusal(NULL, over, 1, "would overwrite the input", 1);
}

Test(cli_bounce, relief_view_renders) {
  height_file(tmp("h.png"));
  run_ok((const char *[]){"render", tmp("h.png"), "--scale", "6", "--rays", "16", "--view",
                          "270,20", "--relief", "-o", tmp("r.png"), NULL});
  run_ok((const char *[]){"render", tmp("h.png"), "--scale", "6", "--rays", "16", "--view",
                          "270,20", "-o", tmp("flat.png"), NULL});
  bb_image r = harness_read(tmp("r.png"), NULL), f = harness_read(tmp("flat.png"), NULL);
  cr_expect_eq(r.width, f.width);
  cr_expect_neq(memcmp(r.pixels, f.pixels, (size_t)r.width * (size_t)r.height * 3 * sizeof(float)),
                0, "relief changed nothing");
  bb_image_free(&r);
  bb_image_free(&f);
}

/* On a terminal the bar runs once from 0 to 100% over the trace and every
 * pass of the bounce, and is cleared before the first "wrote" line (not
 * after it). A bake long enough for the bar to show (it waits a second):
 * 256 x 256 on one thread with --bounce. */
Test(cli_bounce, the_bar_is_monotone_and_cleared_before_wrote) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 256, 256, 1, NULL), BB_OK);
  for (int i = 0; i < 256 * 256; i++)
    h.pixels[i] = (float)(0.5 + 0.4 * sin(0.31 * (i % 256)) * cos(0.23 * (i / 256)));
  harness_write(tmp("big.png"), &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
  int master;
  const pid_t pid = forkpty(&master, NULL, NULL, NULL);
  cr_assert_neq(pid, -1, "forkpty");
  if (pid == 0) {
    execl(harness_binary(), "bumpbake", "bake", tmp("big.png"), "--scale", "24", "--bounce",
          "0.5", "--threads", "1", "--ao", tmp("big_ao.png"), (char *)NULL);
    _exit(127);
  }
  size_t cap = 1 << 20, got = 0;
  char *out = malloc(cap);
  cr_assert_not_null(out);
  ssize_t n;
  while (got + 1 < cap && (n = read(master, out + got, cap - 1 - got)) > 0) /* EIO at the end */
    got += (size_t)n;
  out[got] = '\0';
  close(master);
  int status;
  waitpid(pid, &status, 0);
  cr_assert(WIFEXITED(status) && WEXITSTATUS(status) == 0, "bake failed: %s", out);
  const char *wrote = strstr(out, "wrote ao");
  cr_assert_not_null(wrote, "no wrote line: %s", out);
  int last = -1, bars = 0;
  for (const char *c = strstr(out, "bake ["); c; c = strstr(c + 1, "bake [")) {
    const char *close = strchr(c, ']');
    cr_assert_not_null(close);
    int percent;
    cr_assert_eq(sscanf(close + 1, " %d%%", &percent), 1, "%s", c);
    cr_expect_geq(percent, last, "the bar went back from %d%% to %d%%", last, percent);
    cr_expect_lt(c, wrote, "a bar after the wrote line");
    last = percent, bars++;
  }
  cr_assert_gt(bars, 0, "no bar was drawn (the bake took under a second?): %s", out);
  const char *clear = "\r\033[K";
  cr_expect(wrote - out >= (long)strlen(clear) &&
                !strncmp(wrote - strlen(clear), clear, strlen(clear)),
            "the bar is not cleared right before the wrote line");
  free(out);
}
