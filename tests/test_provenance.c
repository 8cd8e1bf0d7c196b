/* test_provenance.c: image hash, provenance text and its key-by-key diff. */
#include "bumpbake.h"

#include <criterion/criterion.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* FNV-1a 64 over a byte string, written from the published definition
 * (offset basis 14695981039346656037, prime 1099511628211), so the test
 * checks the library against the spec rather than against itself. */
static uint64_t reference_fnv1a(const unsigned char *bytes, size_t n) {
  uint64_t h = 14695981039346656037ULL;
  for (size_t i = 0; i < n; i++) {
    h ^= bytes[i];
    h *= 1099511628211ULL;
  }
  return h;
}

static bb_bake_options sample_options(void) {
  bb_bake_options o;
  memset(&o, 0, sizeof o);
  o.height_scale = 16.0f;
  o.rays = 256;
  o.smooth.radius_texels = 10;
  o.smooth.threshold = 2.0f / 255.0f;
  o.smooth.addressing = BB_ADDRESS_PERIODIC;
  o.trace.bias_texels = 0.55;
  o.power = 1.0;
  o.basis = BB_BASIS_HL2;
  o.normal_filter = BB_NORMAL_VALVE;
  o.normal_y_up = 0;
  o.want_trace = 1;
  return o;
}

static bb_provenance sample_provenance(const bb_bake_options *o) {
  bb_provenance p = {.command = "bumpbake bake in.png --scale 16",
                     .input_name = "in.png",
                     .input_hash = 0x0123456789abcdefULL,
                     .output_kind = "ssbump",
                     .options = o,
                     .channel = BB_CHANNEL_AUTO,
                     .rayset_id = "fib256"};
  return p;
}

/* The value of key in a provenance text, copied into buf; NULL if absent. */
static const char *value_of(const char *text, const char *key, char *buf, size_t cap) {
  size_t klen = strlen(key);
  for (const char *line = text; line && *line;) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    if (n > klen && strncmp(line, key, klen) == 0 && line[klen] == '=') {
      snprintf(buf, cap, "%.*s", (int)(n - klen - 1), line + klen + 1);
      return buf;
    }
    line = end ? end + 1 : line + n;
  }
  return NULL;
}

Test(provenance, hash_is_fnv1a_of_little_endian_size_and_float_bits) {
  float px[2] = {0.5f, -2.0f};
  bb_image img = {.width = 2, .height = 1, .channels = 1, .pixels = px};
  /* 0.5f = 0x3f000000, -2.0f = 0xc0000000, little-endian. */
  const unsigned char bytes[] = {2, 0, 0, 0, 1, 0,    0, 0, 1, 0,
                                 0, 0, 0, 0, 0, 0x3f, 0, 0, 0, 0xc0};
  cr_assert_eq(bb_image_hash(&img), reference_fnv1a(bytes, sizeof bytes));
}

Test(provenance, hash_changes_with_a_pixel_or_the_shape) {
  float px[6] = {0, 0.25f, 0.5f, 0.75f, 1, 0};
  bb_image a = {.width = 3, .height = 2, .channels = 1, .pixels = px};
  uint64_t base = bb_image_hash(&a);
  bb_image b = a;
  b.width = 2;
  b.height = 3;
  cr_assert_neq(bb_image_hash(&b), base, "same floats, transposed shape");
  b = a;
  b.channels = 2;
  b.width = 1;
  b.height = 3;
  cr_assert_neq(bb_image_hash(&b), base, "same floats as 2 channels");
  px[4] = nextafterf(1.0f, 2.0f);
  cr_assert_neq(bb_image_hash(&a), base, "one ulp in one pixel");
  px[4] = 1.0f;
  cr_assert_eq(bb_image_hash(&a), base, "restored pixel gives the same hash");
}

Test(provenance, format_lists_every_key_in_order) {
  bb_bake_options o = sample_options();
  bb_provenance p = sample_provenance(&o);
  char *text = bb_provenance_format(&p);
  cr_assert_not_null(text);
  static const char *const keys[] = {"bumpbake_version",
                                     "command",
                                     "input",
                                     "input_hash",
                                     "output",
                                     "scale",
                                     "rays",
                                     "rayset",
                                     "filter_radius",
                                     "filter_threshold",
                                     "bias",
                                     "power",
                                     "basis",
                                     "normal_filter",
                                     "normal_y",
                                     "addressing",
                                     "channel"};
  const char *line = text;
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
    size_t n = strlen(keys[i]);
    cr_assert(strncmp(line, keys[i], n) == 0 && line[n] == '=',
              "line %zu should be %s=..., is: %.40s", i, keys[i], line);
    line = strchr(line, '\n');
    cr_assert_not_null(line);
    line++;
  }
  cr_assert_eq(*line, '\0', "no lines after channel");
  char buf[256];
  cr_assert_str_eq(value_of(text, "bumpbake_version", buf, sizeof buf),
                   BB_VERSION_STRING);
  cr_assert_str_eq(value_of(text, "input_hash", buf, sizeof buf), "0123456789abcdef");
  cr_assert_str_eq(value_of(text, "output", buf, sizeof buf), "ssbump");
  cr_assert_str_eq(value_of(text, "scale", buf, sizeof buf), "16");
  cr_assert_str_eq(value_of(text, "rays", buf, sizeof buf), "256");
  cr_assert_str_eq(value_of(text, "rayset", buf, sizeof buf), "fib256");
  cr_assert_str_eq(value_of(text, "bias", buf, sizeof buf), "0.55");
  cr_assert_str_eq(value_of(text, "normal_y", buf, sizeof buf), "down");
  cr_assert_str_eq(value_of(text, "addressing", buf, sizeof buf), "periodic");
  cr_assert_str_eq(value_of(text, "channel", buf, sizeof buf), "auto");
  cr_assert_str_eq(value_of(text, "basis", buf, sizeof buf), bb_basis_name(BB_BASIS_HL2));
  cr_assert_str_eq(value_of(text, "normal_filter", buf, sizeof buf),
                   bb_normal_filter_name(BB_NORMAL_VALVE));
  free(text);
}

Test(provenance, floats_round_trip_exactly) {
  bb_bake_options o = sample_options();
  o.height_scale = 1.0f / 3.0f;
  o.smooth.threshold = 2.0f / 255.0f;
  o.trace.bias_texels = 0.1 + 0.2; /* not the double nearest 0.3 */
  o.power = 2.5;
  bb_provenance p = sample_provenance(&o);
  char *text = bb_provenance_format(&p);
  cr_assert_not_null(text);
  char buf[256];
  cr_assert_eq(strtof(value_of(text, "scale", buf, sizeof buf), NULL), o.height_scale);
  cr_assert_eq(strtof(value_of(text, "filter_threshold", buf, sizeof buf), NULL),
               o.smooth.threshold);
  cr_assert_eq(strtod(value_of(text, "bias", buf, sizeof buf), NULL),
               o.trace.bias_texels);
  cr_assert_str_eq(value_of(text, "power", buf, sizeof buf), "2.5");
  free(text);
}

Test(provenance, format_names_modes_and_missing_fields) {
  bb_bake_options o = sample_options();
  o.normal_y_up = 1;
  o.smooth.addressing = BB_ADDRESS_CLAMP;
  bb_provenance p = sample_provenance(&o);
  p.command = "line one\nline two";
  p.input_name = NULL;
  p.rayset_id = NULL;
  p.channel = BB_CHANNEL_LUMA;
  char *text = bb_provenance_format(&p);
  cr_assert_not_null(text);
  char buf[256];
  cr_assert_str_eq(value_of(text, "normal_y", buf, sizeof buf), "up");
  cr_assert_str_eq(value_of(text, "addressing", buf, sizeof buf), "clamp");
  cr_assert_str_eq(value_of(text, "channel", buf, sizeof buf), "luma");
  cr_assert_str_eq(value_of(text, "rayset", buf, sizeof buf), "none");
  cr_assert_str_eq(value_of(text, "input", buf, sizeof buf), "");
  cr_assert_str_eq(value_of(text, "command", buf, sizeof buf), "line one line two",
                   "a newline in the command must not split the record");
  free(text);
}

Test(provenance, channel_line_parses_back_to_the_rule) {
  bb_bake_options o = sample_options();
  for (int c = BB_CHANNEL_AUTO; c <= BB_CHANNEL_MEAN; c++) {
    bb_provenance p = sample_provenance(&o);
    p.channel = (bb_channel)c;
    char *text = bb_provenance_format(&p);
    char buf[64];
    bb_channel parsed;
    cr_assert_eq(bb_channel_parse(value_of(text, "channel", buf, sizeof buf), &parsed), 0,
                 "channel=%s", buf);
    cr_assert_eq((int)parsed, c);
    free(text);
  }
}

Test(provenance, diff_of_identical_texts_is_empty) {
  bb_bake_options o = sample_options();
  bb_provenance p = sample_provenance(&o);
  char *a = bb_provenance_format(&p);
  char out[512] = "junk";
  cr_assert_eq(bb_provenance_diff(a, a, out, sizeof out), 0);
  cr_assert_str_eq(out, "");
  free(a);
}

Test(provenance, diff_names_changed_keys_and_ignores_command_and_output) {
  bb_bake_options oa = sample_options(), ob = sample_options();
  ob.height_scale = 32.0f;
  ob.basis = BB_BASIS_HL2_Z;
  bb_provenance pa = sample_provenance(&oa), pb = sample_provenance(&ob);
  pb.command = "bumpbake bake /tmp/x/in.png --scale 32";
  pb.output_kind = "normal";
  char *a = bb_provenance_format(&pa);
  char *b = bb_provenance_format(&pb);
  char out[1024];
  int n = bb_provenance_diff(a, b, out, sizeof out);
  cr_assert_eq(n, 2, "scale and basis differ; got:\n%s", out);
  cr_assert_not_null(strstr(out, "scale: 16 -> 32\n"), "got:\n%s", out);
  char expect[128];
  snprintf(expect, sizeof expect, "basis: %s -> %s\n", bb_basis_name(BB_BASIS_HL2),
           bb_basis_name(BB_BASIS_HL2_Z));
  cr_assert_not_null(strstr(out, expect), "got:\n%s", out);
  cr_assert_null(strstr(out, "command"));
  cr_assert_null(strstr(out, "output"));
  free(a);
  free(b);
}

Test(provenance, diff_reports_keys_missing_on_either_side) {
  const char *a = "bumpbake_version=0.1.0\nscale=16\nold_key=1\n";
  const char *b = "bumpbake_version=0.1.0\nscale=16\nnew_key=2";
  char out[256];
  cr_assert_eq(bb_provenance_diff(a, b, out, sizeof out), 2);
  cr_assert_str_eq(out, "old_key: 1 -> (none)\nnew_key: (none) -> 2\n");
}

Test(provenance, diff_with_null_text_or_tiny_buffer) {
  char out[8] = "junk";
  cr_assert_eq(bb_provenance_diff(NULL, "a=1\n", out, sizeof out), 0);
  cr_assert_str_eq(out, "");
  /* The count is right even when the lines do not fit; out stays terminated. */
  cr_assert_eq(bb_provenance_diff("a=1\nb=2\n", "a=3\nb=4\n", out, sizeof out), 2);
  cr_assert_eq(strlen(out), sizeof out - 1);
  cr_assert_eq(bb_provenance_diff("a=1\n", "a=2\n", NULL, 0), 1);
}
