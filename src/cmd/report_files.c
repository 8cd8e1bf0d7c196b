/* report_files.c: what `bumpbake compare` and `bumpbake info` print of
 * what they found (run_files.c), once, beside the bake's lines
 * (report.c): text or JSON lines for stdout and one-line errors for
 * stderr, in the order the command line prints them
 * (bb_command_result.prints). */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "core/internal.h"
#include "core/json.h"
#include "files/provenance.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void bb__print_line(FILE *f, const char *fmt, ...) {
  char text[4096], safe[4 * sizeof text];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  fprintf(f, "%s\n", bb_text_printable(text, safe, sizeof safe));
}

/* ------------------------------------------------------ pieces printed */

/* The result's pieces as they are made: stdout lines gather in f until an
 * error (stderr) comes between. */
typedef struct printer {
  bb_command_result *r;
  FILE *f;
  char *data;
  size_t size;
  int failed; /* out of memory */
} printer;

/* The result keeps its own copy of path: the command that named it may be
 * freed before the result is read. */
static bb_status add_piece(printer *p, int error, const char *path, char *text) {
  bb_command_print *grown =
      realloc((bb_command_print *)p->r->prints, ((size_t)p->r->print_count + 1) * sizeof *grown);
  char *kept = path ? strdup(path) : NULL;
  if (!grown || !text || (path && !kept)) {
    free(text);
    free(kept);
    p->failed = 1;
    if (grown)
      p->r->prints = grown;
    return BB_ERR_MEMORY;
  }
  grown[p->r->print_count++] = (bb_command_print){error, kept, text};
  p->r->prints = grown;
  return BB_OK;
}

/* The stdout lines in progress. */
static FILE *out(printer *p) {
  if (!p->f && !p->failed) {
    p->data = NULL;
    p->size = 0;
    p->f = open_memstream(&p->data, &p->size);
    p->failed = !p->f;
  }
  return p->f;
}

/* Ends the stdout lines in progress: a piece when there are any. */
static void end_lines(printer *p) {
  if (!p->f)
    return;
  const int failed = ferror(p->f);
  if (fclose(p->f) || failed) {
    free(p->data);
    p->failed = 1;
  } else if (p->size)
    add_piece(p, 0, NULL, p->data);
  else
    free(p->data);
  p->f = NULL;
}

/* A one-line error for stderr, about path (may be NULL). */
static void error(printer *p, const char *path, const char *text) {
  end_lines(p);
  if (!p->failed)
    add_piece(p, 1, path, strdup(text ? text : ""));
}

static bb_status finish(printer *p, bb_error *err) {
  end_lines(p);
  return p->failed ? bb__fail(err, BB_ERR_MEMORY, "out of memory") : BB_OK;
}

/* ------------------------------------------------------------- compare */

static double percent_of(long count, long total) {
  return total > 0 ? 100.0 * (double)count / (double)total : 0.0;
}

static void compare_text(FILE *f, const char *a, const char *b, const bb_compare_limits *l,
                         const bb_compare_report *r) {
  const bb_compare_stats *s = &r->stats;
  bb__print_line(f, "compare %s %s: %d x %d, %d channel%s", a, b, r->width, r->height,
                 r->channels, r->channels == 1 ? "" : "s");
  fprintf(f, "  mean abs error %.6g\n", s->mean_abs);
  fprintf(f, "  RMS error      %.6g\n", s->rms);
  fprintf(f, "  max abs error  %.6g", s->max_abs);
  if (s->max_abs > 0)
    fprintf(f, " at pixel (%d, %d) channel %d", s->worst_x, s->worst_y, s->worst_channel);
  fputc('\n', f);
  fprintf(f, "  %ld pixels (%.3g%%) over fail %g (allowed %g%%", s->over_fail,
          percent_of(s->over_fail, s->pixels), l->fail, l->fail_percent);
  if (l->allow_failures > 0)
    fprintf(f, ", or %ld pixels", l->allow_failures);
  if (isfinite(l->hard_fail))
    fprintf(f, "; hard fail %g", l->hard_fail);
  fprintf(f, ")\n");
  fprintf(f, "  %ld pixels (%.3g%%) over warn %g (allowed %g%%", s->over_warn,
          percent_of(s->over_warn, s->pixels), l->warn, l->warn_percent);
  if (isfinite(l->hard_warn))
    fprintf(f, "; hard warn %g", l->hard_warn);
  fprintf(f, ")\n");
  if (r->provenance_differences > 0) {
    fprintf(f, "provenance differs:\n");
    for (const char *line = r->provenance_diff; line && *line;) {
      size_t n = strcspn(line, "\n");
      bb__print_line(f, "%.*s", (int)n, line);
      line += n + (line[n] == '\n');
    }
  }
  fprintf(f, "%s\n", r->result);
}

/* The report as one JSON line; with stats 0 (different sizes) the paths
 * and the verdict alone. */
static void compare_json(FILE *f, const char *a, const char *b, const bb_compare_limits *l,
                         const bb_compare_report *r, int stats) {
  bb__json j = {f, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "a", a);
  bb__json_string(&j, "b", b);
  if (stats) {
    bb__json_int(&j, "width", r->width);
    bb__json_int(&j, "height", r->height);
    bb__json_int(&j, "channels", r->channels);
    bb__compare_json(&j, &r->stats, l); /* limits under idiff's option names */
    bb__json_lines(&j, "provenance_diff",
                   r->provenance_differences > 0 ? r->provenance_diff : NULL);
  }
  bb__json_string(&j, "result", r->result);
  bb__json_int(&j, "exit", bb__compare_report_exit_code(r));
  bb__json_close(&j, '}');
  fputc('\n', f);
}

static void compare_prints(printer *p, const bb_command *c, const bb_compare_report *r) {
  const bb_command_options *o = &c->options;
  const char *a = c->inputs[0], *b = c->inputs[1];
  if (!r->same_shape) {
    char line[1024];
    snprintf(line, sizeof line, "%s: %d x %d, %d channel%s, but %s is %d x %d, %d channel%s", b,
             r->b_width, r->b_height, r->b_channels, r->b_channels == 1 ? "" : "s", a,
             r->width, r->height, r->channels, r->channels == 1 ? "" : "s");
    error(p, NULL, line);
    if (o->json && !o->quiet && out(p))
      compare_json(p->f, a, b, &o->limits, r, 0);
    return;
  }
  /* Why provenance was not compared when a file has a damaged copy; on
   * stderr, so --json output stays one line. */
  const char *paths[2] = {a, b};
  const bb_provenance_class classes[2] = {r->provenance_a, r->provenance_b};
  for (int i = 0; i < 2; i++)
    if (classes[i] == BB_PROVENANCE_DAMAGED)
      error(p, paths[i], "provenance is cut or re-wrapped by the file format; not compared");
  if (!out(p))
    return; /* out of memory: the printer says so */
  if (o->quiet)
    ; /* the exit code is the answer */
  else if (o->json)
    compare_json(p->f, a, b, &o->limits, r, 1);
  else
    compare_text(p->f, a, b, &o->limits, r);
  /* A diff that cannot be written is reported but does not change the
   * verdict: the comparison itself was made. */
  if (o->diff && !r->diff_written)
    error(p, o->diff, r->diff_error.message);
  else if (o->diff && !o->quiet && !o->json)
    bb__print_line(p->f, "wrote diff %s", o->diff);
}

bb_status bb__compare_prints(const bb_command *c, bb_command_result *r, bb_error *err) {
  printer p = {r, NULL, NULL, 0, 0};
  compare_prints(&p, c, r->compare);
  return finish(&p, err);
}

/* ---------------------------------------------------------------- info */

/* The names of the flags set, by the library's name of each bit ("SSBUMP
 * NORMAL"; unnamed bits as hex). */
static void flag_names(uint32_t flags, const bb_info_file *file, char *out_, size_t cap) {
  size_t n = 0;
  out_[0] = '\0';
  for (int bit = 0; bit < 32 && n < cap; bit++) {
    if (!(flags & (1u << bit)))
      continue;
    const char *name = file->flag_names[bit];
    int w = name ? snprintf(out_ + n, cap - n, "%s%s", n ? " " : "", name)
                 : snprintf(out_ + n, cap - n, "%s0x%08x", n ? " " : "", 1u << bit);
    n += w > 0 ? (size_t)w : 0;
  }
}

/* The names of the flags set, as a JSON array (unnamed bits left out). */
static void json_flag_names(bb__json *j, const char *key, const bb_info_file *f) {
  bb__json_open(j, key, '[');
  for (int bit = 0; bit < 32; bit++)
    if (f->flag_names[bit])
      bb__json_string(j, NULL, f->flag_names[bit]);
  bb__json_close(j, ']');
}

/* A file's text, line by line, control characters escaped: the first line
 * after first_prefix. */
static void text_lines(FILE *f, const char *first_prefix, const char *text) {
  for (int first = 1; *text; first = 0) {
    size_t n = strcspn(text, "\n");
    bb__print_line(f, "%s%.*s", first ? first_prefix : "", (int)n, text);
    text += n + (text[n] == '\n');
  }
}

static void info_vtf_text(FILE *f, const bb_info_file *file) {
  const bb_vtf_info *v = file->vtf;
  char names[512];
  flag_names(v->flags, file, names, sizeof names);
  fprintf(f, "vtf: version %d.%d, %s, %d mip level%s, flags 0x%08x (%s)\n", v->version_major,
          v->version_minor, v->format_name, v->mip_count, v->mip_count == 1 ? "" : "s",
          (unsigned)v->flags, names[0] ? names : "none");
  fprintf(f,
          "vtf: low-resolution image %d x %d, reflectivity %.4f %.4f %.4f, bump scale %g, "
          "%d frame%s\n",
          v->low_res_width, v->low_res_height, (double)v->reflectivity[0],
          (double)v->reflectivity[1], (double)v->reflectivity[2], (double)v->bump_scale,
          v->frames, v->frames == 1 ? "" : "s");
}

static void info_dds_text(FILE *f, const bb_info_file *file) {
  const bb_dds_info *d = file->dds;
  char names[256];
  flag_names(d->pixel_flags, file, names, sizeof names);
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
  fprintf(f, "dds: %s, %d mip level%s, pixel format flags 0x%08x (%s)\n", what, d->mip_count,
          d->mip_count == 1 ? "" : "s", (unsigned)d->pixel_flags, names[0] ? names : "none");
}

static void info_text(FILE *f, const bb_info_file *file) {
  const bb_image_info *i = &file->image;
  bb__print_line(f, "%s: %d x %d, %d channel%s, %s, %d-bit %s", file->path, file->width,
                 file->height, file->channels, file->channels == 1 ? "" : "s", i->format_name,
                 i->bits_per_sample, i->is_float ? "float" : "integer");
  if (i->alpha_channel >= 0)
    fprintf(f, "alpha channel: %d\n", i->alpha_channel);
  if (file->vtf)
    info_vtf_text(f, file);
  if (file->dds)
    info_dds_text(f, file);
  if (file->provenance == BB_PROVENANCE_NONE) {
    fprintf(f, "no bumpbake provenance\n");
    if (i->description && *i->description)
      text_lines(f, "description: ", i->description);
    return;
  }
  fprintf(f, "%s:\n", file->provenance == BB_PROVENANCE_DAMAGED
                          ? "provenance (cut or re-wrapped by the file format)"
                          : "provenance");
  text_lines(f, "", i->description);
}

/* The key=value lines of intact provenance as a JSON object of strings,
 * values as written: exact, and the same for every key. */
static void json_provenance(bb__json *j, const bb_info_file *file) {
  bb__json_open(j, "provenance", '{');
  for (int i = 0; i < file->provenance_count; i++) {
    /* Whole keys and values, however long: JSON is not cut. */
    const bb_provenance_entry *e = &file->provenance_entries[i];
    char *key = strndup(e->key, e->key_length);
    char *value = strndup(e->value, e->value_length);
    if (key && value)
      bb__json_string(j, key, value);
    free(key);
    free(value);
  }
  bb__json_close(j, '}');
}

static void info_json_vtf(bb__json *j, const bb_info_file *file) {
  const bb_vtf_info *v = file->vtf;
  char text[512];
  bb__json_open(j, "vtf", '{');
  snprintf(text, sizeof text, "%d.%d", v->version_major, v->version_minor);
  bb__json_string(j, "version", text);
  bb__json_string(j, "format", v->format_name);
  bb__json_int(j, "format_code", v->format);
  bb__json_int(j, "mip_count", v->mip_count);
  bb__json_int(j, "flags", (long)v->flags);
  json_flag_names(j, "flag_names", file);
  bb__json_int(j, "low_res_width", v->low_res_width);
  bb__json_int(j, "low_res_height", v->low_res_height);
  bb__json_int(j, "frames", v->frames);
  bb__json_close(j, '}');
}

static void info_json_dds(bb__json *j, const bb_info_file *file) {
  const bb_dds_info *d = file->dds;
  bb__json_open(j, "dds", '{');
  bb__json_string(j, "format", d->format_name);
  bb__json_string(j, "fourcc", d->fourcc[0] ? d->fourcc : NULL);
  bb__json_int(j, "dxgi_format", d->dxgi_format);
  bb__json_string(j, "compression", d->compression);
  bb__json_int(j, "mip_count", d->mip_count);
  bb__json_int(j, "pixel_flags", (long)d->pixel_flags);
  json_flag_names(j, "pixel_flag_names", file);
  bb__json_int(j, "caps2", (long)d->caps2);
  bb__json_close(j, '}');
}

static void info_json(FILE *f, const bb_info_file *file) {
  const bb_image_info *i = &file->image;
  bb__json j = {f, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "path", file->path);
  bb__json_int(&j, "width", file->width);
  bb__json_int(&j, "height", file->height);
  bb__json_int(&j, "channels", file->channels);
  bb__json_string(&j, "format", i->format_name);
  bb__json_int(&j, "bits_per_sample", i->bits_per_sample);
  bb__json_bool(&j, "float", i->is_float);
  bb__json_int(&j, "alpha_channel", i->alpha_channel);
  if (file->vtf)
    info_json_vtf(&j, file);
  if (file->dds)
    info_json_dds(&j, file);
  bb__json_string(&j, "provenance_state", bb__provenance_class_name(file->provenance));
  if (file->provenance == BB_PROVENANCE_INTACT)
    json_provenance(&j, file);
  else
    bb__json_string(&j, "provenance", NULL);
  bb__json_string(&j, "description", i->description);
  bb__json_close(&j, '}');
  fputc('\n', f);
}

/* A file that cannot be read: its one-line error, and with --json a line
 * saying so, so a pipeline sees one line per file. */
static void info_error(FILE *f, const bb_info_file *file) {
  bb__json j = {f, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "path", file->path);
  bb__json_string(&j, "error", file->error);
  bb__json_close(&j, '}');
  fputc('\n', f);
}

bb_status bb__info_prints(const bb_command *c, bb_command_result *r, bb_error *err) {
  printer p = {r, NULL, NULL, 0, 0};
  int described = 0; /* files described so far, for the blank line between */
  for (int i = 0; i < r->info_count && !p.failed; i++) {
    const bb_info_file *file = &r->info[i];
    if (file->status != BB_OK) {
      error(&p, file->path, file->error);
      if (c->options.json && out(&p))
        info_error(p.f, file);
    } else if (!out(&p)) {
      break;
    } else if (c->options.json) {
      info_json(p.f, file);
    } else {
      if (described > 0)
        fputc('\n', p.f); /* a blank line between the files described */
      info_text(p.f, file);
    }
    described += file->status == BB_OK;
    end_lines(&p); /* a piece a file: printed as each is */
  }
  return finish(&p, err);
}
