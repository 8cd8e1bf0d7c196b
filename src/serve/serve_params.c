/* serve_params.c: the page's side of the options: the state it draws as
 * JSON, the ranges of its inputs as the library describes the options
 * (bb_option_bounds), and its controls (scale, rays, slices, bias, bounce,
 * bounces, brightness) applied to the bake options: each set on the page's
 * command as `bumpbake bake` sets its option of that name (bb_command_set),
 * the whole checked as the command line is (bb_command_check), whose
 * words a refusal shows. */
#include "serve.h"
#include "../core/json.h" /* the JSON writer, compiled into the program (Makefile) */
#include "bumpbake_cluster.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- state */

static void add_params(bb__json *j, const serve_state *s) {
  const bb_bake_options *b = &s->settings.bake;
  bb__json_open(j, "params", '{');
  bb__json_number(j, "scale", (double)b->height_scale);
  bb__json_int(j, "rays", b->rays);
  bb__json_int(j, "slices", b->slices);
  bb__json_int(j, "slices_traced", bb_bake_slices(b));
  bb__json_number(j, "bias", b->trace.bias_texels);
  bb__json_number(j, "bounce", b->bounce_albedo);
  bb__json_int(j, "bounces", b->bounces);
  bb__json_string(j, "brightness_file", s->brightness_file);
  bb__json_bool(j, "brightness", s->use_brightness);
  bb__json_string(j, "albedo_file", s->albedo_file);
  bb__json_open(j, "light_color", '[');
  for (int k = 0; k < 3; k++)
    bb__json_number(j, NULL, (double)s->light_color[k]);
  bb__json_close(j, ']');
  bb__json_close(j, '}');
}

static void add_bake(bb__json *j, serve_bake *b) {
  bb__json_open(j, "bake", '{');
  bb__json_int(j, "id", b->id);
  /* an edit of bake "base": its maps outside "changed" are that bake's
   * (map/NAME?since=BASE gives the rectangle alone); 0 when it is not */
  bb__json_int(j, "base", b->base_id);
  bb__json_open(j, "changed", '[');
  const bb_region edit = b->base_id ? b->changed : (bb_region){0, 0, b->width, b->height};
  const int where[4] = {edit.x0, edit.y0, edit.width, edit.height};
  for (int k = 0; k < 4; k++)
    bb__json_int(j, NULL, where[k]);
  bb__json_close(j, ']');
  bb__json_int(j, "width", b->width);
  bb__json_int(j, "height", b->height);
  bb__json_number(j, "seconds", b->seconds);
  const bb_job_report *r = &b->report;
  bb__json_number(j, "seconds_load", r->seconds_load);
  bb__json_number(j, "seconds_smooth", r->seconds_smooth);
  bb__json_number(j, "seconds_pyramid", r->seconds_pyramid);
  bb__json_number(j, "seconds_trace", r->seconds_trace);
  bb__json_number(j, "seconds_bounce", r->seconds_bounce);
  bb__json_number(j, "seconds_derive", r->seconds_derive);
  bb__json_number(j, "seconds_textures", b->seconds_textures);
  bb__json_int(j, "threads", r->threads);
  bb__json_int(j, "slices", r->slices);
  bb__json_number(j, "scale", b->scale);
  bb__json_bool(j, "normal_y_up", b->normal_y_up);
  /* the page lights the ssbump with these directions (sat(sum_c s_c l.B_c)) */
  bb__json_string(j, "basis", b->basis.name);
  bb__json_int(j, "basis_count", b->basis.count);
  bb__json_open(j, "basis_vectors", '[');
  for (int c = 0; c < b->basis.count; c++) {
    bb__json_open(j, NULL, '[');
    for (int k = 0; k < 3; k++)
      bb__json_number(j, NULL, b->basis.vector[c][k]);
    bb__json_close(j, ']');
  }
  bb__json_close(j, ']');
  bb__json_bool(j, "albedo", b->tex[SERVE_TEX_ALBEDO] != NULL);
  bb__json_string(j, "command", b->command);
  bb__json_string(j, "provenance", b->provenance);
  bb__json_close(j, '}');
}

/* The JSON text write(j, arg) makes, malloc'd; NULL when out of memory. */
static char *json_text(void (*write)(bb__json *j, void *arg), void *arg) {
  char *text = NULL;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  if (!f)
    return NULL;
  bb__json j = {f, 0};
  write(&j, arg);
  if (fclose(f) != 0) {
    free(text);
    return NULL;
  }
  return text;
}

static void write_state(bb__json *j, void *arg) {
  serve_state *s = arg;
  pthread_mutex_lock(&s->lock);
  bb_job_options o;
  serve_job_options(s, &o);
  char *command = bb_job_command_text(&o, s->height_path);
  bb__json_open(j, NULL, '{');
  bb__json_string(j, "height", s->height_path);
  bb__json_bool(j, "baking", s->baking);
  bb__json_string(j, "stage", s->baking ? s->stage : NULL);
  bb__json_number(j, "progress", s->progress);
  /* a save or a control asked for a bake not yet begun or done */
  bb__json_bool(j, "pending", atomic_load(&s->wanted) != s->done);
  bb__json_string(j, "error", s->error);
  bb__json_string(j, "command", command);
  add_params(j, s);
  if (s->current)
    add_bake(j, s->current);
  bb__json_close(j, '}');
  pthread_mutex_unlock(&s->lock);
  free(command);
}

char *serve_state_json(serve_state *s) {
  return json_text(write_state, s);
}

/* --------------------------------------------------------------- controls */

/* The bake controls: bake's options of these names (parsed by the library,
 * bb_command_set, which refuses a value with the words every client prints:
 * "--rays needs an integer (got 'x')"), and where each lands in the bake
 * options. brightness is serve's switch of its --brightness FILE. */
#define CONTROL(name, member)                                                            \
  { name, offsetof(bb_bake_options, member), sizeof(((bb_bake_options *)0)->member) }
static const struct {
  const char *name;
  size_t offset, size;
} controls[] = {CONTROL("scale", height_scale),   CONTROL("rays", rays),
                CONTROL("slices", slices),        CONTROL("bias", trace.bias_texels),
                CONTROL("bounce", bounce_albedo), CONTROL("bounces", bounces)};
#define CONTROL_COUNT (sizeof controls / sizeof controls[0])

/* text of size bytes as a string, a NUL in it spelled "\0" (so the
 * parser refuses it as the text it is, not the part before it). malloc'd. */
static char *spelled(const char *text, size_t size) {
  char *out = malloc(2 * size + 1), *o = out;
  for (size_t i = 0; out && i < size; i++) {
    if (text[i] == '\0') {
      *o++ = '\\';
      *o++ = '0';
    } else {
      *o++ = text[i];
    }
  }
  if (out)
    *o = '\0';
  return out;
}

/* Sets control name to value on cmd (brightness: its file, or unset); a
 * bake control at its default is unset. 0, or -1 with the words in err. */
static int apply_one(const serve_state *s, bb_command *cmd, const char *name,
                     const char *value, int *rebake, char *err, size_t cap) {
  bb_error e = {{0}};
  for (size_t i = 0; i < CONTROL_COUNT; i++) {
    if (strcmp(name, controls[i].name))
      continue;
    *rebake = 1;
    if (bb_command_set(cmd, name, value, &e) != BB_OK) {
      snprintf(err, cap, "%s", e.message);
      return -1;
    }
    bb_job_options d;
    bb_job_options_init(&d);
    const char *now =
        (const char *)&bb_command_options_of(cmd)->job.bake + controls[i].offset;
    if (!memcmp(now, (const char *)&d.bake + controls[i].offset, controls[i].size) &&
        bb_command_unset(cmd, name, &e) != BB_OK) {
      snprintf(err, cap, "%s", e.message);
      return -1;
    }
    return 0;
  }
  if (!strcmp(name, "light-color")) { /* render's row: a light of the picture */
    bb_render_options r;
    bb_render_options_init(&r);
    bb_status st = bb_command_set(cmd, name, value, &e);
    const float *now = bb_command_options_of(cmd)->render.light_color;
    if (st == BB_OK && !memcmp(now, r.light_color, sizeof r.light_color))
      st = bb_command_unset(cmd, name, &e);
    if (st != BB_OK) {
      snprintf(err, cap, "%s", e.message);
      return -1;
    }
    return 0;
  }
  *rebake = 1;
  if (!strcmp(name, "brightness")) {
    if (!s->brightness_file) {
      snprintf(err, cap, "brightness: no --brightness FILE was given to serve");
      return -1;
    }
    if (strcmp(value, "on") && strcmp(value, "off")) {
      snprintf(err, cap, "brightness: 'on' or 'off'");
      return -1;
    }
    const bb_status st = !strcmp(value, "on")
                             ? bb_command_set(cmd, "brightness", s->brightness_file, &e)
                             : bb_command_unset(cmd, "brightness", &e);
    if (st != BB_OK) {
      snprintf(err, cap, "%s", e.message);
      return -1;
    }
    return 0;
  }
  snprintf(err, cap, "unknown control '%.40s'", name);
  return -1;
}

int serve_apply_params(serve_state *s, const char *const *names,
                       const char *const *values, const size_t *sizes, int count,
                       int *rebake, char *err, size_t cap) {
  *rebake = 0;
  bb_command *next = NULL;
  bb_error e = {{0}};
  size_t size = 0;
  char *copy = bb_command_handover(s->command, &size);
  if (!copy || bb_command_from_handover(copy, size, NULL, 0, &next, &e) != BB_OK) {
    free(copy);
    snprintf(err, cap, "%s", copy ? e.message : "out of memory");
    return -1;
  }
  free(copy);
  int rc = 0;
  for (int i = 0; i < count && rc == 0; i++) {
    char *value = spelled(values[i], sizes[i]);
    rc = value ? apply_one(s, next, names[i], value, rebake, err, cap) : -1;
    if (!value)
      snprintf(err, cap, "out of memory");
    free(value);
  }
  if (rc == 0 && bb_command_check(next, &e) != BB_OK) {
    snprintf(err, cap, "%s", e.message);
    rc = -1;
  }
  if (rc != 0) {
    bb_command_free(next);
    return -1;
  }
  /* the controls' values, as checked; the rest of the settings (paths
   * and files the command line named, owned by its command) stay */
  const bb_bake_options *b = &bb_command_options_of(next)->job.bake;
  for (size_t i = 0; i < CONTROL_COUNT; i++)
    memcpy((char *)&s->settings.bake + controls[i].offset,
           (const char *)b + controls[i].offset, controls[i].size);
  s->use_brightness = bb_command_given(next, "brightness");
  memcpy(s->light_color, bb_command_options_of(next)->render.light_color,
         sizeof s->light_color);
  bb_command_free(s->command);
  s->command = next;
  s->version++;
  pthread_cond_broadcast(&s->changed);
  return 0;
}

/* ----------------------------------------------------------------- ranges */

/* One input's range as the library describes its option: "min" and
 * "max" where finite, "min_exclusive" when the bottom is not allowed
 * ("scale > 0"). An option without a numeric range writes nothing. */
static void add_range(bb__json *j, const char *key, const char *command,
                      const char *option) {
  const bb_option_info *o = bb_option_find(bb_command_info_find(command), option, 0);
  double min, max;
  int min_exclusive;
  if (!bb_option_bounds(o, &min, &max, &min_exclusive))
    return;
  bb__json_open(j, key, '{');
  if (isfinite(min))
    bb__json_number(j, "min", min);
  if (isfinite(max))
    bb__json_number(j, "max", max);
  bb__json_bool(j, "min_exclusive", min_exclusive);
  bb__json_close(j, '}');
}

static void write_ranges(bb__json *j, void *arg) {
  (void)arg;
  bb__json_open(j, NULL, '{');
  /* the bake controls: bake's options of their names */
  for (size_t i = 0; i < CONTROL_COUNT; i++)
    add_range(j, controls[i].name, "bake", controls[i].name);
  /* the picture's camera and light, as render's --view AZ,EL and --light
   * AZ,EL take them: their range is the elevation's ("range EL 1..90") */
  add_range(j, "view_elevation", "render", "view");
  add_range(j, "light_elevation", "render", "light");
  add_range(j, "light_color", "render", "light-color");
  bb__json_close(j, '}');
}

char *serve_ranges_json(void) {
  return json_text(write_ranges, NULL);
}
