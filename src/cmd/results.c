/* results.c: what a run wrote or found (bb_command_result). */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "texture/vtf.h"

#include <stdlib.h>
#include <string.h>

bb_status bb__result_add(bb_command_result *r, const char *kind, const char *path,
                         bb_error *err) {
  bb_job_file *grown = realloc(r->files, ((size_t)r->file_count + 1) * sizeof *grown);
  if (!grown)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  r->files = grown;
  char *k = strdup(kind), *p = strdup(path);
  if (!k || !p) {
    free(k);
    free(p);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  r->files[r->file_count++] = (bb_job_file){k, p};
  return BB_OK;
}

static void info_files_free(bb_info_file *files, int count) {
  for (int i = 0; files && i < count; i++) {
    bb_info_file *f = &files[i];
    free((char *)f->path);
    free((char *)f->error);
    free((bb_provenance_entry *)f->provenance_entries);
    bb_image_info_free(&f->image);
    if (f->vtf)
      bb__vtf_info_free((bb_vtf_info *)f->vtf);
    free((bb_vtf_info *)f->vtf);
    free((bb_dds_info *)f->dds);
  }
  free(files);
}

void bb_command_result_free(bb_command_result *r) {
  if (!r)
    return;
  for (int i = 0; i < r->file_count; i++) {
    free((char *)r->files[i].kind);
    free((char *)r->files[i].path);
  }
  free(r->files);
  if (r->compare) {
    bb__compare_report_free((bb_compare_report *)r->compare);
    free((bb_compare_report *)r->compare);
  }
  info_files_free((bb_info_file *)r->info, r->info_count);
  for (int i = 0; i < r->print_count; i++) {
    free((char *)r->prints[i].path);
    free(r->prints[i].text);
  }
  free((bb_command_print *)r->prints);
  memset(r, 0, sizeof *r);
}

