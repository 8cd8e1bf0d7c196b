/* mesh.c: the bb_mesh type (allocation, hash) and the projection axes of the
 * flat render bump. Reading and writing files is mesh_assimp.cpp's job. */
#include "core/internal.h"
#include "mesh/mesh_internal.h"

#include <stdlib.h>
#include <string.h>

bb_status bb__mesh_alloc(bb_mesh *m, size_t vertices, size_t triangles,
                        int with_normals, bb_error *err) {
  memset(m, 0, sizeof *m);
  if (vertices == 0)
    return bb__fail(err, BB_ERR_SIZE, "a mesh needs at least one vertex");
  if (vertices > BB_MAX_MESH_ELEMENTS || triangles > BB_MAX_MESH_ELEMENTS)
    return bb__fail(err, BB_ERR_SIZE,
                    "mesh of %zu vertices and %zu triangles is over the maximum (%lu each)",
                    vertices, triangles, (unsigned long)BB_MAX_MESH_ELEMENTS);
  /* Both counts are <= 2^27, so 3 * count elements fit in size_t. */
  m->positions = calloc(3 * vertices, sizeof(float));
  m->normals = with_normals ? calloc(3 * vertices, sizeof(float)) : NULL;
  m->indices = calloc(3 * (triangles ? triangles : 1), sizeof(uint32_t));
  if (!m->positions || !m->indices || (with_normals && !m->normals)) {
    bb__mesh_free(m);
    return bb__fail(err, BB_ERR_MEMORY, "cannot allocate a mesh of %zu vertices", vertices);
  }
  m->vertex_count = vertices;
  m->triangle_count = triangles;
  return BB_OK;
}

void bb__mesh_free(bb_mesh *m) {
  if (!m)
    return;
  free(m->positions);
  free(m->normals);
  free(m->indices);
  memset(m, 0, sizeof *m);
}

uint64_t bb__mesh_hash(const bb_mesh *m) {
  uint64_t h = BB__FNV64_OFFSET;
  if (!m)
    return h;
  h = bb__fnv1a_u32(h, (uint32_t)m->vertex_count);
  h = bb__fnv1a_u32(h, (uint32_t)m->triangle_count);
  h = bb__fnv1a_u32(h, m->normals != NULL);
  if (m->positions)
    h = bb__fnv1a_floats(h, m->positions, 3 * m->vertex_count);
  if (m->normals)
    h = bb__fnv1a_floats(h, m->normals, 3 * m->vertex_count);
  if (m->indices)
    for (size_t i = 0; i < 3 * m->triangle_count; i++)
      h = bb__fnv1a_u32(h, m->indices[i]);
  return h;
}

/* ------------------------------------------------------------------- axes */

/* Each axis as (right, up, out): signed model axes, 1-based (X = 1, Y = 2,
 * Z = 3), chosen so that right x up = out (a right-handed frame) and the
 * views match Blender's numpad views, whose front view is DOOM 3's. */
static const struct {
  const char *name;
  int right, up, out;
} axes[] = {
    [BB_AXIS_NEG_Y] = {"-y", +1, +3, -2}, [BB_AXIS_POS_Y] = {"+y", -1, +3, +2},
    [BB_AXIS_POS_Z] = {"+z", +1, +2, +3}, [BB_AXIS_NEG_Z] = {"-z", +1, -2, -3},
    [BB_AXIS_POS_X] = {"+x", +2, +3, +1}, [BB_AXIS_NEG_X] = {"-x", -2, +3, -1},
};

enum { AXIS_COUNT = sizeof axes / sizeof axes[0] };

bb_status bb__axis_parse(const char *name, bb_axis *out, bb_error *err) {
  const char *names[AXIS_COUNT];
  for (int i = 0; i < AXIS_COUNT; i++)
    names[i] = axes[i].name;
  char full[3] = {'+', 0, 0};
  if (name && strlen(name) == 1) /* "y" is "+y" */
    full[1] = name[0];
  int i;
  bb_status st = bb__parse_name("axis", full[1] ? full : name, names, AXIS_COUNT, 0, &i, NULL);
  if (st != BB_OK) /* again for the message, naming what was given */
    st = bb__parse_name("axis", name, names, AXIS_COUNT, 0, &i, err);
  if (st == BB_OK)
    *out = (bb_axis)i;
  return st;
}

const char *bb__axis_name(bb_axis a) {
  return (int)a >= 0 && (int)a < AXIS_COUNT ? axes[a].name : "unknown";
}

static void signed_unit(int axis, double v[3]) {
  v[0] = v[1] = v[2] = 0.0;
  v[abs(axis) - 1] = axis > 0 ? 1.0 : -1.0;
}

void bb__axis_frame(bb_axis a, double right[3], double up[3], double out[3]) {
  if ((int)a < 0 || (int)a >= AXIS_COUNT)
    a = BB_AXIS_NEG_Y;
  signed_unit(axes[a].right, right);
  signed_unit(axes[a].up, up);
  signed_unit(axes[a].out, out);
}
