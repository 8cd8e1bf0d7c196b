/* compare_files.c: two image files compared as OpenImageIO's idiff compares
 * them, their provenance key by key, and the image of their differences. */
#include "core/internal.h"
#include "image/formats.h"
#include "job/job_internal.h"
#include "files/provenance.h"
#include "maps/maps_internal.h"
#include "core/json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bb__job_output bb__compare_diff_output(const char *path) {
  return (bb__job_output){.path = path,
                          .kind = "diff",
                          .range = BB_RANGE_UNIT,
                          .depth = bb__path_has_extension(path, "exr") ? BB_DEPTH_FLOAT
                                                                      : BB_DEPTH_DEFAULT};
}

/* Writes |A-B| through the job. EXR keeps the raw differences; integer
 * formats would round typical golden differences (1e-5) to 0, so the image
 * is scaled to make the largest finite difference white and NaN/infinite
 * differences clip to 1. */
static bb_status write_diff(const char *path, bb_image *diff, bb_error *err) {
  const bb__job_output out = bb__compare_diff_output(path);
  const size_t n = (size_t)diff->width * (size_t)diff->height * (size_t)diff->channels;
  if (out.depth != BB_DEPTH_FLOAT) {
    double max_finite = 0;
    for (size_t i = 0; i < n; i++)
      if (isfinite(diff->pixels[i]) && diff->pixels[i] > max_finite)
        max_finite = diff->pixels[i];
    if (max_finite > 0)
      for (size_t i = 0; i < n; i++)
        diff->pixels[i] =
            isfinite(diff->pixels[i]) ? (float)(diff->pixels[i] / max_finite) : 1.0f;
  }
  return bb__job_write(&out, diff, NULL, err);
}

static void compare_provenance(const bb_image_info *ia, const bb_image_info *ib,
                               bb_compare_report *r) {
  r->provenance_a = bb__provenance_classify(ia->description);
  r->provenance_b = bb__provenance_classify(ib->description);
  r->provenance_differences = -1;
  if (r->provenance_a != BB_PROVENANCE_INTACT || r->provenance_b != BB_PROVENANCE_INTACT)
    return;
  /* Room for every line of both texts, so no difference is cut off. */
  const size_t cap = strlen(ia->description) + strlen(ib->description) + 1024;
  r->provenance_diff = malloc(cap);
  if (!r->provenance_diff)
    return;
  r->provenance_differences =
      bb__provenance_diff(ia->description, ib->description, r->provenance_diff, cap);
  if (r->provenance_differences < 0) {
    free(r->provenance_diff);
    r->provenance_diff = NULL;
  }
}

/* Bytes a file's samples take as stored, from its header: what the read
 * holds beside the floats while it decodes. */
static double stored_bytes(int width, int height, int channels,
                           const bb_image_info *info) {
  const int bits = info->bits_per_sample > 0 ? info->bits_per_sample : 32;
  return (double)width * height * channels * ((bits + 7) / 8);
}

bb_status bb__compare_files_check(const char *a, const char *b, const char *diff_path,
                                 bb_note_fn note, void *note_user, bb_error *err) {
  if (!a || !b)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: bad arguments");
  int w[2], h[2], c[2];
  bb_image_info info[2];
  const char *paths[2] = {a, b};
  for (int i = 0; i < 2; i++) {
    bb_status st = bb_image_read_info(paths[i], &w[i], &h[i], &c[i], &info[i], err);
    bb_image_info_free(&info[i]); /* (its description; the sizes stay) */
    if (st != BB_OK)
      return st;
  }
  /* A held while B is read (its floats and its stored samples), then,
   * with a diff, both and |A - B| and the encoder's copy of it. */
  double floats[2], reads[2];
  for (int i = 0; i < 2; i++) {
    floats[i] = (double)w[i] * h[i] * c[i] * sizeof(float);
    reads[i] = floats[i] + stored_bytes(w[i], h[i], c[i], &info[i]);
  }
  double peak = reads[0] > floats[0] + reads[1] ? reads[0] : floats[0] + reads[1];
  const int same = w[0] == w[1] && h[0] == h[1] && c[0] == c[1];
  if (same && diff_path) {
    const double texels = (double)w[0] * h[0] * c[0];
    const double diffing =
        3.0 * floats[0] + texels * bb__encoded_sample_bytes(diff_path, BB_DEPTH_DEFAULT);
    peak = diffing > peak ? diffing : peak;
  }
  const double need = peak * 1.05 + 32.0 * 1024 * 1024;
  char what[128], named[4400], text[256];
  snprintf(what, sizeof what, "comparing %s %d x %d image%s of %d channel%s",
           same ? "two" : "a", w[0], h[0], same ? "s" : "", c[0], c[0] == 1 ? "" : "s");
  snprintf(named, sizeof named, "%s: %s", a, what);
  bb_status st = bb__memory_check(need, named, err);
  if (st == BB_OK && note && bb__memory_note(need, what, text, sizeof text))
    note(note_user, a, text);
  return st;
}

/* idiff's word for a report's outcome (bb_compare_report.result). */
static const char *result_word(const bb_compare_report *report) {
  if (!report->same_shape)
    return "DIFFERENT SIZE";
  switch (report->verdict) {
  case BB_COMPARE_PASS: return "PASS";
  case BB_COMPARE_WARN: return "WARNING";
  case BB_COMPARE_FAIL: return "FAILURE";
  }
  return "FAILURE";
}

bb_status bb__compare_files(const char *a, const char *b, const bb_compare_limits *limits,
                           const char *diff_path, bb_compare_report *report, bb_error *err) {
  if (!a || !b || !report)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: bad arguments");
  memset(report, 0, sizeof *report);
  report->provenance_differences = -1;
  bb_compare_limits defaults;
  bb__compare_limits_init(&defaults);
  if (!limits)
    limits = &defaults;
  bb_status checked = bb__compare_limits_check(limits, err);
  if (checked != BB_OK)
    return checked;
  bb_image x = {0}, y = {0};
  bb_image_info ix = {0}, iy = {0};
  /* what it will take, from the headers, before a pixel is read */
  bb_status st = bb__compare_files_check(a, b, diff_path, NULL, NULL, err);
  if (st == BB_OK)
    st = bb_image_read(a, &x, &ix, err);
  if (st == BB_OK)
    st = bb_image_read(b, &y, &iy, err);
  if (st == BB_OK) {
    report->width = x.width, report->height = x.height, report->channels = x.channels;
    report->b_width = y.width, report->b_height = y.height, report->b_channels = y.channels;
    report->same_shape =
        x.width == y.width && x.height == y.height && x.channels == y.channels;
    report->verdict = BB_COMPARE_FAIL;
  }
  bb_image diff = {0};
  if (st == BB_OK && report->same_shape) {
    st = bb__compare_images(&x, &y, limits->fail, limits->warn, &report->stats,
                           diff_path ? &diff : NULL, err);
    if (st == BB_OK) {
      compare_provenance(&ix, &iy, report);
      report->verdict = bb__compare_judge(&report->stats, limits);
      if (diff_path)
        report->diff_written = write_diff(diff_path, &diff, &report->diff_error) == BB_OK;
    }
  }
  if (st == BB_OK)
    report->result = result_word(report);
  bb_image_free(&diff);
  bb_image_free(&x);
  bb_image_free(&y);
  bb_image_info_free(&ix);
  bb_image_info_free(&iy);
  if (st != BB_OK)
    bb__compare_report_free(report);
  return st;
}

void bb__compare_report_free(bb_compare_report *report) {
  if (!report)
    return;
  free(report->provenance_diff);
  report->provenance_diff = NULL;
}

int bb__compare_report_exit_code(const bb_compare_report *report) {
  if (!report)
    return BB_COMPARE_FAIL;
  if (!report->same_shape)
    return BB_COMPARE_DIFFERENT_SIZE;
  return (int)report->verdict;
}


void bb__compare_json(struct bb__json *j, const bb_compare_stats *s, const bb_compare_limits *l) {
  bb__json_int(j, "pixels", s->pixels);
  bb__json_number(j, "mean_abs", s->mean_abs);
  bb__json_number(j, "rms", s->rms);
  bb__json_number(j, "max_abs", s->max_abs); /* null when a NaN differs */
  bb__json_open(j, "worst", '{');
  bb__json_int(j, "x", s->worst_x);
  bb__json_int(j, "y", s->worst_y);
  bb__json_int(j, "channel", s->worst_channel);
  bb__json_close(j, '}');
  /* Limits under idiff's option names; infinite hard limits are null. */
  bb__json_number(j, "fail", l->fail);
  bb__json_number(j, "failpercent", l->fail_percent);
  bb__json_number(j, "hardfail", l->hard_fail);
  bb__json_int(j, "allowfailures", l->allow_failures);
  bb__json_int(j, "over_fail", s->over_fail);
  bb__json_number(j, "warn", l->warn);
  bb__json_number(j, "warnpercent", l->warn_percent);
  bb__json_number(j, "hardwarn", l->hard_warn);
  bb__json_int(j, "over_warn", s->over_warn);
}
