/* fuzz_mesh.c: model bytes -> bb__mesh_load -> bb__renderbump_flat at 16 x 16,
 * the path of `bumpbake renderbumpflat`. The first byte picks the format
 * by extension (OBJ, glTF JSON, Collada XML, binary glTF) in its low two
 * bits and the render's axis and tiling above; the rest is the file,
 * alone in the scratch directory under its format's name.
 *
 * bb__mesh_load imports in a child process, which libFuzzer does not see;
 * so when the child answered quickly the import is run again here
 * (bb__mesh_import, the same code on a stack of the same size), where
 * coverage, AddressSanitizer and LeakSanitizer see Assimp and the confined
 * I/O. Inputs that crash or stall the child are the bounded failures
 * bb__mesh_load exists for and are not run again.
 *
 * Properties: the caller never crashes, leaks or hangs; a failure is one
 * line naming the model; a mesh is within the limits, its indices in
 * range and its positions finite; the import here gives the child's
 * answer, bit for bit; a render is finite, with coverage in [0, 1]. */
#include "bumpbake.h"
#include "fuzz_common.h"
#include "mesh/mesh_import.h"
#include "mesh/mesh_internal.h"

#include <math.h>
#include <pthread.h>
#include <time.h>

static const char *const NAMES[] = {"m.obj", "m.gltf", "m.dae", "m.glb"};

/* Seconds the child may take here (bb__mesh_load allows minutes); slower
 * inputs end as "took more than" errors instead of slow units. */
enum { CHILD_CPU_SECONDS = 10, CHILD_WALL_SECONDS = 20 };
/* The import is run again in this process only after a child this quick. */
static const double RERUN_SECONDS = 1.0;

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void check_mesh(const bb_mesh *m) {
  FUZZ_CHECK(m->positions && m->indices);
  FUZZ_CHECK(m->vertex_count >= 1 && m->vertex_count <= 3 * (size_t)BB_MAX_MODEL_TRIANGLES);
  FUZZ_CHECK(m->triangle_count >= 1 && m->triangle_count <= (size_t)BB_MAX_MODEL_TRIANGLES);
  for (size_t i = 0; i < 3 * m->triangle_count; i++)
    FUZZ_CHECK(m->indices[i] < m->vertex_count);
  for (size_t i = 0; i < 3 * m->vertex_count; i++)
    FUZZ_CHECK(isfinite(m->positions[i]));
}

static void check_error(const char *path, const bb_error *err) {
  FUZZ_CHECK(strncmp(err->message, path, strlen(path)) == 0);
  FUZZ_CHECK(strchr(err->message, '\n') == NULL);
}

typedef struct here {
  const char *path;
  bb_mesh mesh;
  char note[512];
  bb_error err;
  bb_status status;
} here;

static void *import_here(void *user) {
  here *h = user;
  h->status = bb__mesh_import(h->path, &h->mesh, h->note, sizeof h->note, &h->err);
  return NULL;
}

/* The import in this process, on a thread with the child's stack size. */
static void compare_with_here(const char *path, bb_status st, const bb_mesh *m,
                              const char *note, const bb_error *err) {
  static here h;
  memset(&h, 0, sizeof h);
  h.path = path;
  pthread_attr_t attr;
  pthread_t thread;
  FUZZ_CHECK(pthread_attr_init(&attr) == 0);
  FUZZ_CHECK(pthread_attr_setstacksize(&attr, (size_t)BB__IMPORT_STACK_BYTES) == 0);
  FUZZ_CHECK(pthread_create(&thread, &attr, import_here, &h) == 0);
  pthread_join(thread, NULL);
  pthread_attr_destroy(&attr);
  FUZZ_CHECK(h.status == st);
  if (st == BB_OK) {
    FUZZ_CHECK(bb__mesh_hash(&h.mesh) == bb__mesh_hash(m));
    FUZZ_CHECK(strcmp(h.note, note) == 0);
  } else if (st != BB_ERR_MEMORY) { /* the child's names its memory limit */
    FUZZ_CHECK(strcmp(h.err.message, err->message) == 0);
  }
  bb__mesh_free(&h.mesh);
}

static void render(const bb_mesh *m, uint8_t choice) {
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = 16;
  o.samples = 2;
  o.threads = 1;
  o.axis = (bb_axis)((choice >> 2) % 6);
  if (choice & 0x80) { /* a window onto the tiled model */
    o.tile = 1;
    o.rect_given = 1;
    const double rect[4] = {-0.25, -0.5, 0.75, 0.5};
    memcpy(o.rect, rect, sizeof rect);
  }
  bb_renderbump_result r;
  bb_error err;
  bb_status st = bb__renderbump_flat(m, &o, &r, &err);
  FUZZ_CHECK((st == BB_OK) == (r.normal.pixels != NULL));
  if (st != BB_OK) {
    FUZZ_CHECK(err.message[0] != '\0' && strchr(err.message, '\n') == NULL);
    return;
  }
  for (int i = 0; i < 16 * 16; i++) {
    const float *n = r.normal.pixels + 4 * i;
    FUZZ_CHECK(isfinite(n[0]) && isfinite(n[1]) && isfinite(n[2]));
    FUZZ_CHECK(n[3] >= 0.0f && n[3] <= 1.0f);
    FUZZ_CHECK(r.height.pixels[i] >= 0.0f && r.height.pixels[i] <= 1.0f);
  }
  bb_renderbump_result_free(&r);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1)
    return 0;
  const char *dir = fuzz_scratch_dir();
  for (int k = 0; k < 4; k++) { /* the model is alone with whatever it names */
    char other[128];
    snprintf(other, sizeof other, "%s/%s", dir, NAMES[k]);
    unlink(other);
  }
  char path[128];
  snprintf(path, sizeof path, "%s", fuzz_write_file(NAMES[data[0] & 3], data + 1, size - 1));

  bb__import_limits lim;
  bb__import_limits_default(&lim);
  lim.cpu_seconds = CHILD_CPU_SECONDS;
  lim.wall_seconds = CHILD_WALL_SECONDS;
  bb_mesh m;
  char note[512];
  bb_error err;
  int clean = 0;
  double t0 = now_seconds();
  bb_status st = bb__mesh_load_isolated(path, &lim, &m, note, sizeof note, &clean, &err);
  double took = now_seconds() - t0;
  FUZZ_CHECK((st == BB_OK) == (m.positions != NULL));
  if (st == BB_OK) {
    check_mesh(&m);
    FUZZ_CHECK(strchr(note, '\n') == NULL);
  } else {
    check_error(path, &err);
  }
  if (clean && took < RERUN_SECONDS)
    compare_with_here(path, st, &m, note, &err);
  if (st == BB_OK)
    render(&m, data[0]);
  bb__mesh_free(&m);
  return 0;
}
