/* json.h: the one JSON writer (json.c), of the library and of the command
 * line, which compiles json.c into itself: the writer is not part of
 * libbumpbake's ABI (issue 41), and the CLI calls nothing of the library
 * but bumpbake.h. So json.h and json.c include nothing of the library (the
 * CLI includes this header by its relative path), and json.c also holds
 * the one reading of UTF-8 that the writer and bb_text_printable share. */
#ifndef BB_CORE_JSON_H
#define BB_CORE_JSON_H

#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The length of the well-formed UTF-8 sequence at s (1 for ASCII), 0 for
 * the end of the string or bytes that are not UTF-8 (overlong forms,
 * surrogates and code points past U+10FFFF included). */
size_t bb__utf8_sequence(const char *s);

/* Writes s to f as a quoted JSON string, always valid UTF-8 and never cut:
 * '"' and '\' escaped, newline, carriage return and tab as \n, \r, \t,
 * other control characters (C0, DEL, C1) as \u00XX; UTF-8 passes through;
 * a byte that is not part of UTF-8 (a file name in another encoding)
 * becomes the lone surrogate \udcXX, which Python's json and
 * os.fsencode() turn back into the same byte. NULL writes null. */
void bb__json_quoted(FILE *f, const char *s);

/* The one JSON writer of the library and the command line:
 * one-line objects; fields are separated by commas automatically. Values
 * are written as they come; nesting is the caller's to balance. */
typedef struct bb__json {
  FILE *f;
  int need_comma; /* a value was written at the current nesting level */
} bb__json;

/* Opens an object or array; key is its field name, NULL at the top level
 * or inside an array. open is '{' or '['. */
void bb__json_open(bb__json *j, const char *key, char open);
void bb__json_close(bb__json *j, char close);
/* A string field; value NULL writes null. key NULL inside arrays. */
void bb__json_string(bb__json *j, const char *key, const char *value);
/* A number with 9 significant digits (every float reads back exactly);
 * JSON has no NaN or infinity, so those are written as null. */
void bb__json_number(bb__json *j, const char *key, double value);
/* An integer, exactly (counts, sizes, exit codes). */
void bb__json_int(bb__json *j, const char *key, long long value);
void bb__json_bool(bb__json *j, const char *key, int value);
/* An array of text's lines as strings (a last '\n' ends the last line);
 * text NULL writes []. */
void bb__json_lines(bb__json *j, const char *key, const char *text);

#ifdef __cplusplus
}
#endif

#endif /* BB_CORE_JSON_H */
