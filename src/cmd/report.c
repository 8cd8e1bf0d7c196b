/* report.c: what `bumpbake bake` prints of a job, once: each input's lines
 * (text or JSON) and a batch's summary, for the command line and for its
 * --scheduler run in Python, which calls these with the reports its
 * cluster sent back. */
#include "bumpbake.h"
#include "job/job_internal.h"
#include "bumpbake_cluster.h"
#include "bake/bake_internal.h"
#include "core/json.h"
#include "cmd/cmd_internal.h"

#include <stdlib.h>
#include <string.h>

/* The "outputs" array of a report's files; the maps alone (not the slope
 * files) when maps_only. */
static void outputs(bb__json *j, const bb_job_report *r, int maps_only) {
  bb__json_open(j, "outputs", '[');
  for (int i = 0; i < r->output_count; i++) {
    if (maps_only && !strncmp(r->outputs[i].kind, "slope", 5))
      continue;
    bb__json_open(j, NULL, '{');
    bb__json_string(j, "kind", r->outputs[i].kind);
    bb__json_string(j, "path", r->outputs[i].path);
    bb__json_close(j, '}');
  }
  bb__json_close(j, ']');
}

/* Members written as they are, after a comma when one is due. */
static void members(bb__json *j, const char *text) {
  if (!text || !*text)
    return;
  if (j->need_comma)
    fputc(',', j->f);
  fputs(text, j->f);
  j->need_comma = 1;
}

/* Parameters are those used: the channel the rule took and the threads
 * that ran, not "auto" and 0. */
void bb__job_report_json(FILE *f, const bb_bake_options *b, const bb_job_report *r,
                         const char *status, const char *extra_json) {
  const int traced = r->rayset_id[0] != '\0';
  bb__json j = {f, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "input", r->input);
  if (status)
    bb__json_string(&j, "status", status);
  bb__json_number(&j, "width", r->width);
  bb__json_number(&j, "height", r->height);

  bb__json_open(&j, "parameters", '{');
  bb__json_number(&j, "scale", (double)b->height_scale);
  bb__json_number(&j, "rays", b->rays);
  bb__json_number(&j, "slices", r->slices); /* 0: nothing was traced */
  bb__json_string(&j, "rayset", traced ? r->rayset_id : NULL);
  bb__json_number(&j, "filter_radius", b->smooth.radius_texels);
  bb__json_number(&j, "filter_threshold", (double)b->smooth.threshold);
  bb__json_number(&j, "bias", b->trace.bias_texels);
  bb__json_number(&j, "power", b->power);
  bb__json_string(&j, "basis", b->basis.name);
  bb__json_string(&j, "normal_filter", bb__normal_filter_name(b->normal_filter));
  bb__json_string(&j, "normal_y", bb__normal_y_name(b->normal_y_up));
  bb__json_string(&j, "addressing", bb__addressing_name(b->smooth.addressing));
  bb__json_string(&j, "channel", bb_height_source_channel(&r->source));
  bb__json_number(&j, "threads", r->threads);
  if (r->bounces > 0) {
    /* as provenance: the rho used (a bounce ran, so a rho of 0 came with
     * an albedo map) and the count asked */
    bb__json_number(&j, "bounce", bb__bounce_rho(b->bounce_albedo, 1));
    bb__json_number(&j, "bounces", b->bounces);
  }
  bb__json_close(&j, '}');

  bb__json_open(&j, "seconds", '{');
  bb__json_number(&j, "load", r->seconds_load);
  bb__json_number(&j, "smooth", r->seconds_smooth);
  bb__json_number(&j, "pyramid", r->seconds_pyramid);
  bb__json_number(&j, "trace", r->seconds_trace);
  if (r->bounces > 0)
    bb__json_number(&j, "bounce", r->seconds_bounce);
  bb__json_number(&j, "derive", r->seconds_derive);
  if (r->seconds_compress > 0)
    /* the engine textures' block compression, a part of the write */
    bb__json_number(&j, "compress", r->seconds_compress);
  bb__json_number(&j, "write", r->seconds_write);
  bb__json_close(&j, '}');

  bb__json_number(&j, "horizons", r->horizons);
  members(&j, extra_json);
  outputs(&j, r, 1);
  bb__json_close(&j, '}');
}

/* A batch's line for an input that was not baked: up to date or failed. */
static void short_json(FILE *f, const bb_job_report *r) {
  bb__json j = {f, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "input", r->input);
  bb__json_string(&j, "status", bb__job_outcome_name(r->outcome));
  if (r->outcome == BB_JOB_FAILED)
    bb__json_int(&j, "exit_code", 1);
  outputs(&j, r, 0);
  bb__json_close(&j, '}');
  fputc('\n', f);
}

/* One line, control characters escaped (the command line's plain lines). */
static void line(FILE *f, const char *verb, const bb_job_file *file) {
  bb__print_line(f, "%s %s %s", verb, file->kind, file->path);
}

/* The text of f, an open_memstream over *text (set by fclose), or NULL
 * when out of memory. */
static char *closed(FILE *f, char **text) {
  if (!f)
    return NULL;
  const int failed = ferror(f);
  if (fclose(f) || failed) {
    free(*text);
    return NULL;
  }
  return *text;
}

char *bb_command_report_json(const bb_command *command, const bb_job_report *r,
                             const char *status) {
  if (!command || !r)
    return NULL;
  char *text = NULL;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  if (f)
    bb__job_report_json(f, &bb__command_options_of(command)->job.bake, r, status, NULL);
  return closed(f, &text);
}

char *bb_job_report_lines(const bb_command *command, const bb_job_report *r, int batch,
                          const char *extra_json) {
  const bb_command_options *o = bb__command_options_of(command);
  char *text = NULL;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  if (!f || r->outcome == BB_JOB_NOT_RUN)
    return closed(f, &text);
  if (o->json) {
    if (r->outcome == BB_JOB_BAKED) {
      bb__job_report_json(f, &o->job.bake, r, batch ? "baked" : NULL, extra_json);
      fputc('\n', f);
    } else if (batch)
      short_json(f, r);
  } else if (!o->quiet) {
    const char *verb = r->outcome == BB_JOB_BAKED     ? "wrote"
                       : r->outcome == BB_JOB_CURRENT ? "up to date"
                                                      : NULL;
    for (int i = 0; verb && i < r->output_count; i++)
      line(f, verb, &r->outputs[i]);
  }
  return closed(f, &text);
}

char *bb_job_summary_lines(const bb_command *c, const int *counts, int files) {
  const bb_command_options *o = bb__command_options_of(c);
  const char *command = bb_command_describe(c)->name;
  char *text = NULL;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  if (!f)
    return NULL;
  if (o->json) {
    bb__json j = {f, 0};
    bb__json_open(&j, NULL, '{');
    bb__json_open(&j, "summary", '{');
    bb__json_int(&j, "files", files);
    bb__json_int(&j, "baked", counts[BB_JOB_BAKED]);
    bb__json_int(&j, "up_to_date", counts[BB_JOB_CURRENT]);
    bb__json_int(&j, "failed", counts[BB_JOB_FAILED]);
    bb__json_int(&j, "not_run", counts[BB_JOB_NOT_RUN]);
    bb__json_close(&j, '}');
    bb__json_close(&j, '}');
    fputc('\n', f);
  } else if (!o->quiet) {
    fprintf(f, "%s: %d file%s: %d baked, %d up to date, %d failed", command, files,
            files == 1 ? "" : "s", counts[BB_JOB_BAKED], counts[BB_JOB_CURRENT],
            counts[BB_JOB_FAILED]);
    if (counts[BB_JOB_NOT_RUN])
      fprintf(f, ", %d not run (stopped at the first failure; --keep-going goes on)",
              counts[BB_JOB_NOT_RUN]);
    fputc('\n', f);
  }
  return closed(f, &text);
}
