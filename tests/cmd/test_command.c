/* test_command.c: the commands described once (bb_command_*): options set
 * through their parsers, their ranges checked against the library's one
 * range each, the rules between options, the command spelled back as text
 * (what provenance records, and a hand-over that reads back the same). */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include "bumpbake.h"
#include "bumpbake_cluster.h"
#include "cmd/cmd_internal.h"
#include "hostile_headers.h"

#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static bb_command *command(const char *name, const char *const *words) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new(name, &c, &err), BB_OK, "%s", err.message);
  for (int i = 0; words && words[i]; i++) {
    if (words[i][0] != '-') {
      cr_assert_eq(bb_command_add_input(c, words[i], &err), BB_OK, "%s", err.message);
      continue;
    }
    const bb_option_info *o = bb_option_find(bb_command_describe(c), words[i] + 2, 0);
    cr_assert_not_null(o, "%s", words[i]);
    const char *value = o->type == BB_OPTION_FLAG ? NULL : words[++i];
    cr_assert_eq(bb_command_set(c, o->name, value, &err), BB_OK, "%s: %s", words[i],
                 err.message);
  }
  return c;
}

/* A refusal by set or check, and its words. */
static void refused(const char *name, const char *const *words, const char *message) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new(name, &c, &err), BB_OK);
  bb_status st = BB_OK;
  for (int i = 0; words[i] && st == BB_OK; i++) {
    if (words[i][0] != '-') {
      st = bb_command_add_input(c, words[i], &err);
      continue;
    }
    const bb_option_info *o = bb_option_find(bb_command_describe(c), words[i] + 2, 0);
    const char *value = o && o->type != BB_OPTION_FLAG ? words[++i] : NULL;
    st = bb_command_set(c, words[i - (value ? 1 : 0)] + 2, value, &err);
  }
  if (st == BB_OK)
    st = bb_command_check(c, &err);
  cr_expect_eq(st, BB_ERR_ARGUMENT, "%s: refused: %s", message, err.message);
  cr_expect_str_eq(err.message, message);
  bb_command_free(c);
}

/* What provenance records: the options that change the output, in the
 * order of --help, spelled as typed; -q, --json, --threads, --depfile and
 * a batch's --force are left out, since they change no byte. */
Test(cmd, recorded_text_spells_what_changes_the_output) {
  const char *words[] = {"heights/a.png", "--scale", "16", "--out-dir", "out", "--maps",
                         "normal,ao", "--threads", "2", "--json", "--quiet", "--force",
                         "--depfile", "d.d", NULL};
  bb_command *c = command("bake", words);
  cr_assert_eq(bb_command_check(c, NULL), BB_OK);
  char *text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake heights/a.png --scale 16 --out-dir out --maps normal,ao");
  free(text);
  text = bb_command_text(c, "b.png", 0); /* every option but the client's own */
  cr_expect_str_eq(text, "bumpbake bake b.png --scale 16 --threads 2 --out-dir out --maps "
                         "normal,ao --force --depfile d.d");
  free(text);
  bb_command_free(c);

  const char *more[] = {"a.png", "--scale", "0.1", "--rays", "64", "--channel", "a",
                        "--depth", "16", "--mips", "--out-dir", "out", "--name",
                        "{kind}/{stem}.tif", NULL};
  c = command("bake", more);
  text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake a.png --scale 0.1 --rays 64 --channel a --depth 16 "
                         "--mips --out-dir out --name '{kind}/{stem}.tif'");
  free(text);
  bb_command_free(c);

  /* quoted for a POSIX shell, inputs and values alike */
  const char *odd[] = {"my rock.png", "--scale", "8", "--brightness", "it's.png", "--normal",
                       "$HOME/n.png", NULL};
  c = command("bake", odd);
  text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake 'my rock.png' --scale 8 --brightness 'it'\\''s.png' "
                         "--normal '$HOME/n.png'");
  free(text);
  text = bb_command_text(c, "x;touch PWNED;y.png", BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake 'x;touch PWNED;y.png' --scale 8 --brightness "
                         "'it'\\''s.png' --normal '$HOME/n.png'");
  free(text);
  bb_command_free(c);
}

/* The engine textures' settings and the material come last, as in --help,
 * spelled as the parser reads them back. */
Test(cmd, recorded_text_spells_the_texture_options) {
  const char *words[] = {"h.png", "--scale", "64", "--ssbump", "m/rock-ssbump.vtf",
                         "--texture-format", "dxt5", "--vtf-version", "3", "--vtf-flags",
                         "4", "--nomip", "--fast-compression", "--vmt", "m/rock.vmt",
                         "--materials", "m", "--basetexture", "m/rock.vtf", NULL};
  bb_command *c = command("bake", words);
  cr_assert_eq(bb_command_check(c, NULL), BB_OK);
  char *text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake h.png --scale 64 --ssbump m/rock-ssbump.vtf "
                         "--texture-format bc3 --vtf-version 7.3 --vtf-flags 0x4 --nomip "
                         "--fast-compression --vmt m/rock.vmt --materials m "
                         "--basetexture m/rock.vtf");
  free(text);
  bb_command_free(c);
}

/* A command's text reads back into the same command (the hand-over of a
 * planned command to another process). */
Test(cmd, text_reads_back_the_same) {
  const char *words[] = {"h.png", "--scale", "36.8083", "--rays", "100", "--bias", "0.3",
                         "--power", "2.5", "--basis", "dirs:6", "--normal-filter", "sobel",
                         "--normal-y", "up", "--clamp", "--channel", "luma", "--bounce",
                         "0.25", "--bounces", "3", "--ssbump", "s.exr", "--slope", "sl.png",
                         "--lit", "135,45.5", "--threads", "3", NULL};
  bb_command *c = command("bake", words);
  cr_assert_eq(bb_command_check(c, NULL), BB_OK);
  char *text = bb_command_text(c, NULL, 0);
  /* split the text back into words (no word here holds a blank) */
  char *copy = strdup(text), *argv[64];
  int n = 0;
  for (char *w = strtok(copy, " "); w && n < 63; w = strtok(NULL, " "))
    argv[n++] = w;
  argv[n] = NULL;
  cr_assert(n > 3 && !strcmp(argv[0], "bumpbake") && !strcmp(argv[1], "bake"));
  bb_command *back = command("bake", (const char *const *)argv + 2);
  char *again = bb_command_text(back, NULL, 0);
  cr_expect_str_eq(again, text);
  const bb_command_options *a = bb__command_options_of(c), *b = bb__command_options_of(back);
  cr_expect_eq(a->job.bake.height_scale, b->job.bake.height_scale);
  cr_expect_eq(a->job.slope_lit_elevation, b->job.slope_lit_elevation);
  cr_expect_eq(a->job.bake.basis.count, 6);
  free(again);
  free(text);
  free(copy);
  bb_command_free(back);
  bb_command_free(c);
}

/* Each option's range is its parameter's one range: the help spells it
 * from the library's constants, the check refuses outside it in the same
 * words for every client. */
Test(cmd, ranges_are_the_library_constants) {
  const bb_command_info *bake = bb_command_info_find("bake");
  char text[160];
  char expect[64];
  bb_option_range_text(bb_option_find(bake, "rays", 0), text, sizeof text);
  snprintf(expect, sizeof expect, "1..%d", BB_MAX_RAYS);
  cr_expect_str_eq(text, expect);
  bb_option_range_text(bb_option_find(bake, "bounces", 0), text, sizeof text);
  snprintf(expect, sizeof expect, "0..%d", BB_MAX_BOUNCES);
  cr_expect_str_eq(text, expect);
  double min, max;
  int exclusive;
  cr_assert(bb_option_bounds(bb_option_find(bake, "filter_radius", 0), &min, &max, &exclusive));
  cr_expect(min == 0 && max == BB_MAX_FILTER_RADIUS && !exclusive);
  cr_assert(bb_option_bounds(bb_option_find(bake, "scale", 0), &min, &max, &exclusive));
  cr_expect(min == 0 && exclusive);
  const bb_command_info *render = bb_command_info_find("render");
  bb_option_range_text(bb_option_find(render, "specular", 0), text, sizeof text);
  cr_expect_str_eq(text, "0..100000");

  refused("bake", (const char *[]){"h.png", "--scale", "1", "--rays", "0", NULL},
          "--rays must be in 1..65536 (got 0)");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--slices", "0", NULL},
          "--slices must be in 1..256 (got 0)");
  refused("bake", (const char *[]){"h.png", "--scale", "-1", NULL},
          "--scale must be > 0 (got -1)");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--bounce", "1.5", "--ao",
                                   "a.png", NULL},
          "--bounce must be in 0..1 (got 1.5)");
  refused("render", (const char *[]){"--ssbump", "s.png", "--output", "x.png", "--specular",
                                     "1e6", NULL},
          "--specular must be in 0..100000 (got 1e6)");
  refused("render", (const char *[]){"--ssbump", "s.png", "--output", "x.png", "--light",
                                     "0,95", NULL},
          "--light elevation must be in 0..90 (got 95)");
  /* a denormal is a number (5e-324 was "needs a number") */
  const char *tiny[] = {"h.png", "--scale", "1", "--bounce", "5e-324", "--ao", "a.png", NULL};
  bb_command *c = command("bake", tiny);
  cr_expect_eq(bb_command_check(c, NULL), BB_OK);
  bb_command_free(c);
}

/* An option of the other use refused by the command or its plan (the
 * job's rule, bb__job_plan_options), in words naming it or --out-dir. */
static void refused_in_use(const char *const *base, const bb_option_info *o) {
  static const char *const values[] = {[BB_OPTION_PATH] = "x.png",
                                       [BB_OPTION_WORDS] = "normal",
                                       [BB_OPTION_TEXT] = "{stem}_{kind}.png",
                                       [BB_OPTION_NUMBERS] = "45,30"};
  bb_command *c = command("bake", base);
  bb_error err = {{0}};
  const char *value = o->type == BB_OPTION_FLAG ? NULL : values[o->type];
  if (o->type != BB_OPTION_FLAG)
    cr_assert_not_null(value, "--%s: no test value for its type", o->name);
  bb_status st = bb_command_set(c, o->name, value, &err);
  if (st == BB_OK)
    st = bb_command_check(c, &err);
  bb_job *job = NULL;
  if (st == BB_OK)
    st = bb_command_plan(c, NULL, &job, &err);
  char spelled[64];
  snprintf(spelled, sizeof spelled, "--%s", o->name);
  cr_expect_eq(st, BB_ERR_ARGUMENT, "--%s in the other use: accepted", o->name);
  cr_expect(strstr(err.message, spelled) || strstr(err.message, "--out-dir"),
            "--%s: refused in other words: %s", o->name, err.message);
  bb_job_free(job);
  bb_command_free(c);
}

/* Every option the descriptions give to one use (a batch's, a single
 * bake's) is refused in the other: the rows and the job's rules agree. */
Test(cmd, each_option_of_one_use_is_refused_in_the_other) {
  const bb_command_info *bake = bb_command_info_find("bake");
  const char *single[] = {"h.png", "--scale", "1", "--output", "p", NULL};
  const char *batch[] = {"h.png", "--scale", "1", "--out-dir", "o", NULL};
  int walked[3] = {0};
  for (int i = 0; i < bake->option_count; i++) {
    const bb_option_info *o = bb_command_option(bake, i);
    if (o->mode == BB_MODE_BATCH)
      refused_in_use(single, o);
    else if (o->mode == BB_MODE_SINGLE && strcmp(o->name, "output") != 0)
      refused_in_use(batch, o);
    walked[o->mode]++;
  }
  cr_expect_geq(walked[BB_MODE_BATCH], 4, "name, maps, keep-going, force");
  cr_expect_geq(walked[BB_MODE_SINGLE], 10, "-o, the six maps, --slope, --lit, --vmt...");
}

/* An option given where it does nothing is refused, naming what it needs. */
Test(cmd, options_that_do_nothing_are_refused) {
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--normal", "n.png",
                                   "--texture-format", "bc3", NULL},
          "--texture-format does nothing without a .vtf or .dds output");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--normal", "n.dds",
                                   "--vtf-version", "7.3", NULL},
          "--vtf-version does nothing without a .vtf output");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--normal", "n.png", "--nomip",
                                   NULL},
          "--nomip does nothing without a .vtf or .dds output");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--ao", "a.png", "--bounces", "2",
                                   NULL},
          "--bounces does nothing without --bounce RHO or --bounce-albedo FILE");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--normal", "n.png", "--bounce",
                                   "0.5", NULL},
          "--bounce does nothing without a traced map (--ssbump, --ao, --bent)");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--ao", "a.png", "--brightness",
                                   "b.png", NULL},
          "--brightness does nothing without an ssbump or weights map");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--ao", "a.png", "--materials", "",
                                   NULL},
          "--materials needs a path (got '')");
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--ao", "a.png", "--force", NULL},
          "--force does nothing without --out-dir DIR");
  /* a batch's name template stands for its outputs */
  const char *batch[] = {"h.png", "--scale", "1", "--out-dir", "o", "--name",
                         "{stem}_{kind}.vtf", "--texture-format", "bc3", NULL};
  bb_command *c = command("bake", batch);
  cr_expect_eq(bb_command_check(c, NULL), BB_OK);
  bb_command_free(c);
}

/* A command made of another's settings (serve's page's, as the bake of
 * the files a write names): the inputs, the options at other values than
 * the new command's defaults (--rays under --slices too: the files record
 * it), not the files the source writes; one that does nothing in it is
 * dropped by the check where the caller's own is refused. */
Test(cmd, derive_takes_the_settings_and_drops_what_does_nothing) {
  const char *words[] = {"h.png", "--scale", "8", "--rays", "32", "--slices", "8",
                         "--bias", "0.25", "--power", "1", "--brightness", "b.png",
                         "--normal", "n.png", "--ssbump", "s.png", NULL};
  bb_command *from = command("serve", words);
  bb_command *bake = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_derive(from, "bake", &bake, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(bb_command_describe(bake)->name, "bake");
  cr_expect_str_eq(bb_command_input(bake, 0), "h.png");
  cr_expect(bb_command_given(bake, "scale") && bb_command_given(bake, "rays") &&
            bb_command_given(bake, "slices") && bb_command_given(bake, "bias"));
  cr_expect(!bb_command_given(bake, "power"), "--power 1 is bake's default");
  cr_expect(!bb_command_given(bake, "normal") && !bb_command_given(bake, "ssbump"),
            "the files the source writes are not taken");
  cr_assert_eq(bb_command_set(bake, "ao", "a.png", &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_check(bake, &err), BB_OK, "%s", err.message);
  cr_expect(!bb_command_given(bake, "brightness"), "an ao alone: --brightness dropped");
  char *text = bb_command_text(bake, NULL, BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake h.png --scale 8 --rays 32 --slices 8 --bias 0.25 "
                         "--ao a.png");
  free(text);
  /* set by the caller, the same option is refused as on a command line */
  cr_assert_eq(bb_command_set(bake, "brightness", "b.png", &err), BB_OK);
  cr_expect_eq(bb_command_check(bake, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--brightness does nothing without an ssbump or weights map");
  bb_command_free(bake);
  /* an ssbump named: it does something, and is kept */
  cr_assert_eq(bb_command_derive(from, "bake", &bake, &err), BB_OK);
  cr_assert_eq(bb_command_set(bake, "ssbump", "s2.png", &err), BB_OK);
  cr_assert_eq(bb_command_check(bake, &err), BB_OK, "%s", err.message);
  cr_expect(bb_command_given(bake, "brightness"));
  bb_command_free(bake);
  cr_expect_eq(bb_command_derive(from, "bak", &bake, &err), BB_ERR_ARGUMENT);
  cr_expect_null(bake);
  cr_expect(strstr(err.message, "unknown command 'bak'"), "%s", err.message);
  bb_command_free(from);
}

/* The file each map goes to, by -o PREFIX's rule (bb_command_map_file):
 * a map's own file, else PREFIX_KIND.png for the maps -o writes; serve's
 * write, with no output named, takes HEIGHT without its extension for
 * PREFIX (filled in by the check, as other commands' default names). */
static void expect_map_files(const char *name, const char *const *words,
                             const char *const want[BB_MAP_BAKED_COUNT]) {
  bb_command *c = command(name, words);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    char *path = (char *)"unset";
    cr_assert_eq(bb_command_map_file(c, (bb_map_kind)k, &path, &err), BB_OK, "%s",
                 err.message);
    if (want[k])
      cr_expect_str_eq(path ? path : "(null)", want[k], "%s %s: map %d", name, words[2], k);
    else
      cr_expect_null(path, "%s %s: map %d: %s", name, words[2], k, path);
    free(path);
  }
  bb_command_free(c);
}

Test(cmd, map_files_follow_the_prefix_rule) {
  const char *stem[BB_MAP_BAKED_COUNT] = {[BB_MAP_NORMAL] = "d/rock_normal.png",
                                          [BB_MAP_SSBUMP] = "d/rock_ssbump.png",
                                          [BB_MAP_AO] = "d/rock_ao.png"};
  expect_map_files("serve", (const char *[]){"d/rock.png", "--scale", "8", NULL}, stem);
  const char *named[BB_MAP_BAKED_COUNT] = {[BB_MAP_NORMAL] = "n.png"};
  expect_map_files("serve", (const char *[]){"d/rock.png", "--scale", "8", "--normal", "n.png",
                                             NULL},
                   named);
  const char *prefixed[BB_MAP_BAKED_COUNT] = {[BB_MAP_NORMAL] = "o/p_normal.png",
                                              [BB_MAP_SSBUMP] = "o/p_ssbump.png",
                                              [BB_MAP_AO] = "o/p_ao.png",
                                              [BB_MAP_BENT] = "b.png"};
  expect_map_files("serve", (const char *[]){"rock.png", "--scale", "8", "--bent", "b.png",
                                             "--output", "o/p", NULL},
                   prefixed);
  expect_map_files("bake", (const char *[]){"rock.png", "--scale", "8", "--output", "o/p",
                                            "--bent", "b.png", NULL},
                   prefixed);
  /* bake has no default prefix: a map named is the only one */
  const char *ao[BB_MAP_BAKED_COUNT] = {[BB_MAP_AO] = "a.png"};
  expect_map_files("bake", (const char *[]){"rock.png", "--scale", "8", "--ao", "a.png", NULL},
                   ao);
  bb_command *c = command("serve", (const char *[]){"rock.png", "--scale", "8", NULL});
  char *path = NULL;
  bb_error err = {{0}};
  cr_expect_eq(bb_command_map_file(c, BB_MAP_NORMAL, &path, &err), BB_OK);
  cr_expect_null(path, "not checked: no default yet");
  cr_expect_eq(bb_command_map_file(NULL, BB_MAP_NORMAL, &path, &err), BB_ERR_ARGUMENT);
  cr_expect_eq(bb_command_map_file(c, BB_MAP_NORMAL, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_map_file(c, (bb_map_kind)BB_MAP_BAKED_COUNT, &path, &err), BB_OK);
  cr_expect_null(path, "no such map");
  bb_command_free(c);
}

/* The slices a bake traces and the albedo it bounces with, the bake's and
 * the job's rules (bumpbake serve's page reads them so). */
Test(cmd, slices_and_bounce_are_the_bakes_rules) {
  static const struct {
    const char *words[9];
    int slices;
    double bounce;
  } cases[] = {
      {{"h.png", "--scale", "8", "--ao", "a.png", NULL}, 16, 0.0},
      {{"h.png", "--scale", "8", "--rays", "300", "--ao", "a.png", NULL}, 17, 0.0},
      {{"h.png", "--scale", "8", "--rays", "64", "--slices", "6", NULL}, 6, 0.0},
      {{"h.png", "--scale", "8", "--bounce", "0.5", "--ao", "a.png", NULL}, 16, 0.5},
      {{"h.png", "--scale", "8", "--bounce-albedo", "b.png", "--ao", "a.png", NULL}, 16, 1.0},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    bb_command *c = command("bake", cases[i].words);
    cr_expect_eq(bb_command_slices(c), cases[i].slices, "case %zu", i);
    cr_expect_eq(bb_command_bounce(c), cases[i].bounce, "case %zu", i);
    bb_command_free(c);
  }
  cr_expect_eq(bb_command_slices(NULL), 0);
  cr_expect_eq(bb_command_bounce(NULL), 0.0);
}

/* A file option names one file: given again with another name, the first
 * would be dropped without a word. A map's file is the exception: given
 * again, a further file of the same bake (--ssbump s.png --ssbump s.vtf),
 * spelled again in the command's text. The same name twice is harmless. */
Test(cmd, a_file_option_given_twice_is_refused_but_a_map_takes_several) {
  refused("bake", (const char *[]){"h.png", "--scale", "1", "--ao", "a.png", "--depfile",
                                   "a.d", "--depfile", "b.d", NULL},
          "--depfile is given twice ('a.d', then 'b.d'): it names one file; run once per file");
  refused("render", (const char *[]){"--normal", "n.png", "--normal", "m.png", "--output",
                                     "r.png", NULL},
          "--normal is given twice ('n.png', then 'm.png'): it names one file; run once per "
          "file");
  const char *same[] = {"h.png", "--scale", "1", "--ssbump", "s.png", "--ssbump", "s.png",
                        NULL};
  bb_command *c = command("bake", same);
  cr_expect_eq(bb_command_check(c, NULL), BB_OK);
  cr_expect_str_eq(bb__command_options_of(c)->job.paths[BB_MAP_SSBUMP], "s.png");
  char *text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect(text && strstr(text, " --ssbump s.png") && !strstr(text, "--ssbump s.png --"),
            "%s", text);
  free(text);
  bb_command_free(c);
  const char *two[] = {"h.png", "--scale",  "1",     "--ssbump",
                       "s.png", "--ssbump", "s.vtf", NULL};
  c = command("bake", two);
  cr_expect_eq(bb_command_check(c, NULL), BB_OK);
  cr_expect_str_eq(bb__command_options_of(c)->job.paths[BB_MAP_SSBUMP], "s.png");
  text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect(text && strstr(text, " --ssbump s.png --ssbump s.vtf"), "%s", text);
  free(text);
  bb_command_free(c);
}

/* A colour above a float's largest is too large, said so; a denormal is
 * a number like any other. */
Test(cmd, a_value_past_a_float_is_too_large_and_a_denormal_a_number) {
  refused("render", (const char *[]){"--normal", "n.png", "--mode", "normal", "--light-color",
                                     "3e39,1,1", "--output", "r.png", NULL},
          "--light-color is too large: at most 3.40282e38, a float's largest (got 3e39)");
  const char *denormal[] = {"h.png", "--scale", "1", "--ao", "a.png", "--bounce", "5e-324",
                            NULL};
  bb_command *c = command("bake", denormal);
  cr_expect_eq(bb_command_check(c, NULL), BB_OK);
  bb_command_free(c);
}

/* Names: an unknown option or command gets the nearest, Python's spelling
 * (filter_radius) finds the option, the enums' own names are the words. */
Test(cmd, names_and_did_you_mean) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_expect_eq(bb_command_new("bkae", &c, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "unknown command 'bkae' (did you mean bake?)");
  cr_assert_eq(bb_command_new("bake", &c, &err), BB_OK);
  cr_expect_eq(bb_command_set(c, "filter_radus", "3", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "unknown option '--filter_radus' (did you mean --filter-radius?)");
  cr_expect_eq(bb_command_set(c, "filter_radius", "3", &err), BB_OK);
  cr_expect_eq(bb__command_options_of(c)->job.bake.smooth.radius_texels, 3);
  cr_expect_eq(bb_command_set(c, "normal-filter", "fancy", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message,
                   "--normal-filter must be one of valve, central, sobel, vertex (got 'fancy')");
  bb_command_free(c);
  char words[128];
  bb__option_choices(bb_option_find(bb_command_info_find("bake"), "normal-y", 0), words,
                    sizeof words);
  cr_expect_str_eq(words, "down|up");
}

/* height2ssbump through the job: Valve's file named next to FILE, its
 * BUMPSCALE the scale, the second positional no input. */
Test(cmd, height2ssbump_plans_a_job) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new("height2ssbump", &c, &err), BB_OK);
  cr_assert_eq(bb_command_add_input(c, "dir/rock.png", &err), BB_OK);
  cr_expect_eq(bb_command_add_input(c, "zero", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "BUMPSCALE needs a number (got 'zero')");
  cr_expect_eq(bb_command_add_input(c, "0", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "BUMPSCALE must be > 0 (got 0)");
  cr_assert_eq(bb_command_add_input(c, "16", &err), BB_OK);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  const bb_command_options *o = bb__command_options_of(c);
  cr_expect_eq(o->job.bake.height_scale, 16.0f);
  cr_expect_eq(o->job.bake.rays, 250);
  cr_expect_eq(o->job.channel, BB_CHANNEL_VALVE);
  cr_expect(bb__command_has_job(bb_command_describe(c)));
  bb_command_free(c);
}

/* A flag takes "1" and "0" as bumpbake.h says (Python's True and False):
 * "0" unsets it, and the command no longer counts it as given; a flag
 * whose setter does more than set it refuses "0" with one line. */
Test(cmd, a_flag_set_to_0_is_unset) {
  bb_command *c = command("bake", (const char *const[]){"h.png", "--out-dir", "out", NULL});
  bb_error err = {{0}};
  cr_assert_eq(bb_command_set(c, "force", "1", &err), BB_OK, "%s", err.message);
  cr_assert(bb_command_given(c, "force"));
  cr_assert_eq(bb_command_set(c, "force", "0", &err), BB_OK, "%s", err.message);
  cr_expect_not(bb_command_given(c, "force"));
  cr_expect_eq(bb__command_options_of(c)->job.force, 0);
  cr_expect_eq(bb_command_set(c, "clamp", "0", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--clamp cannot be unset: leave it out");
  cr_expect_eq(bb_command_set(c, "force", "2", &err), BB_ERR_ARGUMENT);
  bb_command_free(c);
}

/* ssbump2normal --kind and combine --kind: one parser, the library's
 * (bb__map_kind_parse, any case), each taking its own kinds. */
Test(cmd, kind_options_take_the_librarys_words) {
  const char *s2n[] = {"--kind", "Weights", NULL};
  bb_command *c = command("ssbump2normal", s2n);
  cr_expect_eq(bb__command_options_of(c)->ssbump_kind, BB_MAP_WEIGHTS);
  bb_command_free(c);
  const char *comb[] = {"--kind", "WEIGHTS", NULL};
  c = command("combine", comb);
  cr_expect_eq(bb__command_options_of(c)->map_kind, BB_MAP_WEIGHTS);
  bb_command_free(c);
  const char *kinds[] = {"normal", "ao", "bent", "slope"};
  for (int i = 0; i < 4; i++) {
    bb_error err = {{0}};
    cr_assert_eq(bb_command_new("ssbump2normal", &c, &err), BB_OK);
    cr_expect_eq(bb_command_set(c, "kind", kinds[i], &err), BB_ERR_ARGUMENT, "%s", kinds[i]);
    cr_expect(strstr(err.message, "weights, ssbump"), "%s", err.message);
    bb_command_free(c);
  }
}

/* Flags that set one other field (the option table's bb__flag_sets): set
 * when given, and refused as "0" since they cannot be unset. */
Test(cmd, flags_set_their_field) {
  const char *bake[] = {"--scale", "2", "--clamp", "--nomip", "--fast-compression", NULL};
  bb_command *c = command("bake", bake);
  const bb_command_options *o = bb__command_options_of(c);
  cr_expect_eq(o->job.bake.smooth.addressing, BB_ADDRESS_CLAMP);
  cr_expect_eq(o->job.texture.mips, 0);
  cr_expect_eq(o->job.texture.fast, 1);
  bb_error err = {{0}};
  cr_expect_eq(bb_command_set(c, "nomip", "0", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--nomip cannot be unset: leave it out");
  bb_command_free(c);
  cr_assert_eq(bb_command_new("height2ssbump", &c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_set(c, "dump-filtered", NULL, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(bb__command_options_of(c)->job.paths[BB_MAP_FILTERED], "filtered.tga");
  bb_command_free(c);
}

/* The same refusal, as the command line words it and as keyword arguments
 * (Python, serve's page) read it: every option of the command respelled
 * from its row, the value's name joined to its keyword, nothing else. */
Test(cmd, refusals_are_spelled_in_the_clients_words) {
  static const struct {
    const char *const words[8];
    const char *line, *keywords;
  } cases[] = {
      {{"h.png", "--scale", "8", "--bounce", "2", NULL},
       "--bounce must be in 0..1 (got 2)",
       "bounce must be in 0..1 (got 2)"},
      {{"h.png", "--scale", "8", "--filter-radius", "9999", NULL},
       "--filter-radius must be in 0..4096 (got 9999)",
       "filter_radius must be in 0..4096 (got 9999)"},
      {{"h.png", "--scale", "8", "--bounces", "3", "--normal", "n.png", NULL},
       "--bounces does nothing without --bounce RHO or --bounce-albedo FILE",
       "bounces does nothing without bounce=RHO or bounce_albedo=FILE"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
    for (int keywords = 0; keywords < 2; keywords++) {
      bb_command *c = NULL;
      bb_error err = {{0}};
      cr_assert_eq(bb_command_new("bake", &c, &err), BB_OK);
      if (keywords)
        bb_command_set_spelling(c, BB_SPELLING_KEYWORDS);
      const char *const *w = cases[k].words;
      cr_assert_eq(bb_command_add_input(c, w[0], &err), BB_OK);
      for (int i = 1; w[i]; i += 2)
        cr_assert_eq(bb_command_set(c, w[i] + 2, w[i + 1], &err), BB_OK, "%s",
                     err.message);
      cr_expect_eq(bb_command_check(c, &err), BB_ERR_ARGUMENT);
      cr_expect_str_eq(err.message, keywords ? cases[k].keywords : cases[k].line);
      bb_command_free(c);
    }
  /* the plan's refusals: a short option and its value's name; a path that
   * holds an option's name stays as it is */
  for (int keywords = 0; keywords < 2; keywords++) {
    bb_command *c = NULL;
    bb_error err = {{0}};
    cr_assert_eq(bb_command_new("bake", &c, &err), BB_OK);
    if (keywords)
      bb_command_set_spelling(c, BB_SPELLING_KEYWORDS);
    cr_assert_eq(bb_command_add_input(c, "/tmp/--normal/h.png", &err), BB_OK);
    cr_assert_eq(bb_command_set(c, "scale", "8", &err), BB_OK);
    cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
    bb_job *job = NULL;
    cr_expect_eq(bb_command_plan(c, NULL, &job, &err), BB_ERR_ARGUMENT);
    cr_expect_str_eq(
        err.message,
        keywords ? "nothing to write: give output=PREFIX or at least one of "
                   "normal, weights, ssbump, ao, bent, filtered, slope (or "
                   "out_dir=DIR for a batch)"
                 : "nothing to write: give -o PREFIX or at least one of --normal, "
                   "--weights, --ssbump, --ao, --bent, --filtered, --slope (or "
                   "--out-dir DIR for a batch)");
    cr_assert_eq(bb_command_set(c, "normal", "/tmp/--normal/x.exr", &err), BB_OK);
    cr_assert_eq(bb_command_set(c, "mips", "1", &err), BB_OK);
    cr_assert_eq(bb_command_set(c, "depth", "8", &err), BB_OK);
    cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
    cr_expect_eq(bb_command_plan(c, NULL, &job, &err), BB_ERR_ARGUMENT);
    cr_expect(strstr(err.message, "/tmp/--normal/x.exr: "), "%s", err.message);
    cr_expect(strstr(err.message, keywords ? " depth 8 " : " --depth 8 "), "%s",
              err.message);
    bb_command_free(c);
  }
}

/* A render of large maps says what it will take before it reads them (the
 * note of bb_command_run's hooks), as a comparison does: a 4096 x 8192
 * map of RGBA floats (a 148-byte DDS header, the rest a hole) is 1.1 GiB
 * to render; a small one says nothing. */
static void keep_note(void *user, const char *path, const char *text) {
  snprintf(user, 512, "%s: %s", path, text);
}

Test(cmd, a_large_render_says_its_cost_before_it_starts) {
  char dir[] = "/tmp/bb-render-cost-XXXXXX";
  cr_assert_not_null(mkdtemp(dir));
  char big[64], small[64], out[64];
  snprintf(big, sizeof big, "%s/n.dds", dir);
  snprintf(small, sizeof small, "%s/s.dds", dir);
  snprintf(out, sizeof out, "%s/r.png", dir);
  cr_assert_eq(write_dds_float_header(big, 4096, 8192), 0);
  cr_assert_eq(write_dds_float_header(small, 64, 64), 0);
  for (int k = 0; k < 2; k++) {
    bb_command *c =
        command("render", (const char *const[]){"--normal", k ? small : big, "--mode",
                                                "normal", "--output", out, NULL});
    bb_error err = {{0}};
    cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
    char note[512] = "";
    const bb_command_hooks hooks = {.note = keep_note, .note_user = note};
    cr_assert_not_null(c->def->before_run); /* what bb_command_run says first */
    c->def->before_run(c, &hooks);
    if (k)
      cr_expect_str_empty(note);
    else
      cr_expect(
          strstr(note, "/r.png: a 4096 x 8192 render takes about 1.1 GiB of memory ("),
          "%s", note);
    bb_command_free(c);
  }
  unlink(big);
  unlink(small);
  rmdir(dir);
}

/* bb_command_unset: an option back at its default and no longer given,
 * so the rules see the command as if it had never been set (a page's
 * control put back to its default is left out of the line it shows);
 * an option whose setter does more than set its field refuses, as "0"
 * does for such a flag. */
Test(cmd, unset_puts_an_option_back_at_its_default) {
  const char *words[] = {"h.png", "--scale", "8", "--ssbump", "s.png", "--bounce", "0.5",
                         "--bounces", "3", "--slices", "8", NULL};
  bb_command *c = command("bake", words);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_unset(c, "bounce", &err), BB_OK, "%s", err.message);
  cr_expect_not(bb_command_given(c, "bounce"));
  cr_expect_eq(bb__command_options_of(c)->job.bake.bounce_albedo, 0.0);
  /* the line without --bounce is the CLI's refusal */
  cr_expect_eq(bb_command_check(c, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--bounces does nothing without --bounce RHO or --bounce-albedo FILE");
  cr_assert_eq(bb_command_unset(c, "bounces", &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_unset(c, "slices", &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb__command_options_of(c)->job.bake.slices, 0);
  cr_expect_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  char *text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
  cr_expect_str_eq(text, "bumpbake bake h.png --scale 8 --ssbump s.png");
  free(text);
  /* an option never set: nothing to do; one unknown: the usual words */
  cr_expect_eq(bb_command_unset(c, "bias", &err), BB_OK);
  cr_expect_eq(bb_command_unset(c, "rayz", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "unknown option '--rayz' (did you mean --rays?)");
  /* a setter of its own (--basis also reads a file) cannot be undone */
  cr_assert_eq(bb_command_set(c, "basis", "hl2+z", &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_unset(c, "basis", &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--basis cannot be unset: leave it out");
  bb_command_free(c);
  /* a command's own default (height2ssbump's 250 rays) comes back too */
  const char *h2s[] = {"h.png", "8", "--rays", "64", NULL};
  c = command("height2ssbump", h2s);
  cr_expect_eq(bb__command_options_of(c)->job.bake.rays, 64);
  cr_assert_eq(bb_command_unset(c, "rays", &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb__command_options_of(c)->job.bake.rays, 250);
  bb_command_free(c);
}

/* bb_command_numbers: a numbers option read back by its own parser, the
 * value set or the default; a float held comes back as that float. */
Test(cmd, numbers_read_an_option_back_by_its_parser) {
  bb_error err = {{0}};
  const char *render_words[] = {"--normal", "n.png", "--light-color", "0.8,0.9,1", NULL};
  bb_command *c = command("render", render_words);
  double v[4] = {0};
  int n = 0;
  cr_assert_eq(bb_command_numbers(c, "light", v, 4, &n, &err), BB_OK, "%s", err.message);
  cr_expect_eq(n, 2);
  cr_expect(v[0] == 135.0 && v[1] == 45.0, "%g %g", v[0], v[1]);
  cr_assert_eq(bb_command_numbers(c, "light-color", v, 3, &n, &err), BB_OK, "%s", err.message);
  const float *held = bb__command_options_of(c)->render.light_color;
  for (int k = 0; k < 3; k++)
    cr_expect((float)v[k] == held[k], "%d: %.9g against %.9g", k, v[k], (double)held[k]);
  cr_expect_eq(bb_command_numbers(c, "light-color", v, 2, &n, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--light-color holds 3 numbers, room for 2");
  cr_expect_eq(n, 0);
  cr_expect_eq(bb_command_numbers(c, "normal", v, 4, NULL, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--normal takes no numbers");
  cr_expect_eq(bb_command_numbers(c, "lihgt", v, 4, NULL, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "unknown option '--lihgt' (did you mean --light?)");
  /* floats of every size held come back as themselves */
  char text[64];
  unsigned seed = 12345;
  for (int i = 0; i < 2000; i++) {
    float f[3];
    for (int k = 0; k < 3; k++) {
      seed = seed * 1103515245u + 12345u;
      f[k] = (float)ldexp((double)(seed >> 8) / 16777216.0, (int)(seed % 9) - 6);
    }
    snprintf(text, sizeof text, "%.9g,%.9g,%.9g", (double)f[0], (double)f[1], (double)f[2]);
    cr_assert_eq(bb_command_set(c, "light-color", text, &err), BB_OK, "%s", err.message);
    cr_assert_eq(bb_command_numbers(c, "light-color", v, 3, NULL, &err), BB_OK, "%s",
                 err.message);
    for (int k = 0; k < 3; k++)
      cr_assert((float)v[k] == held[k], "%s: %.9g against %.9g", text, v[k], (double)held[k]);
  }
  bb_command_free(c);

  const char *rbf[] = {"m.obj", "--size", "256 128", "--samples", "3", NULL};
  c = command("renderbumpflat", rbf);
  cr_assert_eq(bb_command_numbers(c, "size", v, 4, &n, &err), BB_OK, "%s", err.message);
  cr_expect(n == 2 && v[0] == 256.0 && v[1] == 128.0, "%d: %g %g", n, v[0], v[1]);
  cr_assert_eq(bb_command_numbers(c, "samples", v, 1, &n, &err), BB_OK, "%s", err.message);
  cr_expect(n == 1 && v[0] == 3.0, "%g", v[0]);
  bb_command_free(c);
}

/* bb_command_value: an option's value as the command holds it, spelled as
 * bb_command_text spells it, given or not; and serve's own options, which
 * land in no field of the options (--port, --address): the text given,
 * else the row's default, and back to it when unset. */
Test(cmd, value_reads_an_option_given_or_not) {
  const char *words[] = {"h.png", "--scale", "8", "--bias", "0.25", "--clamp", NULL};
  bb_command *c = command("bake", words);
  bb_error err = {{0}};
  char v[64];
  const struct {
    const char *name, *value;
  } want[] = {{"scale", "8"},  {"bias", "0.25"},     {"rays", "256"},   {"slices", "0"},
              {"clamp", "1"},  {"mips", "0"},        {"normal-filter", "vertex"},
              {"normal", ""},  {"filter_radius", "10"}};
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    cr_assert_eq(bb_command_value(c, want[i].name, v, sizeof v, &err), BB_OK, "%s",
                 err.message);
    cr_expect_str_eq(v, want[i].value, "%s", want[i].name);
  }
  cr_expect_eq(bb_command_value(c, "rayz", v, sizeof v, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "unknown option '--rayz' (did you mean --rays?)");
  cr_expect_eq(bb_command_value(c, "normal-filter", v, 4, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(v, "");
  bb_command_free(c);

  const char *serve[] = {"h.png", "--scale", "8", "--port", "9000", "--address", "::1", NULL};
  c = command("serve", serve);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_value(c, "port", v, sizeof v, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(v, "9000");
  cr_assert_eq(bb_command_value(c, "address", v, sizeof v, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(v, "::1");
  char *text = bb_command_text(c, NULL, 0);
  cr_expect_str_eq(text, "bumpbake serve h.png --scale 8 --port 9000 --address ::1");
  free(text);
  cr_assert_eq(bb_command_unset(c, "port", &err), BB_OK, "%s", err.message);
  cr_expect_not(bb_command_given(c, "port"));
  cr_assert_eq(bb_command_value(c, "port", v, sizeof v, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(v, "8077");
  /* the range is the row's, checked as any other */
  cr_assert_eq(bb_command_set(c, "port", "65536", &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_check(c, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "--port must be in 0..65535 (got 65536)");
  bb_command_free(c);
  const char *plain[] = {"h.png", "--scale", "8", NULL};
  c = command("serve", plain);
  cr_assert_eq(bb_command_value(c, "address", v, sizeof v, &err), BB_OK, "%s", err.message);
  cr_expect_str_eq(v, "127.0.0.1");
  cr_expect_not(bb_command_given(c, "address"));
  bb_command_free(c);
}

/* The type names every client shows (Python's option table, serve's
 * controls) come from one function. */
Test(cmd, option_type_names_are_the_librarys) {
  const char *names[] = {"flag", "integer", "number", "word", "words", "numbers", "text", "path"};
  for (int t = BB_OPTION_FLAG; t <= BB_OPTION_PATH; t++)
    cr_assert_str_eq(bb_option_type_name((bb_option_type)t), names[t]);
  cr_assert_null(bb_option_type_name((bb_option_type)(BB_OPTION_PATH + 1)));
  cr_assert_null(bb_option_type_name((bb_option_type)-1));
}

/* bb_option_parse and bb_option_word: a client parses and names an
 * option's value through the option rows, with no command to set. */
static const bb_option_info *option_of(const char *command, const char *name) {
  const bb_option_info *o = bb_option_find(bb_command_info_find(command), name, 0);
  cr_assert_not_null(o, "%s --%s", command, name);
  return o;
}

static void expect_parsed(const char *command, const char *name, const char *text,
                          long long expected) {
  bb_error err = {{0}};
  long long v = -12345;
  cr_expect_eq(bb_option_parse(option_of(command, name), text, &v, &err), BB_OK,
               "%s --%s %s: %s", command, name, text, err.message);
  cr_expect_eq(v, expected, "%s --%s %s: %lld", command, name, text, v);
}

static void expect_refused(const char *command, const char *name, const char *text,
                           const char *message) {
  bb_error err = {{0}};
  long long v = -12345;
  cr_expect_eq(bb_option_parse(option_of(command, name), text, &v, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, message);
  cr_expect_eq(v, -12345, "a refused value leaves *value alone");
}

Test(cmd, option_parse_reads_a_value_by_the_options_parser) {
  expect_parsed("bake", "channel", "LUMA", BB_CHANNEL_LUMA);
  expect_parsed("bake", "depth", "16", BB_DEPTH_16);
  expect_parsed("bake", "normal-y", "up", 1);
  expect_parsed("bake", "normal_y", "down", 0);
  expect_parsed("bake", "normal-filter", "sobel", BB_NORMAL_SOBEL);
  expect_parsed("bake", "texture-format", "DXT5", BB_TEXTURE_FORMAT_BC3);
  expect_parsed("bake", "vtf-version", "7.3", 3);
  expect_parsed("bake", "vtf-version", "5", 5);
  expect_parsed("bake", "vtf-flags", "0xffffffff", 0xffffffffLL);
  expect_parsed("renderbumpflat", "axis", "z", BB_AXIS_POS_Z);
  expect_parsed("ssbump2normal", "kind", "weights", BB_MAP_WEIGHTS);
}

Test(cmd, option_parse_refuses_in_the_values_own_words) {
  expect_refused("bake", "channel", "z",
                 "channel must be one of auto, r, g, b, a, luma, mean, valve (got 'z')");
  expect_refused("bake", "depth", "12", "depth must be one of 8, 16, half, float (got '12')");
  expect_refused("bake", "normal-y", "left", "normal y must be one of down, up (got 'left')");
  expect_refused("bake", "vtf-version", "7.9",
                 "VTF version must be 7.2, 7.3, 7.4 or 7.5 (got '7.9')");
  expect_refused("bake", "vtf-flags", "-1",
                 "VTF flags must be a 32-bit number, e.g. 0x4 (got '-1')");
  expect_refused("ssbump2normal", "kind", "ao",
                 "map kind must be one of weights, ssbump (got 'ao')");
  /* options bb_command_set reads: nothing of their own to parse */
  expect_refused("bake", "rays", "256", "--rays has no word or value of its own to parse");
  expect_refused("bake", "normal", "n.png", "--normal has no word or value of its own to parse");
  bb_error err = {{0}};
  long long v = 0;
  cr_expect_eq(bb_option_parse(NULL, "x", &v, &err), BB_ERR_ARGUMENT);
  cr_expect_eq(bb_option_parse(option_of("bake", "channel"), NULL, &v, &err), BB_ERR_ARGUMENT);
}

Test(cmd, option_word_names_what_option_parse_reads) {
  cr_expect_str_eq(bb_option_word(option_of("bake", "normal-filter"), BB_NORMAL_VERTEX),
                   "vertex");
  cr_expect_str_eq(bb_option_word(option_of("renderbumpflat", "axis"), BB_AXIS_NEG_Y), "-y");
  cr_expect_str_eq(bb_option_word(option_of("bake", "normal-y"), 1), "up");
  /* no word: a value outside the enum, depth's DEFAULT (no word a user
   * types), a kind the option does not take, an option without words */
  cr_expect_null(bb_option_word(option_of("bake", "normal-filter"), 99));
  cr_expect_null(bb_option_word(option_of("bake", "normal-filter"), -1));
  cr_expect_null(bb_option_word(option_of("bake", "depth"), BB_DEPTH_DEFAULT));
  cr_expect_null(bb_option_word(option_of("ssbump2normal", "kind"), BB_MAP_AO));
  cr_expect_null(bb_option_word(option_of("bake", "rays"), 0));
  cr_expect_null(bb_option_word(NULL, 0));
  /* every word of every option parses back to its value */
  int words = 0;
  const bb_command_info *c;
  for (int i = 0; (c = bb_command_info_get(i)) != NULL; i++) {
    for (int k = 0; k < c->option_count; k++) {
      const bb_option_info *o = bb_command_option(c, k);
      for (long long v = 0; v < 64; v++) {
        const char *w = bb_option_word(o, v);
        if (!w)
          continue;
        long long back = -1;
        bb_error err = {{0}};
        cr_expect_eq(bb_option_parse(o, w, &back, &err), BB_OK, "%s --%s %s", c->name,
                     o->name, w);
        cr_expect_eq(back, v, "%s --%s %s", c->name, o->name, w);
        words++;
      }
    }
  }
  cr_expect_gt(words, 50, "the words of every command's word options (%d)", words);
}

/* bb_command_program: program's run in memory, the image bb_command_run
 * writes (float EXR: the values as they are), bit for bit. */
static void expect_program_as_run(const char *text, int expect_normal) {
  char dir[] = "/tmp/bb_program_XXXXXX";
  cr_assert_not_null(mkdtemp(dir));
  char out_path[64];
  snprintf(out_path, sizeof out_path, "%s/out.exr", dir);
  const char *words[] = {text, "--base", "fixtures", "--output", out_path, NULL};
  bb_command *c = command("program", words);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  bb_image mem = {0};
  int is_normal = -1;
  cr_assert_eq(bb_command_program(c, &mem, &is_normal, &err), BB_OK, "%s", err.message);
  cr_expect_eq(is_normal, expect_normal, "%s", text);
  cr_expect_eq(mem.channels, expect_normal ? 3 : 4, "%s", text);
  cr_expect_eq(access(out_path, F_OK), -1, "nothing written in memory");
  bb_command_result r = {0};
  cr_assert_eq(bb_command_run(c, NULL, &r, &err), BB_OK, "%s", err.message);
  bb_image file = {0};
  cr_assert_eq(bb_image_read(out_path, &file, NULL, &err), BB_OK, "%s", err.message);
  cr_assert_eq(file.width, mem.width);
  cr_assert_eq(file.height, mem.height);
  cr_assert_eq(file.channels, mem.channels);
  const size_t n = (size_t)mem.width * (size_t)mem.height * (size_t)mem.channels;
  cr_expect_eq(memcmp(file.pixels, mem.pixels, n * sizeof(float)), 0, "%s: the run's pixels",
               text);
  bb_image_free(&file);
  bb_image_free(&mem);
  bb_command_result_free(&r);
  bb_command_free(c);
  unlink(out_path);
  rmdir(dir);
}

Test(cmd, program_in_memory_is_the_runs_image) {
  expect_program_as_run("heightmap(pit_65x65.png, 4)", 1);
  expect_program_as_run("invertColor(bricks_128x64.png)", 0);
}

Test(cmd, program_in_memory_refuses_in_the_programs_words) {
  bb_error err = {{0}};
  bb_image out = {0};
  int is_normal = 0;
  const char *missing[] = {"invertColor(nonexistent_image.png)", NULL};
  bb_command *c = command("program", missing);
  bb_command_set_in_memory(c, 0); /* Python's program(): no output file */
  cr_expect_eq(bb_command_program(c, &out, &is_normal, &err), BB_ERR_ARGUMENT, "unchecked");
  cr_expect_str_eq(err.message, "bb_command_program: not a checked program command");
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_program(c, &out, &is_normal, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, "nonexistent_image.png"), "names the file: %s", err.message);
  cr_expect_null(out.pixels);
  bb_command_free(c);
  const char *outside[] = {"heightmap(/nonexistent/h.tga, 4)", NULL};
  c = command("program", outside);
  bb_command_set_in_memory(c, 0);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_program(c, &out, &is_normal, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "absolute"), "%s", err.message);
  bb_command_free(c);
  const char *bake[] = {"h.png", "--scale", "8", NULL};
  c = command("bake", bake);
  cr_expect_eq(bb_command_program(c, &out, &is_normal, &err), BB_ERR_ARGUMENT, "not program");
  bb_command_free(c);
}

Test(cmd, the_commands_end_with_null) {
  int n = 0;
  while (bb_command_info_get(n))
    n++;
  cr_expect_gt(n, 10, "every command of bumpbake --help (%d)", n);
  cr_expect_null(bb_command_info_get(-1));
  cr_expect_str_eq(bb_command_info_get(0)->name, "normal", "the order of bumpbake --help");
  cr_expect_str_eq(bb_command_info_get(n - 1)->name,
                   bb_command_info_find(bb_command_info_get(n - 1)->name)->name);
}

/* bb_report_word: the words of the reports' enums, as printed. */
Test(cmd, report_words_are_the_printed_ones) {
  cr_expect_str_eq(bb_report_word("outcome", BB_JOB_CURRENT), "up to date");
  cr_expect_str_eq(bb_report_word("outcome", BB_JOB_NOT_RUN), "not run");
  cr_expect_str_eq(bb_report_word("result", BB_CHECK_PASS), "PASS");
  cr_expect_str_eq(bb_report_word("result", BB_CHECK_DIFFERENT_SIZE), "DIFFERENT SIZE");
  cr_expect_null(bb_report_word("outcome", BB_JOB_NOT_RUN + 1));
  cr_expect_null(bb_report_word("result", -1));
  cr_expect_null(bb_report_word("status", 0));
  cr_expect_null(bb_report_word(NULL, 0));
  /* every value of each enum has its own word */
  const char *seen[16] = {0};
  int n = 0;
  for (int v = BB_JOB_PENDING; v <= BB_JOB_NOT_RUN; v++)
    seen[n++] = bb_report_word("outcome", v);
  for (int v = BB_CHECK_PASS; v <= BB_CHECK_EXTRA; v++)
    seen[n++] = bb_report_word("result", v);
  for (int i = 0; i < n; i++) {
    cr_assert_not_null(seen[i], "word %d", i);
    for (int k = 0; k < i; k++)
      cr_expect_str_neq(seen[i], seen[k]);
  }
}

/* The stage struct a client takes is the command's bake as set; the rest
 * is read by name (bb_command_value), and what no option spells is set by
 * its own call (bb_command_set_picture). */
Test(cmd, the_stage_struct_is_the_commands_bake) {
  bb_command *c = command("render", (const char *const[]){"h.png", "--rays", "64", "--light",
                                                         "10,20", "--tile", "3", NULL});
  cr_expect_eq(bb__command_job_options(c)->bake.rays, 64);
  char light[32];
  bb_error err = {{0}};
  cr_assert_eq(bb_command_value(c, "light", light, sizeof light, &err), BB_OK);
  cr_expect_str_eq(light, "10,20");
  cr_expect_null(bb__command_job_options(NULL));
  const bb_render_options *o = &bb__command_options_of(c)->render;
  bb_command_set_picture(c, 1, 0); /* leaves both */
  cr_expect(o->dynamic_light && o->tile_x == 3 && o->tile_y == 3);
  bb_command_set_picture(c, 0, 5);
  cr_expect(!o->dynamic_light && o->tile_x == 3 && o->tile_y == 5);
  bb_command_set_picture(NULL, 0, 5);
  bb_command_free(c);
}

/* A batch's summary as the command's --json and --quiet ask, named by it. */
Test(cmd, the_summary_lines_follow_the_commands_flags) {
  const int counts[5] = {0, 2, 1, 0, 0}; /* by bb_job_outcome */
  bb_command *plain = command("normal", NULL);
  bb_command *quiet = command("normal", (const char *const[]){"--quiet", NULL});
  bb_command *json = command("normal", (const char *const[]){"--json", NULL});
  char *a = bb_job_summary_lines(plain, counts, 3), *b = bb_job_summary_lines(quiet, counts, 3),
       *j = bb_job_summary_lines(json, counts, 3);
  cr_assert(a && b && j);
  cr_expect_str_eq(a, "normal: 3 files: 2 baked, 1 up to date, 0 failed\n");
  cr_expect_str_eq(b, "");
  cr_expect_eq(strncmp(j, "{\"summary\":{\"files\":3,", 22), 0, "%s", j);
  free(a);
  free(b);
  free(j);
  bb_command_free(plain);
  bb_command_free(quiet);
  bb_command_free(json);
}
