/* json.h: the one JSON writer of bumpbake's command line and tools:
 * one-line objects for --json output, with strings escaped in one place. */
#ifndef BB_CLI_JSON_H
#define BB_CLI_JSON_H

#include <stddef.h>
#include <stdio.h>

/* Writes s to f as a quoted JSON string, always valid UTF-8 and never cut:
 * '"' and '\' escaped, newline, carriage return and tab as \n, \r, \t,
 * other control characters (C0, DEL, C1) as \u00XX; UTF-8 passes through;
 * a byte that is not part of UTF-8 (a file name in another encoding)
 * becomes the lone surrogate \udcXX, which Python's json and
 * os.fsencode() turn back into the same byte. NULL writes null. */
void cli_json_quoted(FILE *f, const char *s);

/* A one-line JSON writer: fields are separated by commas automatically.
 * Values are written as they come; nesting is the caller's to balance. */
typedef struct cli_json {
  FILE *f;
  int need_comma; /* a value was written at the current nesting level */
} cli_json;

/* Opens an object or array; key is its field name, NULL at the top level
 * or inside an array. open is '{' or '['. */
void cli_json_open(cli_json *j, const char *key, char open);
void cli_json_close(cli_json *j, char close);
/* A string field; value NULL writes null. key NULL inside arrays. */
void cli_json_string(cli_json *j, const char *key, const char *value);
/* A number with 9 significant digits (every float reads back exactly);
 * JSON has no NaN or infinity, so those are written as null. */
void cli_json_number(cli_json *j, const char *key, double value);
/* An integer, exactly (counts, sizes, exit codes). */
void cli_json_int(cli_json *j, const char *key, long long value);
void cli_json_bool(cli_json *j, const char *key, int value);

#endif /* BB_CLI_JSON_H */
