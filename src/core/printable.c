/* printable.c: text read from files (names, descriptions, a VTF's KVD, a
 * model's names) made safe to show a person. A terminal obeys control
 * characters, and a bidirectional control reorders what follows it, so a
 * file name or a provenance line could move the cursor, retitle the
 * window, or show "evil\u202egnp.exe" as "evilexe.png". One rule for every
 * line the command line prints. */
#include "core/internal.h"
#include "core/json.h"

#include <stdio.h>
#include <string.h>

/* 1 when the n-byte UTF-8 sequence at s is a bidirectional control:
 * U+061C ALM, U+200E LRM, U+200F RLM, U+202A..U+202E (LRE, RLE, PDF, LRO,
 * RLO), U+2066..U+2069 (LRI, RLI, FSI, PDI). */
static int is_bidi_control(const unsigned char *s, size_t n) {
  if (n == 2)
    return s[0] == 0xd8 && s[1] == 0x9c;
  if (n != 3 || s[0] != 0xe2)
    return 0;
  if (s[1] == 0x80)
    return s[2] == 0x8e || s[2] == 0x8f || (s[2] >= 0xaa && s[2] <= 0xae);
  return s[1] == 0x81 && s[2] >= 0xa6 && s[2] <= 0xa9;
}

/* The length of the sequence at s that may be shown as it is: 0 for a
 * control (C0, DEL, C1: 0x9b is CSI to some terminals; a bidirectional
 * one) or bytes that are not UTF-8. */
static size_t printable_sequence(const unsigned char *s) {
  if (s[0] < 0x80)
    return s[0] >= 0x20 && s[0] != 0x7f;
  const size_t n = bb__utf8_sequence((const char *)s);
  if (n == 2 && s[0] == 0xc2 && s[1] < 0xa0)
    return 0;
  return is_bidi_control(s, n) ? 0 : n;
}

const char *bb_text_printable(const char *s, char *out, size_t cap) {
  if (!out || !cap)
    return out;
  size_t used = 0;
  for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p;) {
    size_t n = printable_sequence(p);
    if (n == 0) {
      /* every byte of a control sequence, so none is left to act */
      const size_t k = p[0] < 0x80 ? 1 : bb__utf8_sequence((const char *)p);
      const size_t bytes = k ? k : 1;
      if (used + 4 * bytes >= cap)
        break;
      for (size_t i = 0; i < bytes; i++)
        used += (size_t)snprintf(out + used, cap - used, "\\x%02x", p[i]);
      p += bytes;
      continue;
    }
    if (used + n >= cap)
      break;
    memcpy(out + used, p, n);
    used += n;
    p += n;
  }
  out[used] = '\0';
  return out;
}
