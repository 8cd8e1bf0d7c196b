/* test_bake_memory.c: bb_command_bake, bake's and normal's bake of a height
 * in memory: the bits of bb__bake_checked with the command's options (and the
 * images and basis handed over), the same through a context (warm and
 * edit-local), only the maps asked handed back; and its refusals. */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "command_words.h"
#include "pattern_image.h"

#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* words checked for images in memory with the maps asked. */
static bb_command *checked(const char *name, const char *const *words, unsigned maps) {
  bb_command *c = command(name, words);
  bb_command_set_in_memory(c, maps);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  return c;
}

static int same(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         a->pixels && b->pixels &&
         memcmp(a->pixels, b->pixels,
                (size_t)a->width * (size_t)a->height * (size_t)a->channels * sizeof(float)) == 0;
}

static void maps_free(bb_image *maps) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    bb_image_free(&maps[k]);
}

/* maps holds exactly the kinds asked, each bit for bit r's. */
static void expect_maps(const bb_image *maps, unsigned asked, const bb_bake_result *r) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    if (asked & BB_MAP_BIT(k))
      cr_expect(same(&maps[k], bb__bake_result_image(r, (bb_map_kind)k)), "map %d differs", k);
    else
      cr_expect_null(maps[k].pixels, "map %d was not asked", k);
  }
}

static const unsigned traced = BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_SSBUMP) |
                               BB_MAP_BIT(BB_MAP_AO) | BB_MAP_BIT(BB_MAP_BENT);

Test(cmd_bake, bits_of_the_stage_bake_with_the_commands_options) {
  const char *words[] = {"--scale", "6", "--rays", "16", "--basis", "dirs:6", "--filter-radius",
                         "1", "--normal-filter", "sobel", NULL};
  bb_command *c = checked("bake", words, traced);
  bb_image h = pattern_image(24, 20, 1, 0.f, 1.f, 0.f);
  bb_image maps[BB_MAP_BAKED_COUNT];
  bb_region changed = {-1, -1, -1, -1};
  bb_error err = {{0}};
  cr_assert_eq(bb_command_bake(c, &h, NULL, NULL, NULL, NULL, NULL, maps, &changed, &err),
               BB_OK, "%s", err.message);
  bb_bake_options o = bb__command_job_options(c)->bake;
  cr_assert_eq(o.basis.count, 6);
  bb_bake_result r;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_OK, "%s", err.message);
  expect_maps(maps, traced, &r);
  cr_expect_eq(maps[BB_MAP_SSBUMP].channels, 6);
  cr_expect(changed.x0 == 0 && changed.y0 == 0 && changed.width == 24 && changed.height == 20);
  bb_bake_result_free(&r);
  maps_free(maps);
  bb_image_free(&h);
  bb_command_free(c);
}

Test(cmd_bake, the_images_and_basis_handed_over) {
  const char *words[] = {"--scale", "4", "--rays", "16", "--brightness", "(array)",
                         "--bounce-albedo", "(array)", NULL};
  bb_command *c = checked("bake", words, traced);
  bb_image h = pattern_image(16, 16, 1, 0.f, 1.f, 0.f);
  bb_image bright = pattern_image(16, 16, 1, 0.2f, 0.9f, 0.5f);
  bb_image albedo = pattern_image(16, 16, 3, 0.1f, 0.8f, 1.0f);
  const double dirs[4][3] = {{0.5, 0.1, 0.8}, {-0.4, 0.4, 0.8}, {0.1, -0.6, 0.7}, {0, 0, 1}};
  bb_basis basis;
  bb_error err = {{0}};
  cr_assert_eq(bb_basis_from_vectors(dirs, 4, &basis, &err), BB_OK, "%s", err.message);
  bb_image maps[BB_MAP_BAKED_COUNT];
  cr_assert_eq(bb_command_bake(c, &h, &albedo, &bright, &basis, NULL, NULL, maps, NULL, &err),
               BB_OK, "%s", err.message);
  bb_bake_options o = bb__command_job_options(c)->bake;
  o.basis = basis;
  o.brightness = &bright;
  o.bounce_albedo_map = &albedo;
  bb_bake_result r;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_OK, "%s", err.message);
  expect_maps(maps, traced, &r);
  cr_expect_eq(maps[BB_MAP_SSBUMP].channels, 4);
  /* without the brightness map the ssbump differs: it was used */
  bb_bake_result plain;
  o.brightness = NULL;
  cr_assert_eq(bb__bake_checked(&h, &o, &plain, &err), BB_OK, "%s", err.message);
  cr_expect_not(same(&maps[BB_MAP_SSBUMP], &plain.ssbump));
  bb_bake_result_free(&plain);
  bb_bake_result_free(&r);
  maps_free(maps);
  bb_image_free(&albedo);
  bb_image_free(&bright);
  bb_image_free(&h);
  bb_command_free(c);
}

Test(cmd_bake, through_a_context_the_bits_of_a_cold_bake) {
  const char *words[] = {"--scale", "5", "--rays", "16", NULL};
  bb_command *c = checked("bake", words, traced);
  bb_bake_context *context = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_bake_context_new(&context, &err), BB_OK, "%s", err.message);
  bb_bake_context_keep(context, 1);
  bb_image h = pattern_image(32, 32, 1, 0.f, 1.f, 0.f);
  bb_image maps[BB_MAP_BAKED_COUNT];
  bb_region changed;
  cr_assert_eq(bb_command_bake(c, &h, NULL, NULL, NULL, NULL, context, maps, &changed, &err),
               BB_OK, "%s", err.message);
  cr_expect_eq(changed.width, 32);
  maps_free(maps);
  bb_image_texel(&h, 20, 9)[0] += 0.25f; /* an edit: baked again around it */
  cr_assert_eq(bb_command_bake(c, &h, NULL, NULL, NULL, NULL, context, maps, &changed, &err),
               BB_OK, "%s", err.message);
  cr_expect(changed.width > 0 && changed.width * changed.height < 32 * 32,
            "changed %dx%d", changed.width, changed.height);
  bb_image cold[BB_MAP_BAKED_COUNT];
  cr_assert_eq(bb_command_bake(c, &h, NULL, NULL, NULL, NULL, NULL, cold, NULL, &err), BB_OK,
               "%s", err.message);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (traced & BB_MAP_BIT(k))
      cr_expect(same(&maps[k], &cold[k]), "map %d differs from the cold bake's", k);
  maps_free(cold);
  maps_free(maps);
  bb_image_free(&h);
  bb_bake_context_free(context);
  bb_command_free(c);
}

Test(cmd_bake, normal_bakes_the_normal_alone) {
  const char *words[] = {"--scale", "3", "--normal-y", "up", NULL};
  bb_command *c = checked("normal", words, BB_MAP_BIT(BB_MAP_NORMAL));
  bb_image h = pattern_image(12, 10, 1, 0.f, 1.f, 0.f);
  bb_image maps[BB_MAP_BAKED_COUNT];
  bb_error err = {{0}};
  cr_assert_eq(bb_command_bake(c, &h, NULL, NULL, NULL, NULL, NULL, maps, NULL, &err), BB_OK,
               "%s", err.message);
  bb_bake_options o = bb__command_job_options(c)->bake;
  cr_expect(o.normal_y_up);
  bb_bake_result r;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_OK, "%s", err.message);
  expect_maps(maps, BB_MAP_BIT(BB_MAP_NORMAL), &r);
  bb_bake_result_free(&r);
  maps_free(maps);
  bb_image_free(&h);
  bb_command_free(c);
}

static int cancel(void *user, long done, long total) {
  (void)user, (void)done, (void)total;
  return 1;
}

Test(cmd_bake, cancelled_hands_back_nothing) {
  const char *words[] = {"--scale", "3", "--rays", "16", NULL};
  bb_command *c = checked("bake", words, traced);
  bb_image h = pattern_image(16, 16, 1, 0.f, 1.f, 0.f);
  bb_image maps[BB_MAP_BAKED_COUNT];
  bb_command_hooks hooks = {0};
  hooks.progress = cancel;
  bb_error err = {{0}};
  cr_expect_eq(bb_command_bake(c, &h, NULL, NULL, NULL, &hooks, NULL, maps, NULL, &err),
               BB_ERR_CANCELLED);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    cr_expect_null(maps[k].pixels);
  bb_image_free(&h);
  bb_command_free(c);
}

/* A trace of the caller's that fails: the bake stops there. */
static bb_status failing_trace(void *user, const bb_pyramid *p, const bb_rayset *rs,
                               const bb_trace_options *o, bb_image *vis, bb_error *err) {
  (void)p, (void)rs, (void)o, (void)vis;
  ++*(int *)user;
  snprintf(err->message, sizeof err->message, "the split trace failed");
  return BB_ERR_IO;
}

Test(cmd_bake, the_callers_trace_in_place_of_its_own) {
  const char *words[] = {"--scale", "3", "--rays", "16", NULL};
  bb_command *c = checked("bake", words, traced);
  bb_image h = pattern_image(16, 16, 1, 0.f, 1.f, 0.f);
  bb_image maps[BB_MAP_BAKED_COUNT];
  int calls = 0;
  bb_command_hooks hooks = {0};
  hooks.trace = failing_trace;
  hooks.trace_user = &calls;
  bb_error err = {{0}};
  cr_expect_eq(bb_command_bake(c, &h, NULL, NULL, NULL, &hooks, NULL, maps, NULL, &err),
               BB_ERR_IO);
  cr_expect_eq(calls, 1);
  cr_expect(strstr(err.message, "the split trace failed") != NULL, "%s", err.message);
  bb_image_free(&h);
  bb_command_free(c);
}

/* bb_command_bake refuses c with message. */
static void expect_refused(bb_command *c, const bb_image *h, const bb_image *bright,
                           const char *message) {
  bb_image maps[BB_MAP_BAKED_COUNT];
  bb_error err = {{0}};
  cr_expect_eq(bb_command_bake(c, h, NULL, bright, NULL, NULL, NULL, maps, NULL, &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, message);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    cr_expect_null(maps[k].pixels);
}

Test(cmd_bake, refusals) {
  bb_image h = pattern_image(8, 8, 1, 0.f, 1.f, 0.f);
  const char *words[] = {"--scale", "3", NULL};
  bb_command *unchecked = command("bake", words);
  expect_refused(unchecked, &h, NULL, "bake: the command is not checked for images in memory");
  bb_command_set_in_memory(unchecked, traced);
  expect_refused(unchecked, &h, NULL, "bake: the command is not checked for images in memory");
  bb_command_free(unchecked);

  const char *files[] = {"h.png", "--scale", "3", NULL};
  bb_command *for_files = command("bake", files);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(for_files, &err), BB_OK, "%s", err.message);
  expect_refused(for_files, &h, NULL, "bake: the command is not checked for images in memory");
  bb_command_free(for_files);

  const char *none[] = {NULL};
  bb_command *other = checked("normal2ssbump", none, 0);
  expect_refused(other, &h, NULL, "normal2ssbump bakes no height in memory");
  bb_command_free(other);

  bb_command *c = checked("bake", words, traced);
  expect_refused(c, NULL, NULL, "bake: a height is needed");
  expect_refused(c, &h, &h, "bake: an image for --brightness, which is not set");
  bb_command_set_spelling(c, BB_SPELLING_KEYWORDS);
  expect_refused(c, &h, &h, "bake: an image for brightness, which is not set");
  bb_command_free(c);

  const char *bright[] = {"--scale", "3", "--brightness", "(array)", NULL};
  c = checked("bake", bright, traced);
  expect_refused(c, &h, NULL, "bake: --brightness is set but its image is missing");
  bb_command_free(c);
  bb_image_free(&h);
}
