/* provenance_format.c: how an output was made, as "key=value" lines stored
 * in the file (bb_provenance_format).
 *
 * The text is the contract between a bake and a later `bumpbake compare`: a
 * golden that no longer matches names the parameters that changed. So every
 * line is "key=value\n", keys are always present in the same order, and
 * numbers print so that parsing them gives back the same value. Reading
 * them back is files/provenance.c's.
 */

#include "core/internal.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Appends "key=value\n". A value with line breaks (a command line pasted
 * with newlines) would split the record, so they become spaces. */
static void put(bb__text *t, const char *key, const char *value) {
  bb__text_append(t, key, strlen(key));
  bb__text_append(t, "=", 1);
  for (const char *s = value ? value : ""; *s; s++) {
    char ch = (*s == '\n' || *s == '\r') ? ' ' : *s;
    bb__text_append(t, &ch, 1);
  }
  bb__text_append(t, "\n", 1);
}

static void put_float(bb__text *t, const char *key, float value) {
  char buf[64];
  snprintf(buf, sizeof buf, "%.9g", (double)value); /* 9 digits: any float round-trips */
  put(t, key, buf);
}

/* Doubles print in the shortest of %.15g / %.17g that reads back exactly, so
 * 0.55 stays "0.55" instead of "0.55000000000000004". */
static void format_double(char *buf, size_t cap, double value) {
  snprintf(buf, cap, "%.15g", value);
  if (strtod(buf, NULL) != value)
    snprintf(buf, cap, "%.17g", value);
}

static void put_double(bb__text *t, const char *key, double value) {
  char buf[64];
  format_double(buf, sizeof buf, value);
  put(t, key, buf);
}

/* The basis by name; a caller's vectors (named by their hash) are also
 * written out, "x y z" per direction joined by "; " (a basis file's lines),
 * so the file records what to bake it again with. */
static void put_basis(bb__text *t, const bb_basis *b) {
  put(t, "basis", b->name);
  if (strncmp(b->name, "vectors:", 8) != 0 || b->count < 1 || b->count > BB_MAX_BASIS)
    return;
  char line[BB_MAX_BASIS * 3 * 26 + 1];
  size_t used = 0;
  line[0] = '\0';
  for (int c = 0; c < b->count; c++)
    for (int k = 0; k < 3; k++) {
      char number[32];
      format_double(number, sizeof number, b->vector[c][k]);
      used += (size_t)snprintf(line + used, sizeof line - used, "%s%s",
                               k ? " " : (c ? "; " : ""), number);
    }
  put(t, "basis_vectors", line);
}

static void put_int(bb__text *t, const char *key, long value) {
  char buf[32];
  snprintf(buf, sizeof buf, "%ld", value);
  put(t, key, buf);
}

static void put_scale_and_rays(bb__text *t, const bb_bake_options *o) {
  put_float(t, "scale", o->height_scale);
  put_int(t, "rays", o->rays);
}

static void put_smoothing_and_tracing(bb__text *t, const bb_bake_options *o) {
  put_int(t, "filter_radius", o->smooth.radius_texels);
  put_float(t, "filter_threshold", o->smooth.threshold);
  put_double(t, "bias", o->trace.bias_texels);
  put_double(t, "power", o->power);
  put_basis(t, &o->basis);
  put(t, "normal_filter", bb_normal_filter_name(o->normal_filter));
  put(t, "normal_y", o->normal_y_up ? "up" : "down");
  put(t, "addressing", o->smooth.addressing == BB_ADDRESS_CLAMP ? "clamp" : "periodic");
  /* Inter-reflection and brightness only when used, so the provenance of
   * a bake without them (and its up-to-date check) stays as it was. Maps
   * are named by bb_image_hash of their pixels as given. */
  char hash[32];
  if (o->bounce_albedo > 0.0) {
    put_double(t, "bounce", o->bounce_albedo);
    put_int(t, "bounces", o->bounces);
    if (o->bounce_albedo_map) {
      snprintf(hash, sizeof hash, "%016" PRIx64, bb_image_hash(o->bounce_albedo_map));
      put(t, "bounce_albedo_map", hash);
    }
  }
  if (o->brightness) {
    snprintf(hash, sizeof hash, "%016" PRIx64, bb_image_hash(o->brightness));
    put(t, "brightness", hash);
  }
}

char *bb_provenance_format(const bb_provenance *p) {
  if (!p)
    return NULL;
  bb__text t = {0};
  char hash[32];
  snprintf(hash, sizeof hash, "%016" PRIx64, p->input_hash);

  put(&t, "bumpbake_version", BB_VERSION_STRING);
  put(&t, "command", p->command);
  put(&t, "input", p->input_name);
  put(&t, "input_hash", hash);
  if (p->input_file_hash) {
    snprintf(hash, sizeof hash, "%016" PRIx64, p->input_file_hash);
    put(&t, "input_file_hash", hash);
  }
  put(&t, "output", p->output_kind);
  /* The key order is fixed so two texts line up when read side by side. */
  if (p->options)
    put_scale_and_rays(&t, p->options);
  put(&t, "rayset", p->rayset_id ? p->rayset_id : "none");
  if (p->options)
    put_smoothing_and_tracing(&t, p->options);
  put(&t, "channel", bb_channel_name(p->channel));
  if (p->extra) {
    /* Lines of the caller's, each ended by a newline. */
    size_t n = strlen(p->extra);
    bb__text_append(&t, p->extra, n);
    if (n && p->extra[n - 1] != '\n')
      bb__text_append(&t, "\n", 1);
  }

  if (t.failed) {
    free(t.data);
    return NULL;
  }
  return t.data;
}
