/* text.c: the library's one growable text (bb__text, core/internal.h), for
 * provenance and the command lines it records, a word quoted for a POSIX
 * shell (those command lines' words), and numbers spelled the shortest way
 * that reads back as the same value. */

#include "core/internal.h"

#include <math.h>
#include <stdio.h>
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
  if (s) /* a string not set adds nothing */
    bb__text_append(t, s, strlen(s));
}

/* A byte no POSIX shell (nor bash) treats specially anywhere in a word:
 * letters, digits, "@%+=:,./-_" and the bytes of UTF-8 beyond ASCII. */
static int shell_plain(unsigned char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         c >= 0x80 || (c && strchr("@%+=:,./-_", c));
}

void bb__text_add_word(bb__text *t, const char *word) {
  if (!word)
    return;
  int plain = word[0] != '\0';
  for (const char *p = word; *p && plain; p++)
    plain = shell_plain((unsigned char)*p);
  if (plain) {
    bb__text_add(t, word);
    return;
  }
  /* Single quotes keep every byte as it is; a quote ends them, is given
   * escaped, and they start again: it's -> 'it'\''s'. */
  bb__text_add(t, "'");
  for (const char *p = word, *q; *p; p = q) {
    q = strchr(p, '\'');
    if (!q) {
      bb__text_add(t, p);
      break;
    }
    bb__text_append(t, p, (size_t)(q - p));
    bb__text_add(t, "'\\''");
    q++;
  }
  bb__text_add(t, "'");
}

char *bb_text_shell_quoted(const char *word) {
  if (!word)
    return NULL;
  bb__text t = {0};
  bb__text_add_word(&t, word);
  return bb__text_take(&t);
}

void bb__text_printf(bb__text *t, const char *fmt, ...) {
  char small[256];
  va_list ap;
  va_start(ap, fmt);
  const int n = vsnprintf(small, sizeof small, fmt, ap);
  va_end(ap);
  if (n < 0) {
    t->failed = 1;
    return;
  }
  if ((size_t)n < sizeof small) {
    bb__text_append(t, small, (size_t)n);
    return;
  }
  char *big = malloc((size_t)n + 1);
  if (!big) {
    t->failed = 1;
    return;
  }
  va_start(ap, fmt);
  vsnprintf(big, (size_t)n + 1, fmt, ap);
  va_end(ap);
  bb__text_append(t, big, (size_t)n);
  free(big);
}

char *bb__text_take(bb__text *t) {
  char *s = t->data;
  if (t->failed) {
    free(s);
    s = NULL;
  } else if (!s) {
    s = calloc(1, 1);
  }
  memset(t, 0, sizeof *t);
  return s;
}

void bb__text_free(bb__text *t) {
  free(t->data);
  memset(t, 0, sizeof *t);
}

/* The shortest %g that reads back as v has an exponent for a whole number
 * of more digits than it needs (30 as "3e+01"): a user types 30. */
static void whole_number_plainly(double v, char *buf, size_t cap) {
  if (strstr(buf, "e+") && fabs(v) < 1e15)
    snprintf(buf, cap, "%.0f", v);
}

void bb__float_text(float v, char *buf, size_t cap) {
  for (int digits = 1; digits <= 9; digits++) {
    snprintf(buf, cap, "%.*g", digits, (double)v);
    if (strtof(buf, NULL) == v)
      break;
  }
  whole_number_plainly(v, buf, cap);
}

void bb__double_text(double v, char *buf, size_t cap) {
  for (int digits = 1; digits <= 17; digits++) {
    snprintf(buf, cap, "%.*g", digits, v);
    if (strtod(buf, NULL) == v)
      break;
  }
  whole_number_plainly(v, buf, cap);
}
