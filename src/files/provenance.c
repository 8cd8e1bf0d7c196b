/* provenance.c: provenance texts read: a key's value, two texts compared key
 * by key, a text told from a foreign description, and fitted into a small
 * comment field. The texts are "key=value" lines (job/provenance_format.c
 * writes a bake's).
 */

#include "core/internal.h"
#include "files/provenance.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ diff */

/* One "key=value" line of a provenance text, as pointers into it. */
typedef struct entry {
  const char *key, *value;
  size_t key_length, value_length;
} entry;

/* Reads the line starting at *cursor into e and advances past it. Returns 0
 * at the end of the text; lines without '=' come back with key_length 0. */
static int next_entry(const char **cursor, entry *e) {
  const char *s = *cursor;
  if (!*s)
    return 0;
  const char *end = strchr(s, '\n');
  if (!end)
    end = s + strlen(s);
  const char *eq = memchr(s, '=', (size_t)(end - s));
  memset(e, 0, sizeof *e);
  if (eq) {
    e->key = s;
    e->key_length = (size_t)(eq - s);
    e->value = eq + 1;
    e->value_length = (size_t)(end - eq - 1);
    if (e->value_length && e->value[e->value_length - 1] == '\r')
      e->value_length--;
  }
  *cursor = *end ? end + 1 : end;
  return 1;
}

/* The first entry of text whose key is key; 0 when there is none. */
static int find_entry(const char *text_, const char *key, size_t key_length, entry *out) {
  entry e;
  const char *cursor = text_;
  while (next_entry(&cursor, &e))
    if (e.key_length == key_length && memcmp(e.key, key, key_length) == 0) {
      *out = e;
      return 1;
    }
  return 0;
}

int bb__provenance_value(const char *description, const char *key, char *out, size_t cap) {
  if (out && cap)
    out[0] = '\0';
  entry e;
  if (!description || !key || !find_entry(description, key, strlen(key), &e))
    return 0;
  if (out && cap)
    snprintf(out, cap, "%.*s", (int)e.value_length, e.value);
  return 1;
}

/* What decides which keys of a text count: the kind it records ("output")
 * and whether its bake reflected light (a "bounce" key), by the rule of
 * bb__map_kind_records, so a key a map does not depend on is neither a
 * difference nor a reason to bake again, also in a text written before
 * the rule that records it. */
typedef struct text_kind {
  char kind[64]; /* "" (any key counts) when there is none or it is too long */
  int bounce;
} text_kind;

static void kind_of(const char *text_, text_kind *k) {
  entry e;
  k->kind[0] = '\0';
  if (find_entry(text_, "output", 6, &e) && e.value_length < sizeof k->kind) {
    memcpy(k->kind, e.value, e.value_length);
    k->kind[e.value_length] = '\0';
  }
  k->bounce = find_entry(text_, "bounce", 6, &e);
}

/* 0 when neither kind records e's key (a diff of two texts, or a file
 * against what writing it would make, counts a key either side's kind
 * records); else 1, e's value cut to what they record of it. */
static int kinds_record(const text_kind *a, const text_kind *b, entry *e) {
  const bb__key_use ua = bb__map_kind_key(a->kind, e->key, e->key_length, a->bounce);
  const bb__key_use ub = bb__map_kind_key(b->kind, e->key, e->key_length, b->bounce);
  if (ua == BB__KEY_RECORDED || ub == BB__KEY_RECORDED)
    return 1;
  if (ua == BB__KEY_DROPPED && ub == BB__KEY_DROPPED)
    return 0;
  e->value_length = bb__rayset_slices_length(e->value, e->value_length);
  return 1;
}

static int is_ignored_key(const entry *e) {
  /* The command line names temporary paths and "output" the map kind; both
   * differ between a golden and a re-bake without any pixel changing. */
  static const char *const ignored[] = {"command", "output"};
  for (size_t i = 0; i < sizeof ignored / sizeof ignored[0]; i++)
    if (e->key_length == strlen(ignored[i]) &&
        memcmp(e->key, ignored[i], e->key_length) == 0)
      return 1;
  return 0;
}

/* Appends to out (capacity cap, always NUL-terminated) without overflowing. */
static void append_bounded(char *out, size_t cap, size_t *used, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static void append_bounded(char *out, size_t cap, size_t *used, const char *fmt, ...) {
  if (!out || cap == 0 || *used >= cap - 1)
    return;
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(out + *used, cap - *used, fmt, ap);
  va_end(ap);
  if (n < 0)
    return;
  *used += (size_t)n < cap - *used ? (size_t)n : cap - 1 - *used;
}

static void report(char *out, size_t cap, size_t *used, const entry *key, const entry *a,
                   const entry *b) {
  append_bounded(out, cap, used, "%.*s: %.*s -> %.*s\n", (int)key->key_length, key->key,
                 a ? (int)a->value_length : 6, a ? a->value : "(none)",
                 b ? (int)b->value_length : 6, b ? b->value : "(none)");
}

static int same_value(const entry *a, const entry *b) {
  return a->value_length == b->value_length &&
         memcmp(a->value, b->value, a->value_length) == 0;
}

/* A text's entries that count (a key, not ignored), first occurrence of
 * each key only, sorted by key for binary search; `order` keeps the line
 * order for the report. Sorting makes a diff O(n log n): the scan it
 * replaces searched the whole text for every line, and a crafted 300 KB
 * description (32000 lines) held `bumpbake compare` for 100 s. */
typedef struct keyed_entry {
  entry e;
  size_t order;
} keyed_entry;

typedef struct entry_index {
  keyed_entry *entries;
  size_t count;
} entry_index;

static int compare_keys(const entry *x, const entry *y) {
  size_t n = x->key_length < y->key_length ? x->key_length : y->key_length;
  int c = memcmp(x->key, y->key, n);
  if (c)
    return c;
  return (x->key_length > y->key_length) - (x->key_length < y->key_length);
}

static int by_key_then_order(const void *p, const void *q) {
  const keyed_entry *x = p, *y = q;
  int c = compare_keys(&x->e, &y->e);
  return c ? c : (x->order > y->order) - (x->order < y->order);
}

static int by_order(const void *p, const void *q) {
  const keyed_entry *x = p, *y = q;
  return (x->order > y->order) - (x->order < y->order);
}

/* Returns 0, or -1 when out of memory. kinds NULL: every key counts, as
 * written ("command", "output" and the keys the kind does not record, as
 * bb__provenance_entries reads them); else those a diff compares, the keys
 * either of kinds[0..1] records. */
static int index_entries(const char *text_, entry_index *index, const text_kind *kinds) {
  size_t lines = 1;
  for (const char *c = text_; *c; c++)
    lines += *c == '\n';
  index->count = 0;
  index->entries = malloc(lines * sizeof *index->entries);
  if (!index->entries)
    return -1;
  entry e;
  const char *cursor = text_;
  for (size_t order = 0; next_entry(&cursor, &e); order++)
    if (e.key_length &&
        (!kinds || (!is_ignored_key(&e) && kinds_record(&kinds[0], &kinds[1], &e))))
      index->entries[index->count++] = (keyed_entry){e, order};
  qsort(index->entries, index->count, sizeof *index->entries, by_key_then_order);
  /* A repeated key: only its first occurrence counts. */
  size_t kept = 0;
  for (size_t i = 0; i < index->count; i++)
    if (kept == 0 || compare_keys(&index->entries[kept - 1].e, &index->entries[i].e) != 0)
      index->entries[kept++] = index->entries[i];
  index->count = kept;
  return 0;
}

static const entry *lookup(const entry_index *index, const entry *key) {
  size_t lo = 0, hi = index->count;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    int c = compare_keys(&index->entries[mid].e, key);
    if (c == 0)
      return &index->entries[mid].e;
    if (c < 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  return NULL;
}

int bb__provenance_diff(const char *a, const char *b, char *out, size_t cap) {
  size_t used = 0;
  if (out && cap)
    out[0] = '\0';
  if (!a || !b)
    return 0;
  entry_index ia = {0}, ib = {0};
  text_kind kinds[2];
  kind_of(a, &kinds[0]);
  kind_of(b, &kinds[1]);
  if (index_entries(a, &ia, kinds) != 0 || index_entries(b, &ib, kinds) != 0) {
    free(ia.entries);
    free(ib.entries);
    return -1;
  }
  int differing = 0;
  /* Keys of a, in a's order: changed or missing from b. */
  qsort(ia.entries, ia.count, sizeof *ia.entries, by_order);
  for (size_t i = 0; i < ia.count; i++) {
    const entry *e = &ia.entries[i].e, *other = lookup(&ib, e);
    if (other && same_value(e, other))
      continue;
    report(out, cap, &used, e, e, other);
    differing++;
  }
  /* Keys only b has, in b's order (a sorted by key again for the lookup). */
  qsort(ia.entries, ia.count, sizeof *ia.entries, by_key_then_order);
  qsort(ib.entries, ib.count, sizeof *ib.entries, by_order);
  for (size_t i = 0; i < ib.count; i++) {
    const entry *e = &ib.entries[i].e;
    if (lookup(&ia, e))
      continue;
    report(out, cap, &used, e, NULL, e);
    differing++;
  }
  free(ia.entries);
  free(ib.entries);
  return differing;
}

long bb__provenance_entries(const char *description, bb_provenance_entry *entries,
                           size_t cap) {
  if (!description)
    return 0;
  entry_index index = {0};
  if (index_entries(description, &index, NULL) != 0)
    return -1;
  qsort(index.entries, index.count, sizeof *index.entries, by_order);
  for (size_t i = 0; i < index.count && i < cap && entries; i++) {
    const entry *e = &index.entries[i].e;
    entries[i] = (bb_provenance_entry){e->key, e->key_length, e->value, e->value_length};
  }
  const long count = (long)index.count;
  free(index.entries);
  return count;
}

/* ------------------------------------------------------------ mismatch */

static int is_listed(const entry *e, const char *const *keys) {
  for (; keys && *keys; keys++)
    if (e->key_length == strlen(*keys) && memcmp(e->key, *keys, e->key_length) == 0)
      return 1;
  return 0;
}

/* The first key of `from` (not ignored) that `other` does not hold with
 * the same value, reported as "key: have -> want"; 0 when there is none.
 * Linear in the size of each text times the lines of the other, and `want`
 * is the short text bb__provenance_format made. */
static int first_missing(const char *from, const char *other, int from_is_have,
                         const char *const *ignored, char *reason, size_t cap) {
  entry e, o;
  text_kind kinds[2];
  kind_of(from, &kinds[0]);
  kind_of(other, &kinds[1]);
  for (const char *cursor = from; next_entry(&cursor, &e);) {
    if (!e.key_length || is_listed(&e, ignored) || !kinds_record(&kinds[0], &kinds[1], &e))
      continue;
    int found = find_entry(other, e.key, e.key_length, &o) &&
                kinds_record(&kinds[0], &kinds[1], &o);
    if (found && same_value(&e, &o))
      continue;
    size_t used = 0;
    const entry *have = from_is_have ? &e : (found ? &o : NULL);
    const entry *want = from_is_have ? (found ? &o : NULL) : &e;
    report(reason, cap, &used, &e, have, want);
    if (reason && cap && used && reason[used - 1] == '\n')
      reason[used - 1] = '\0';
    return 1;
  }
  return 0;
}

int bb__provenance_mismatch(const char *have, const char *want, const char *const *ignored,
                            char *reason, size_t cap) {
  if (reason && cap)
    reason[0] = '\0';
  return first_missing(want, have, 0, ignored, reason, cap) ||
         first_missing(have, want, 1, ignored, reason, cap);
}

/* ---------------------------------------------------------------- classify */

static int is_key_char(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
}

/* 1 when the line [line, line + n) is "key=value" or empty. */
static int is_entry_line(const char *line, size_t n) {
  size_t k = 0;
  while (k < n && is_key_char(line[k]))
    k++;
  return n == 0 || (k > 0 && k < n && line[k] == '=');
}

const char *bb__provenance_class_name(bb_provenance_class c) {
  switch (c) {
  case BB_PROVENANCE_NONE: return "none";
  case BB_PROVENANCE_INTACT: return "intact";
  case BB_PROVENANCE_DAMAGED: return "damaged";
  }
  return "unknown";
}

bb_provenance_class bb__provenance_classify(const char *description) {
  static const char marker[] = "bumpbake_version=";
  if (!description || (strncmp(description, marker, sizeof marker - 1) != 0 &&
                       !strstr(description, "\nbumpbake_version=")))
    return BB_PROVENANCE_NONE;
  /* A format that cuts or re-wraps long comments (TGA keeps 4 rows of 80
   * characters; bb__image_write fits whole lines into them, but other tools
   * may not) leaves lines that are not key=value. */
  for (const char *line = description; *line;) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    if (n && line[n - 1] == '\r')
      n--;
    if (!is_entry_line(line, n))
      return BB_PROVENANCE_DAMAGED;
    line = end ? end + 1 : line + n;
  }
  return BB_PROVENANCE_INTACT;
}

/* -------------------------------------------------------------------- pack */

/* The keys in the order a cut copy keeps them: what the pixels depend on
 * first (so two cut copies still diff meaningfully), then keys of other
 * producers (renderbumpflat's axis, rect, ...: parameters too), then what
 * names the file, and the long command line last. NULL marks where the
 * other keys go; lines of one rank keep their text order. */
static const char *const PACK_ORDER[] = {
    "bumpbake_version", "input_hash", "input_file_hash", "scale", "rays", "rayset",
    "filter_radius",
    "filter_threshold", "bias",       "power", "basis",  "normal_filter", "normal_y",
    "addressing",       "bounce",     "bounces", "bounce_albedo_map", "brightness",
    "channel",          NULL,         "output", "input",         "command"};
enum { PACK_RANKS = sizeof PACK_ORDER / sizeof PACK_ORDER[0] };

/* Rank of a line's key in PACK_ORDER (the NULL entry's for other keys). */
static int pack_rank(const entry *e) {
  int other = 0;
  for (int k = 0; k < PACK_RANKS; k++) {
    if (!PACK_ORDER[k])
      other = k;
    else if (e->key_length == strlen(PACK_ORDER[k]) &&
             memcmp(e->key, PACK_ORDER[k], e->key_length) == 0)
      return k;
  }
  return other;
}

/* Puts the line [line, line + n) into the first row with room; 0 if none. */
static int pack_line(const char *line, size_t n, int rows, int row_chars, char *out) {
  for (int r = 0; r < rows; r++) {
    char *row = out + (size_t)r * (size_t)(row_chars + 1);
    size_t used = strlen(row), sep = used ? 1 : 0;
    if (used + sep + n > (size_t)row_chars)
      continue;
    if (sep)
      row[used++] = '\n';
    memcpy(row + used, line, n);
    row[used + n] = '\0';
    return 1;
  }
  return 0;
}

/* Appends line [line, line + n) to the NUL-terminated overflow text
 * (capacity cap; NULL: none kept) when it fits whole, '\n'-separated. */
static void keep_overflow(const char *line, size_t n, char *overflow, size_t cap) {
  if (!overflow)
    return;
  size_t used = strlen(overflow), sep = used ? 1 : 0;
  if (used + sep + n + 1 > cap)
    return;
  if (sep)
    overflow[used++] = '\n';
  memcpy(overflow + used, line, n);
  overflow[used + n] = '\0';
}

static int pack(const char *description, int rows, int row_chars, char *out,
                char *overflow, size_t overflow_cap) {
  memset(out, 0, (size_t)rows * (size_t)(row_chars + 1));
  if (overflow && overflow_cap)
    overflow[0] = '\0';
  int dropped = 0;
  /* One pass per rank keeps the order stable without sorting or memory. */
  for (int rank = 0; rank < PACK_RANKS; rank++) {
    const char *cursor = description ? description : "";
    for (const char *line = cursor; *line; line = cursor) {
      entry e;
      next_entry(&cursor, &e);
      size_t n = strcspn(line, "\n");
      if (n && line[n - 1] == '\r')
        n--;
      if (n == 0 || pack_rank(&e) != rank) /* a line without '=' ranks as other */
        continue;
      if (!pack_line(line, n, rows, row_chars, out)) {
        dropped++;
        keep_overflow(line, n, overflow, overflow_cap);
      }
    }
  }
  return dropped;
}

int bb__provenance_pack(const char *description, int rows, int row_chars, char *out) {
  return pack(description, rows, row_chars, out, NULL, 0);
}

int bb__provenance_pack_overflow(const char *description, int rows, int row_chars,
                                 char *out, char *overflow, size_t overflow_cap) {
  return pack(description, rows, row_chars, out, overflow, overflow_cap);
}
