/* serve_params.c: the page's side of the options: its controls, the state
 * it draws as JSON, and its controls' values applied. The controls are
 * options of serve's command, named once here (which rows the page shows,
 * in order); everything else about them is the library's: the page builds
 * its inputs from their rows (GET controls: name, type, help, default,
 * range, bb_option_bounds), their values in the state are the command's
 * (bb_command_value), and a value the page sends is set on the page's
 * command by the option's name (bb_command_set), the whole checked as the
 * command line is (bb_command_check), whose words a refusal shows. */
#include "serve.h"
#include "../core/json.h" /* the JSON writer, compiled into the program (Makefile) */
#include "bumpbake_cluster.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --------------------------------------------------------------- controls */

/* The page's controls: serve's options of these names, in the page's
 * order, each on the bake (a change bakes again) or on the light of the
 * picture (render's --light-color: the picture is lit anew). A file
 * option (--brightness FILE) is a switch of the file serve was given. */
static const struct {
  const char *name;
  int light; /* 1: the picture's light, not the bake */
} controls[] = {{"scale", 0},  {"rays", 0},    {"slices", 0},     {"bias", 0},
                {"bounce", 0}, {"bounces", 0}, {"brightness", 0}, {"light-color", 1}};
#define CONTROL_COUNT (sizeof controls / sizeof controls[0])

static const bb_option_info *row_of(const char *name) {
  return bb_option_find(bb_command_info_find("serve"), name, 0);
}

/* A control's key in the JSON: its name with '_' for '-' (light_color). */
static void key_of(const char *name, char *out, size_t cap) {
  snprintf(out, cap, "%s", name);
  for (char *c = out; *c; c++)
    if (*c == '-')
      *c = '_';
}

/* ---------------------------------------------------------------- state */

/* The controls' values as the page's command holds them: numbers as
 * numbers (several as an array), a file option as whether it is on, with
 * the file serve was given ("brightness_file"). */
static void add_params(bb__json *j, const serve_state *s) {
  bb__json_open(j, "params", '{');
  for (size_t i = 0; i < CONTROL_COUNT; i++) {
    const bb_option_info *o = row_of(controls[i].name);
    char key[64], value[256], file[80];
    key_of(controls[i].name, key, sizeof key);
    if (bb_command_value(s->command, controls[i].name, value, sizeof value, NULL) != BB_OK)
      value[0] = '\0';
    switch (o->type) {
    case BB_OPTION_INT:
    case BB_OPTION_NUMBER:
      bb__json_number(j, key, strtod(value, NULL));
      break;
    case BB_OPTION_NUMBERS:
      bb__json_open(j, key, '[');
      for (const char *v = value; *v;) {
        char *end = NULL;
        bb__json_number(j, NULL, strtod(v, &end));
        v = *end == ',' ? end + 1 : end + strlen(end);
      }
      bb__json_close(j, ']');
      break;
    case BB_OPTION_PATH: {
      char given[4096];
      const int has = bb_command_value(s->line, controls[i].name, given, sizeof given,
                                       NULL) == BB_OK && given[0];
      snprintf(file, sizeof file, "%s_file", key);
      bb__json_bool(j, key, bb_command_given(s->command, controls[i].name));
      bb__json_string(j, file, has ? given : NULL);
      break;
    }
    default:
      bb__json_string(j, key, value);
      break;
    }
  }
  bb__json_int(j, "slices_traced", bb_command_slices(s->command));
  bb__json_string(j, "albedo_file", s->albedo_file);
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

char *serve_json_text(void (*write)(bb__json *j, void *arg), void *arg) {
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
  bb_command *bake = NULL;
  char *command = NULL;
  bb_error err = {{0}};
  serve_bake_command(s, &bake, &command, &err); /* NULL on failure: no line */
  bb_command_free(bake);
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
  return serve_json_text(write_state, s);
}


/* The controls as the page builds them (GET controls): each row's name,
 * type, value words, help, default and range as help prints them, its
 * numeric bounds (bb_option_bounds: "min" and "max" where finite,
 * "min_exclusive" when the bottom is not allowed, "scale > 0"), and
 * "unset": the value a command holds without it, which a control back at
 * it leaves out (slices 0, "from rays", below --slices's range). */
static void add_bounds(bb__json *j, const bb_option_info *o) {
  double min, max;
  int min_exclusive;
  if (!bb_option_bounds(o, &min, &max, &min_exclusive))
    return;
  if (isfinite(min))
    bb__json_number(j, "min", min);
  if (isfinite(max))
    bb__json_number(j, "max", max);
  bb__json_bool(j, "min_exclusive", min_exclusive);
}

static void add_control(bb__json *j, const bb_command *fresh, size_t i) {
  const bb_command_info *serve = bb_command_describe(fresh);
  const bb_option_info *o = row_of(controls[i].name);
  char key[64], text[256];
  key_of(o->name, key, sizeof key);
  bb__json_open(j, NULL, '{');
  bb__json_string(j, "name", o->name);
  bb__json_string(j, "key", key);
  bb__json_string(j, "place", controls[i].light ? "light" : "bake");
  bb__json_string(j, "type", bb_option_type_name(o->type));
  bb__json_int(j, "count", o->count);
  bb_option_value_text(o, text, sizeof text);
  bb__json_string(j, "value_name", text);
  bb__json_string(j, "help", o->help);
  bb_option_default_text(serve, o, text, sizeof text);
  bb__json_string(j, "default", text);
  bb_option_range_text(o, text, sizeof text);
  bb__json_string(j, "range", text);
  if (bb_command_value(fresh, o->name, text, sizeof text, NULL) != BB_OK)
    text[0] = '\0';
  bb__json_string(j, "unset", text);
  add_bounds(j, o);
  bb__json_close(j, '}');
}

/* The range of an input of the picture, from render's option: its
 * elevation's for --view AZ,EL and --light AZ,EL ("range EL 1..90"). */
static void add_view_range(bb__json *j, const char *key, const char *option) {
  const bb_option_info *o = bb_option_find(bb_command_info_find("render"), option, 0);
  double min, max;
  int min_exclusive;
  if (!bb_option_bounds(o, &min, &max, &min_exclusive))
    return;
  bb__json_open(j, key, '{');
  add_bounds(j, o);
  bb__json_close(j, '}');
}

static void write_controls(bb__json *j, void *arg) {
  const bb_command *fresh = arg;
  bb__json_open(j, NULL, '{');
  bb__json_open(j, "controls", '[');
  for (size_t i = 0; i < CONTROL_COUNT; i++)
    add_control(j, fresh, i);
  bb__json_close(j, ']');
  /* the picture's camera and light, as render's --view and --light take them */
  bb__json_open(j, "view", '{');
  add_view_range(j, "view_elevation", "view");
  add_view_range(j, "light_elevation", "light");
  bb__json_close(j, '}');
  bb__json_close(j, '}');
}

char *serve_controls_json(void) {
  bb_command *fresh = NULL;
  if (bb_command_new("serve", &fresh, NULL) != BB_OK)
    return NULL;
  char *text = serve_json_text(write_controls, fresh);
  bb_command_free(fresh);
  return text;
}

/* ------------------------------------------------------- values applied */

/* text of size bytes as a string, a NUL in it spelled "\\0" (so the
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

/* Sets control i to value on cmd, as the command line sets its option; a
 * file option: "on" is the file serve was given, "off" none. A value at
 * what a command holds without the option (fresh's) leaves it out, as the
 * line the page shows does. 0, or -1 with the library's words in err. */
static int apply_one(const serve_state *s, const bb_command *fresh, bb_command *cmd, size_t i,
                     const char *value, char *err, size_t cap) {
  const char *name = controls[i].name;
  const bb_option_info *o = row_of(name);
  bb_error e = {{0}};
  bb_status st;
  if (o->type == BB_OPTION_PATH) {
    char given[4096];
    if (bb_command_value(s->line, name, given, sizeof given, &e) != BB_OK || !given[0]) {
      snprintf(err, cap, "%s: no --%s %s was given to serve", name, name, o->value_name);
      return -1;
    }
    if (strcmp(value, "on") && strcmp(value, "off")) {
      snprintf(err, cap, "%s: 'on' or 'off'", name);
      return -1;
    }
    st = !strcmp(value, "on") ? bb_command_set(cmd, name, given, &e)
                              : bb_command_unset(cmd, name, &e);
  } else {
    char now[256], unset[256];
    st = bb_command_set(cmd, name, value, &e);
    if (st == BB_OK && bb_command_value(cmd, name, now, sizeof now, &e) == BB_OK &&
        bb_command_value(fresh, name, unset, sizeof unset, &e) == BB_OK &&
        !strcmp(now, unset))
      st = bb_command_unset(cmd, name, &e);
  }
  if (st != BB_OK) {
    snprintf(err, cap, "%s", e.message);
    return -1;
  }
  return 0;
}

int serve_apply_params(serve_state *s, const char *const *names,
                       const char *const *values, const size_t *sizes, int count,
                       int *rebake, char *err, size_t cap) {
  *rebake = 0;
  bb_command *next = NULL, *fresh = NULL;
  bb_error e = {{0}};
  size_t size = 0;
  char *copy = bb_command_handover(s->command, &size);
  if (!copy || bb_command_from_handover(copy, size, NULL, 0, &next, &e) != BB_OK ||
      bb_command_new("serve", &fresh, &e) != BB_OK) {
    free(copy);
    bb_command_free(next);
    snprintf(err, cap, "%s", copy ? e.message : "out of memory");
    return -1;
  }
  free(copy);
  int rc = 0;
  for (int k = 0; k < count && rc == 0; k++) {
    size_t i = 0;
    while (i < CONTROL_COUNT && strcmp(names[k], controls[i].name))
      i++;
    if (i == CONTROL_COUNT) {
      snprintf(err, cap, "unknown control '%.40s'", names[k]);
      rc = -1;
      break;
    }
    *rebake |= !controls[i].light;
    char *value = spelled(values[k], sizes[k]);
    rc = value ? apply_one(s, fresh, next, i, value, err, cap) : -1;
    if (!value)
      snprintf(err, cap, "out of memory");
    free(value);
  }
  bb_command_free(fresh);
  if (rc == 0 && bb_command_check(next, &e) != BB_OK) {
    snprintf(err, cap, "%s", e.message);
    rc = -1;
  }
  if (rc != 0) {
    bb_command_free(next);
    return -1;
  }
  /* the controls' values, as checked: the page's command, which the bakes
   * derive theirs from, and its light */
  serve_light_color(next, s->light_color);
  bb_command_free(s->command);
  s->command = next;
  s->version++;
  pthread_cond_broadcast(&s->changed);
  return 0;
}

void serve_light_color(const bb_command *command, float rgb[3]) {
  double v[3] = {1.0, 1.0, 1.0};
  bb_command_numbers(command, "light-color", v, 3, NULL, NULL);
  for (int k = 0; k < 3; k++)
    rgb[k] = (float)v[k]; /* the float the command holds */
}
