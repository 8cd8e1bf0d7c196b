/* rules.c: when an option does anything (the "applies when" of its
 * description): engine texture settings with an engine texture written,
 * inter-reflection with a traced map, and so on. bb_command_check refuses
 * an option given where its rule says it would do nothing, as --depth 16
 * with a .vtf is refused. */
#include "cmd/cmd_internal.h"
#include "core/file_names.h"
#include "job/job_internal.h"

#include <strings.h>

/* The files c writes whose formats are known before it runs (a batch's
 * name template stands for all of its files); the count. */
static int outputs(const bb_command *c, const char **out) {
  const bb_command_options *o = &c->options;
  int n = 0;
  if (o->job.out_dir) {
    out[n++] = o->job.name_template ? o->job.name_template : BB_JOB_DEFAULT_NAME;
    return n;
  }
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (o->job.paths[k])
      out[n++] = o->job.paths[k];
  if (o->job.slope_path)
    out[n++] = o->job.slope_path;
  if (o->job.valve_path)
    out[n++] = o->job.valve_path;
  if (o->output)
    out[n++] = o->output;
  return n;
}

static int any_output(const bb_command *c, const char *ext, const char *also) {
  const char *paths[BB_MAP_BAKED_COUNT + 4];
  const int n = outputs(c, paths);
  for (int i = 0; i < n; i++)
    if (bb__path_has_extension(paths[i], ext) || (also && bb__path_has_extension(paths[i], also)))
      return 1;
  return 0;
}

int bb__applies_texture(const bb_command *c) {
  return any_output(c, "vtf", "dds");
}

int bb__applies_vtf(const bb_command *c) {
  return any_output(c, "vtf", NULL);
}

/* The bake's maps c asks for: those of a bake in memory, or those the
 * command always asks (serve's: its page shows every map), else the job's
 * rule (bb__job_maps_asked). */
static unsigned maps_asked(const bb_command *c) {
  if (c->in_memory)
    return c->memory_maps;
  if (c->def->maps_asked)
    return c->def->maps_asked;
  return bb__job_maps_asked(&c->options.job);
}

/* --force: a single bake always bakes (bb__command_bake's job). */
int bb__applies_batch(const bb_command *c) {
  return c->options.job.out_dir != NULL;
}

int bb__applies_traced(const bb_command *c) {
  return (maps_asked(c) & BB_MAPS_TRACED) != 0;
}

int bb__applies_bounces(const bb_command *c) {
  return c->options.job.bake.bounce_albedo > 0.0 || c->options.job.bounce_albedo_file;
}

int bb__applies_brightness(const bb_command *c) {
  return (maps_asked(c) &
          (BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_WEIGHTS))) != 0;
}
