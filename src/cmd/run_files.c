/* run_files.c: the runs of the commands that look at files and write
 * none of their own (compare, info): what they find, kept as data in the
 * result (result.compare, result.info), and rendered as the command line
 * prints it (report_files.c). */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "core/internal.h"
#include "files/provenance.h"
#include "texture/dds.h"
#include "texture/vtf.h"

#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------- compare */

bb_status bb__run_compare(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                          bb_error *err) {
  const bb_command_options *o = &c->options;
  const char *a = c->inputs[0], *b = c->inputs[1];
  bb_compare_report *report = calloc(1, sizeof *report);
  if (!report)
    return bb__fail(err, BB_ERR_MEMORY, "compare: out of memory");
  r->compare = report;
  /* what it will cost, said before it starts when that is much */
  bb_status st = bb__compare_files_check(a, b, o->diff, hooks ? hooks->note : NULL,
                                         hooks ? hooks->note_user : NULL, err);
  if (st == BB_OK)
    st = bb__compare_files(a, b, &o->limits, o->diff, report, err);
  if (st != BB_OK)
    return st; /* idiff's "cannot compare": no report */
  r->exit_code = bb__compare_report_exit_code(report);
  if (o->diff && report->diff_written)
    st = bb__result_add(r, "diff", o->diff, err);
  return st == BB_OK ? bb__compare_prints(c, r, err) : st;
}

/* ---------------------------------------------------------------- info */

/* What the header of path says; a file that cannot be read keeps its
 * status and message. BB_ERR_MEMORY alone fails. */
static bb_status info_file(const char *path, bb_info_file *f, bb_error *err) {
  bb_error e = {{0}};
  f->path = strdup(path); /* the result's own: the command may go first */
  if (!f->path)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  f->status = bb_image_read_info(path, &f->width, &f->height, &f->channels, &f->image, &e);
  if (f->status != BB_OK) {
    f->error = strdup(e.message[0] ? e.message : bb_status_name(f->status));
    return f->error ? BB_OK : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  f->provenance = bb__provenance_classify(f->image.description);
  if (f->provenance == BB_PROVENANCE_INTACT) {
    const long count = bb__provenance_entries(f->image.description, NULL, 0);
    bb_provenance_entry *entries =
        count > 0 ? malloc((size_t)count * sizeof *entries) : NULL;
    if (count < 0 || (count > 0 && !entries))
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
    bb__provenance_entries(f->image.description, entries, (size_t)count);
    f->provenance_entries = entries;
    f->provenance_count = (int)count;
  }
  /* A texture whose own header cannot be read is described as the image
   * reader saw it. */
  const int vtf = !strcmp(f->image.format_name, "vtf"), dds = !strcmp(f->image.format_name, "dds");
  if (!vtf && !dds)
    return BB_OK;
  void *header = calloc(1, vtf ? sizeof(bb_vtf_info) : sizeof(bb_dds_info));
  if (!header)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  if ((vtf ? bb__vtf_read_info(path, header, &e) : bb__dds_read_info(path, header, &e)) != BB_OK) {
    free(header);
    return BB_OK;
  }
  const uint32_t flags = vtf ? ((bb_vtf_info *)header)->flags : ((bb_dds_info *)header)->pixel_flags;
  for (int bit = 0; bit < 32; bit++)
    f->flag_names[bit] = !(flags & (1u << bit)) ? NULL
                         : vtf                  ? bb__vtf_flag_name(bit)
                                                : bb__dds_pixel_flag_name(bit);
  if (vtf)
    f->vtf = header;
  else
    f->dds = header;
  return BB_OK;
}

bb_status bb__run_info(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                       bb_error *err) {
  (void)hooks;
  bb_info_file *files = calloc((size_t)c->input_count, sizeof *files);
  if (!files)
    return bb__fail(err, BB_ERR_MEMORY, "info: out of memory");
  r->info = files;
  r->info_count = c->input_count;
  for (int i = 0; i < c->input_count; i++) {
    bb_status st = info_file(c->inputs[i], &files[i], err);
    if (st != BB_OK)
      return st;
    if (files[i].status != BB_OK)
      r->exit_code = 1; /* reported and skipped */
  }
  return bb__info_prints(c, r, err);
}
