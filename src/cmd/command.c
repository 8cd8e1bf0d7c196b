/* command.c: one use of a command: its options set through their parsers
 * into one typed struct, its inputs, the checks that come before any file
 * is read, the command spelled back as text, and its plan through the job.
 *
 * Invariant: every value in options came through the parser of the option
 * that sets it; bb_command_check has checked each number against its
 * parameter's one range and every rule between options, so a plan made
 * from a checked command checks nothing again. */
#include "cmd/cmd_internal.h"
#include "trace/basis.h"
#include "render/render_internal.h"
#include "job/job_internal.h"
#include "maps/maps_internal.h"
#include "mesh/mesh_internal.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const bb__command *find_command(const char *name) {
  for (int i = 0; name && i < bb__command_total; i++)
    if (!strcmp(bb__commands[i]->info.name, name))
      return bb__commands[i];
  return NULL;
}

bb_status bb_command_new(const char *name, bb_command **out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no place for it");
  *out = NULL;
  const bb__command *def = find_command(name);
  if (!def) {
    const bb_command_info *near = bb__command_info_nearest(name ? name : "");
    if (near)
      return bb__fail(err, BB_ERR_ARGUMENT, "unknown command '%.64s' (did you mean %s?)",
                      name ? name : "", near->name);
    return bb__fail(err, BB_ERR_ARGUMENT, "unknown command '%.64s' (see bumpbake --help)",
                    name ? name : "");
  }
  bb_command *c = calloc(1, sizeof *c);
  if (!c)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  c->def = def;
  bb_command_options *o = &c->options;
  bb__job_options_init(&o->job);
  bb__render_options_init(&o->render);
  bb__compare_limits_init(&o->limits);
  bb__renderbump_options_init(&o->renderbump);
  o->map_kind = BB_MAP_SSBUMP;
  o->ssbump_kind = BB_MAP_SSBUMP;
  if (def->init)
    def->init(o);
  *out = c;
  return BB_OK;
}

void bb_command_free(bb_command *c) {
  if (!c)
    return;
  for (int i = 0; i < c->string_count; i++)
    free(c->strings[i]);
  free(c->strings);
  for (int i = 0; i < c->input_count; i++)
    free(c->inputs[i]);
  free(c->inputs);
  free(c->record_line);
  free(c->record_options);
  for (int r = 0; r < c->file_record_count; r++) {
    free(c->file_record_path[r]);
    free(c->file_record_line[r]);
  }
  free(c);
}

const bb_command_info *bb_command_describe(const bb_command *c) {
  return c ? &c->def->info : NULL;
}

void bb_command_set_in_memory(bb_command *c, unsigned maps) {
  if (!c)
    return;
  c->in_memory = 1;
  c->memory_maps = maps;
  c->options.job.bake.outputs = maps ? maps : c->options.job.bake.outputs;
  c->checked = 0;
}

int bb_command_given(const bb_command *c, const char *name) {
  return c && name && bb__given(c, name);
}

const bb_command_options *bb__command_options_of(const bb_command *c) {
  return c ? &c->options : NULL;
}

const bb_job_options *bb__command_job_options(const bb_command *c) {
  return c ? &c->options.job : NULL;
}

void bb_command_set_picture(bb_command *c, int dynamic_light, int tile_y) {
  if (!c)
    return;
  if (!dynamic_light)
    c->options.render.dynamic_light = 0;
  if (tile_y > 0)
    c->options.render.tile_y = tile_y;
}

bb_status bb_command_set_basis(bb_command *c, const bb_basis *basis, bb_error *err) {
  if (!c || !basis)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_command_set_basis: bad arguments");
  const char *name = c->def->info.name;
  if (bb__option_find(c->def, "basis") < 0)
    return bb__spelled(c, bb__fail(err, BB_ERR_ARGUMENT, "%s takes no --basis", name), err);
  if (!c->checked)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: set a basis of vectors after the check",
                    name);
  if (bb__given(c, "basis"))
    return bb__spelled(c,
                       bb__fail(err, BB_ERR_ARGUMENT,
                                "%s: --basis is given: a basis of vectors goes in its place",
                                name),
                       err);
  bb_status st = bb__basis_check(basis, name, err);
  if (st == BB_OK)
    c->options.job.bake.basis = *basis;
  return st;
}

int bb__command_input_count(const bb_command *c) {
  return c ? c->input_count : 0;
}

const char *bb_command_input(const bb_command *c, int i) {
  return c && i >= 0 && i < c->input_count ? c->inputs[i] : NULL;
}

/* The option's value as c holds it, spelled as it takes it: the text of an
 * option kept as text (BB__FIELD_KEPT), else its field's, printed. */
void bb__command_value_text(const bb_command *c, int i, bb__text *t) {
  const bb__option *o = c->def->options[i];
  if (o->info.type == BB_OPTION_FLAG)
    bb__text_add(t, c->given[i] ? "1" : "0");
  else if (bb__option_field(o) == BB__FIELD_KEPT && !c->given[i])
    bb__text_add(t, o->info.default_text);
  else if (o->print)
    o->print(c, o, t);
  else
    bb__print_generic(c, o, t);
}

static bb_status unknown_option(const bb_command *c, const char *name, bb_error *err);

bb_status bb_command_value(const bb_command *c, const char *name, char *out, size_t cap,
                           bb_error *err) {
  if (out && cap)
    out[0] = '\0';
  if (!c || !name || !out || !cap)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no option named, or no room for its value");
  const int i = bb__option_find(c->def, name);
  if (i < 0)
    return bb__spelled(c, unknown_option(c, name, err), err);
  bb__text t = {0};
  bb__command_value_text(c, i, &t);
  char *text = bb__text_take(&t); /* "" for no value (a file not given) */
  if (!text)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  const size_t n = strlen(text);
  if (n >= cap) {
    free(text);
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s: its value is longer than %zu bytes",
                    c->def->options[i]->info.name, cap - 1);
  }
  memcpy(out, text, n + 1);
  free(text);
  return BB_OK;
}

bb_status bb_command_numbers(const bb_command *c, const char *name, double *values, int cap,
                             int *count, bb_error *err) {
  if (count)
    *count = 0;
  if (!c || !name || !values)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no option named, or no room for its numbers");
  const int i = bb__option_find(c->def, name);
  if (i < 0)
    return bb__spelled(c, unknown_option(c, name, err), err);
  const bb__option *o = c->def->options[i];
  const bb_option_type type = o->info.type;
  if (type != BB_OPTION_INT && type != BB_OPTION_NUMBER && type != BB_OPTION_NUMBERS)
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s takes no numbers", o->info.name);
  const int n = type == BB_OPTION_NUMBERS ? o->info.count : 1;
  if (n > cap)
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s holds %d numbers, room for %d", o->info.name,
                    n, cap);
  bb__text t = {0};
  bb__command_value_text(c, i, &t);
  char *text = bb__text_take(&t);
  if (!text)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  bb_status st = bb__parse_numbers(o, text, n, type == BB_OPTION_INT, values, err);
  free(text);
  if (st == BB_OK && count)
    *count = n;
  return st;
}

/* --------------------------------------------------------------- setting */

/* "unknown option '--rayz' (did you mean --rays?)" */
static bb_status unknown_option(const bb_command *c, const char *name, bb_error *err) {
  const bb_option_info *near = bb_option_nearest(&c->def->info, name, 0);
  if (near)
    return bb__fail(err, BB_ERR_ARGUMENT, "unknown option '--%.64s' (did you mean --%s?)",
                    name, near->name);
  return bb__fail(err, BB_ERR_ARGUMENT, "unknown option '--%.64s' (see --help)", name);
}

static bb_status set_option(bb_command *c, const char *name, const char *text,
                            bb_error *err) {
  if (!c || !name)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no option named");
  const int i = bb__option_find(c->def, name);
  if (i < 0)
    return unknown_option(c, name, err);
  const bb__option *o = c->def->options[i];
  if (o->info.type != BB_OPTION_FLAG && !text)
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s needs a value", o->info.name);
  if (o->info.type == BB_OPTION_FLAG && text && !strcmp(text, "0") &&
      (o->set || bb__option_sets(o).field != BB__FIELD_NONE))
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s cannot be unset: leave it out", o->info.name);
  /* A map's file given again is a further file of the map, written from
   * the same bake in its own format (--ssbump s.png --ssbump s.vtf); the
   * same name again is the same file. */
  if (c->given[i] && o->repeats && text) {
    const char *was = *(const char *const *)(const void *)((const char *)&c->options +
                                                            bb__option_offset(o));
    int known = was && !strcmp(was, text);
    for (int m = 0; m < c->more_count; m++)
      known |= c->more_option[m] == i && !strcmp(c->more_path[m], text);
    if (known)
      return BB_OK;
    if (c->more_count + 1 >= BB_JOB_MAX_OUTPUTS) /* its first file, the others */
      return bb__fail(err, BB_ERR_ARGUMENT, "a bake writes at most %d files",
                      BB_JOB_MAX_OUTPUTS);
    const char *kept = bb__command_keep(c, text);
    if (!kept)
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    c->more_option[c->more_count] = i;
    c->more_path[c->more_count++] = kept;
    c->checked = 0;
    return BB_OK;
  }
  /* Any other file option names one file: a second, different name would
   * leave the first unwritten (or unread) without a word. */
  if (c->given[i] && o->info.type == BB_OPTION_PATH && bb__option_field(o) == BB__FIELD_STRING) {
    const char *was = *(const char *const *)(const void *)((const char *)&c->options +
                                                            bb__option_offset(o));
    if (was && strcmp(was, text) != 0) {
      char spelled[80];
      bb__option_spelling(o, spelled, sizeof spelled);
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s is given twice ('%.200s', then '%.200s'): it names one file; "
                      "run once per file",
                      spelled, was, text);
    }
  }
  double values[BB__MAX_NUMBERS] = {0};
  int count = o->info.type == BB_OPTION_NUMBERS ? o->info.count : 1;
  bb_status st = o->set ? o->set(c, o, text, values, &count, err)
                        : bb__set_generic(c, o, text, values, &count, err);
  if (st != BB_OK)
    return st;
  if (text && !(c->texts[i] = bb__command_keep(c, text)))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  if (!text)
    c->texts[i] = NULL;
  c->given[i] = !(o->info.type == BB_OPTION_FLAG && text && !strcmp(text, "0"));
  c->derived[i] = 0; /* the caller's own now: checked as given */
  if (!c->given[i])
    c->texts[i] = NULL;
  c->value_count[i] = count < BB__MAX_NUMBERS ? count : BB__MAX_NUMBERS;
  memcpy(c->values[i], values, sizeof values);
  c->checked = 0;
  return BB_OK;
}

/* The bytes of an option's field, or 0 for one its set function writes. */
static size_t field_size(int field) {
  switch (field) {
  case BB__FIELD_INT:
  case BB__FIELD_ENUM:
    return sizeof(int);
  case BB__FIELD_FLOAT:
    return sizeof(float);
  case BB__FIELD_DOUBLE:
    return sizeof(double);
  case BB__FIELD_STRING:
    return sizeof(const char *);
  case BB__FIELD_ANGLES:
    return 2 * sizeof(double);
  default:
    return 0;
  }
}

bb_status bb_command_unset(bb_command *c, const char *name, bb_error *err) {
  if (!c || !name)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no option named");
  const int i = bb__option_find(c->def, name);
  if (i < 0)
    return bb_command_set(c, name, NULL, err); /* its words for an unknown name */
  const bb__option *o = c->def->options[i];
  const size_t size = field_size(bb__option_field(o));
  const size_t offset = bb__option_offset(o);
  const int kept = bb__option_field(o) == BB__FIELD_KEPT; /* its text alone */
  if (o->set || bb__option_sets(o).field != BB__FIELD_NONE || (!size && !kept))
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s cannot be unset: leave it out",
                    o->info.name);
  if (!c->given[i])
    return BB_OK;
  /* the default is a fresh command's (its init included); a default
   * string is a constant, never one of that command's copies */
  if (!kept) {
    bb_command *fresh = NULL;
    bb_status st = bb_command_new(c->def->info.name, &fresh, err);
    if (st != BB_OK)
      return st;
    memcpy((char *)&c->options + offset, (const char *)&fresh->options + offset, size);
    bb_command_free(fresh);
  }
  c->given[i] = 0;
  c->texts[i] = NULL;
  int more = 0; /* its further files go too */
  for (int m = 0; m < c->more_count; m++)
    if (c->more_option[m] != i) {
      c->more_option[more] = c->more_option[m];
      c->more_path[more++] = c->more_path[m];
    }
  c->more_count = more;
  c->value_count[i] = 0;
  memset(c->values[i], 0, sizeof c->values[i]);
  c->checked = 0;
  return BB_OK;
}

static bb_status add_input(bb_command *c, const char *text, bb_error *err) {
  if (!c || !text)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no input given");
  if (c->def->add_input) {
    bb_status st = c->def->add_input(c, c->input_count, text, err);
    if (st != BB_OK)
      return st;
  }
  char **grown = realloc(c->inputs, ((size_t)c->input_count + 1) * sizeof *grown);
  if (!grown)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  c->inputs = grown;
  if (!(c->inputs[c->input_count] = strdup(text)))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  c->input_count++;
  c->checked = 0;
  return BB_OK;
}

/* -------------------------------------------------------------- checking */

/* The positional arguments' count: "missing HEIGHT (usage: ...)" names
 * the ones missing. */
static bb_status check_inputs(const bb_command *c, bb_error *err) {
  const bb_command_info *info = &c->def->info;
  if (c->input_count < info->min_inputs) {
    const char *missing = info->inputs;
    for (int k = 0; k < c->input_count && missing; k++) {
      missing = strchr(missing, ' ');
      missing = missing ? missing + 1 : NULL;
    }
    return bb__fail(err, BB_ERR_ARGUMENT, "missing %s (usage: bumpbake %s %s)",
                    missing ? missing : info->inputs, info->name, info->synopsis);
  }
  if (info->max_inputs >= 0 && c->input_count > info->max_inputs)
    return bb__fail(err, BB_ERR_ARGUMENT, "unexpected argument '%.128s' (expected only %s)",
                    c->inputs[info->max_inputs], info->inputs);
  return BB_OK;
}

static bb_status check_required(const bb_command *c, bb_error *err) {
  for (int i = 0; c->def->options[i]; i++) {
    const bb__option *o = c->def->options[i];
    if (c->in_memory && c->given[i] && (o->info.flags & BB_OPTION_FILES))
      return bb__fail(err, BB_ERR_ARGUMENT, "--%s is about files: not for images in memory",
                      o->info.name);
    if (!(o->info.flags & BB_OPTION_REQUIRED) || c->given[i] ||
        (c->in_memory && (o->info.flags & BB_OPTION_FILES)))
      continue;
    if (o->info.short_name)
      return bb__fail(err, BB_ERR_ARGUMENT, "-%c %s is required", o->info.short_name,
                      o->info.value_name);
    if (o->required_note)
      return bb__fail(err, BB_ERR_ARGUMENT, "--%s is required (%s)", o->info.name,
                      o->required_note);
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s is required", o->info.name);
  }
  return BB_OK;
}

/* Every number given against its parameter's one range: the only check of
 * it on the way to the work. */
static bb_status check_ranges(const bb_command *c, bb_error *err) {
  for (int i = 0; c->def->options[i]; i++) {
    const bb__option *o = c->def->options[i];
    if (!c->given[i] || !o->range)
      continue;
    char name[96];
    bb__option_spelling(o, name, sizeof name);
    if (o->range_of)
      snprintf(name + strlen(name), sizeof name - strlen(name), " %s", o->range_of);
    for (int k = 0; k < c->value_count[i]; k++) {
      bb_status st = bb__range_check(o->range, c->values[i][k], name, err);
      if (st != BB_OK)
        return st;
    }
  }
  return BB_OK;
}

/* An option given where it would do nothing: refused; one a derived
 * command took from its source's settings (serve's --brightness, when the
 * write names no ssbump) is dropped instead, as if never given, so the
 * command's text no longer names it. Its field is left as it was: it does
 * nothing for the files the command writes, and a client baking more maps
 * than those (serve's page, bb_job_bake_item's `also`) still bakes them
 * with it. The rules read fields, not what was given, so one pass drops
 * them all. */
static bb_status check_applies(bb_command *c, bb_error *err) {
  for (int i = 0; c->def->options[i]; i++) {
    const bb__option *o = c->def->options[i];
    if (!c->given[i] || !o->applies || o->applies(c))
      continue;
    if (!c->derived[i])
      return bb__fail(err, BB_ERR_ARGUMENT, "--%s does nothing without %s", o->info.name,
                      o->info.applies);
    c->given[i] = c->derived[i] = 0;
    c->texts[i] = NULL;
  }
  return BB_OK;
}

static bb_status check(bb_command *c, bb_error *err) {
  if (!c)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: none to check");
  bb_status st = c->in_memory ? BB_OK : check_inputs(c, err);
  if (st == BB_OK)
    st = check_ranges(c, err);
  if (st == BB_OK)
    st = check_required(c, err);
  if (st == BB_OK)
    st = check_applies(c, err);
  if (st == BB_OK && c->def->check)
    st = c->def->check(c, err);
  c->checked = st == BB_OK;
  return st;
}

static bb_status record_of(bb_command *c, const char *path, const char *line, bb_error *err);

bb_status bb_command_set_record(bb_command *c, const char *path, const char *line,
                                const char *options, bb_error *err) {
  if (!c)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: none to record");
  if (path)
    return options ? bb__fail(err, BB_ERR_ARGUMENT, "command: a file records a line alone")
                   : record_of(c, path, line, err);
  char *l = line ? strdup(line) : NULL, *o = options ? strdup(options) : NULL;
  if ((line && !l) || (options && !o)) {
    free(l);
    free(o);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  free(c->record_line);
  free(c->record_options);
  c->record_line = l;
  c->record_options = o;
  return BB_OK;
}

/* The line one of the files of a map written to several records. */
static bb_status record_of(bb_command *c, const char *path, const char *line, bb_error *err) {
  if (!line)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: no file record");
  int r = 0;
  while (r < c->file_record_count && strcmp(c->file_record_path[r], path))
    r++;
  if (r == BB_JOB_MAX_OUTPUTS)
    return bb__fail(err, BB_ERR_ARGUMENT, "command: more file records than files");
  char *p = strdup(path), *l = strdup(line);
  if (!p || !l) {
    free(p);
    free(l);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  if (r < c->file_record_count) {
    free(c->file_record_path[r]);
    free(c->file_record_line[r]);
  } else {
    c->file_record_count++;
  }
  c->file_record_path[r] = p;
  c->file_record_line[r] = l;
  return BB_OK;
}

/* The further files of the maps given more than once, and the command line
 * each file of such a map records: its own record (the command line less
 * the map's other files), else the command as the library spells it for
 * that file. The strings go to kept (freed by the caller). */
static bb_status more_files(const bb_command *c, bb__job_more *more, int *kinds,
                            const char **paths, const char **commands, char **kept,
                            int *kept_count, bb_error *err) {
  memset(more, 0, sizeof *more);
  *kept_count = 0;
  if (!c->more_count)
    return BB_OK;
  const size_t first_path = offsetof(bb_command_options, job.paths);
  for (int i = 0; c->def->options[i]; i++) {
    const bb__option *o = c->def->options[i];
    int n = 0;
    for (int m = 0; m < c->more_count; m++)
      n += c->more_option[m] == i;
    if (!n || !o->repeats)
      continue;
    const size_t offset = bb__option_offset(o);
    const int kind = (int)((offset - first_path) / sizeof(char *));
    const char *first =
        *(const char *const *)(const void *)((const char *)&c->options + offset);
    /* the option's files: its first, then the others, in the order given */
    for (int m = -1; m < c->more_count; m++) {
      if (m >= 0 && c->more_option[m] != i)
        continue;
      const char *path = m < 0 ? first : c->more_path[m];
      const char *record = NULL;
      for (int r = 0; r < c->file_record_count; r++)
        if (!strcmp(c->file_record_path[r], path))
          record = c->file_record_line[r];
      char *text = NULL;
      if (!record) {
        bb__text t = {0};
        bb__text_printf(&t, "bumpbake %s", c->def->info.name);
        for (int k = 0; k < c->input_count; k++) {
          bb__text_add(&t, " ");
          bb__text_add_word(&t, c->inputs[k]);
        }
        bb__add_options_of_file(c, BB_OPTION_RECORDED, i, path, &t);
        if (!(text = bb__text_take(&t)))
          return bb__fail(err, BB_ERR_MEMORY, "out of memory");
        kept[(*kept_count)++] = text;
        record = text;
      }
      if (m < 0) {
        more->first_commands[kind] = record;
      } else {
        kinds[more->count] = kind;
        paths[more->count] = path;
        commands[more->count++] = record;
      }
    }
  }
  more->kinds = kinds;
  more->paths = paths;
  more->commands = commands;
  return BB_OK;
}

/* ------------------------------------------------------------------ plan */

static bb_status plan(bb_command *c, const bb_command_hooks *hooks, bb_job **job,
                      bb_error *err) {
  if (!c || !job)
    return bb__fail(err, BB_ERR_ARGUMENT, "command plan: bad arguments");
  *job = NULL;
  if (!c->def->job)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s writes no job", c->def->info.name);
  return bb__command_plan(c, hooks, c->def->job, 0, 0, job, err);
}

bb_status bb__command_plan(bb_command *c, const bb_command_hooks *hooks,
                           bb_status (*job_of)(bb_command *c, bb_job_options *o, bb_error *err),
                           int first_input, unsigned flags, bb_job **job, bb_error *err) {
  *job = NULL;
  if (!c->checked)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the command is not checked (bb_command_check)",
                    c->def->info.name);
  bb_job_options o;
  bb_status st = job_of(c, &o, err);
  if (st != BB_OK)
    return st;
  /* the provenance's command: the line as typed less what does not change
   * the output, else the options as the library spells them */
  char *canonical = NULL;
  o.command = o.out_dir ? NULL : c->record_line;
  o.command_options = o.out_dir ? c->record_options : NULL;
  if (!o.command && !o.command_options) {
    bb__text t = {0};
    if (o.out_dir) {
      bb__add_options(c, BB_OPTION_RECORDED, &t);
      canonical = bb__text_take(&t);
      o.command_options = canonical && canonical[0] == ' ' ? canonical + 1 : canonical;
    } else {
      o.command = canonical = bb_command_text(c, NULL, BB_OPTION_RECORDED);
    }
    if (!canonical)
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  /* A batch's outputs name its output directory, as bake --out-dir's do,
   * also when the command names it otherwise (check --bake's GOLDEN). */
  if (o.out_dir && bb__option_find(c->def, "out-dir") < 0) {
    bb__text t = {0};
    bb__text_printf(&t, "%s%s--out-dir %s", o.command_options ? o.command_options : "",
                    o.command_options && *o.command_options ? " " : "", o.out_dir);
    free(canonical);
    if (!(o.command_options = canonical = bb__text_take(&t)))
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  if (hooks) {
    o.note = hooks->note;
    o.note_user = hooks->note_user;
    o.bake.trace.trace = hooks->trace;
    o.bake.trace.trace_user = hooks->trace_user;
  }
  /* height2ssbump's second positional is its scale, not an input */
  const int inputs = o.valve_path ? 1 : c->input_count;
  bb__job_more more;
  int kinds[BB_JOB_MAX_OUTPUTS], kept_count = 0;
  const char *paths[BB_JOB_MAX_OUTPUTS], *commands[BB_JOB_MAX_OUTPUTS];
  char *kept[2 * BB_JOB_MAX_OUTPUTS];
  st = more_files(c, &more, kinds, paths, commands, kept, &kept_count, err);
  if (st == BB_OK)
    st = bb__job_plan((const char *const *)c->inputs + first_input, inputs - first_input, &o,
                      flags | BB__PLAN_CHECKED, &more, job, err);
  for (int k = 0; k < kept_count; k++)
    free(kept[k]);
  free(canonical);
  return st;
}

bb_status bb_command_set(bb_command *c, const char *name, const char *text,
                         bb_error *err) {
  return bb__spelled(c, set_option(c, name, text, err), err);
}

bb_status bb_command_add_input(bb_command *c, const char *text, bb_error *err) {
  return bb__spelled(c, add_input(c, text, err), err);
}

bb_status bb_command_check(bb_command *c, bb_error *err) {
  return bb__spelled(c, check(c, err), err);
}

bb_status bb_command_plan(bb_command *c, const bb_command_hooks *hooks, bb_job **job,
                          bb_error *err) {
  /* (the job keeps hooks' note function past this call: a run respells
   * its notes, bb_command_run) */
  return bb__spelled(c, plan(c, hooks, job, err), err);
}
