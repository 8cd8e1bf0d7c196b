/* mesh_import.h: reading a model in two layers (internal to bumpbake): the
 * import itself through Assimp, confined to the model's directory
 * (mesh_assimp.cpp), and the child process it runs in so that a crash, a
 * runaway allocation or an endless loop inside Assimp cannot take the
 * caller down (mesh_load.c). */
#ifndef BB_MESH_IMPORT_H
#define BB_MESH_IMPORT_H

#include "bumpbake.h"
#include "mesh/mesh_internal.h" /* bb_mesh */

#ifdef __cplusplus
extern "C" {
#endif

/* Stack of the thread an isolated import runs on, whatever the caller's:
 * Assimp's readers recurse over nodes and nested brackets, and a model
 * deeper than this allows crashes the child, not the caller. */
#define BB__IMPORT_STACK_BYTES (32L << 20)

/* Checks the model file itself before anything else reads it: a regular
 * file (opened without blocking), not empty, at most BB_MAX_MODEL_BYTES.
 * *size gets its size. */
bb_status bb__mesh_check_model(const char *path, size_t *size, bb_error *err);

/* The whole import in this process and on this thread: Assimp reads path
 * through an I/O system that opens nothing outside the model's directory
 * and nothing but regular files, the triangle limits are applied, and the
 * scene becomes one bb_mesh (out, zeroed on failure). note (cap bytes, may
 * be NULL) gets "" or one line naming files that were missing. Nothing
 * bounds Assimp's stack, memory or time here: bb__mesh_load runs this in a
 * child process (bb__mesh_load_isolated); fuzzing and tests call it
 * directly to see Assimp's code. */
bb_status bb__mesh_import(const char *path, bb_mesh *out, char *note, size_t cap,
                          bb_error *err);

/* What the child process of an import may take. */
typedef struct bb__import_limits {
  long memory_bytes;   /* address space beyond the process's own at the fork;
                          0: no limit (always 0 in sanitizer builds, which
                          reserve terabytes of address space) */
  long stack_bytes;    /* stack of the thread the import runs on */
  int cpu_seconds;     /* CPU time, after which the child is killed */
  int wall_seconds;    /* wall-clock time, after which the child is killed */
  int stall_seconds;   /* time without using CPU or answering, after which a
                          child is taken for stuck, killed and made once more
                          (a lock another thread of the caller's held at the
                          fork stays held in the child); 0: never */
} bb__import_limits;

/* The limits bb__mesh_load uses: BB_MAX_IMPORT_MEMORY, BB__IMPORT_STACK_BYTES,
 * BB_MAX_IMPORT_SECONDS of CPU, four times that of wall-clock time, and
 * 10 s of standing still. */
void bb__import_limits_default(bb__import_limits *lim);

/* bb__mesh_import in a child process within lim, the mesh returned through
 * a pipe and checked again here (counts within the limits, indices in
 * range, finite positions) before it is accepted. *clean (may be NULL) is
 * 1 when the child ran to its end and answered, success or not; 0 when it
 * crashed, was killed or answered nothing valid. */
bb_status bb__mesh_load_isolated(const char *path, const bb__import_limits *lim, bb_mesh *out,
                                 char *note, size_t cap, int *clean, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_MESH_IMPORT_H */
