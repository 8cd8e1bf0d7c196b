/* test_basis.c: bases (named, dirs:N, a caller's vectors, basis files) and
 * what every stage that reads one makes of it: the lobes' totals, the
 * trace's channels, derive and the whole bake. */
#include "maps/maps_internal.h"
#include "trace/rayset.h"
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bumpbake.h"
#include "bake_harness.h"
#include "bake/bake_internal.h"
#include "render/render_internal.h"
#include "trace/basis.h"
#include "trace/pyramid.h"
#include "trace/trace.h"

static const double PI = 3.14159265358979323846;

static bb_basis named(const char *name) {
  bb_basis b;
  bb_error err;
  cr_assert_eq(bb__basis_parse(name, &b, &err), BB_OK, "%s: %s", name, err.message);
  return b;
}

static int same_bits(const double a[3], const double b[3]) {
  return memcmp(a, b, 3 * sizeof(double)) == 0;
}

/* ------------------------------------------------------------ the bases */

Test(basis, names_parse_and_anything_else_is_refused) {
  bb_basis b;
  bb__basis_init(&b);
  cr_assert_eq(b.count, 3);
  cr_assert_str_eq(b.name, "hl2");
  b = named("hl2+z");
  cr_assert_eq(b.count, 4);
  cr_assert_str_eq(b.name, "hl2+z");
  cr_assert(b.vector[3][0] == 0.0 && b.vector[3][1] == 0.0 && b.vector[3][2] == 1.0);
  for (int n = 3; n <= BB_MAX_BASIS; n++) {
    char name[32]; /* room for any int, so -Wformat-truncation stays quiet */
    snprintf(name, sizeof name, "dirs:%d", n);
    b = named(name);
    cr_assert_eq(b.count, n);
    cr_assert_str_eq(b.name, name);
  }
  const char *bad[] = {"hl3", "HL2", "hl2 ", "", "dirs:", "dirs:2", "dirs:17", "dirs:6x",
                       "dirs:-6", "dirs: 6", "dirs:+6", "dirs:99999999999999999999"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    bb_basis kept = named("dirs:5");
    bb_error err;
    cr_assert_eq(bb__basis_parse(bad[i], &kept, &err), BB_ERR_ARGUMENT, "'%s'", bad[i]);
    cr_expect(strstr(err.message, "dirs:N"), "'%s': %s", bad[i], err.message);
    cr_expect_str_eq(kept.name, "dirs:5", "a failed parse must not write");
  }
  cr_assert_eq(bb__basis_parse(NULL, &b, NULL), BB_ERR_ARGUMENT);
}

/* dirs:N as the header defines it: Half-Life 2's elevation, azimuth
 * 360 c / N from +x towards +y; Half-Life 2's own directions with their
 * own bits; quarter turns exact; mirror images mirrored bit for bit. */
Test(basis, dirs_spreads_directions_evenly_at_hl2s_elevation) {
  const double side = sqrt(2.0 / 3.0), up = 1.0 / sqrt(3.0);
  for (int n = 3; n <= BB_MAX_BASIS; n++) {
    char name[32];
    snprintf(name, sizeof name, "dirs:%d", n);
    const bb_basis b = named(name);
    for (int c = 0; c < n; c++) {
      const double *v = b.vector[c];
      cr_assert_float_eq(v[0] * v[0] + v[1] * v[1] + v[2] * v[2], 1.0, 1e-15, "%s B%d", name, c);
      cr_assert_eq(v[2], up, "%s B%d: elevation asin(1/sqrt(3))", name, c);
      const double azimuth = atan2(v[1], v[0]);
      cr_assert_float_eq(remainder(azimuth - 2 * PI * c / n, 2 * PI), 0.0, 1e-15, "%s B%d", name,
                         c);
      if (c > 0) {
        const double *mirror = b.vector[n - c];
        cr_assert(v[0] == mirror[0] && v[1] == -mirror[1], "%s: B%d and B%d mirror", name, c,
                  n - c);
      }
      if ((3 * c) % n == 0) {
        double hl2[3];
        bb__basis_vector(3 * c / n, hl2);
        cr_assert(same_bits(v, hl2), "%s B%d is Half-Life 2's B%d", name, c, 3 * c / n);
      }
      if ((4 * c) % n == 0) { /* a quarter turn: exactly on an axis */
        const double expect[4][2] = {{side, 0}, {0, side}, {-side, 0}, {0, -side}};
        cr_assert(v[0] == expect[4 * c / n][0] && v[1] == expect[4 * c / n][1],
                  "%s B%d: (%.17g, %.17g)", name, c, v[0], v[1]);
        cr_assert(!(v[0] == 0.0 && signbit(v[0])) && !(v[1] == 0.0 && signbit(v[1])),
                  "%s B%d: no negative zero", name, c);
      }
    }
  }
  /* dirs:3 is hl2; dirs:6 holds it at 0, 2, 4 between three more. */
  const bb_basis hl2 = named("hl2"), d3 = named("dirs:3"), d6 = named("dirs:6");
  cr_assert(memcmp(hl2.vector, d3.vector, sizeof hl2.vector) == 0);
  for (int c = 0; c < 3; c++) cr_assert(same_bits(d6.vector[2 * c], hl2.vector[c]));
  cr_assert(bb__basis_is_hl2(&d3) && bb__basis_is_hl2(&hl2) && !bb__basis_is_hl2(&d6));
  cr_assert(bb__basis_is_hl2((bb_basis[]){named("hl2+z")}));
  cr_assert(!bb__basis_is_hl2(NULL));
}

Test(basis, dirs_refuses_counts_outside_3_to_16) {
  bb_basis b;
  bb_error err;
  cr_assert_eq(bb__basis_dirs(2, &b, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__basis_dirs(BB_MAX_BASIS + 1, &b, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "3..16"), "%s", err.message);
}

Test(basis, vectors_are_made_unit_and_named_by_their_hash) {
  const double v[4][3] = {{3, 0, 4}, {0, -1e200, 1e200}, {1e-300, 0, 0}, {0, 0, 2}};
  bb_basis b;
  bb_error err;
  cr_assert_eq(bb_basis_from_vectors(v, 4, &b, &err), BB_OK, "%s", err.message);
  cr_assert_eq(b.count, 4);
  cr_assert_eq(b.vector[0][0], 0.6);
  cr_assert_eq(b.vector[0][2], 0.8);
  cr_assert_float_eq(b.vector[1][1], -sqrt(0.5), 2.3e-16);
  cr_assert_float_eq(b.vector[1][2], sqrt(0.5), 2.3e-16);
  cr_assert(b.vector[2][0] == 1.0 && b.vector[2][2] == 0.0, "horizontal is allowed");
  cr_assert(b.vector[3][2] == 1.0);
  cr_assert_eq(strncmp(b.name, "vectors:", 8), 0, "%s", b.name);
  cr_assert_eq(strlen(b.name), 8 + 16, "%s", b.name);
  for (int c = 4; c < BB_MAX_BASIS; c++)
    cr_assert(b.vector[c][0] == 0 && b.vector[c][1] == 0 && b.vector[c][2] == 0);
  /* The same directions at other lengths give the same basis and name;
   * another direction another name. */
  const double scaled[4][3] = {{6, 0, 8}, {0, -1, 1}, {5, 0, 0}, {0, 0, 0.5}};
  bb_basis same, other;
  cr_assert_eq(bb_basis_from_vectors(scaled, 4, &same, NULL), BB_OK);
  cr_assert_str_eq(same.name, b.name);
  cr_assert(memcmp(same.vector, b.vector, sizeof b.vector) == 0);
  const double moved[4][3] = {{6, 0, 8}, {0, -1, 1}, {5, 0, 0.001}, {0, 0, 0.5}};
  cr_assert_eq(bb_basis_from_vectors(moved, 4, &other, NULL), BB_OK);
  cr_assert_str_neq(other.name, b.name);

  const struct {
    double v[3];
    const char *why;
  } bad[] = {{{0, 0, 0}, "zero vector"},
             {{NAN, 0, 1}, "not finite"},
             {{0, INFINITY, 1}, "not finite"},
             {{1, 0, -0.01}, "below the surface"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    double three[3][3] = {{0, 0, 1}, {1, 0, 1}, {0, 0, 0}};
    memcpy(three[2], bad[i].v, sizeof three[2]);
    bb_basis kept = named("hl2");
    cr_assert_eq(bb_basis_from_vectors((const double(*)[3])three, 3, &kept, &err),
                 BB_ERR_ARGUMENT, "case %zu", i);
    cr_expect(strstr(err.message, "vector 2") && strstr(err.message, bad[i].why), "case %zu: %s",
              i, err.message);
    cr_expect_str_eq(kept.name, "hl2");
  }
  double many[BB_MAX_BASIS + 1][3];
  for (int c = 0; c <= BB_MAX_BASIS; c++) many[c][0] = 0, many[c][1] = 0, many[c][2] = 1;
  cr_assert_eq(bb_basis_from_vectors((const double(*)[3])many, BB_MAX_BASIS + 1, &b, NULL),
               BB_ERR_ARGUMENT);
  cr_assert_eq(bb_basis_from_vectors((const double(*)[3])many, 2, &b, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb_basis_from_vectors((const double(*)[3])many, BB_MAX_BASIS, &b, NULL), BB_OK);
}

/* ------------------------------------------------------------ basis files */

Test(basis, text_has_one_direction_per_line_and_comments) {
  const char *text = "\xEF\xBB\xBF# three lights, and one overhead\n"
                     "\n"
                     "  1 0 1   # right\r\n"
                     "-1,0,1\n"
                     "\t0 1e0 1.0\n"
                     "0 0 3"; /* no final newline */
  bb_basis b;
  bb_error err;
  cr_assert_eq(bb__basis_read_text(text, "four.txt", &b, &err), BB_OK, "%s", err.message);
  cr_assert_eq(b.count, 4);
  cr_assert_float_eq(b.vector[0][0], sqrt(0.5), 2.3e-16);
  cr_assert_float_eq(b.vector[1][0], -sqrt(0.5), 2.3e-16);
  cr_assert_float_eq(b.vector[2][1], sqrt(0.5), 2.3e-16);
  cr_assert(b.vector[3][2] == 1.0);
  const double v[4][3] = {{1, 0, 1}, {-1, 0, 1}, {0, 1, 1}, {0, 0, 3}};
  bb_basis from_array;
  cr_assert_eq(bb_basis_from_vectors(v, 4, &from_array, NULL), BB_OK);
  cr_assert_str_eq(b.name, from_array.name, "a file's basis is its vectors");
}

/* Each refusal is one line naming the source and, for a line's fault, the
 * line number. */
Test(basis, text_errors_name_the_file_and_line) {
  const struct {
    const char *text, *message;
    bb_status status;
  } cases[] = {
      {"0 0 1\n1 0 1\n0 1\n", "f.txt:3: 2 numbers; a direction is 3 (x y z)", BB_ERR_FORMAT},
      {"0 0 1\n1 0 1 5\n", "f.txt:2: 4 numbers; a direction is 3 (x y z)", BB_ERR_FORMAT},
      {"# x\n0 0 1\n1 0 abc\n", "f.txt:3: 'abc' is not a number (want x y z)", BB_ERR_FORMAT},
      {"0 0 1\n1 0 1x\n", "f.txt:2: '1x' is not a number (want x y z)", BB_ERR_FORMAT},
      {"0 0 1\n\n1 0 1\n0 0 0\n", "f.txt:4: the zero vector has no direction", BB_ERR_ARGUMENT},
      {"0 0 1\n1 0 -1\n", "f.txt:2: points below the surface (z < 0)", BB_ERR_ARGUMENT},
      {"0 0 1\nnan 0 1\n", "f.txt:2: a component is not finite", BB_ERR_ARGUMENT},
      {"0 0 1\n1 0 1e999\n", "f.txt:2: a component is not finite", BB_ERR_ARGUMENT},
      {"0 0 1\n1 0 1\n", "f.txt: 2 directions; a basis has 3..16", BB_ERR_ARGUMENT},
      {"# nothing\n\n", "f.txt: 0 directions; a basis has 3..16", BB_ERR_ARGUMENT},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    bb_basis b = named("hl2");
    bb_error err;
    cr_expect_eq(bb__basis_read_text(cases[i].text, "f.txt", &b, &err), cases[i].status,
                 "case %zu", i);
    cr_expect_str_eq(err.message, cases[i].message, "case %zu", i);
    cr_expect_str_eq(b.name, "hl2", "case %zu wrote its output", i);
  }
  char many[1024] = "";
  for (int c = 0; c < 17; c++) strcat(many, "0 0.5 1\n");
  bb_basis b;
  bb_error err;
  cr_assert_eq(bb__basis_read_text(many, "many.txt", &b, &err), BB_ERR_ARGUMENT);
  cr_assert_str_eq(err.message, "many.txt:17: more than 16 directions");
}

static void write_file(const char *path, const void *bytes, size_t n) {
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  cr_assert_eq(fwrite(bytes, 1, n, f), n);
  cr_assert_eq(fclose(f), 0);
}

Test(basis, files_load_and_bad_files_are_refused) {
  char dir[] = "/tmp/bb_basis_XXXXXX";
  cr_assert_not_null(mkdtemp(dir));
  char path[256];
  snprintf(path, sizeof path, "%s/five.txt", dir);
  const char good[] = "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n0 0 1\n";
  write_file(path, good, sizeof good - 1);
  bb_basis b;
  bb_error err;
  cr_assert_eq(bb__basis_load(path, &b, &err), BB_OK, "%s", err.message);
  cr_assert_eq(b.count, 5);

  cr_assert_eq(bb__basis_load(dir, &b, &err), BB_ERR_IO, "a directory");
  char missing[300];
  snprintf(missing, sizeof missing, "%s/missing.txt", dir);
  cr_assert_eq(bb__basis_load(missing, &b, &err), BB_ERR_IO);
  cr_assert(strstr(err.message, missing) && strstr(err.message, "no such file"), "%s",
            err.message);

  const char nul[] = "0 0 1\n1 0 1\0\n0 1 1\n";
  write_file(path, nul, sizeof nul - 1);
  cr_assert_eq(bb__basis_load(path, &b, &err), BB_ERR_FORMAT);
  cr_assert(strstr(err.message, "NUL"), "%s", err.message);

  char *big = malloc(64 * 1024 + 1);
  cr_assert_not_null(big);
  memset(big, '#', 64 * 1024 + 1);
  write_file(path, big, 64 * 1024 + 1);
  cr_assert_eq(bb__basis_load(path, &b, &err), BB_ERR_SIZE);
  big[0] = '\n'; /* exactly 64 KiB of comment after the three lines still loads */
  char text[64 * 1024 + 32];
  snprintf(text, sizeof text, "0 0 1\n1 0 1\n0 1 1\n%.*s", 64 * 1024 - 18, big);
  write_file(path, text, strlen(text));
  cr_assert_eq(strlen(text), 64 * 1024);
  cr_assert_eq(bb__basis_load(path, &b, &err), BB_OK, "%s", err.message);
  free(big);

  const char short_line[] = "0 0 1\n1 0\n";
  write_file(path, short_line, sizeof short_line - 1);
  cr_assert_eq(bb__basis_load(path, &b, &err), BB_ERR_FORMAT);
  char expect[300];
  snprintf(expect, sizeof expect, "%s:2: 2 numbers; a direction is 3 (x y z)", path);
  cr_assert_str_eq(err.message, expect);
  remove(path);
  rmdir(dir);
}

/* ------------------------------------------- through the stages of a bake */

/* P = 1: a lobe max(0, w.B) over the upper hemisphere holds
 * pi (1 + B.z) / 2 (a uniform sky on a plane tilted by acos(B.z)), whatever
 * the slices. */
Test(basis, each_lobes_total_is_its_closed_form) {
  const double v[5][3] = {{1, 0, 0}, {0.3, -0.2, 0.9}, {0, 0, 1}, {-1, 1, 0.2}, {0.1, 0.7, 0.05}};
  bb_basis bases[3] = {named("dirs:6"), named("dirs:16")};
  cr_assert_eq(bb_basis_from_vectors(v, 5, &bases[2], NULL), BB_OK);
  const int slices[] = {1, 7, 16, 32};
  for (int k = 0; k < 3; k++)
    for (size_t i = 0; i < sizeof slices / sizeof slices[0]; i++) {
      bb_rayset rs;
      bb_error err;
      cr_assert_eq(bb__rayset_make(slices[i], 1.0, &bases[k], 0, &rs, &err), BB_OK, "%s",
                   err.message);
      cr_assert_eq(rs.basis_count, bases[k].count);
      cr_assert(strstr(rs.id, bases[k].name), "%s", rs.id);
      for (int c = 0; c < rs.basis_count; c++) {
        const double exact = PI * (1.0 + bases[k].vector[c][2]) / 2.0;
        cr_assert_float_eq(rs.total[1 + c], exact, 1e-9, "%s, %d slices, lobe %d: %.12f vs %.12f",
                           bases[k].name, slices[i], c, rs.total[1 + c], exact);
      }
      bb__rayset_release(&rs);
    }
}

static bb_bake_options options(const bb_basis *basis, float scale, int slices) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = scale;
  o.slices = slices;
  o.basis = *basis;
  return o;
}

/* Flat and open: every vis_c exactly 1, s_c = max(0, B_c.z), the weights
 * Valve's formula over N, the bent normal straight up. */
Test(basis, a_flat_field_gives_vis_1_and_the_lobes_height) {
  const double v[4][3] = {{1, 0, 0}, {0.3, -0.2, 0.9}, {-1, 1, 0.2}, {0, 0, 1}};
  bb_basis bases[3] = {named("dirs:6"), named("dirs:16")};
  cr_assert_eq(bb_basis_from_vectors(v, 4, &bases[2], NULL), BB_OK);
  bb_image h = harness_field(9, 7, 0.25f);
  for (int k = 0; k < 3; k++) {
    const bb_basis *b = &bases[k];
    bb_bake_options o = options(b, 16.0f, 8);
    bb_bake_result r = harness_bake(&h, &o);
    cr_assert_str_eq(r.basis.name, b->name);
    cr_assert_eq(r.vis.channels, 1 + b->count);
    cr_assert_eq(r.ssbump.channels, b->count);
    cr_assert_eq(r.weights.channels, b->count);
    cr_assert_eq(r.bent.channels, 3);
    double squares = 0;
    for (int c = 0; c < b->count; c++) squares += b->vector[c][2] * b->vector[c][2];
    for (int i = 0; i < 9 * 7; i++) {
      for (int c = 0; c <= b->count; c++)
        cr_assert_eq(r.vis.pixels[i * (1 + b->count) + c], 1.0f, "%s channel %d", b->name, c);
      for (int c = 0; c < b->count; c++) {
        const double z = b->vector[c][2];
        cr_assert_eq(r.ssbump.pixels[i * b->count + c], (float)z, "%s s_%d", b->name, c);
        cr_assert_float_eq(r.weights.pixels[i * b->count + c], z * z / squares, 1e-7, "%s w_%d",
                           b->name, c);
      }
      if (k < 2) /* evenly spread: the sideways parts cancel */
        cr_assert_float_eq(r.bent.pixels[3 * i + 2], 1.0, 1e-7, "%s bent", b->name);
    }
    bb_bake_result_free(&r);
  }
  bb_image_free(&h);
}

/* With every direction of Half-Life 2's, dirs:3 is hl2 and dirs:6's even
 * channels are hl2's, bit for bit, through trace and derive. */
Test(basis, shared_directions_bake_to_the_same_bits) {
  bb_image h = harness_field(23, 17, 0.0f);
  unsigned seed = 7;
  for (int i = 0; i < 23 * 17; i++) {
    seed = seed * 1103515245u + 12345u;
    h.pixels[i] = (float)(seed >> 8) / 16777216.0f;
  }
  const bb_basis hl2 = named("hl2"), d3 = named("dirs:3"), d6 = named("dirs:6");
  bb_bake_options o = options(&hl2, 6.0f, 16);
  bb_bake_result a = harness_bake(&h, &o);
  o.basis = d3;
  bb_bake_result b = harness_bake(&h, &o);
  cr_assert(memcmp(a.vis.pixels, b.vis.pixels, 23 * 17 * 4 * sizeof(float)) == 0);
  cr_assert(memcmp(a.ssbump.pixels, b.ssbump.pixels, 23 * 17 * 3 * sizeof(float)) == 0);
  cr_assert(memcmp(a.weights.pixels, b.weights.pixels, 23 * 17 * 3 * sizeof(float)) == 0);
  cr_assert(memcmp(a.bent.pixels, b.bent.pixels, 23 * 17 * 3 * sizeof(float)) == 0);
  o.basis = d6;
  bb_bake_result c = harness_bake(&h, &o);
  for (int i = 0; i < 23 * 17; i++) {
    cr_assert_eq(c.vis.pixels[7 * i], a.vis.pixels[4 * i], "ao");
    for (int k = 0; k < 3; k++) {
      cr_assert_eq(c.vis.pixels[7 * i + 1 + 2 * k], a.vis.pixels[4 * i + 1 + k]);
      cr_assert_eq(c.ssbump.pixels[6 * i + 2 * k], a.ssbump.pixels[3 * i + k]);
    }
  }
  bb_bake_result_free(&a);
  bb_bake_result_free(&b);
  bb_bake_result_free(&c);
  bb_image_free(&h);
}

/* Any basis: the same bits on 1 and 3 threads, and a region traced by
 * marches equals the same texels of the whole trace by sweeps. */
Test(basis, more_directions_stay_deterministic_on_every_path) {
  bb_image h = harness_field(21, 18, 0.0f);
  for (int y = 0; y < 18; y++)
    for (int x = 0; x < 21; x++) h.pixels[y * 21 + x] = (float)(sin(x * 0.9) * cos(y * 1.3));
  const bb_basis d7 = named("dirs:7");
  bb_bake_options o = options(&d7, 3.0f, 12);
  o.trace.threads = 1;
  bb_bake_result one = harness_bake(&h, &o);
  o.trace.threads = 3;
  bb_bake_result three = harness_bake(&h, &o);
  const size_t n = 21 * 18 * 8;
  cr_assert(memcmp(one.vis.pixels, three.vis.pixels, n * sizeof(float)) == 0);

  bb_image z = harness_field(21, 18, 0.0f);
  for (int i = 0; i < 21 * 18; i++) z.pixels[i] = 3.0f * one.filtered.pixels[i];
  bb_pyramid *p;
  bb_rayset rs;
  cr_assert_eq(bb__pyramid_build_all_cores(&z, BB_ADDRESS_PERIODIC, &p, NULL), BB_OK);
  cr_assert_eq(bb__rayset_make(12, 1.0, &d7, 0, &rs, NULL), BB_OK);
  bb_trace_options t;
  bb__trace_options_init(&t);
  t.region = (bb_region){5, 4, 9, 7};
  bb_image region;
  cr_assert_eq(bb__trace_occlusion(p, &rs, &t, &region, NULL, NULL), BB_OK);
  for (int y = 0; y < 7; y++)
    for (int x = 0; x < 9; x++)
      cr_assert(memcmp(bb_image_texel(&region, x, y), bb_image_texel(&one.vis, 5 + x, 4 + y),
                       8 * sizeof(float)) == 0,
                "texel (%d, %d)", 5 + x, 4 + y);
  bb_image_free(&region);
  bb__rayset_release(&rs);
  bb_pyramid_free(p);
  bb_image_free(&z);
  bb_bake_result_free(&one);
  bb_bake_result_free(&three);
  bb_image_free(&h);
}

/* vis of lobe max(0, w.B) (P = 1) under a horizon of tangent t(phi), by a
 * midpoint rule over azimuths of the closed form in elevation. */
static double lobe_open(const double b[3], double phi, double t) {
  const double a = b[0] * cos(phi) + b[1] * sin(phi), c = b[2];
  const double start = fmax(atan(fmax(t, 0.0)), atan2(-a, c)), end = PI / 2;
  if (start >= end) return 0.0;
  return a * ((end - start) / 2 + (sin(2 * end) - sin(2 * start)) / 4) +
         c * (sin(end) * sin(end) - sin(start) * sin(start)) / 2;
}

/* A straight wall of height H at distance d on the side at azimuth
 * `side` (0: +x, pi/2: +y), running on for ever: t = H cos(phi - side) / d
 * where that is positive. */
static double wall_vis(const double b[3], double side, double height_over_distance) {
  double open = 0, all = 0;
  for (int i = 0; i < 7200; i++) {
    const double phi = 2 * PI * (i + 0.5) / 7200;
    open += lobe_open(b, phi, height_over_distance * cos(phi - side));
    all += lobe_open(b, phi, 0.0);
  }
  return open / all;
}

/* One wall in clamp mode, facing the texel from the right (x) or from below
 * (y, the +Y-down frame's +y): the channel facing the wall darkens most,
 * mirror channels alike, and the channel facing away (its lobe meets the
 * wall only above tan = sqrt(2), and H / d = 0.8) not at all, but for the
 * sliver a sector near the wall's side loses by taking its centre's
 * horizon for all of it (3e-5 here). Each vis_c within 0.0015 of the
 * integral at 32 slices. */
static void expect_one_wall(const char *basis_name, int wall_below, int facing, int away) {
  const int size = 48, wall = 30, texel = 20; /* H / d = 8 / 10 */
  bb_image h = harness_field(size, size, 0.0f);
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++)
      h.pixels[y * size + x] = (wall_below ? y : x) >= wall ? 1.0f : 0.0f;
  const bb_basis b = named(basis_name);
  bb_bake_options o = options(&b, 8.0f, 32);
  o.smooth.radius_texels = 0;
  o.smooth.addressing = BB_ADDRESS_CLAMP;
  o.trace.bias_texels = 0.0;
  bb_bake_result r = harness_bake(&h, &o);
  const float *vis = bb_image_texel(&r.vis, wall_below ? size / 2 : texel,
                                    wall_below ? texel : size / 2);
  const double side = wall_below ? PI / 2 : 0.0;
  double lowest = 2.0;
  for (int c = 0; c < b.count; c++) {
    const double exact = wall_vis(b.vector[c], side, 0.8), got = vis[1 + c];
    cr_log_info("%s: vis_%d %.5f, exact %.5f", basis_name, c, got, exact);
    cr_expect(fabs(got - exact) <= 0.0015, "%s vis_%d %.5f, exact %.5f", basis_name, c, got,
              exact);
    lowest = fmin(lowest, got);
  }
  cr_expect_eq(vis[1 + facing], lowest, "%s: channel %d faces the wall", basis_name, facing);
  cr_expect_geq(vis[1 + away], 1.0 - 1e-4, "%s: channel %d faces away", basis_name, away);
  for (int c = 1; c < b.count; c++) { /* mirror images about the wall's normal */
    const int mirror = (2 * facing - c + b.count) % b.count;
    cr_expect_float_eq(vis[1 + c], vis[1 + mirror], 2e-4, "%s: channels %d and %d", basis_name,
                       c, mirror);
  }
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

Test(basis, a_wall_on_one_side_darkens_the_channels_facing_it) {
  expect_one_wall("dirs:6", 0, 0, 3);
  expect_one_wall("dirs:4", 1, 1, 3); /* phi = 90: light from the bottom, +y */
  expect_one_wall("dirs:8", 1, 2, 6);
}

/* derive with an explicit basis; NULL keeps Half-Life 2's (and hl2+z's for
 * a fourth channel). */
Test(basis, derive_takes_the_basis_or_defaults_to_hl2) {
  bb_image n, vis, out = {0};
  cr_assert_eq(bb_image_alloc(&n, 2, 1, 3, NULL), BB_OK);
  n.pixels[0] = 0.0f, n.pixels[1] = 0.0f, n.pixels[2] = 1.0f;
  n.pixels[3] = 0.0f, n.pixels[4] = 0.0f, n.pixels[5] = -1.0f; /* faces away from all */
  const bb_basis d5 = named("dirs:5");
  bb_error err;
  cr_assert_eq(bb__derive_weights_all_cores(&n, &d5, &out, &err), BB_OK, "%s", err.message);
  cr_assert_eq(out.channels, 5);
  for (int c = 0; c < 5; c++) {
    cr_assert_float_eq(out.pixels[c], 0.2, 1e-7);
    cr_assert_float_eq(out.pixels[5 + c], 0.2, 1e-7, "no preferred direction: 1 / N");
  }
  bb_image_free(&out);
  cr_assert_eq(bb_image_alloc(&vis, 2, 1, 6, NULL), BB_OK);
  for (int i = 0; i < 12; i++) vis.pixels[i] = 0.5f;
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis, &d5, &out, &err), BB_OK, "%s", err.message);
  cr_assert_eq(out.channels, 5);
  cr_assert_float_eq(out.pixels[0], 0.5 / sqrt(3.0), 1e-7);
  bb_image ssbump = out, bent = {0};
  cr_assert_eq(bb__derive_bent_all_cores(&ssbump, &d5, &bent, &err), BB_OK, "%s", err.message);
  cr_assert_float_eq(bent.pixels[2], 1.0, 1e-7);
  bb_image_free(&bent);
  /* A count that does not match the basis, and NULL with 5 channels. */
  cr_assert_eq(bb__derive_bent_all_cores(&ssbump, NULL, &bent, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "3 (hl2) or 4 (hl2+z)"), "%s", err.message);
  const bb_basis d6 = named("dirs:6");
  cr_assert_eq(bb__derive_bent_all_cores(&ssbump, &d6, &bent, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "5 basis channels but the basis dirs:6 has 6"), "%s",
            err.message);
  cr_assert_eq(bb__derive_ssbump_all_cores(&n, &vis, &d6, &bent, &err), BB_ERR_ARGUMENT);
  bb_basis broken = d5;
  broken.vector[2][2] = 2.0;
  cr_assert_eq(bb__derive_weights_all_cores(&n, &broken, &bent, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "basis vector 2 is not a unit vector"), "%s", err.message);
  bb_image_free(&ssbump);
  bb_image_free(&vis);
  bb_image_free(&n);
}

/* A hand-filled basis is checked by the bake before anything runs. */
Test(basis, bake_refuses_a_broken_basis) {
  bb_image h = harness_field(4, 4, 0.0f);
  bb_basis b = named("dirs:4");
  b.count = 2;
  bb_bake_options o = options(&b, 1.0f, 4);
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "bake: a basis of 2 directions"), "%s", err.message);
  o.basis.count = 4;
  o.basis.vector[1][2] = -o.basis.vector[1][2];
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_ERR_ARGUMENT);
  bb_image_free(&h);
}

/* Readers of Half-Life 2's three channels refuse more. */
Test(basis, hl2_readers_refuse_maps_of_other_bases) {
  bb_image s6, n;
  cr_assert_eq(bb_image_alloc(&s6, 2, 2, 6, NULL), BB_OK);
  cr_assert_eq(bb__ssbump_to_normal(&s6, BB_MAP_SSBUMP, &n, NULL), BB_ERR_ARGUMENT);
  bb_render_options ro;
  bb__render_options_init(&ro);
  bb_render_maps maps = {NULL, &s6, NULL, NULL, NULL, NULL};
  bb_image out = {0};
  bb_error err;
  cr_assert_eq(bb__render(&maps, &ro, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "6 channels"), "%s", err.message);
  cr_assert_eq(bb__combine_detail(&s6, &s6, BB_MAP_SSBUMP, NULL, &out, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__combine_blend(&s6, &s6, NULL, 0.5f, BB_MAP_SSBUMP, &out, &err), BB_OK,
               "a blend is linear in every channel: %s", err.message);
  bb_image_free(&out);
  bb_image_free(&s6);

  /* A 3-direction basis that is not Half-Life 2's: caught by the result's basis. */
  bb_image h = harness_field(6, 6, 0.0f);
  const double v[3][3] = {{1, 0, 1}, {0, 1, 1}, {-1, -1, 1}};
  bb_basis mine;
  cr_assert_eq(bb_basis_from_vectors(v, 3, &mine, NULL), BB_OK);
  bb_bake_options o = options(&mine, 1.0f, 4);
  bb_bake_result r = harness_bake(&h, &o);
  bb_valve_options vo;
  bb__valve_options_init(&vo);
  cr_assert_eq(bb__valve_pack(&r, &vo, &out, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "--basis vectors:"), "%s", err.message);
  vo.normal_map = 1; /* the normal map is the same in any basis */
  cr_assert_eq(bb__valve_pack(&r, &vo, &out, &err), BB_OK, "%s", err.message);
  bb_image_free(&out);
  bb_bake_result_free(&r);
  bb_image_free(&h);
}
