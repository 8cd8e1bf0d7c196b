/* install_client.c: a program built against an installed bumpbake the way a
 * user builds one (`cc client.c $(pkg-config --cflags --libs bumpbake)`);
 * tools/check_install.sh compiles and runs it. It bakes two small height
 * fields through the public API and checks values known on paper, so a
 * broken install, header or library fails here. Prints "ok" and exits 0
 * when every check passes, else names the failed checks and exits 1. */
#include <bumpbake.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

enum { SIDE = 32 };

static int failures = 0;

/* Records one check; what says the expected value. */
static void check(int ok, const char *what, double got) {
  printf("%-44s %10.6f%s\n", what, got, ok ? "" : "  FAILED");
  if (!ok)
    failures++;
}

static float value_at(const bb_image *img, int x, int y, int channel) {
  return bb_image_texel(img, x, y)[channel];
}

/* Bakes every map of a SIDE x SIDE field; returns 0 on success. */
static int bake(const bb_image *height, bb_bake_result *result) {
  bb_bake_options o;
  bb_bake_options_init(&o);
  o.height_scale = 8.0f;
  o.rays = 64;
  bb_error err = {{0}};
  bb_status st = bb_bake(height, &o, result, &err);
  if (st != BB_OK) {
    printf("bb_bake failed: %s: %s\n", bb_status_name(st), err.message);
    return 1;
  }
  return 0;
}

/* A flat field: N = (0, 0, 1), ssbump 1/sqrt(3) per channel, ao 1. */
static void check_flat(void) {
  bb_image h = {0};
  bb_bake_result r;
  bb_error err = {{0}};
  if (bb_image_alloc(&h, SIDE, SIDE, 1, &err) != BB_OK || bake(&h, &r)) {
    printf("flat: setup failed: %s\n", err.message);
    failures++;
    bb_image_free(&h);
    return;
  }
  const double s = 1.0 / sqrt(3.0);
  check(fabs(value_at(&r.normal, 5, 7, 2) - 1.0) < 1e-6, "flat: normal z (1)",
        value_at(&r.normal, 5, 7, 2));
  check(fabs(value_at(&r.ssbump, 5, 7, 0) - s) < 1e-5, "flat: ssbump red (0.57735)",
        value_at(&r.ssbump, 5, 7, 0));
  check(fabs(value_at(&r.ao, 5, 7, 0) - 1.0) < 1e-6, "flat: ao (1)",
        value_at(&r.ao, 5, 7, 0));
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* A round bump in the middle: on its right flank the surface falls towards
 * +x, so the normal leans to +x; at its foot the bump blocks rays. */
static void check_bump(void) {
  bb_image h = {0};
  bb_bake_result r;
  bb_error err = {{0}};
  if (bb_image_alloc(&h, SIDE, SIDE, 1, &err) != BB_OK) {
    printf("bump: setup failed: %s\n", err.message);
    failures++;
    return;
  }
  for (int y = 0; y < SIDE; y++)
    for (int x = 0; x < SIDE; x++) {
      double dx = x - SIDE / 2, dy = y - SIDE / 2;
      *bb_image_texel(&h, x, y) = (float)exp(-(dx * dx + dy * dy) / 18.0);
    }
  if (bake(&h, &r)) {
    failures++;
    bb_image_free(&h);
    return;
  }
  const int right = SIDE / 2 + 3, foot = SIDE / 2 + 5;
  check(value_at(&r.normal, right, SIDE / 2, 0) > 0.3f,
        "bump: normal x on the right flank (> 0.3)",
        value_at(&r.normal, right, SIDE / 2, 0));
  check(value_at(&r.ao, foot, SIDE / 2, 0) < 0.95f, "bump: ao at its foot (< 0.95)",
        value_at(&r.ao, foot, SIDE / 2, 0));
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* A bad option fails with BB_ERR_ARGUMENT and says why. */
static void check_error(void) {
  bb_image h = {0};
  bb_error err = {{0}};
  bb_image_alloc(&h, SIDE, SIDE, 1, &err);
  bb_bake_options o;
  bb_bake_options_init(&o);
  o.height_scale = 8.0f;
  o.rays = 0;
  bb_bake_result r;
  bb_status st = bb_bake(&h, &o, &r, &err);
  int ok =
      st == BB_ERR_ARGUMENT && strstr(err.message, "rays must be in 1..65536") != NULL;
  printf("%-44s %s: %s\n", "rays = 0 is refused", bb_status_name(st), err.message);
  if (!ok)
    failures++;
  bb_image_free(&h);
}

int main(void) {
  printf("bumpbake %s (header)\n", BB_VERSION_STRING);
  check_flat();
  check_bump();
  check_error();
  if (failures) {
    printf("install_client: %d check(s) failed\n", failures);
    return 1;
  }
  printf("ok\n");
  return 0;
}
