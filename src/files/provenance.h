/* provenance.h: what the file writers and the up-to-date check
 * need of provenance texts beyond the public calls (provenance.c). */
#ifndef BB_FILES_PROVENANCE_H
#define BB_FILES_PROVENANCE_H

#include "bumpbake.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Fits the "key=value" lines of a provenance text into `rows` rows of at
 * most `row_chars` characters (TGA's comment field: 4 rows of 80), whole
 * lines only: the keys that affect pixels first, then the others, each line
 * in the first row it fits; lines joined by '\n' within a row. Row r is
 * written NUL-terminated at out + r * (row_chars + 1), which must hold
 * rows * (row_chars + 1) bytes. Returns how many lines did not fit. */
int bb__provenance_pack(const char *description, int rows, int row_chars, char *out);

/* bb__provenance_pack, and the lines that did not fit into overflow
 * (capacity overflow_cap, NUL-terminated): whole lines in the order they
 * were left out, '\n'-separated, as many as fit. */
int bb__provenance_pack_overflow(const char *description, int rows, int row_chars,
                                 char *out, char *overflow, size_t overflow_cap);

/* 1 when two provenance texts differ in a key not in `ignored` (a
 * NULL-terminated list): a key of want missing from have or holding
 * another value there, or a key have holds and want lacks (first
 * occurrences count). reason (capacity cap, may be NULL) receives the first
 * such key as "key: have-value -> want-value" ("(none)" for a missing one).
 * 0 when they agree. */
int bb__provenance_mismatch(const char *have, const char *want, const char *const *ignored,
                            char *reason, size_t cap);


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Writes into out (capacity cap) the keys whose values differ between two
 * provenance texts, as "key: A-value -> B-value" lines (empty when none, or
 * when either text is NULL). Keys "command" and "output" are ignored, and so
 * is a key neither text's kind ("output") records (bb__map_kind_records:
 * "rays" of a normal map; an ao's "rayset" is compared by its scheme and
 * slices alone without inter-reflection). Returns
 * the number of differing keys, or -1 when out of memory. Time is
 * O(n log n) in the number of lines, whatever the texts hold. */
int bb__provenance_diff(const char *a, const char *b, char *out, size_t cap);

/* The value of key in a provenance text (its first "key=value" line) into
 * out (capacity cap, NUL-terminated, cut to fit). Returns 1 when the key is
 * there, 0 when it is not or description is NULL (out is then ""). So a
 * reader can ask which basis a map was baked with ("basis"). */
int bb__provenance_value(const char *description, const char *key, char *out, size_t cap);

/* The one reading of a provenance text, which every reader uses (the
 * values and diffs above, the up-to-date check, info's report: `bumpbake
 * info --json`, Python's bumpbake.info): a line ends at '\n', and a '\r'
 * before it is dropped (a text re-saved on Windows); its key is what comes
 * before its first '=', its value what follows; a line without '=' is
 * skipped; a key seen before keeps its first value (its later lines are
 * skipped). Fills entries with up to cap of them, in line order; returns
 * how many there are (which may exceed cap), or -1 when out of memory.
 * Time O(n log n) in the lines. */
long bb__provenance_entries(const char *text, bb_provenance_entry *entries, size_t cap);

/* "none", "intact", "damaged"; "unknown" else. */
const char *bb__provenance_class_name(bb_provenance_class c);

#ifdef __cplusplus
}
#endif

/* Classifies a description (NULL is NONE): bumpbake's when it has a
 * "bumpbake_version=" line; intact when each non-empty line is key=value
 * with a key of lower-case letters, digits and '_'. */
bb_provenance_class bb__provenance_classify(const char *description);

#endif /* BB_FILES_PROVENANCE_H */
