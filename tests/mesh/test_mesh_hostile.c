/* test_mesh_hostile.c: models as an attacker writes them: files
 * named outside the model's directory, FIFOs, devices, nesting that
 * overflows Assimp's stack, instancing and overdraw that multiply the
 * work, through bb__mesh_load (test_mesh_cli.c runs the CLI on them). */
#define _GNU_SOURCE /* wait4 (cli_harness.h), mkfifo, symlink, realpath */

#include "bumpbake.h"
#include "cli_harness.h"
#include "mesh/mesh_import.h"
#include "mesh/mesh_internal.h"

#include <criterion/criterion.h>

#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

TestSuite(mesh_hostile, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

/* ------------------------------------------------------------- making */

static void write_text(const char *path, const char *text) {
  write_bytes(path, text, strlen(text));
}

static const char triangle_obj[] = "v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n";

/* An OBJ of the one triangle above, its first line `mtllib NAME`. */
static void write_obj_naming(const char *path, const char *mtl) {
  char text[PATH_MAX + 64];
  snprintf(text, sizeof text, "mtllib %s\n%s", mtl, triangle_obj);
  write_text(path, text);
}

static char *base64(const void *data, size_t n) {
  static const char digits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const unsigned char *p = data;
  char *out = malloc(4 * ((n + 2) / 3) + 1), *o = out;
  cr_assert_not_null(out);
  for (size_t i = 0; i < n; i += 3) {
    unsigned v = (unsigned)p[i] << 16 | (i + 1 < n ? (unsigned)p[i + 1] << 8 : 0) |
                 (i + 2 < n ? p[i + 2] : 0);
    *o++ = digits[v >> 18 & 63];
    *o++ = digits[v >> 12 & 63];
    *o++ = i + 1 < n ? digits[v >> 6 & 63] : '=';
    *o++ = i + 2 < n ? digits[v & 63] : '=';
  }
  *o = '\0';
  return out;
}

/* `triangles` triangles side by side in the XZ plane, unindexed: 9 floats
 * each. */
static float *strip_positions(int triangles, size_t *bytes) {
  *bytes = (size_t)triangles * 9 * sizeof(float);
  float *p = malloc(*bytes);
  cr_assert_not_null(p);
  for (int t = 0; t < triangles; t++) {
    float x = (float)t / (float)triangles, w = 1.0f / (float)triangles;
    const float v[9] = {x, 0, 0, x + w, 0, 0, x + w, 0, 1};
    memcpy(p + 9 * t, v, sizeof v);
  }
  return p;
}

/* Appends printf-style text at *len of text (cap bytes). */
static void append(char *text, size_t *len, size_t cap, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(text + *len, cap - *len, fmt, ap);
  va_end(ap);
  cr_assert(n >= 0 && (size_t)n < cap - *len, "glTF text over %zu bytes", cap);
  *len += (size_t)n;
}

/* A glTF of one mesh of `triangles` triangles whose buffer is `uri`
 * (NULL: the positions as a data: URI), placed by `instances` nodes. */
static char *gltf_text(const char *uri, int triangles, int instances) {
  size_t bytes;
  float *pos = strip_positions(triangles, &bytes);
  char *data = NULL;
  if (!uri) {
    char *b64 = base64(pos, bytes);
    data = malloc(strlen(b64) + 64);
    cr_assert_not_null(data);
    sprintf(data, "data:application/octet-stream;base64,%s", b64);
    free(b64);
  }
  free(pos);
  const char *buffer = data ? data : uri;
  size_t cap = strlen(buffer) + 32 * (size_t)instances + 2048;
  char *text = malloc(cap);
  if (!text)
    abort(); /* out of memory */
  size_t len = 0;
  append(text, &len, cap, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":"
                          "[{\"nodes\":[0]}],\"nodes\":[{\"children\":[");
  for (int i = 1; i <= instances; i++)
    append(text, &len, cap, "%s%d", i > 1 ? "," : "", i);
  append(text, &len, cap, "]}");
  for (int i = 1; i <= instances; i++)
    append(text, &len, cap, ",{\"mesh\":0}");
  append(text, &len, cap,
         "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
         "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
         "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu}],"
         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,"
         "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,0,1]}]}",
         buffer, bytes, bytes, 3 * triangles);
  free(data);
  return text;
}

static void write_gltf(const char *path, const char *uri, int triangles, int instances) {
  char *text = gltf_text(uri, triangles, instances);
  write_text(path, text);
  free(text);
}

static bb_status load(const char *path, bb_mesh *m, char *note, bb_error *err) {
  bb_status st = bb__mesh_load_noted(path, m, note, 512, err);
  cr_expect(st == BB_OK || (m->positions == NULL && note[0] == '\0'),
            "a failed load leaves the mesh and the note empty");
  cr_expect(strchr(err->message, '\n') == NULL, "one line: %s", err->message);
  return st;
}

/* Expects bb__mesh_load to refuse path with status and a message holding
 * part (and naming the model). */
static void expect_refused(const char *path, bb_status status, const char *part) {
  bb_mesh m;
  bb_error err = {{0}};
  char note[512];
  bb_status st = load(path, &m, note, &err);
  cr_expect_eq(st, status, "%s: status %d (%s), expected %d", path, st, err.message, status);
  cr_expect(strstr(err.message, part) && strstr(err.message, path),
            "%s: '%s' lacks '%s'", path, err.message, part);
  if (st == BB_OK)
    bb__mesh_free(&m);
}

/* ------------------------------------------------- 1. files it may read */

/* A glTF run from its directory whose buffer is /etc/passwd: read, the
 * file's bytes would become vertex coordinates. (With a directory in the
 * model's name, Assimp looks for "DIR//etc/passwd": inside, missing, an
 * error of its own.) */
Test(mesh_hostile, a_gltf_buffer_outside_the_directory_is_refused) {
  cr_assert_eq(chdir(harness_dir), 0);
  write_gltf("passwd.gltf", "/etc/passwd", 1, 1);
  expect_refused("passwd.gltf", BB_ERR_IO, "refers to /etc/passwd, outside the model's "
                                           "directory");
  bb_mesh m;
  bb_error err = {{0}};
  char note[512];
  cr_expect_neq(load(tmp("passwd.gltf"), &m, note, &err), BB_OK);
  /* also as ../ from a directory of its own, and through a link out */
  cr_assert_eq(mkdir("sub", 0755), 0);
  write_bytes("outside.bin", "0123456789abcdef0123456789abcdef0123", 36);
  write_gltf("sub/up.gltf", "../outside.bin", 1, 1);
  expect_refused("sub/up.gltf", BB_ERR_IO, "refers to ../outside.bin, outside the model's");
  cr_assert_eq(symlink(tmp("outside.bin"), "sub/link.bin"), 0);
  write_gltf("sub/link.gltf", "link.bin", 1, 1);
  expect_refused("sub/link.gltf", BB_ERR_IO, "refers to link.bin, outside the model's");
}

/* The same triangle from an embedded data: URI, from a .bin beside the
 * model (by a relative and by an absolute name) and from a .bin reached
 * through a link that stays inside: all load, to the same mesh. */
Test(mesh_hostile, buffers_inside_the_directory_and_data_uris_load) {
  size_t bytes;
  float *pos = strip_positions(1, &bytes);
  write_bytes(tmp("tri.bin"), pos, bytes);
  free(pos);
  cr_assert_eq(mkdir(tmp("parts"), 0755), 0);
  cr_assert_eq(symlink("../tri.bin", tmp("parts/inside.bin")), 0);
  char absolute[PATH_MAX];
  cr_assert_not_null(realpath(tmp("tri.bin"), absolute));
  write_gltf(tmp("embedded.gltf"), NULL, 1, 1);
  write_gltf(tmp("beside.gltf"), "tri.bin", 1, 1);
  write_gltf(tmp("absolute.gltf"), absolute, 1, 1);
  write_gltf(tmp("linked.gltf"), "parts/inside.bin", 1, 1);
  const char *names[] = {"embedded.gltf", "beside.gltf", "absolute.gltf", "linked.gltf"};
  uint64_t first = 0;
  for (int i = 0; i < 4; i++) {
    bb_mesh m;
    bb_error err = {{0}};
    char note[512];
    cr_assert_eq(load(tmp(names[i]), &m, note, &err), BB_OK, "%s: %s", names[i], err.message);
    cr_expect_eq(m.triangle_count, 1, "%s", names[i]);
    cr_expect_str_empty(note, "%s: %s", names[i], note);
    if (i == 0)
      first = bb__mesh_hash(&m);
    cr_expect_eq(bb__mesh_hash(&m), first, "%s differs from the embedded one", names[i]);
    bb__mesh_free(&m);
  }
}

/* mtllib naming /etc/passwd, ../../../../etc/shadow and a link out: each
 * must be refused, not read. Run from the models' directory, as a user
 * runs them: Assimp puts an OBJ's own directory, when its name has one, in
 * front of the .mtl's name. */
Test(mesh_hostile, an_obj_mtllib_outside_the_directory_is_refused) {
  cr_assert_eq(chdir(harness_dir), 0);
  cr_assert_eq(mkdir("a", 0755), 0);
  cr_assert_eq(mkdir("a/b", 0755), 0);
  write_text("secret.mtl", "newmtl secret\n");
  cr_assert_eq(symlink(tmp("secret.mtl"), "a/b/link.mtl"), 0);
  const char *cases[][3] = {
      {"passwd.obj", "/etc/passwd", "refers to /etc/passwd, outside the model's directory"},
      {"a/b/shadow.obj", "../../../../etc/shadow",
       "refers to ../../../../etc/shadow, outside the model's directory"},
      {"a/b/up.obj", "../../secret.mtl", "refers to ../../secret.mtl, outside"},
      {"a/b/link.obj", "link.mtl", "refers to link.mtl, outside the model's directory"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    write_obj_naming(cases[i][0], cases[i][1]);
    expect_refused(cases[i][0], BB_ERR_IO, cases[i][2]);
  }
  /* From a/b/, Assimp looks for "/etc/passwd" as a/b//etc/passwd: inside,
   * missing, read without. */
  write_obj_naming("a/b/passwd.obj", "/etc/passwd");
  bb_mesh m;
  bb_error err = {{0}};
  char note[512];
  cr_assert_eq(load("a/b/passwd.obj", &m, note, &err), BB_OK, "%s", err.message);
  cr_expect(strstr(note, "read without /etc/passwd"), "%s", note);
  bb__mesh_free(&m);
}

/* A .mtl that is a directory (LeakSanitizer: Assimp lost the stream it
 * opened on it), a FIFO (would block in open) or /dev/zero (would never
 * end): each is an error naming it; a missing one is a note. */
Test(mesh_hostile, a_side_file_that_is_not_a_regular_file_fails_and_a_missing_one_is_a_note) {
  cr_assert_eq(mkdir(tmp("sub"), 0755), 0);
  cr_assert_eq(mkfifo(tmp("fifo.mtl"), 0644), 0);
  cr_assert_eq(symlink("/dev/zero", tmp("zero.mtl")), 0);
  write_obj_naming(tmp("dir.obj"), "sub");
  expect_refused(tmp("dir.obj"), BB_ERR_IO, "refers to sub, which is a directory");
  write_obj_naming(tmp("fifo.obj"), "fifo.mtl");
  expect_refused(tmp("fifo.obj"), BB_ERR_IO, "refers to fifo.mtl, which is a FIFO");
  write_obj_naming(tmp("zero.obj"), "zero.mtl");
  expect_refused(tmp("zero.obj"), BB_ERR_IO, "outside the model's directory"); /* /dev */

  write_obj_naming(tmp("missing.obj"), "gone.mtl");
  bb_mesh m;
  bb_error err = {{0}};
  char note[512];
  cr_assert_eq(load(tmp("missing.obj"), &m, note, &err), BB_OK, "%s", err.message);
  cr_expect_eq(m.triangle_count, 1);
  cr_expect(strstr(note, "read without gone.mtl") && strstr(note, "no such file"), "%s", note);
  bb__mesh_free(&m);
  /* a glTF cannot do without its buffer */
  write_gltf(tmp("nobin.gltf"), "nothere.bin", 1, 1);
  cr_assert_neq(load(tmp("nobin.gltf"), &m, note, &err), BB_OK);
}

/* The model itself as a FIFO or a device: refused at once, not opened
 * for blocking reads. */
Test(mesh_hostile, a_model_that_is_a_fifo_or_a_device_is_refused_without_blocking,
     .timeout = 300) {
  cr_assert_eq(mkfifo(tmp("fifo.obj"), 0644), 0);
  cr_assert_eq(symlink("/dev/zero", tmp("zero.obj")), 0);
  expect_refused(tmp("fifo.obj"), BB_ERR_IO, "is a FIFO, not a regular file");
  expect_refused(tmp("zero.obj"), BB_ERR_IO, "is a device, not a regular file");
}

/* ------------------------------------------------------ 2. crashes */

/* 20,000 nodes each the child of the one before, and JSON brackets five
 * million deep: Assimp overflowed the stack (SIGSEGV, the test process
 * gone). Now the first fits the importer's stack (and holds no mesh) and
 * the second crashes only the importer's process. */
Test(mesh_hostile, nesting_that_overflows_assimp_fails_with_one_line) {
  FILE *f = fopen(tmp("chain.gltf"), "w");
  cr_assert_not_null(f);
  fprintf(f, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[");
  for (int i = 0; i < 20000; i++)
    fprintf(f, "{\"children\":[%d]},", i + 1);
  fprintf(f, "{}]}");
  cr_assert_eq(fclose(f), 0);
  expect_refused(tmp("chain.gltf"), BB_ERR_FORMAT, "no triangles");

  const size_t depth = 5000000;
  char *deep = malloc(2 * depth + 64);
  cr_assert_not_null(deep);
  size_t n = (size_t)sprintf(deep, "{\"asset\":{\"version\":\"2.0\"},\"x\":");
  memset(deep + n, '[', depth);
  memset(deep + n + depth, ']', depth);
  n += 2 * depth;
  deep[n++] = '}';
  write_bytes(tmp("deep.gltf"), deep, n);
  free(deep);
  expect_refused(tmp("deep.gltf"), BB_ERR_FORMAT, "the importer crashed");
}

/* The importer's stack is its own, not the caller's: a chain of nodes over
 * a triangle loads on the default stack and crashes only the child on a
 * tiny one. */
Test(mesh_hostile, the_import_runs_on_a_stack_of_its_own) {
  FILE *f = fopen(tmp("tall.gltf"), "w");
  cr_assert_not_null(f);
  char *one = gltf_text(NULL, 1, 1);
  /* the one-triangle glTF with its node 1 moved to the end of a chain */
  char *nodes = strstr(one, "\"nodes\":[{");
  char *meshes = strstr(one, "],\"meshes\"");
  cr_assert(nodes && meshes);
  fwrite(one, 1, (size_t)(nodes - one), f);
  enum { LEVELS = 3000 };
  fprintf(f, "\"nodes\":[");
  for (int i = 0; i < LEVELS; i++)
    fprintf(f, "{\"children\":[%d]},", i + 1);
  fprintf(f, "{\"mesh\":0}%s", meshes);
  cr_assert_eq(fclose(f), 0);
  free(one);

  bb__import_limits lim;
  bb__import_limits_default(&lim);
  bb_mesh m;
  bb_error err = {{0}};
  int clean = 0;
  cr_assert_eq(bb__mesh_load_isolated(tmp("tall.gltf"), &lim, &m, NULL, 0, &clean, &err), BB_OK,
               "%s", err.message);
  cr_expect_eq(m.triangle_count, 1);
  cr_expect(clean);
  bb__mesh_free(&m);
  lim.stack_bytes = 64 << 10;
  cr_assert_eq(bb__mesh_load_isolated(tmp("tall.gltf"), &lim, &m, NULL, 0, &clean, &err),
               BB_ERR_FORMAT);
  cr_expect(strstr(err.message, "the importer crashed"), "%s", err.message);
  cr_expect(!clean);
  cr_expect_null(m.positions);
}

/* What comes back through the pipe is what the import made in-process:
 * the same counts, normals and bits. */
Test(mesh_hostile, the_isolated_load_returns_the_in_process_mesh) {
  bb_mesh m, here;
  bb_error err = {{0}};
  const char *fixtures = getenv("BB_FIXTURES");
  char path[PATH_MAX];
  snprintf(path, sizeof path, "%s/rivet_panel.obj", fixtures ? fixtures : "fixtures");
  cr_assert_eq(bb__mesh_load(path, &m, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__mesh_import(path, &here, NULL, 0, &err), BB_OK, "%s", err.message);
  cr_expect_eq(m.vertex_count, here.vertex_count);
  cr_expect_eq(m.triangle_count, here.triangle_count);
  cr_expect(m.normals && here.normals);
  cr_expect_eq(bb__mesh_hash(&m), bb__mesh_hash(&here));
  bb__mesh_free(&m);
  bb__mesh_free(&here);
}

/* --------------------------------------------------------- 3. limits */

/* 10,000 instances of a 1,000-triangle mesh: 10 M triangles from 200 KB,
 * refused on the importer's scene, before PreTransformVertices copies
 * them (which took minutes and gigabytes). */
Test(mesh_hostile, instancing_past_the_triangle_limit_is_refused_before_it_is_built) {
  write_gltf(tmp("many.gltf"), NULL, 1000, 10000);
  expect_refused(tmp("many.gltf"), BB_ERR_SIZE, "over the 8388608 triangles");
  /* under the limit, instances are placed */
  write_gltf(tmp("few.gltf"), NULL, 1000, 3);
  bb_mesh m;
  bb_error err = {{0}};
  char note[512];
  cr_assert_eq(load(tmp("few.gltf"), &m, note, &err), BB_OK, "%s", err.message);
  cr_expect_eq(m.triangle_count, 3000);
  bb__mesh_free(&m);
}

/* A model over BB_MAX_MODEL_BYTES (a sparse file: no disk used) is refused
 * before anything reads it. */
Test(mesh_hostile, a_model_over_the_byte_limit_is_refused_unread) {
  int fd = open(tmp("huge.obj"), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  cr_assert(fd >= 0);
  cr_assert_eq(ftruncate(fd, BB_MAX_MODEL_BYTES + 1), 0);
  cr_assert_eq(close(fd), 0);
  expect_refused(tmp("huge.obj"), BB_ERR_SIZE, "over the 256 MiB a model may have");
}

/* The import's memory is capped in the child (release builds: ASan
 * reserves terabytes of address space, so it has no cap). */
Test(mesh_hostile, the_importer_memory_is_capped) {
#ifdef __SANITIZE_ADDRESS__
  cr_skip_test("no address-space cap under AddressSanitizer");
#endif
  FILE *f = fopen(tmp("grid.obj"), "w");
  cr_assert_not_null(f);
  enum { N = 600 };
  for (int k = 0; k <= N; k++)
    for (int i = 0; i <= N; i++)
      fprintf(f, "v %d 0 %d\n", i, k);
  for (int k = 0; k < N; k++)
    for (int i = 0; i < N; i++) {
      int a = k * (N + 1) + i + 1;
      fprintf(f, "f %d %d %d %d\n", a, a + 1, a + N + 2, a + N + 1);
    }
  cr_assert_eq(fclose(f), 0);
  bb__import_limits lim;
  bb__import_limits_default(&lim);
  bb_mesh m;
  bb_error err = {{0}};
  cr_assert_eq(bb__mesh_load_isolated(tmp("grid.obj"), &lim, &m, NULL, 0, NULL, &err), BB_OK,
               "%s", err.message);
  cr_expect_eq(m.triangle_count, 2 * N * N);
  bb__mesh_free(&m);
  lim.memory_bytes = 64 << 20; /* the thread's stack and little more */
  bb_status st = bb__mesh_load_isolated(tmp("grid.obj"), &lim, &m, NULL, 0, NULL, &err);
  cr_expect_eq(st, BB_ERR_MEMORY, "%d: %s", st, err.message);
  cr_expect(strstr(err.message, "out of memory") || strstr(err.message, "killed"), "%s",
            err.message);
}

/* Loads from several threads at once: each child may hold, for a moment,
 * the pipes of the others' children; every load still gets its own mesh. */
typedef struct loader {
  const char *path;
  uint64_t hash[6];
  bb_status status[6];
} loader;

static void *load_six(void *user) {
  loader *l = user;
  for (int i = 0; i < 6; i++) {
    bb_mesh m;
    bb_error err;
    l->status[i] = bb__mesh_load(l->path, &m, &err);
    l->hash[i] = l->status[i] == BB_OK ? bb__mesh_hash(&m) : 0;
    if (l->status[i] == BB_OK)
      bb__mesh_free(&m);
  }
  return NULL;
}

Test(mesh_hostile, loads_on_several_threads_at_once_each_get_their_mesh) {
  const char *fixtures = getenv("BB_FIXTURES");
  char path[PATH_MAX];
  snprintf(path, sizeof path, "%s/rivet_panel.obj", fixtures ? fixtures : "fixtures");
  bb_mesh m;
  bb_error err = {{0}};
  cr_assert_eq(bb__mesh_import(path, &m, NULL, 0, &err), BB_OK, "%s", err.message);
  uint64_t expected = bb__mesh_hash(&m);
  bb__mesh_free(&m);
  enum { THREADS = 4 };
  pthread_t threads[THREADS];
  loader loaders[THREADS];
  for (int t = 0; t < THREADS; t++) {
    loaders[t].path = path;
    cr_assert_eq(pthread_create(&threads[t], NULL, load_six, &loaders[t]), 0);
  }
  for (int t = 0; t < THREADS; t++) {
    pthread_join(threads[t], NULL);
    for (int i = 0; i < 6; i++) {
      cr_expect_eq(loaders[t].status[i], BB_OK, "thread %d, load %d", t, i);
      cr_expect_eq(loaders[t].hash[i], expected, "thread %d, load %d", t, i);
    }
  }
}
