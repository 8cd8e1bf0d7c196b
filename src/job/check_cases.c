/* check_cases.c: a golden check and its cases: the check made from its
 * setup, the limits of a map (idiff's options, then the rules that select
 * it), a case decided (two images compared, their provenance diffed, the
 * report's pictures drawn) and added, and what a case found in words. The
 * runs that make cases are check.c's and check_bake.c's. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "core/internal.h"
#include "job/check.h"
#include "job/job_internal.h"
#include "files/provenance.h"
#include "maps/maps_internal.h"

#include <fnmatch.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static char *copy(const char *s) {
  return s ? strdup(s) : NULL;
}

/* ------------------------------------------------------------- the check */

bb_status bb__check_new(bb__check_setup *setup, bb_check **out, bb_error *err) {
  *out = NULL;
  bb_check *c = calloc(1, sizeof *c);
  if (!c) {
    bb_job_free(setup->job);
    for (int i = 0; i < setup->rule_count; i++)
      free(setup->rules[i].selector);
    free(setup->rules);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  c->setup = *setup;
  c->golden = copy(setup->golden);
  c->fresh = copy(setup->fresh);
  c->junit = copy(setup->junit);
  c->html = copy(setup->html);
  c->setup.golden = c->golden;
  c->setup.fresh = c->fresh;
  c->setup.junit = c->junit;
  c->setup.html = c->html;
  if (!c->golden || (setup->fresh && !c->fresh) || (setup->junit && !c->junit) ||
      (setup->html && !c->html)) {
    bb_check_free(c);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  bb_status st = BB_OK;
  if (c->html) { /* the pictures go to DIR/img as the cases are decided */
    char img[PATH_MAX];
    snprintf(img, sizeof img, "%s/img", c->html);
    st = bb__directory_create(img, err);
  }
  if (st != BB_OK) {
    bb_check_free(c);
    return st;
  }
  *out = c;
  return BB_OK;
}

void bb_check_free(bb_check *c) {
  if (!c)
    return;
  for (int i = 0; i < c->count; i++)
    bb__check_case_free(c->cases[i]);
  free(c->cases);
  bb__check_atlas_free(c->atlas);
  bb_job_free(c->setup.job);
  for (int i = 0; i < c->setup.rule_count; i++)
    free(c->setup.rules[i].selector);
  free(c->setup.rules);
  free(c->golden);
  free(c->fresh);
  free(c->junit);
  free(c->html);
  free(c);
}

const bb__check_setup *bb__check_setup_of(const bb_check *c) {
  return &c->setup;
}

bb_job *bb__check_job(bb_check *c) {
  return c->setup.job;
}

int bb_check_case_count(const bb_check *c) {
  return c ? c->count : 0;
}

const bb_check_case *bb_check_case_get(const bb_check *c, int i) {
  return c && i >= 0 && i < c->count ? &c->cases[i]->pub : NULL;
}

/* --------------------------------------------------------------- limits */

/* 1 when a rule's kind selects a map of kind: its name, or the first part
 * of a packed kind ("ssbump" selects "ssbump+height"). */
static int kind_selects(const char *selector, const char *kind) {
  const size_t n = strcspn(kind, "+");
  return strlen(selector) == n && strncmp(selector, kind, n) == 0;
}

bb_compare_limits bb__check_limits(const bb_check *c, const char *kind,
                                   const char *name) {
  bb_compare_limits l = c->setup.limits;
  for (int i = 0; i < c->setup.rule_count; i++) {
    const bb__check_rule *r = &c->setup.rules[i];
    if (r->is_kind ? !kind_selects(r->selector, kind ? kind : "")
                   : fnmatch(r->selector, name, 0) != 0)
      continue;
    if (r->given & BB__LIMIT_FAIL)
      l.fail = r->limits.fail;
    if (r->given & BB__LIMIT_FAIL_PERCENT)
      l.fail_percent = r->limits.fail_percent;
    if (r->given & BB__LIMIT_HARD_FAIL)
      l.hard_fail = r->limits.hard_fail;
    if (r->given & BB__LIMIT_ALLOW_FAILURES)
      l.allow_failures = r->limits.allow_failures;
    if (r->given & BB__LIMIT_WARN)
      l.warn = r->limits.warn;
    if (r->given & BB__LIMIT_WARN_PERCENT)
      l.warn_percent = r->limits.warn_percent;
    if (r->given & BB__LIMIT_HARD_WARN)
      l.hard_warn = r->limits.hard_warn;
  }
  return l;
}

/* ---------------------------------------------------------------- cases */

static int exit_code_of(bb_check_status s) {
  switch (s) {
  case BB_CHECK_PASS:
    return 0;
  case BB_CHECK_WARNING:
    return 1;
  case BB_CHECK_FAILURE:
  case BB_CHECK_MISSING:
  case BB_CHECK_EXTRA:
    return 2;
  case BB_CHECK_DIFFERENT_SIZE:
    return BB_COMPARE_DIFFERENT_SIZE;
  case BB_CHECK_UNREADABLE:
    return BB_COMPARE_CANNOT_READ;
  }
  return BB_COMPARE_CANNOT_READ;
}

const char *bb__check_status_name(bb_check_status s) {
  switch (s) {
  case BB_CHECK_PASS:
    return "PASS";
  case BB_CHECK_WARNING:
    return "WARNING";
  case BB_CHECK_FAILURE:
    return "FAILURE";
  case BB_CHECK_DIFFERENT_SIZE:
    return "DIFFERENT SIZE";
  case BB_CHECK_UNREADABLE:
    return "UNREADABLE";
  case BB_CHECK_MISSING:
    return "MISSING";
  case BB_CHECK_EXTRA:
    return "EXTRA";
  }
  return "unknown";
}

/* The public record's strings point at the case's own. */
static void publish(bb__check_case *k) {
  k->pub.name = k->name;
  k->pub.golden = k->golden;
  k->pub.fresh = k->fresh;
  k->pub.kind = k->kind ? k->kind : "";
  k->pub.provenance_diff = k->provenance_diff;
  k->pub.message = k->message ? k->message : "";
  k->pub.update_error = k->update_error;
  k->pub.exit_code = exit_code_of(k->pub.status);
}

bb__check_case *bb__check_case_new(const char *name, const char *golden,
                                   const char *fresh, const char *kind) {
  bb__check_case *k = calloc(1, sizeof *k);
  if (!k)
    return NULL;
  k->name = copy(name);
  k->golden = copy(golden);
  k->fresh = copy(fresh);
  k->kind = copy(kind ? kind : "");
  if (!k->name || !k->golden || (fresh && !k->fresh) || !k->kind) {
    bb__check_case_free(k);
    return NULL;
  }
  bb__compare_limits_init(&k->pub.limits);
  publish(k);
  return k;
}

void bb__check_case_free(bb__check_case *k) {
  if (!k)
    return;
  free(k->name);
  free(k->golden);
  free(k->fresh);
  free(k->kind);
  free(k->provenance_diff);
  free(k->message);
  free(k->update_error);
  free(k->thumbs);
  free(k->strip);
  free(k);
}

static int same_shape(const bb_image *a, const bb_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels;
}

/* "key: golden -> new" lines of two intact provenance texts (malloc'd), or
 * NULL when either is not intact or memory ran out. */
static char *provenance_diff(const char *golden, const char *fresh) {
  if (bb__provenance_classify(golden) != BB_PROVENANCE_INTACT ||
      bb__provenance_classify(fresh) != BB_PROVENANCE_INTACT)
    return NULL;
  const size_t cap = strlen(golden) + strlen(fresh) + 1024;
  char *out = malloc(cap);
  if (out && bb__provenance_diff(golden, fresh, out, cap) < 0) {
    free(out);
    out = NULL;
  }
  return out;
}

/* The kind a case's files record ("output"), the new one's first. */
static void kind_from(const bb__check_sides *s, char *kind, size_t cap) {
  kind[0] = '\0';
  if (!bb__provenance_value(s->fresh_text, "output", kind, cap))
    bb__provenance_value(s->golden_text, "output", kind, cap);
}

bb_status bb__check_decide(bb_check *c, bb__check_case *k, const bb__check_sides *s,
                           bb_check_status status, const char *message, bb_error *err) {
  if (!k->kind[0]) {
    char kind[64];
    kind_from(s, kind, sizeof kind);
    if (kind[0]) {
      free(k->kind);
      if (!(k->kind = strdup(kind)))
        return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    }
  }
  k->pub.limits = bb__check_limits(c, k->kind, k->name);
  if (s->golden)
    k->pub.width = s->golden->width, k->pub.height = s->golden->height,
    k->pub.channels = s->golden->channels;
  if (s->fresh)
    k->pub.new_width = s->fresh->width, k->pub.new_height = s->fresh->height,
    k->pub.new_channels = s->fresh->channels;
  if (status == BB_CHECK_PASS && s->golden && s->fresh &&
      !same_shape(s->golden, s->fresh))
    status = BB_CHECK_DIFFERENT_SIZE;
  if (status == BB_CHECK_PASS && s->golden && s->fresh) {
    const bb_compare_limits *l = &k->pub.limits;
    bb_status st = bb__compare_images(s->golden, s->fresh, l->fail, l->warn, &k->pub.stats,
                                     NULL, err);
    if (st != BB_OK)
      return st;
    switch (bb__compare_judge(&k->pub.stats, l)) {
    case BB_COMPARE_PASS:
      status = BB_CHECK_PASS;
      break;
    case BB_COMPARE_WARN:
      status = BB_CHECK_WARNING;
      break;
    case BB_COMPARE_FAIL:
      status = BB_CHECK_FAILURE;
      break;
    }
  }
  k->pub.status = status;
  if (message && !(k->message = strdup(message)))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  if (s->golden && s->fresh)
    k->provenance_diff = provenance_diff(s->golden_text, s->fresh_text);
  publish(k);
  /* a report that cannot be drawn stops the run: its pictures would lie */
  return c->html ? bb__check_pictures(&c->atlas, c->html, k, s, err) : BB_OK;
}

bb_status bb__check_add(bb_check *c, bb__check_case *k, bb_check_case_fn each, void *user,
                        bb_error *err) {
  if (c->count == c->capacity) {
    const int cap = c->capacity ? 2 * c->capacity : 64;
    bb__check_case **grown = realloc(c->cases, (size_t)cap * sizeof *grown);
    if (!grown) {
      bb__check_case_free(k);
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    }
    c->cases = grown;
    c->capacity = cap;
  }
  publish(k);
  c->cases[c->count++] = k;
  if (each)
    each(user, &k->pub);
  return BB_OK;
}

int bb_check_exit_code(const bb_check *c) {
  int worst = 0;
  /* a golden updated is the new map now: it passes */
  for (int i = 0; c && i < c->count; i++)
    if (!c->cases[i]->pub.updated && c->cases[i]->pub.exit_code > worst)
      worst = c->cases[i]->pub.exit_code;
  return worst;
}

/* ----------------------------------------------------------------- links */

const char *bb__check_link_refusal(const char *real_root, const char *path) {
  char real[PATH_MAX];
  if (!realpath(path, real))
    return "a link to nothing";
  const size_t n = strlen(real_root);
  if (strncmp(real, real_root, n) != 0 || (real[n] != '/' && n > 1))
    return "a link leading out of its tree: not read";
  struct stat s;
  if (stat(real, &s) != 0 || !S_ISREG(s.st_mode))
    return "a link to something other than a regular file";
  return NULL;
}

const char *bb__check_real_root(const char *root, char *out) {
  return realpath(root, out);
}

static double percent_of(long count, long total) {
  return total > 0 ? 100.0 * (double)count / (double)total : 0.0;
}

/* The one-line account of a case ("max abs error ..."), into t. */
static void case_account(bb__text *t, const bb_check_case *k) {
  const bb_compare_stats *s = &k->stats;
  switch (k->status) {
  case BB_CHECK_PASS:
  case BB_CHECK_WARNING:
  case BB_CHECK_FAILURE:
    bb__text_printf(t, "max abs error %.6g", s->max_abs);
    if (s->max_abs > 0)
      bb__text_printf(t, " at (%d, %d) channel %d", s->worst_x, s->worst_y,
                      s->worst_channel);
    bb__text_printf(t, ", mean %.3g, RMS %.3g; %ld pixels (%.3g%%) over fail %g",
                    s->mean_abs, s->rms, s->over_fail,
                    percent_of(s->over_fail, s->pixels), k->limits.fail);
    if (k->limits.fail_percent > 0 || k->limits.allow_failures > 0)
      bb__text_printf(t, " (allowed %g%% or %ld pixels)", k->limits.fail_percent,
                      k->limits.allow_failures);
    bb__text_printf(t, ", %ld over warn %g", s->over_warn, k->limits.warn);
    break;
  case BB_CHECK_DIFFERENT_SIZE:
    bb__text_printf(t, "golden %d x %d, %d channels; new %d x %d, %d channels", k->width,
                    k->height, k->channels, k->new_width, k->new_height, k->new_channels);
    break;
  case BB_CHECK_UNREADABLE:
  case BB_CHECK_MISSING:
  case BB_CHECK_EXTRA:
    bb__text_add(t, k->message);
    break;
  }
}

char *bb__check_case_text(const bb_check_case *k) {
  bb__text t = {0};
  case_account(&t, k);
  if (k->provenance_diff && k->provenance_diff[0])
    bb__text_printf(&t, "\nprovenance differs (golden -> new):\n%s", k->provenance_diff);
  if (k->update_error)
    bb__text_printf(&t, "\n%s", k->update_error);
  return bb__text_take(&t);
}
