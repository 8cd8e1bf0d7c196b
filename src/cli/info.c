/* info.c: `bumpbake info`, what image files are (size, channels, format,
 * sample type, alpha) and the provenance bumpbake stored in them. Reads
 * headers only: no pixel is decoded. */
#include "cli.h"
#include "common.h"

#include "bumpbake.h"
#include "../core/json.h" /* the JSON writer, compiled into the CLI (Makefile) */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct info_args {
  int json;
} info_args;

/* What one file is, as read from its header. */
typedef struct file_info {
  int width, height, channels;
  bb_image_info info;
  bb_provenance_class provenance;
  int is_vtf;
  bb_vtf_info vtf; /* when is_vtf */
  int is_dds;
  bb_dds_info dds; /* when is_dds */
} file_info;

/* The names of the flags set, by the library's name of each bit ("SSBUMP
 * NORMAL"; unnamed bits as hex). */
static void flag_names(uint32_t flags, const char *(*name_of)(int bit), char *out, size_t cap) {
  size_t n = 0;
  out[0] = '\0';
  for (int bit = 0; bit < 32 && n < cap; bit++) {
    if (!(flags & (1u << bit)))
      continue;
    const char *name = name_of(bit);
    int w = name ? snprintf(out + n, cap - n, "%s%s", n ? " " : "", name)
                 : snprintf(out + n, cap - n, "%s0x%08x", n ? " " : "", 1u << bit);
    n += w > 0 ? (size_t)w : 0;
  }
}

/* The names of the flags set, as a JSON array (unnamed bits left out). */
static void json_flag_names(bb__json *j, const char *key, uint32_t flags,
                            const char *(*name_of)(int bit)) {
  bb__json_open(j, key, '[');
  for (int bit = 0; bit < 32; bit++)
    if ((flags & (1u << bit)) && name_of(bit))
      bb__json_string(j, NULL, name_of(bit));
  bb__json_close(j, ']');
}

/* ------------------------------------------------------------------ text */

/* A file's text, line by line, control characters escaped: the first line
 * after first_prefix. */
static void print_lines(const char *first_prefix, const char *text) {
  for (int first = 1; *text; first = 0) {
    size_t n = strcspn(text, "\n");
    cli_printf_line("%s%.*s", first ? first_prefix : "", (int)n, text);
    text += n + (text[n] == '\n');
  }
}

static void print_text(const char *path, const file_info *f) {
  const bb_image_info *i = &f->info;
  cli_printf_line("%s: %d x %d, %d channel%s, %s, %d-bit %s", path, f->width, f->height,
                  f->channels, f->channels == 1 ? "" : "s", i->format_name,
                  i->bits_per_sample, i->is_float ? "float" : "integer");
  if (i->alpha_channel >= 0)
    printf("alpha channel: %d\n", i->alpha_channel);
  if (f->is_vtf) {
    const bb_vtf_info *v = &f->vtf;
    char names[512];
    flag_names(v->flags, bb_vtf_flag_name, names, sizeof names);
    printf("vtf: version %d.%d, %s, %d mip level%s, flags 0x%08x (%s)\n", v->version_major,
           v->version_minor, v->format_name, v->mip_count, v->mip_count == 1 ? "" : "s",
           (unsigned)v->flags, names[0] ? names : "none");
    printf("vtf: low-resolution image %d x %d, reflectivity %.4f %.4f %.4f, bump scale %g, "
           "%d frame%s\n",
           v->low_res_width, v->low_res_height, (double)v->reflectivity[0],
           (double)v->reflectivity[1], (double)v->reflectivity[2], (double)v->bump_scale,
           v->frames, v->frames == 1 ? "" : "s");
  }
  if (f->is_dds) {
    const bb_dds_info *d = &f->dds;
    char names[256];
    flag_names(d->pixel_flags, bb_dds_pixel_flag_name, names, sizeof names);
    /* "BC1 (FourCC DXT1)", "BC5 (DX10 BC5_UNORM = 83)", "R8G8B8A8, uncompressed" */
    const int blocks = strcmp(d->compression, "none") != 0;
    char what[96];
    if (d->dxgi_format && blocks)
      snprintf(what, sizeof what, "%s (DX10 %s = %d)", d->compression, d->format_name,
               d->dxgi_format);
    else if (d->dxgi_format)
      snprintf(what, sizeof what, "%s (DX10 DXGI format %d), uncompressed", d->format_name,
               d->dxgi_format);
    else if (d->fourcc[0])
      snprintf(what, sizeof what, "%s (FourCC %s)%s", blocks ? d->compression : d->format_name,
               d->fourcc, blocks ? "" : ", uncompressed");
    else
      snprintf(what, sizeof what, "%s, uncompressed", d->format_name);
    printf("dds: %s, %d mip level%s, pixel format flags 0x%08x (%s)\n", what, d->mip_count,
           d->mip_count == 1 ? "" : "s", (unsigned)d->pixel_flags, names[0] ? names : "none");
  }
  if (f->provenance == BB_PROVENANCE_NONE) {
    printf("no bumpbake provenance\n");
    if (i->description && *i->description)
      print_lines("description: ", i->description);
    return;
  }
  printf("%s:\n", f->provenance == BB_PROVENANCE_DAMAGED
                      ? "provenance (cut or re-wrapped by the file format)"
                      : "provenance");
  print_lines("", i->description);
}

/* ------------------------------------------------------------------ JSON */

/* The key=value lines of intact provenance as a JSON object of strings, as
 * the library reads them (bb_provenance_entries); values are kept as
 * written: exact, and the same for every key. */
static void json_provenance(bb__json *j, const char *text) {
  bb__json_open(j, "provenance", '{');
  const long count = bb_provenance_entries(text, NULL, 0);
  bb_provenance_entry *entries = count > 0 ? malloc((size_t)count * sizeof *entries) : NULL;
  if (entries)
    bb_provenance_entries(text, entries, (size_t)count);
  for (long i = 0; entries && i < count; i++) {
    /* Whole keys and values, however long: JSON is not cut. */
    char *key = strndup(entries[i].key, entries[i].key_length);
    char *value = strndup(entries[i].value, entries[i].value_length);
    if (key && value)
      bb__json_string(j, key, value);
    free(key);
    free(value);
  }
  free(entries);
  bb__json_close(j, '}');
}

static void print_json(const char *path, const file_info *f) {
  const bb_image_info *i = &f->info;
  bb__json j = {stdout, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "path", path);
  bb__json_int(&j, "width", f->width);
  bb__json_int(&j, "height", f->height);
  bb__json_int(&j, "channels", f->channels);
  bb__json_string(&j, "format", i->format_name);
  bb__json_int(&j, "bits_per_sample", i->bits_per_sample);
  bb__json_bool(&j, "float", i->is_float);
  bb__json_int(&j, "alpha_channel", i->alpha_channel);
  if (f->is_vtf) {
    const bb_vtf_info *v = &f->vtf;
    char text[512];
    bb__json_open(&j, "vtf", '{');
    snprintf(text, sizeof text, "%d.%d", v->version_major, v->version_minor);
    bb__json_string(&j, "version", text);
    bb__json_string(&j, "format", v->format_name);
    bb__json_int(&j, "format_code", v->format);
    bb__json_int(&j, "mip_count", v->mip_count);
    bb__json_int(&j, "flags", (long)v->flags);
    json_flag_names(&j, "flag_names", v->flags, bb_vtf_flag_name);
    bb__json_int(&j, "low_res_width", v->low_res_width);
    bb__json_int(&j, "low_res_height", v->low_res_height);
    bb__json_int(&j, "frames", v->frames);
    bb__json_close(&j, '}');
  }
  if (f->is_dds) {
    const bb_dds_info *d = &f->dds;
    bb__json_open(&j, "dds", '{');
    bb__json_string(&j, "format", d->format_name);
    bb__json_string(&j, "fourcc", d->fourcc[0] ? d->fourcc : NULL);
    bb__json_int(&j, "dxgi_format", d->dxgi_format);
    bb__json_string(&j, "compression", d->compression);
    bb__json_int(&j, "mip_count", d->mip_count);
    bb__json_int(&j, "pixel_flags", (long)d->pixel_flags);
    json_flag_names(&j, "pixel_flag_names", d->pixel_flags, bb_dds_pixel_flag_name);
    bb__json_int(&j, "caps2", (long)d->caps2);
    bb__json_close(&j, '}');
  }
  bb__json_string(&j, "provenance_state", bb_provenance_class_name(f->provenance));
  if (f->provenance == BB_PROVENANCE_INTACT)
    json_provenance(&j, i->description);
  else
    bb__json_string(&j, "provenance", NULL);
  bb__json_string(&j, "description", i->description);
  bb__json_close(&j, '}');
  fputc('\n', stdout);
}

/* A file that cannot be read: its one-line error on stderr, and with --json
 * a line saying so, so a pipeline sees one line per file. */
static void report_error(const info_args *a, const char *path, const bb_error *err) {
  cli_file_error(path, err->message);
  if (!a->json)
    return;
  bb__json j = {stdout, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "path", path);
  bb__json_string(&j, "error", err->message);
  bb__json_close(&j, '}');
  fputc('\n', stdout);
}

/* Reports one file; returns 0 or BB_EXIT_FAILURE. */
static int info_file(const info_args *a, const char *path, int index) {
  file_info f;
  memset(&f, 0, sizeof f);
  bb_error err = {{0}};
  bb_status st =
      bb_image_read_info(path, &f.width, &f.height, &f.channels, &f.info, &err);
  if (st != BB_OK) {
    report_error(a, path, &err);
    return BB_EXIT_FAILURE;
  }
  f.provenance = bb_provenance_classify(f.info.description);
  if (strcmp(f.info.format_name, "vtf") == 0 && bb_vtf_read_info(path, &f.vtf, &err) == BB_OK)
    f.is_vtf = 1;
  if (strcmp(f.info.format_name, "dds") == 0 && bb_dds_read_info(path, &f.dds, &err) == BB_OK)
    f.is_dds = 1;
  if (a->json) {
    print_json(path, &f);
  } else {
    if (index > 0)
      putchar('\n'); /* a blank line between the files described */
    print_text(path, &f);
  }
  bb_image_info_free(&f.info);
  bb_vtf_info_free(&f.vtf);
  return 0;
}

int cli_run_info(const cli_run *r) {
  const info_args a = {r->options->json};
  int rc = BB_EXIT_OK;
  int described = 0; /* files described so far, for the blank line between */
  for (int i = 0; i < bb_command_input_count(r->command); i++) {
    if (info_file(&a, bb_command_input(r->command, i), described))
      rc = BB_EXIT_FAILURE;
    else
      described++;
    fflush(stdout); /* keep stdout and stderr lines in order */
  }
  return rc;
}
