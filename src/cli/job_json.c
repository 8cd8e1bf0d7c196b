/* job_json.c: the JSON line of one baked input, as bake and normal print it
 * with --json. */
#include "job_json.h"
#include "json.h"

#include <string.h>

/* The "outputs" array of a report's files; the maps alone (not the slope
 * files) when maps_only. */
static void outputs(cli_json *j, const bb_job_report *r, int maps_only) {
  cli_json_open(j, "outputs", '[');
  for (int i = 0; i < r->output_count; i++) {
    if (maps_only && !strncmp(r->outputs[i].kind, "slope", 5))
      continue;
    cli_json_open(j, NULL, '{');
    cli_json_string(j, "kind", r->outputs[i].kind);
    cli_json_string(j, "path", r->outputs[i].path);
    cli_json_close(j, '}');
  }
  cli_json_close(j, ']');
}

/* Parameters are those used: the channel the rule took and the threads
 * that ran, not "auto" and 0. */
void cli_job_json_to(FILE *f, const bb_bake_options *b, const bb_job_report *r,
                     const char *status) {
  const int traced = r->rayset_id[0] != '\0';
  cli_json j = {f, 0};
  cli_json_open(&j, NULL, '{');
  cli_json_string(&j, "input", r->input);
  if (status)
    cli_json_string(&j, "status", status);
  cli_json_number(&j, "width", r->width);
  cli_json_number(&j, "height", r->height);

  cli_json_open(&j, "parameters", '{');
  cli_json_number(&j, "scale", (double)b->height_scale);
  cli_json_number(&j, "rays", b->rays);
  cli_json_number(&j, "slices", r->slices); /* 0: nothing was traced */
  cli_json_string(&j, "rayset", traced ? r->rayset_id : NULL);
  cli_json_number(&j, "filter_radius", b->smooth.radius_texels);
  cli_json_number(&j, "filter_threshold", (double)b->smooth.threshold);
  cli_json_number(&j, "bias", b->trace.bias_texels);
  cli_json_number(&j, "power", b->power);
  cli_json_string(&j, "basis", b->basis.name);
  cli_json_string(&j, "normal_filter", bb_normal_filter_name(b->normal_filter));
  cli_json_string(&j, "normal_y", bb_normal_y_name(b->normal_y_up));
  cli_json_string(&j, "addressing", bb_addressing_name(b->smooth.addressing));
  cli_json_string(&j, "channel", bb_height_source_channel(&r->source));
  cli_json_number(&j, "threads", r->threads);
  if (r->bounces > 0) { /* as provenance: rho (1 for an albedo map alone) and the count asked */
    cli_json_number(&j, "bounce", b->bounce_albedo > 0.0 ? b->bounce_albedo : 1.0);
    cli_json_number(&j, "bounces", b->bounces);
  }
  cli_json_close(&j, '}');

  cli_json_open(&j, "seconds", '{');
  cli_json_number(&j, "load", r->seconds_load);
  cli_json_number(&j, "smooth", r->seconds_smooth);
  cli_json_number(&j, "pyramid", r->seconds_pyramid);
  cli_json_number(&j, "trace", r->seconds_trace);
  if (r->bounces > 0)
    cli_json_number(&j, "bounce", r->seconds_bounce);
  cli_json_number(&j, "derive", r->seconds_derive);
  cli_json_number(&j, "write", r->seconds_write);
  cli_json_close(&j, '}');

  cli_json_number(&j, "horizons", r->horizons);
  outputs(&j, r, 1);
  cli_json_close(&j, '}');
}

void cli_job_json_short(const bb_job_report *r) {
  cli_json j = {stdout, 0};
  cli_json_open(&j, NULL, '{');
  cli_json_string(&j, "input", r->input);
  cli_json_string(&j, "status", bb_job_outcome_name(r->outcome));
  if (r->outcome == BB_JOB_FAILED)
    cli_json_int(&j, "exit_code", 1);
  outputs(&j, r, 0);
  cli_json_close(&j, '}');
  fputc('\n', stdout);
}

void cli_job_json(const bb_bake_options *b, const bb_job_report *r, const char *status) {
  cli_job_json_to(stdout, b, r, status);
  fputc('\n', stdout);
}
