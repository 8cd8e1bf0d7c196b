/* provenance_format.c: how an output was made, as "key=value" lines stored
 * in the file (bb__provenance_format).
 *
 * The text is the contract between a bake and a later `bumpbake compare`: a
 * golden that no longer matches names the parameters that changed. So every
 * line is "key=value\n", keys are always present in the same order, and
 * numbers print so that parsing them gives back the same value. Reading
 * them back is files/provenance.c's.
 */

#include "job/job_internal.h"
#include "core/internal.h"
#include "image/height_channel.h"
#include "bake/bake_internal.h"

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

static void put_int(bb__text *t, const char *key, long value) {
  char buf[32];
  snprintf(buf, sizeof buf, "%ld", value);
  put(t, key, buf);
}

/* A bake's parameter, put only when the output's kind records it
 * (bb__map_kind_records: a normal map does not record the trace's). */
typedef struct bake_keys {
  bb__text *t;
  const char *kind;
  int bounce;
} bake_keys;

static int records(const bake_keys *k, const char *key) {
  return bb__map_kind_key(k->kind, key, strlen(key), k->bounce) != BB__KEY_DROPPED;
}

static void put_bake(const bake_keys *k, const char *key, const char *value) {
  if (records(k, key))
    put(k->t, key, value);
}

static void put_bake_float(const bake_keys *k, const char *key, float value) {
  if (records(k, key))
    put_float(k->t, key, value);
}

static void put_bake_double(const bake_keys *k, const char *key, double value) {
  if (records(k, key))
    put_double(k->t, key, value);
}

static void put_bake_int(const bake_keys *k, const char *key, long value) {
  if (records(k, key))
    put_int(k->t, key, value);
}

/* The basis by name; a caller's vectors (named by their hash) are also
 * written out, "x y z" per direction joined by "; " (a basis file's lines),
 * so the file records what to bake it again with. */
static void put_basis(const bake_keys *k, const bb_basis *b) {
  put_bake(k, "basis", b->name);
  if (strncmp(b->name, "vectors:", 8) != 0 || b->count < 1 || b->count > BB_MAX_BASIS)
    return;
  char line[BB_MAX_BASIS * 3 * 26 + 1];
  size_t used = 0;
  line[0] = '\0';
  for (int c = 0; c < b->count; c++)
    for (int i = 0; i < 3; i++) {
      char number[32];
      format_double(number, sizeof number, b->vector[c][i]);
      used += (size_t)snprintf(line + used, sizeof line - used, "%s%s",
                               i ? " " : (c ? "; " : ""), number);
    }
  put_bake(k, "basis_vectors", line);
}

/* The ray set's id, or its scheme and slices where the kind records only
 * those (ao without inter-reflection). */
static void put_rayset(const bake_keys *k, const char *id) {
  switch (bb__map_kind_key(k->kind, "rayset", 6, k->bounce)) {
  case BB__KEY_DROPPED: return;
  case BB__KEY_RECORDED: put(k->t, "rayset", id); return;
  case BB__KEY_SLICES: {
    char cut[64];
    snprintf(cut, sizeof cut, "%.*s", (int)bb__rayset_slices_length(id, strlen(id)), id);
    put(k->t, "rayset", cut);
    return;
  }
  }
}

static void put_smoothing_and_tracing(const bake_keys *k, const bb_bake_options *o) {
  put_bake_int(k, "filter_radius", o->smooth.radius_texels);
  put_bake_float(k, "filter_threshold", o->smooth.threshold);
  put_bake_double(k, "bias", o->trace.bias_texels);
  put_bake_double(k, "power", o->power);
  put_basis(k, &o->basis);
  put_bake(k, "normal_filter", bb__normal_filter_name(o->normal_filter));
  put_bake(k, "normal_y", o->normal_y_up ? "up" : "down");
  put_bake(k, "addressing",
           o->smooth.addressing == BB_ADDRESS_CLAMP ? "clamp" : "periodic");
  /* Inter-reflection and brightness only when used, so the provenance of
   * a bake without them (and its up-to-date check) stays as it was. Maps
   * are named by bb__image_hash of their pixels as given. */
  char hash[32];
  if (o->bounce_albedo > 0.0) {
    put_bake_double(k, "bounce", o->bounce_albedo);
    put_bake_int(k, "bounces", o->bounces);
    if (o->bounce_albedo_map) {
      snprintf(hash, sizeof hash, "%016" PRIx64, bb__image_hash(o->bounce_albedo_map));
      put_bake(k, "bounce_albedo_map", hash);
    }
  }
  if (o->brightness) {
    snprintf(hash, sizeof hash, "%016" PRIx64, bb__image_hash(o->brightness));
    put_bake(k, "brightness", hash);
  }
}

char *bb__provenance_format(const bb_provenance *p) {
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
  /* The key order is fixed so two texts line up when read side by side.
   * A bake's maps record only the parameters their kind depends on; other
   * outputs (without bake options) record the ray set as they always have. */
  const bake_keys k = {&t, p->output_kind, p->options && p->options->bounce_albedo > 0.0};
  if (p->options) {
    put_bake_float(&k, "scale", p->options->height_scale);
    put_bake_int(&k, "rays", p->options->rays);
    put_rayset(&k, p->rayset_id ? p->rayset_id : "none");
    put_smoothing_and_tracing(&k, p->options);
  } else {
    put(&t, "rayset", p->rayset_id ? p->rayset_id : "none");
  }
  put(&t, "channel", bb__channel_name(p->channel));
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
