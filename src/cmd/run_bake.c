/* run_bake.c: bake's and normal's bake of a height in memory
 * (bb_command_bake): the options of a command checked for images in memory,
 * the images its file options would read given by the caller, the maps
 * asked handed back as images; a warm (or edit-local) bake through a
 * context when one is given. */
#include "bake/bake_internal.h"
#include "cmd/cmd_internal.h"
#include "core/internal.h"

#include <string.h>

/* An image the caller gives for an option naming a file: both or neither. */
static bb_status image_of(const char *command, const char *option, const char *file,
                          const bb_image *img, bb_error *err) {
  if (file && !img)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: %s is set but its image is missing", command,
                    option);
  if (!file && img)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: an image for %s, which is not set", command,
                    option);
  return BB_OK;
}

/* The maps asked moved from result into maps (the others left empty). */
static void hand_over(bb_bake_result *result, unsigned asked, bb_image *maps) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    bb_image *img = (bb_image *)(void *)bb__bake_result_image(result, (bb_map_kind)k);
    if ((asked & BB_MAP_BIT(k)) && img && img->pixels) {
      maps[k] = *img;
      memset(img, 0, sizeof *img);
    }
  }
}

static bb_status bake(bb_command *c, const bb_image *height, const bb_image *bounce_albedo,
                      const bb_image *brightness, const bb_basis *basis,
                      const bb_command_hooks *hooks, bb_bake_context *context, bb_image *maps,
                      bb_region *changed, bb_error *err) {
  if (!c || !maps)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_command_bake: bad arguments");
  memset(maps, 0, BB_MAP_BAKED_COUNT * sizeof *maps);
  const char *name = c->def->info.name;
  if (c->def != &bb__command_bake && c->def != &bb__command_normal)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s bakes no height in memory", name);
  if (!c->checked || !c->in_memory)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the command is not checked for images in memory",
                    name);
  if (!height)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: a height is needed", name);
  const bb_job_options *job = &c->options.job;
  bb_status st = image_of(name, "--bounce-albedo", job->bounce_albedo_file, bounce_albedo, err);
  if (st == BB_OK)
    st = image_of(name, "--brightness", job->brightness_file, brightness, err);
  if (st != BB_OK)
    return st;
  bb_bake_options o = job->bake;
  if (basis)
    o.basis = *basis;
  o.bounce_albedo_map = bounce_albedo;
  o.brightness = brightness;
  o.trace.progress = hooks ? hooks->progress : NULL;
  o.trace.progress_user = hooks ? hooks->progress_user : NULL;
  o.trace.trace = hooks ? hooks->trace : NULL;
  o.trace.trace_user = hooks ? hooks->trace_user : NULL;
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  bb_region whole = {0, 0, height->width, height->height};
  if (context) {
    st = bb__bake_context_bake(context, height, &o, &result, &whole, err);
  } else {
    st = bb__bake_checked(height, &o, &result, err);
  }
  if (st == BB_OK) {
    hand_over(&result, c->memory_maps ? c->memory_maps : o.outputs, maps);
    if (changed)
      *changed = whole;
  }
  bb_bake_result_free(&result);
  return st;
}

bb_status bb_command_bake(bb_command *command, const bb_image *height,
                          const bb_image *bounce_albedo, const bb_image *brightness,
                          const bb_basis *basis, const bb_command_hooks *hooks,
                          bb_bake_context *context, bb_image *maps, bb_region *changed,
                          bb_error *err) {
  return bb__spelled(command,
                     bake(command, height, bounce_albedo, brightness, basis, hooks, context,
                          maps, changed, err),
                     err);
}
