/* bake_reads.c: what a client holding a command reads of its bake beyond
 * one option's value (bumpbake serve's page): the slices it traces, the
 * albedo it bounces light with, the file each map goes to. Each is the
 * bake's or the job's own rule, applied to the command's options. */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"

int bb_command_slices(const bb_command *c) {
  return c ? bb__bake_slices(&c->options.job.bake) : 0;
}

double bb_command_bounce(const bb_command *c) {
  return c ? bb__bounce_rho(c->options.job.bake.bounce_albedo,
                            c->options.job.bounce_albedo_file != NULL)
           : 0.0;
}

bb_status bb_command_map_file(const bb_command *c, bb_map_kind kind, char **path,
                              bb_error *err) {
  if (path)
    *path = NULL;
  if (!c || !path)
    return bb__fail(err, BB_ERR_ARGUMENT, "command map file: bad arguments");
  return bb__job_map_file(&c->options.job, kind, path, err);
}
