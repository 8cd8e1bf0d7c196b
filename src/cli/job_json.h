/* job_json.h: the JSON line of one baked input (job_json.c). */
#ifndef BB_CLI_JOB_JSON_H
#define BB_CLI_JOB_JSON_H

#include "bumpbake.h"

#include <stdio.h>

/* Prints r (an input the library baked with options b) as one JSON line on
 * stdout: input, status (when not NULL), size, the parameters used (the
 * channel the rule took, the threads that ran), seconds per stage,
 * horizons and the maps written. */
void cli_job_json(const bb_bake_options *b, const bb_job_report *r, const char *status);
/* The same object to f, without the newline (serve's reply to "write"). */
void cli_job_json_to(FILE *f, const bb_bake_options *b, const bb_job_report *r,
                     const char *status);

/* A batch's line for an input that was not baked: up to date or failed. */
void cli_job_json_short(const bb_job_report *r);

#endif /* BB_CLI_JOB_JSON_H */
