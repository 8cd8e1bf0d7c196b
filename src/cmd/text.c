/* text.c: a command spelled back as text through the descriptions: the
 * provenance's command (the options that determine the output) and the
 * hand-over of a command to another process (every option), each word
 * quoted for a POSIX shell (bb__text_add_word). */
#include "cmd/cmd_internal.h"

#include <stdlib.h>
#include <string.h>

/* " --name value" of every option given, in the order of --help; only
 * those that determine what is made when recorded. */
void bb__add_options(const bb_command *c, unsigned flags, bb__text *t) {
  for (int i = 0; c->def->options[i]; i++) {
    const bb__option *o = c->def->options[i];
    if (!c->given[i] || (o->info.flags & BB_OPTION_CLIENT) ||
        ((flags & BB_OPTION_RECORDED) && !(o->info.flags & BB_OPTION_RECORDED)))
      continue;
    bb__text_printf(t, " --%s", o->info.name);
    if (o->info.type == BB_OPTION_FLAG)
      continue;
    bb__text value = {0};
    if (o->print)
      o->print(c, o, &value);
    else
      bb__print_generic(c, o, &value);
    if (value.failed)
      t->failed = 1;
    /* an option of several words ("--size 48 40") gives each its own */
    const char *v = value.data ? value.data : "";
    do {
      const char *blank = o->info.values > 1 ? strchr(v, ' ') : NULL;
      const size_t n = blank ? (size_t)(blank - v) : strlen(v);
      char *word = strndup(v, n);
      if (!word)
        t->failed = 1;
      bb__text_add(t, " ");
      bb__text_add_word(t, word ? word : "");
      free(word);
      v = blank ? blank + 1 : v + n;
    } while (*v);
    bb__text_free(&value);
  }
}

char *bb_command_text(const bb_command *c, const char *input, unsigned flags) {
  if (!c)
    return NULL;
  bb__text t = {0};
  bb__text_printf(&t, "bumpbake %s", c->def->info.name);
  for (int i = 0; i < c->input_count; i++) {
    bb__text_add(&t, " ");
    bb__text_add_word(&t, i == 0 && input ? input : c->inputs[i]);
  }
  if (!c->input_count && input) {
    bb__text_add(&t, " ");
    bb__text_add_word(&t, input);
  }
  bb__add_options(c, flags, &t);
  return bb__text_take(&t);
}


char *bb__command_record(const bb_command *c) {
  if (c->record_line)
    return strdup(c->record_line);
  return bb_command_text(c, NULL, BB_OPTION_RECORDED);
}

