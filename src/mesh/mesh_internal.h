/* mesh_internal.h: what the mesh family shares with the families above it
 * (not public): the range of a render bump's samples, written once
 * (renderbump.c) and referred to by the option that sets it (cmd/). */
#ifndef BB_MESH_INTERNAL_H
#define BB_MESH_INTERNAL_H

#include "core/internal.h"

#ifdef __cplusplus
extern "C" {
#endif

extern const bb__range bb__range_renderbump_samples;

/* Once in bumpbake.h (issue 41): no public function takes them; the
 * mesh family and the commands above it do. */

/* A triangle mesh in model units. renderbumpflat reads one from a file: every
 * mesh of the file merged, node transforms applied, polygons triangulated,
 * points and lines dropped. */
typedef struct bb_mesh {
  size_t vertex_count;
  size_t triangle_count;
  float *positions;  /* 3 floats per vertex: x, y, z in model units */
  float *normals;    /* 3 floats per vertex, or NULL when the model has none;
                        a vertex whose normal is zero or not finite has none */
  uint32_t *indices; /* 3 per triangle, each < vertex_count */
} bb_mesh;

typedef struct bb_renderbump_options {
  int width, height;  /* output size in texels; default 256 x 256 (DOOM 3) */
  int samples;        /* samples per texel side, 1..16: samples^2 per texel on
                         a regular grid; default 4 (DOOM 3's 16x) */
  bb_axis axis;       /* the side the sculpt faces; default BB_AXIS_NEG_Y */
  int face_normals;   /* 1: every triangle's own plane normal, even when the
                         mesh has vertex normals; default 0 */
  int rect_given;     /* 1: rect below, 0: the mesh's bounding rectangle */
  double rect[4];     /* left, bottom, right, top: the rectangle mapped onto
                         the image, in model units along right and up */
  int tile;           /* 1: geometry outside the rectangle wraps around into
                         it (the sculpt tiles with the rectangle as period) */
  int threads;        /* 0..BB_MAX_THREADS, 0 = all cores; the result is the
                         same for any count */
  bb_note_fn note;    /* told when the texels come out not square, with the
                         size or rectangle that keeps them square (may be
                         NULL) */
  void *note_user;
} bb_renderbump_options;

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Allocates a zeroed mesh of the given counts (normals only when
 * with_normals). Rejects counts of 0 vertices or over BB_MAX_MESH_ELEMENTS
 * (BB_ERR_SIZE) and failed allocations (BB_ERR_MEMORY), leaving m zeroed. */
bb_status bb__mesh_alloc(bb_mesh *m, size_t vertices, size_t triangles,
                        int with_normals, bb_error *err);

/* Frees the arrays and zeroes the struct; safe on a zeroed struct. */
void bb__mesh_free(bb_mesh *m);

/* 64-bit FNV-1a hash of the counts, positions, normals and indices, for
 * provenance (the input_hash of outputs baked from a mesh). */
uint64_t bb__mesh_hash(const bb_mesh *m);

/* Reads a model through Assimp (OBJ, PLY, STL, glTF, FBX, Collada, 3DS, ...:
 * anything Assimp imports), merged as described at bb_mesh. Normals are kept
 * when any part of the model has them (vertices of parts without are zero).
 *
 * Model files are untrusted. A model may read only regular files inside its
 * own directory (after following links and ".."; a glTF's buffers, an OBJ's
 * .mtl; embedded data: URIs need no file): naming a file outside it, or a
 * FIFO, device, directory or unreadable file, fails the load. A file it
 * names that does not exist is done without when the format can be (an
 * OBJ's .mtl; a glTF's missing buffer fails), and bb__mesh_load_noted says
 * so. The import runs in a child process (fork) held to BB_MAX_MODEL_BYTES,
 * BB_MAX_MODEL_TRIANGLES, BB_MAX_IMPORT_MEMORY and BB_MAX_IMPORT_SECONDS,
 * on a stack of its own: a model that crashes Assimp (nodes nested 20,000
 * deep) fails the load, not the caller. The child never returns into the
 * caller's code (it ends with _exit) and takes no signal handler of the
 * caller's; a caller that reaps every child from a SIGCHLD handler only
 * loses the check of the child's exit status.
 *
 * Errors: BB_ERR_IO (missing, a directory, a FIFO or device, unreadable, or
 * a file the model names refused as above), BB_ERR_FORMAT (not a model
 * Assimp reads, corrupt, no triangles, the importer crashed), BB_ERR_VALUE
 * (a coordinate is NaN or infinite), BB_ERR_SIZE (over a limit above),
 * BB_ERR_MEMORY (over BB_MAX_IMPORT_MEMORY, or no memory here). */
bb_status bb__mesh_load(const char *path, bb_mesh *out, bb_error *err);

/* bb__mesh_load, also saying what the load did without: on success note (cap
 * bytes; NULL or cap 0 for none) holds "" or one line such as "read without
 * bricks.mtl (no such file)"; on failure "". */
bb_status bb__mesh_load_noted(const char *path, bb_mesh *out, char *note, size_t cap,
                             bb_error *err);

/* Writes m through Assimp's exporters; the format comes from the extension:
 * .obj (without a material file), .ply (binary little-endian), .stl
 * (binary), .glb. Normals are written when m has them. The file is written
 * to a temporary name in the destination directory and renamed into place.
 * Errors: BB_ERR_FORMAT (unknown extension), BB_ERR_ARGUMENT (an index out
 * of range), BB_ERR_IO (cannot write). */
bb_status bb__mesh_write(const char *path, const bb_mesh *m, bb_error *err);

void bb__renderbump_options_init(bb_renderbump_options *o);

/* DOOM 3's RenderBumpFlat on the CPU: projects mesh orthographically along
 * o->axis onto the rectangle, keeps the front-most surface at each sample
 * (no culling: the side facing the viewer is taken), and averages the
 * samples of each texel into result (allocated; free with
 * bb_renderbump_result_free). Bit-identical for any thread count. Errors:
 * BB_ERR_ARGUMENT (bad options, an index out of range, a degenerate
 * rectangle, nothing facing the viewer), BB_ERR_VALUE (a NaN or infinite
 * coordinate), BB_ERR_SIZE (size over the maximum, or the model covering
 * the image too many times over with tile), BB_ERR_MEMORY. */
bb_status bb__renderbump_flat(const bb_mesh *mesh, const bb_renderbump_options *o,
                             bb_renderbump_result *result, bb_error *err);

/* The "key=value" provenance lines of a render (axis, size, samples,
 * normals, rect, tile, depth_min, depth_max, scale), malloc'd, to follow
 * bb__provenance_format's lines; NULL when out of memory. */
char *bb__renderbump_describe(const bb_renderbump_options *o,
                             const bb_renderbump_result *r);

/* Once in bumpbake.h beside the functions that stay public there. */
/* The model-space unit vectors right, up and out of axis a. */
void bb__axis_frame(bb_axis a, double right[3], double up[3], double out[3]);
/* Parses "-y", "+y", "+z", "-z", "+x", "-x" ("y" means "+y"). */
bb_status bb__axis_parse(const char *name, bb_axis *out, bb_error *err);

/* "-y", "+z", ...; "unknown" for a value outside the enum. */
const char *bb__axis_name(bb_axis a);

#ifdef __cplusplus
}
#endif

#endif /* BB_MESH_INTERNAL_H */
