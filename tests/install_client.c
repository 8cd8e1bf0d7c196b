/* install_client.c: a program built against an installed bumpbake the way a
 * user builds one (`cc client.c $(pkg-config --cflags --libs bumpbake)`);
 * tools/check_install.sh compiles and runs it. It bakes two small height
 * fields through the public API (a bake command on a height in memory,
 * bb_command_bake) and checks values known on paper, so a
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

/* A bake command on a height in memory with --scale 8 --rays 64, set and
 * checked; NULL (and the reason printed) when the library refuses it. */
static bb_command *bake_command(void) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  bb_status st = bb_command_new("bake", &c, &err);
  if (st == BB_OK)
    st = bb_command_set(c, "scale", "8", &err);
  if (st == BB_OK)
    st = bb_command_set(c, "rays", "64", &err);
  if (st == BB_OK) {
    bb_command_set_in_memory(c, BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_SSBUMP) |
                                    BB_MAP_BIT(BB_MAP_AO));
    st = bb_command_check(c, &err);
  }
  if (st != BB_OK) {
    printf("bake command refused: %s: %s\n", bb_status_name(st), err.message);
    bb_command_free(c);
    return NULL;
  }
  return c;
}

/* Bakes the normal, ssbump and ao of a SIDE x SIDE field into maps (by
 * bb_map_kind); returns 0 on success. */
static int bake(const bb_image *height, bb_image maps[BB_MAP_BAKED_COUNT]) {
  bb_command *c = bake_command();
  if (!c)
    return 1;
  bb_error err = {{0}};
  bb_status st = bb_command_bake(c, height, NULL, NULL, NULL, NULL, NULL, maps, NULL, &err);
  bb_command_free(c);
  if (st != BB_OK) {
    printf("bb_command_bake failed: %s: %s\n", bb_status_name(st), err.message);
    return 1;
  }
  return 0;
}

static void maps_free(bb_image maps[BB_MAP_BAKED_COUNT]) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    bb_image_free(&maps[k]);
}

/* A flat field: N = (0, 0, 1), ssbump 1/sqrt(3) per channel, ao 1. */
static void check_flat(void) {
  bb_image h = {0};
  bb_image r[BB_MAP_BAKED_COUNT];
  bb_error err = {{0}};
  if (bb_image_alloc(&h, SIDE, SIDE, 1, &err) != BB_OK || bake(&h, r)) {
    printf("flat: setup failed: %s\n", err.message);
    failures++;
    bb_image_free(&h);
    return;
  }
  const double s = 1.0 / sqrt(3.0);
  check(fabs(value_at(&r[BB_MAP_NORMAL], 5, 7, 2) - 1.0) < 1e-6, "flat: normal z (1)",
        value_at(&r[BB_MAP_NORMAL], 5, 7, 2));
  check(fabs(value_at(&r[BB_MAP_SSBUMP], 5, 7, 0) - s) < 1e-5, "flat: ssbump red (0.57735)",
        value_at(&r[BB_MAP_SSBUMP], 5, 7, 0));
  check(fabs(value_at(&r[BB_MAP_AO], 5, 7, 0) - 1.0) < 1e-6, "flat: ao (1)",
        value_at(&r[BB_MAP_AO], 5, 7, 0));
  maps_free(r);
  bb_image_free(&h);
}

/* A round bump in the middle: on its right flank the surface falls towards
 * +x, so the normal leans to +x; at its foot the bump blocks rays. */
static void check_bump(void) {
  bb_image h = {0};
  bb_image r[BB_MAP_BAKED_COUNT];
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
  if (bake(&h, r)) {
    failures++;
    bb_image_free(&h);
    return;
  }
  const int right = SIDE / 2 + 3, foot = SIDE / 2 + 5;
  check(value_at(&r[BB_MAP_NORMAL], right, SIDE / 2, 0) > 0.3f,
        "bump: normal x on the right flank (> 0.3)",
        value_at(&r[BB_MAP_NORMAL], right, SIDE / 2, 0));
  check(value_at(&r[BB_MAP_AO], foot, SIDE / 2, 0) < 0.95f, "bump: ao at its foot (< 0.95)",
        value_at(&r[BB_MAP_AO], foot, SIDE / 2, 0));
  maps_free(r);
  bb_image_free(&h);
}

/* A bad option fails with BB_ERR_ARGUMENT and says why. */
static void check_error(void) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  bb_status st = bb_command_new("bake", &c, &err);
  if (st == BB_OK)
    st = bb_command_set(c, "rays", "0", &err);
  if (st == BB_OK) {
    bb_command_set_in_memory(c, BB_MAP_BIT(BB_MAP_AO));
    st = bb_command_check(c, &err);
  }
  int ok =
      st == BB_ERR_ARGUMENT && strstr(err.message, "rays must be in 1..65536") != NULL;
  printf("%-44s %s: %s\n", "rays = 0 is refused", bb_status_name(st), err.message);
  if (!ok)
    failures++;
  bb_command_free(c);
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
