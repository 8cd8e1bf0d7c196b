/* spelling.c: a command's messages in its client's words. The library
 * words every refusal as the command line spells the options ("--bounce
 * must be in 0..1", "give -o PREFIX or ..."); a client that takes them as
 * keyword arguments (Python; serve's page controls) gets the same
 * message with each option of the command spelled as its keyword
 * ("bounce must be in 0..1", "give output=PREFIX or ..."). The option rows
 * know both spellings, so the rewrite reads them and nothing else: only
 * the names of this command's options change, and only where a name
 * stands as a word of its own (a path holding "--normal" stays). */
#include "cmd/cmd_internal.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

void bb_command_set_spelling(bb_command *c, bb_spelling spelling) {
  if (c)
    c->spelling = spelling;
}

/* Where an option's name may start: the message's start or after a
 * blank, a bracket, a comma, a quote or a colon. */
static int starts_word(const char *message, const char *p) {
  return p == message || strchr(" (,'\":", p[-1]) != NULL;
}

/* Where it must end: the end, a blank, closing punctuation, or a full
 * stop that ends a sentence. */
static int ends_word(const char *p) {
  return *p == '\0' || strchr(" ),;:'\"?!", *p) != NULL ||
         (*p == '.' && (p[1] == '\0' || p[1] == ' '));
}

/* The option of c whose command-line spelling starts at p ("--name",
 * "-x", or "-name" for a single-dash one), and that spelling's length. */
static const bb__option *option_at(const bb__command *def, const char *p,
                                   size_t *length) {
  if (p[0] != '-')
    return NULL;
  const int dashes = p[1] == '-' ? 2 : 1;
  const char *name = p + dashes;
  size_t n = 0;
  while (islower((unsigned char)name[n]) || isdigit((unsigned char)name[n]) ||
         (n > 0 && name[n] == '-'))
    n++;
  if (n == 0 || !ends_word(name + n))
    return NULL;
  for (int i = 0; def->options[i]; i++) {
    const bb__option *o = def->options[i];
    const int long_name = strlen(o->info.name) == n && !strncmp(o->info.name, name, n);
    const int matches = dashes == 2
                            ? long_name
                            : (n == 1 && o->info.short_name == name[0]) ||
                                  (long_name && (o->info.flags & BB_OPTION_SINGLE_DASH));
    if (matches) {
      *length = (size_t)dashes + n;
      return o;
    }
  }
  return NULL;
}

void bb__respell(const bb_command *c, char *message, size_t cap) {
  if (!c || c->spelling != BB_SPELLING_KEYWORDS || !message || !cap)
    return;
  char out[sizeof(((bb_error *)0)->message)];
  size_t n = 0;
  for (const char *p = message; *p && n + 1 < sizeof out;) {
    size_t length = 0;
    const bb__option *o = starts_word(message, p) ? option_at(c->def, p, &length) : NULL;
    if (!o) {
      out[n++] = *p++;
      continue;
    }
    for (const char *k = o->info.name; *k && n + 1 < sizeof out; k++)
      out[n++] = *k == '-' ? '_' : *k;
    p += length;
    /* "-o PREFIX": the value's name after the option is the keyword's
     * value, "output=PREFIX" */
    const char *value = o->info.value_name;
    const size_t v = value ? strlen(value) : 0;
    if (v && p[0] == ' ' && !strncmp(p + 1, value, v) && ends_word(p + 1 + v) &&
        n + 1 + v + 1 < sizeof out) {
      out[n++] = '=';
      memcpy(out + n, value, v);
      n += v;
      p += 1 + v;
    }
  }
  out[n] = '\0';
  snprintf(message, cap, "%s", out);
}

bb_status bb__spelled(const bb_command *c, bb_status st, bb_error *err) {
  if (st != BB_OK && err)
    bb__respell(c, err->message, sizeof err->message);
  return st;
}

/* A note on its way to the caller's note function, respelled. */
static void respelled_note(void *user, const char *path, const char *text) {
  const bb__spelled_hooks *h = user;
  char message[sizeof(((bb_error *)0)->message)];
  snprintf(message, sizeof message, "%s", text);
  bb__respell(h->command, message, sizeof message);
  h->caller->note(h->caller->note_user, path, message);
}

const bb_command_hooks *bb__spelled_hooks_of(const bb_command *c,
                                             const bb_command_hooks *hooks,
                                             bb__spelled_hooks *h) {
  if (!hooks || !hooks->note || c->spelling != BB_SPELLING_KEYWORDS)
    return hooks;
  h->command = c;
  h->caller = hooks;
  h->hooks = *hooks;
  h->hooks.note = respelled_note;
  h->hooks.note_user = h;
  return &h->hooks;
}
