/* printed_text.h: what the hostile tests and the print fuzz target ask of
 * text bumpbake prints for a human or as JSON. */
#ifndef BB_TESTS_PRINTED_TEXT_H
#define BB_TESTS_PRINTED_TEXT_H

/* 1 when s holds a byte that drives a terminal: C0 controls but newline,
 * DEL, or a C1 control (UTF-8 0xc2 0x80..0x9f). */
static inline int has_control(const char *s) {
  for (const unsigned char *c = (const unsigned char *)s; *c; c++)
    if ((*c < 0x20 && *c != '\n') || *c == 0x7f || (c[0] == 0xc2 && c[1] >= 0x80 && c[1] < 0xa0))
      return 1;
  return 0;
}

/* 1 when s is valid UTF-8. */
static inline int valid_utf8(const char *s) {
  for (const unsigned char *c = (const unsigned char *)s; *c;) {
    int n = *c < 0x80 ? 1 : (*c & 0xe0) == 0xc0 ? 2 : (*c & 0xf0) == 0xe0 ? 3 : (*c & 0xf8) == 0xf0 ? 4 : 0;
    if (!n || (n == 2 && *c < 0xc2))
      return 0;
    for (int i = 1; i < n; i++)
      if ((c[i] & 0xc0) != 0x80)
        return 0;
    c += n;
  }
  return 1;
}

#endif /* BB_TESTS_PRINTED_TEXT_H */
