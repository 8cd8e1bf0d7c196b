/* text.c: the library's one growable text (bb__text, core/internal.h), for
 * provenance and the command lines it records. */

#include "core/internal.h"

#include <stdlib.h>
#include <string.h>

void bb__text_append(bb__text *t, const char *s, size_t n) {
  if (t->failed)
    return;
  if (t->length + n + 1 > t->capacity) {
    size_t cap = t->capacity ? t->capacity : 256;
    while (t->length + n + 1 > cap)
      cap *= 2;
    char *grown = realloc(t->data, cap);
    if (!grown) {
      t->failed = 1;
      return;
    }
    t->data = grown;
    t->capacity = cap;
  }
  memcpy(t->data + t->length, s, n);
  t->length += n;
  t->data[t->length] = '\0';
}

void bb__text_add(bb__text *t, const char *s) {
  bb__text_append(t, s, strlen(s));
}
