/* printed_text.h: what the hostile tests and the print fuzz target ask of
 * text bumpbake prints for a human or as JSON. */
#ifndef BB_TESTS_PRINTED_TEXT_H
#define BB_TESTS_PRINTED_TEXT_H

/* 1 when s holds a byte that drives a terminal: C0 controls but newline,
 * DEL, or a C1 control (UTF-8 0xc2 0x80..0x9f); or a bidirectional control
 * that reorders what a terminal shows (U+061C, U+200E, U+200F,
 * U+202A..U+202E, U+2066..U+2069). */
static inline int has_control(const char *s) {
  for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
    if ((*c < 0x20 && *c != '\n') || *c == 0x7f || (c[0] == 0xc2 && c[1] >= 0x80 && c[1] < 0xa0))
      return 1;
    if ((c[0] == 0xd8 && c[1] == 0x9c) ||
        (c[0] == 0xe2 && c[1] == 0x80 && (c[2] == 0x8e || c[2] == 0x8f || (c[2] >= 0xaa && c[2] <= 0xae))) ||
        (c[0] == 0xe2 && c[1] == 0x81 && c[2] >= 0xa6 && c[2] <= 0xa9))
      return 1;
  }
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
