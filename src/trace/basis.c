/* basis.c: the directions occlusion is projected on: Half-Life 2's, N of them
 * evenly spread in azimuth ("dirs:N"), or a caller's vectors (from an array
 * or a text file). A basis is a plain value; everything downstream (the
 * integration tables, derive, the writers) reads its count and vectors.
 */

#include "trace/basis.h"
#include "core/input_file.h"
#include "core/internal.h"
#include "files/provenance.h"
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Largest basis file bb__basis_load reads: 16 lines of vectors and room for
 * generous comments, and a bound on what a wrong path can make it read. */
#define BASIS_FILE_MAX_BYTES (64 * 1024)

/* docs/conventions.md "Bases", +Y down; index 3 is hl2+z's (0, 0, 1).
 * cos(elevation) = sqrt(2/3) and sin(elevation) = 1/sqrt(3) are written the
 * same way in dirs_vector, so shared directions have the same bits. */
void bb__basis_vector(int index, double v[3]) {
  if (index < 0 || index > 3) {
    v[0] = v[1] = v[2] = 0.0;
    return;
  }
  const double side = sqrt(2.0 / 3.0), back = 1.0 / sqrt(6.0), across = 1.0 / sqrt(2.0),
               up = 1.0 / sqrt(3.0);
  const double hl2[4][3] = {
      {side, 0.0, up},      /* B0: light from the right */
      {-back, across, up},  /* B1: from the bottom-left */
      {-back, -across, up}, /* B2: from the top-left */
      {0.0, 0.0, 1.0},      /* B3: light from straight above */
  };
  for (int k = 0; k < 3; k++) v[k] = hl2[index][k];
}

static void set_hl2(bb_basis *b, int count, const char *name) {
  memset(b, 0, sizeof *b);
  b->count = count;
  for (int c = 0; c < count; c++) bb__basis_vector(c, b->vector[c]);
  snprintf(b->name, sizeof b->name, "%s", name);
}

void bb__basis_init(bb_basis *b) {
  set_hl2(b, 3, "hl2");
}

static bb_status check_count(int count, bb_error *err) {
  if (count >= 3 && count <= BB_MAX_BASIS) return BB_OK;
  return bb__fail(err, BB_ERR_ARGUMENT, "basis: %d directions; a basis has 3..%d", count,
                  BB_MAX_BASIS);
}

/* cos and sin of the angle 2 pi c / n (0 <= c < n): exact at quarter turns,
 * and mirror images (c and n - c) get the same x and opposite y bit for
 * bit, because each is computed from the angle's distance to the nearest
 * axis. */
static void circle_point(int c, int n, double *x, double *y) {
  const int quarter = 4 * c / n, rest = 4 * c - quarter * n; /* in quarter turns / n */
  double near_axis, far_axis; /* cos and sin of the angle past the quarter turn */
  if (2 * rest < n) {
    const double a = (BB__PI / 2.0) * rest / n;
    near_axis = cos(a), far_axis = sin(a);
  } else if (2 * rest > n) {
    const double a = (BB__PI / 2.0) * (n - rest) / n;
    near_axis = sin(a), far_axis = cos(a);
  } else {
    near_axis = far_axis = sqrt(0.5);
  }
  /* Rotated by whole quarter turns; 0.0 - v keeps a zero positive. */
  switch (quarter) {
  case 0: *x = near_axis, *y = far_axis; break;
  case 1: *x = 0.0 - far_axis, *y = near_axis; break;
  case 2: *x = 0.0 - near_axis, *y = 0.0 - far_axis; break;
  default: *x = far_axis, *y = 0.0 - near_axis; break;
  }
}

static void dirs_vector(int c, int n, double v[3]) {
  if ((3 * c) % n == 0) { /* one of Half-Life 2's three: its own bits */
    bb__basis_vector(3 * c / n, v);
    return;
  }
  const double side = sqrt(2.0 / 3.0), up = 1.0 / sqrt(3.0);
  double x, y;
  circle_point(c, n, &x, &y);
  v[0] = side * x;
  v[1] = side * y;
  v[2] = up;
}

bb_status bb__basis_dirs(int count, bb_basis *out, bb_error *err) {
  bb_status st = check_count(count, err);
  if (st != BB_OK) return st;
  memset(out, 0, sizeof *out);
  out->count = count;
  for (int c = 0; c < count; c++) dirs_vector(c, count, out->vector[c]);
  snprintf(out->name, sizeof out->name, "dirs:%d", count);
  return BB_OK;
}

bb_status bb__basis_parse(const char *name, bb_basis *out, bb_error *err) {
  if (name && strcmp(name, "hl2") == 0) {
    bb__basis_init(out);
    return BB_OK;
  }
  if (name && strcmp(name, "hl2+z") == 0) {
    set_hl2(out, 4, "hl2+z");
    return BB_OK;
  }
  if (name && strncmp(name, "dirs:", 5) == 0) {
    const char *digits = name + 5;
    char *end = NULL;
    errno = 0;
    const long n = strtol(digits, &end, 10);
    if (*digits >= '0' && *digits <= '9' && !*end && errno == 0 && n >= 3 &&
        n <= BB_MAX_BASIS)
      return bb__basis_dirs((int)n, out, err);
    return bb__fail(err, BB_ERR_ARGUMENT, "basis: dirs:N needs a count N in 3..%d (got '%s')",
                    BB_MAX_BASIS, name);
  }
  return bb__fail(err, BB_ERR_ARGUMENT, "basis: '%s' is not hl2, hl2+z or dirs:N",
                  name ? name : "(null)");
}

/* v scaled to unit length into out, or NULL; else why not. Signed zeros
 * become +0, so equal directions hash alike. */
static const char *unit_vector(const double v[3], double out[3]) {
  if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])) return "a component is not finite";
  /* Scaled by the largest component first, so 1e200 or 1e-200 do not overflow. */
  double largest = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
  if (!(largest > 0.0)) return "the zero vector has no direction";
  double u[3] = {v[0] / largest, v[1] / largest, v[2] / largest};
  const double length = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (int k = 0; k < 3; k++) u[k] = u[k] / length + 0.0;
  if (u[2] < 0.0) return "points below the surface (z < 0)";
  memcpy(out, u, sizeof u);
  return NULL;
}

/* FNV-1a over the count and the bits of the unit vectors. */
static uint64_t vectors_hash(const double (*v)[3], int count) {
  uint64_t h = bb__fnv1a_u32(BB__FNV64_OFFSET, (uint32_t)count);
  for (int c = 0; c < count; c++)
    for (int k = 0; k < 3; k++) {
      uint64_t bits;
      memcpy(&bits, &v[c][k], sizeof bits);
      h = bb__fnv1a_u32(h, (uint32_t)bits);
      h = bb__fnv1a_u32(h, (uint32_t)(bits >> 32));
    }
  return h;
}

/* The caller has checked the count and made every vector unit. */
static void set_vectors(bb_basis *out, const double (*unit)[3], int count) {
  memset(out, 0, sizeof *out);
  out->count = count;
  memcpy(out->vector, unit, (size_t)count * sizeof unit[0]);
  snprintf(out->name, sizeof out->name, "vectors:%016" PRIx64, vectors_hash(unit, count));
}

bb_status bb_basis_from_vectors(const double (*vectors)[3], int count, bb_basis *out,
                                bb_error *err) {
  bb_status st = check_count(count, err);
  if (st != BB_OK) return st;
  if (!vectors) return bb__fail(err, BB_ERR_ARGUMENT, "basis: no vectors");
  double unit[BB_MAX_BASIS][3];
  for (int c = 0; c < count; c++) {
    const char *why = unit_vector(vectors[c], unit[c]);
    if (why) return bb__fail(err, BB_ERR_ARGUMENT, "basis: vector %d: %s", c, why);
  }
  set_vectors(out, (const double(*)[3])unit, count);
  return BB_OK;
}

/* ------------------------------------------------------------ basis files */

/* The numbers of one line (comment already cut), separated by blanks or
 * commas, into v (at most 3 are stored). Returns how many there are, or -1
 * with the offending word in bad (capacity cap) when one is not a number. */
static int line_numbers(char *line, double v[3], char *bad, size_t cap) {
  int n = 0;
  for (char *s = line;;) {
    while (*s == ' ' || *s == '\t' || *s == ',' || *s == '\r' || *s == '\v' || *s == '\f') s++;
    if (!*s) return n;
    char *end = NULL;
    const double x = strtod(s, &end);
    const int separated = end && end > s && (!*end || strchr(" \t,\r\v\f", *end));
    if (!separated) {
      size_t len = strcspn(s, " \t,\r\v\f");
      snprintf(bad, cap, "%.*s", (int)(len < 40 ? len : 40), s);
      return -1;
    }
    if (n < 3) v[n] = x;
    n++;
    s = end;
  }
}

bb_status bb__basis_read_text(const char *text, const char *source, bb_basis *out,
                             bb_error *err) {
  if (!text) return bb__fail(err, BB_ERR_ARGUMENT, "basis: no text");
  if (!source) source = "basis";
  if ((unsigned char)text[0] == 0xEF && (unsigned char)text[1] == 0xBB &&
      (unsigned char)text[2] == 0xBF)
    text += 3; /* a UTF-8 byte order mark, as some editors write */
  char *line = malloc(strlen(text) + 1);
  if (!line) return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", source);
  double unit[BB_MAX_BASIS][3];
  int count = 0, line_number = 0;
  bb_status st = BB_OK;
  for (const char *s = text; *s && st == BB_OK;) {
    line_number++;
    const size_t len = strcspn(s, "\n");
    memcpy(line, s, len);
    line[len] = '\0';
    s += len + (s[len] == '\n');
    line[strcspn(line, "#")] = '\0';
    double v[3];
    char bad[48];
    const int n = line_numbers(line, v, bad, sizeof bad);
    const char *why = NULL;
    if (n == 0) continue;
    if (n < 0)
      st = bb__fail(err, BB_ERR_FORMAT, "%s:%d: '%s' is not a number (want x y z)", source,
                    line_number, bad);
    else if (n != 3)
      st = bb__fail(err, BB_ERR_FORMAT, "%s:%d: %d numbers; a direction is 3 (x y z)", source,
                    line_number, n);
    else if (count == BB_MAX_BASIS)
      st = bb__fail(err, BB_ERR_ARGUMENT, "%s:%d: more than %d directions", source,
                    line_number, BB_MAX_BASIS);
    else if ((why = unit_vector(v, unit[count])) != NULL)
      st = bb__fail(err, BB_ERR_ARGUMENT, "%s:%d: %s", source, line_number, why);
    else
      count++;
  }
  free(line);
  if (st != BB_OK) return st;
  if (count < 3)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: %d direction%s; a basis has 3..%d", source,
                    count, count == 1 ? "" : "s", BB_MAX_BASIS);
  set_vectors(out, (const double(*)[3])unit, count);
  return BB_OK;
}

bb_status bb__basis_load(const char *path, bb_basis *out, bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "basis: no path");
  /* A FIFO, a device or a directory is refused before it is read. */
  int fd;
  bb_status opened = bb__input_open(path, &fd, err);
  if (opened != BB_OK) return opened;
  FILE *f = fdopen(fd, "rb");
  if (!f) {
    int e = errno;
    close(fd);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(e));
  }
  char *text = malloc(BASIS_FILE_MAX_BYTES + 1);
  if (!text) {
    fclose(f);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  /* One byte more than allowed tells an over-long file from one that fits. */
  const size_t n = fread(text, 1, BASIS_FILE_MAX_BYTES + 1, f);
  const int failed = ferror(f);
  fclose(f);
  bb_status st = BB_OK;
  if (failed)
    st = bb__fail(err, BB_ERR_IO, "%s: cannot read", path);
  else if (n > BASIS_FILE_MAX_BYTES)
    st = bb__fail(err, BB_ERR_SIZE, "%s: over %d KiB; a basis file is a few lines of x y z",
                  path, BASIS_FILE_MAX_BYTES / 1024);
  else if (memchr(text, '\0', n))
    st = bb__fail(err, BB_ERR_FORMAT, "%s: not a text file (it holds a NUL byte)", path);
  if (st == BB_OK) {
    text[n] = '\0';
    st = bb__basis_read_text(text, path, out, err);
  }
  free(text);
  return st;
}

bb_status bb__basis_check(const bb_basis *b, const char *who, bb_error *err) {
  if (!b) return bb__fail(err, BB_ERR_ARGUMENT, "%s: no basis", who);
  if (b->count < 3 || b->count > BB_MAX_BASIS)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: a basis of %d directions (3..%d)", who, b->count,
                    BB_MAX_BASIS);
  for (int c = 0; c < b->count; c++) {
    const double *v = b->vector[c];
    const double length2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (!(fabs(length2 - 1.0) <= 1e-12) || !(v[2] >= 0.0))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: basis vector %d is not a unit vector with z >= 0 "
                      "(bb_basis_from_vectors makes one)",
                      who, c);
  }
  return BB_OK;
}

bb_status bb__check_hl2_map(const bb_image *img, const bb_basis *basis, const char *what,
                            bb_error *err) {
  if (basis && !bb__basis_is_hl2(basis))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s was baked with --basis %s; this reads Half-Life 2's basis "
                    "(bake with --basis hl2)",
                    what, basis->name);
  if (img && img->channels > 4)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s has %d channels, one per direction of a basis other than Half-Life "
                    "2's; this reads Half-Life 2's 3 (bake with --basis hl2)",
                    what, img->channels);
  return BB_OK;
}

int bb__basis_is_hl2(const bb_basis *b) {
  if (!b || b->count < 3 || b->count > 4) return 0;
  for (int c = 0; c < 3; c++) {
    double v[3];
    bb__basis_vector(c, v);
    if (memcmp(v, b->vector[c], sizeof v) != 0) return 0;
  }
  return 1;
}

bb_status bb_basis_resolve(const char *spec, bb_basis *out, int *from_file, bb_error *err) {
  if (from_file)
    *from_file = 0;
  if (!spec || !out)
    return bb__fail(err, BB_ERR_ARGUMENT, "basis: no basis named");
  if (!strcmp(spec, "hl2") || !strcmp(spec, "hl2+z") || !strncmp(spec, "dirs:", 5)) {
    if (bb__basis_parse(spec, out, NULL) == BB_OK)
      return BB_OK;
    return bb__fail(err, BB_ERR_ARGUMENT, "basis dirs:N needs a whole N in 3..%d (got '%s')",
                    BB_MAX_BASIS, spec);
  }
  struct stat st;
  if (stat(spec, &st) != 0)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "basis must be hl2, hl2+z, dirs:N (N in 3..%d) or a file of directions "
                    "(got '%s': %s)",
                    BB_MAX_BASIS, spec, strerror(errno));
  if (from_file)
    *from_file = 1;
  return bb__basis_load(spec, out, err);
}

bb_status bb__basis_map_check(const bb_image *img, const char *description, bb_error *err) {
  char name[64];
  bb_basis basis;
  if (bb__provenance_value(description, "basis", name, sizeof name) && name[0] &&
      (bb__basis_parse(name, &basis, NULL) != BB_OK || !bb__basis_is_hl2(&basis)))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "baked with --basis %s; this reads Half-Life 2's basis (bake with --basis "
                    "hl2)",
                    name);
  if (img && img->channels > 4)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%d channels, one per direction of a basis other than Half-Life 2's; this "
                    "reads Half-Life 2's 3 (bake with --basis hl2)",
                    img->channels);
  return BB_OK;
}
