/* trace_input.c: what a checked command's bake traces, built on a worker
 * of a trace split over processes (bb_command_trace_input): its input read
 * as the bake reads it, with the command's own options, so a client hands
 * over the command and reads none of the bake's settings itself. */
#include "job/job_internal.h"
#include "bake/bake_internal.h"
#include "cmd/cmd_internal.h"
#include "core/internal.h"
#include "bumpbake_cluster.h"

#include <string.h>

static bb_status trace_input(const bb_command *c, int threads, uint64_t file_hash,
                             bb_pyramid **pyramid, bb_rayset **rays, bb_error *err) {
  if (!c || !pyramid || !rays)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_command_trace_input: bad arguments");
  *pyramid = NULL;
  *rays = NULL;
  const char *name = c->def->info.name;
  if (c->def != &bb__command_bake && c->def != &bb__command_height2ssbump)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s traces nothing", name);
  if (!c->checked || c->in_memory)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the command is not checked for files", name);
  if (c->input_count != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: a trace's input is of one height file (got %d)",
                    name, c->input_count);
  const char *path = c->inputs[0];
  const bb_job_options *job = &c->options.job;
  bb_image height;
  bb_height_source source;
  bb_status st = bb__height_file_read(path, job->channel, job->bake.height_scale, NULL, NULL,
                                     &height, &source, err);
  if (st != BB_OK)
    return st;
  if (source.file_hash != file_hash) {
    bb_image_free(&height);
    return bb__fail(err, BB_ERR_IO,
                    "%s: the file changed while it was baked (a worker read other bytes than "
                    "the bake's)",
                    path);
  }
  /* what the bake traces, whatever maps the command writes */
  bb_bake_options o = job->bake;
  o.outputs = BB_MAPS_TRACED;
  o.trace.threads = threads;
  st = bb__bake_trace_input(&height, &o, pyramid, rays, err);
  bb_image_free(&height);
  return st;
}

bb_status bb_command_trace_input(const bb_command *command, int threads, uint64_t file_hash,
                                 bb_pyramid **pyramid, bb_rayset **rays, bb_error *err) {
  return bb__spelled(command, trace_input(command, threads, file_hash, pyramid, rays, err),
                     err);
}
