/* json_string.h: writing a JSON string, shared by the measuring tools. */
#ifndef BB_TOOLS_JSON_STRING_H
#define BB_TOOLS_JSON_STRING_H

#include <stdio.h>

/* Prints s as a quoted JSON string: quotes, backslashes and control bytes
 * escaped. */
static inline void print_json_string(const char *s) {
  putchar('"');
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      printf("\\%c", c);
    else if (c < 0x20)
      printf("\\u%04x", c);
    else
      putchar(c);
  }
  putchar('"');
}

#endif
