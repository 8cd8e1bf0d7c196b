/* handover.c: a checked command handed to another process (`bake
 * --scheduler` hands its command to bumpbake.dask, which runs it on a
 * cluster) and set up there again through the same parsers and checks, so
 * the two processes mean the same thing by every option.
 *
 * The bytes are NUL-terminated fields: the magic, the command's name, then
 * records ("input" TEXT, "option" NAME TEXT, "flag" NAME, "record" LINE,
 * "record-options" TEXT, "record-of" PATH LINE), then "end". An option's TEXT is the one
 * it was set from (bb_command_set), never a value printed and parsed again. */
#include "cmd/cmd_internal.h"
#include "bumpbake_cluster.h"

#include <stdlib.h>
#include <string.h>

#define MAGIC "bumpbake-command 1"

static void field(bb__text *t, const char *s) {
  bb__text_append(t, s, strlen(s) + 1);
}

char *bb_command_handover(const bb_command *c, size_t *size) {
  if (!c || !size)
    return NULL;
  bb__text t = {0};
  field(&t, MAGIC);
  field(&t, c->def->info.name);
  for (int i = 0; i < c->input_count; i++) {
    field(&t, "input");
    field(&t, c->inputs[i]);
  }
  for (int i = 0; c->def->options[i]; i++) {
    if (!c->given[i])
      continue;
    field(&t, c->texts[i] ? "option" : "flag");
    field(&t, c->def->options[i]->info.name);
    if (c->texts[i])
      field(&t, c->texts[i]);
  }
  for (int m = 0; m < c->more_count; m++) { /* a map's further files, set again after */
    field(&t, "option");
    field(&t, c->def->options[c->more_option[m]]->info.name);
    field(&t, c->more_path[m]);
  }
  if (c->record_line) {
    field(&t, "record");
    field(&t, c->record_line);
  }
  if (c->record_options) {
    field(&t, "record-options");
    field(&t, c->record_options);
  }
  for (int r = 0; r < c->file_record_count; r++) {
    field(&t, "record-of");
    field(&t, c->file_record_path[r]);
    field(&t, c->file_record_line[r]);
  }
  field(&t, "end");
  *size = t.length;
  return bb__text_take(&t);
}

/* The next field of data[*at..size) into *out; 0 when none is whole. */
static int next(const char *data, size_t size, size_t *at, const char **out) {
  if (*at >= size)
    return 0;
  const char *nul = memchr(data + *at, '\0', size - *at);
  if (!nul)
    return 0;
  *out = data + *at;
  *at = (size_t)(nul - data) + 1;
  return 1;
}

static bb_status replay(bb_command *c, const char *data, size_t size, size_t at,
                        const char *const *inputs, int input_count, bb_error *err) {
  char *line = NULL, *options = NULL;
  const char *tag, *a, *b;
  bb_status st = BB_OK;
  for (int i = 0; st == BB_OK && inputs && i < input_count; i++)
    st = bb_command_add_input(c, inputs[i], err);
  while (st == BB_OK) {
    if (!next(data, size, &at, &tag)) {
      st = bb__fail(err, BB_ERR_ARGUMENT, "command hand-over: cut short");
      break;
    }
    if (!strcmp(tag, "end"))
      break;
    if (!next(data, size, &at, &a)) {
      st = bb__fail(err, BB_ERR_ARGUMENT, "command hand-over: cut short");
    } else if (!strcmp(tag, "input")) {
      if (!inputs)
        st = bb_command_add_input(c, a, err);
    } else if (!strcmp(tag, "flag")) {
      st = bb_command_set(c, a, NULL, err);
    } else if (!strcmp(tag, "option")) {
      st = next(data, size, &at, &b) ? bb_command_set(c, a, b, err)
                                     : bb__fail(err, BB_ERR_ARGUMENT,
                                                "command hand-over: cut short");
    } else if (!strcmp(tag, "record")) {
      line = (char *)a;
    } else if (!strcmp(tag, "record-options")) {
      options = (char *)a;
    } else if (!strcmp(tag, "record-of")) {
      st = next(data, size, &at, &b)
               ? bb_command_set_record(c, a, b, NULL, err)
               : bb__fail(err, BB_ERR_ARGUMENT, "command hand-over: cut short");
    } else {
      st = bb__fail(err, BB_ERR_ARGUMENT, "command hand-over: unknown field '%.32s'", tag);
    }
  }
  if (st == BB_OK && (line || options))
    st = bb_command_set_record(c, NULL, line, options, err);
  if (st == BB_OK)
    st = bb_command_check(c, err);
  return st;
}

bb_status bb_command_from_handover(const char *data, size_t size, const char *const *inputs,
                                   int input_count, bb_command **out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "command hand-over: no place for it");
  *out = NULL;
  size_t at = 0;
  const char *magic, *name;
  if (!data || !next(data, size, &at, &magic) || strcmp(magic, MAGIC) ||
      !next(data, size, &at, &name))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "command hand-over: not a command of this bumpbake version");
  bb_command *c = NULL;
  bb_status st = bb_command_new(name, &c, err);
  if (st == BB_OK)
    st = replay(c, data, size, at, inputs, input_count, err);
  if (st != BB_OK) {
    bb_command_free(c);
    return st;
  }
  *out = c;
  return BB_OK;
}
