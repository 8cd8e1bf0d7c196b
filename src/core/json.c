/* json.c: the one JSON writer of the library and of the command line,
 * compiled into both (json.h says why), and the UTF-8 reading it shares
 * with bb_text_printable. It includes nothing of the library. */

#include "json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t bb__utf8_sequence(const char *text) {
  const unsigned char *s = (const unsigned char *)text;
  if (!s || !s[0])
    return 0;
  if (s[0] < 0x80)
    return 1;
  size_t n = s[0] >= 0xf0 && s[0] <= 0xf4 ? 4 : s[0] >= 0xe0 ? 3 : s[0] >= 0xc2 ? 2 : 0;
  if (s[0] > 0xf4)
    n = 0;
  for (size_t i = 1; i < n; i++)
    if ((s[i] & 0xc0) != 0x80)
      return 0;
  if (n == 3 && ((s[0] == 0xe0 && s[1] < 0xa0) || (s[0] == 0xed && s[1] >= 0xa0)))
    return 0; /* overlong, or a surrogate */
  if (n == 4 && ((s[0] == 0xf0 && s[1] < 0x90) || (s[0] == 0xf4 && s[1] >= 0x90)))
    return 0; /* overlong, or past U+10FFFF */
  return n;
}

void bb__json_quoted(FILE *f, const char *s) {
  if (!s) {
    fputs("null", f);
    return;
  }
  fputc('"', f);
  for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
    if (*c >= 0x80) {
      const size_t n = bb__utf8_sequence((const char *)c);
      if (n == 0) /* not UTF-8: the byte as a lone surrogate, as Python's
                     surrogateescape reads it back */
        fprintf(f, "\\udc%02x", *c);
      else if (n == 2 && c[0] == 0xc2 && c[1] < 0xa0) /* a C1 control */
        fprintf(f, "\\u%04x", c[1]);
      else
        fwrite(c, 1, n, f);
      c += n ? n - 1 : 0;
      continue;
    }
    switch (*c) {
    case '"':
    case '\\':
      fputc('\\', f);
      fputc(*c, f);
      break;
    case '\n':
      fputs("\\n", f);
      break;
    case '\r':
      fputs("\\r", f);
      break;
    case '\t':
      fputs("\\t", f);
      break;
    default:
      if (*c < 0x20 || *c == 0x7f)
        fprintf(f, "\\u%04x", *c);
      else
        fputc(*c, f);
    }
  }
  fputc('"', f);
}

/* The separator and "key": that precede every value. */
static void json_begin_value(bb__json *j, const char *key) {
  if (j->need_comma)
    fputc(',', j->f);
  if (key) {
    bb__json_quoted(j->f, key);
    fputc(':', j->f);
  }
  j->need_comma = 1;
}

void bb__json_open(bb__json *j, const char *key, char open) {
  json_begin_value(j, key);
  fputc(open, j->f);
  j->need_comma = 0;
}

void bb__json_close(bb__json *j, char close) {
  fputc(close, j->f);
  j->need_comma = 1;
}

void bb__json_string(bb__json *j, const char *key, const char *value) {
  json_begin_value(j, key);
  bb__json_quoted(j->f, value);
}

void bb__json_number(bb__json *j, const char *key, double value) {
  json_begin_value(j, key);
  if (isfinite(value))
    fprintf(j->f, "%.9g", value);
  else
    fputs("null", j->f);
}

void bb__json_int(bb__json *j, const char *key, long long value) {
  json_begin_value(j, key);
  fprintf(j->f, "%lld", value);
}

void bb__json_bool(bb__json *j, const char *key, int value) {
  json_begin_value(j, key);
  fputs(value ? "true" : "false", j->f);
}

void bb__json_lines(bb__json *j, const char *key, const char *text) {
  bb__json_open(j, key, '[');
  for (const char *line = text; line && *line;) {
    const size_t n = strcspn(line, "\n");
    char *one = strndup(line, n);
    bb__json_string(j, NULL, one ? one : "");
    free(one);
    line += n + (line[n] == '\n');
  }
  bb__json_close(j, ']');
}
