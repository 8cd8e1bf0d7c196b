/* bake_options.h: bake's parameters and outputs as options, shared with
 * `bumpbake serve`, which bakes with the same options (bake.c). */
#ifndef BB_CLI_BAKE_OPTIONS_H
#define BB_CLI_BAKE_OPTIONS_H

#include "options.h"

/* The option rows of the bake's parameters, its outputs (-o PREFIX,
 * --normal FILE ...) and the engine texture settings, as `bake --help`
 * shows them. */
extern const cli_option *const cli_bake_parameter_rows[];
extern const int cli_bake_parameter_row_count;

/* Applies one option of cli_bake_parameter_rows to s and job (messages
 * name command). Returns 0, or BB_EXIT_USAGE after a usage error. */
int cli_bake_parameter(const char *command, cli_settings *s, bb_job_options *job,
                       const cli_option *opt, const char *arg);

/* The parsed settings into the job's options (bake, channel, depth, mips,
 * texture, basis file). */
void cli_bake_settings_to_job(const cli_settings *s, bb_job_options *job);

#endif /* BB_CLI_BAKE_OPTIONS_H */
