/* fuzz_provenance.c: the provenance parser, bb__provenance_diff, on two
 * texts (split at the first NUL) and an output capacity taken from the
 * first byte (0, tiny and large), plus the round trip through
 * bb__provenance_format. Properties: no crash or overflow, the output always
 * NUL-terminated inside its capacity, one line per difference when it fits,
 * a text never differs from itself, and formatting two option sets that
 * differ in the scale alone gives exactly the "scale" difference. */
#include "job/job_internal.h"
#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "fuzz_common.h"
#include "files/provenance.h"

static const size_t CAPACITIES[] = {0, 1, 2, 7, 64, 4096};

static int count_lines(const char *s) {
  int n = 0;
  for (; *s; s++)
    n += *s == '\n';
  return n;
}

/* Capacity index, texts a and b: NUL-terminated copies (malloc'd). */
static void split(const uint8_t *data, size_t size, size_t *cap, char **a, char **b) {
  *cap = CAPACITIES[data[0] % 6];
  const uint8_t *rest = data + 1, *end = data + size;
  const uint8_t *nul = memchr(rest, 0, (size_t)(end - rest));
  size_t na = nul ? (size_t)(nul - rest) : (size_t)(end - rest);
  size_t nb = nul ? (size_t)(end - nul - 1) : 0;
  *a = malloc(na + 1);
  *b = malloc(nb + 1);
  if (!*a || !*b)
    abort();
  memcpy(*a, rest, na);
  (*a)[na] = '\0';
  if (nb)
    memcpy(*b, nul + 1, nb);
  (*b)[nb] = '\0';
}

static void check_diff(const char *a, const char *b, size_t cap) {
  char *out = malloc(cap ? cap : 1);
  if (!out)
    abort();
  int n = bb__provenance_diff(a, b, cap ? out : NULL, cap);
  FUZZ_CHECK(n >= 0);
  if (cap) {
    FUZZ_CHECK(memchr(out, '\0', cap) != NULL);
    if (strlen(out) + 1 < cap) /* nothing was cut */
      FUZZ_CHECK(count_lines(out) == n);
  }
  free(out);
}

/* Formatting is the writer of what diff parses: fuzzed free text (command
 * line, input name, kind) must not bleed into other keys. */
static void check_round_trip(const char *a, const char *b) {
  bb_bake_options o1, o2;
  bb__bake_options_init(&o1);
  o1.height_scale = 2.0f;
  o2 = o1;
  o2.height_scale = 3.0f;
  bb_provenance p = {a, b, 0x1234, a, &o1, BB_CHANNEL_AUTO, b, 0x5678, NULL};
  char *t1 = bb__provenance_format(&p);
  p.options = &o2;
  char *t2 = bb__provenance_format(&p);
  FUZZ_CHECK(t1 && t2);
  char out[4096];
  FUZZ_CHECK(bb__provenance_diff(t1, t1, out, sizeof out) == 0 && out[0] == '\0');
  int n = bb__provenance_diff(t1, t2, out, sizeof out);
  FUZZ_CHECK(n == 1 && strncmp(out, "scale: 2 -> 3\n", sizeof out) == 0);
  free(t1);
  free(t2);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1)
    return 0;
  size_t cap;
  char *a, *b;
  split(data, size, &cap, &a, &b);
  check_diff(a, b, cap);
  check_diff(b, a, cap);
  char self[64];
  FUZZ_CHECK(bb__provenance_diff(a, a, self, sizeof self) == 0);
  check_round_trip(a, b);
  free(a);
  free(b);
  return 0;
}
