/* serve_command.c: the `bumpbake bake` command of the options now, which
 * serve plans its bakes and writes through (bb_command_plan), and the line
 * its files record and the page shows. */
#include "serve.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* 1 when name is the option of a baked map's file (--normal ...). */
static int is_map_file(const char *name) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (!strcmp(bb_map_kind_get((bb_map_kind)k)->name, name))
      return 1;
  return 0;
}

/* 1 when the page's command holds name at text. */
static int holds(const serve_state *s, const char *name, const char *text) {
  char value[64];
  return bb_command_value(s->command, name, value, sizeof value, NULL) == BB_OK &&
         !strcmp(value, text);
}

/* 1 for an option the line leaves out though the bake takes it, as the
 * line the page has always shown does: --rays with --slices (which
 * overrides it) and --bounce 1 with --bounce-albedo (its default there). */
static int unspelled(const serve_state *s, const char *name) {
  return (!strcmp(name, "rays") && !holds(s, "slices", "0")) ||
         (!strcmp(name, "bounce") && bb_command_given(s->command, "bounce-albedo") &&
          holds(s, "bounce", "1"));
}

/* Option o of the page's command onto bake when its value differs from
 * the one a bake command holds without it (fresh's): the line names the
 * options that differ from bake's defaults. */
static bb_status copy_option(const serve_state *s, const bb_command *fresh,
                             const bb_option_info *o, bb_command *bake, bb_error *err) {
  char value[4096], unset[4096];
  bb_status st = bb_command_value(s->command, o->name, value, sizeof value, err);
  if (st == BB_OK)
    st = bb_command_value(fresh, o->name, unset, sizeof unset, err);
  if (st != BB_OK || !strcmp(value, unset))
    return st;
  return bb_command_set(bake, o->name, value, err);
}

/* The page's command's options that bake takes, those spelled (pass 0) or
 * those left unspelled (pass 1); the outputs are the write action's files,
 * named one by one. */
static bb_status copy_options(const serve_state *s, const bb_command *fresh, int pass,
                              bb_command *bake, bb_error *err) {
  const bb_command_info *serve = bb_command_describe(s->command);
  const bb_command_info *bake_info = bb_command_info_find("bake");
  bb_status st = BB_OK;
  for (int i = 0; st == BB_OK && i < serve->option_count; i++) {
    const bb_option_info *o = bb_command_option(serve, i);
    if (bb_option_find(bake_info, o->name, 0) && strcmp(o->name, "output") &&
        !is_map_file(o->name) && unspelled(s, o->name) == pass)
      st = copy_option(s, fresh, o, bake, err);
  }
  return st;
}

bb_status serve_bake_command(const serve_state *s, bb_command **out, char **line,
                             bb_error *err) {
  *out = NULL;
  *line = NULL;
  bb_command *bake = NULL, *fresh = NULL;
  bb_status st = bb_command_new("bake", &bake, err);
  if (st == BB_OK)
    st = bb_command_new("bake", &fresh, err);
  if (st == BB_OK)
    st = bb_command_add_input(bake, s->height_path, err);
  if (st == BB_OK)
    st = copy_options(s, fresh, 0, bake, err);
  for (int k = 0; st == BB_OK && k < BB_MAP_BAKED_COUNT; k++)
    if (s->job.paths[k])
      st = bb_command_set(bake, bb_map_kind_get((bb_map_kind)k)->name, s->job.paths[k], err);
  char *spelled = st == BB_OK ? bb_command_text(bake, NULL, BB_OPTION_RECORDED) : NULL;
  if (st == BB_OK && !spelled) {
    st = BB_ERR_MEMORY;
    snprintf(err->message, sizeof err->message, "out of memory");
  }
  if (st == BB_OK)
    st = copy_options(s, fresh, 1, bake, err);
  if (st == BB_OK)
    st = bb_command_set_record(bake, NULL, spelled, NULL, err);
  if (st == BB_OK)
    st = bb_command_check(bake, err);
  bb_command_free(fresh);
  if (st != BB_OK) {
    bb_command_free(bake);
    free(spelled);
    return st;
  }
  *out = bake;
  *line = spelled;
  return BB_OK;
}
