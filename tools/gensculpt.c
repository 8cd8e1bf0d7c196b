/* gensculpt.c: writes the project's flat sculpt fixture, a tileable riveted
 * panel, as a model file through bb__mesh_write (Assimp's exporters).
 *
 *   gensculpt OUT.obj|OUT.ply|OUT.stl|OUT.glb
 *
 * The panel lies in the XZ plane with its front facing -Y, as DOOM 3's
 * RenderBumpFlat expects, and tiles with the square [0, 1] x [0, 1] of X
 * and Z as its period: a base plate, four bevelled plates in a running
 * bond (one crossing the right edge), sixteen domed rivets, a pipe lying
 * along X across the whole tile and beyond, and a hexagonal bolt on the
 * tile's corner. Plates and the bolt are faceted (one normal per face),
 * rivets and the pipe smooth. Plates, bolt and pipe stand on the base with
 * vertical walls and an undercut, which no height map can hold. The output
 * is the same bytes on every run.
 */
#include "bumpbake.h"
#include "mesh/mesh_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* Dimensions in model units (the tile is 1 x 1). */
#define PLATE_THICKNESS 0.05
#define PLATE_BEVEL 0.015
#define RIVET_RADIUS 0.022
#define RIVET_INSET 0.045
#define PIPE_RADIUS 0.025
#define PIPE_Z 0.5
#define BOLT_RADIUS 0.03
#define BOLT_HEIGHT 0.03
#define BOLT_BEVEL 0.008

/* ----------------------------------------------------------- mesh builder */

typedef struct builder {
  float *positions, *normals;
  uint32_t *indices;
  size_t vertices, triangles, vertex_cap, triangle_cap;
} builder;

static void *checked_realloc(void *p, size_t bytes) {
  void *q = realloc(p, bytes);
  if (!q) {
    fprintf(stderr, "gensculpt: out of memory\n");
    exit(1);
  }
  return q;
}

static uint32_t add_vertex(builder *b, const double p[3], const double n[3]) {
  if (b->vertices == b->vertex_cap) {
    b->vertex_cap = b->vertex_cap ? 2 * b->vertex_cap : 256;
    b->positions = checked_realloc(b->positions, 3 * b->vertex_cap * sizeof(float));
    b->normals = checked_realloc(b->normals, 3 * b->vertex_cap * sizeof(float));
  }
  for (int k = 0; k < 3; k++) {
    b->positions[3 * b->vertices + (size_t)k] = (float)p[k];
    b->normals[3 * b->vertices + (size_t)k] = (float)n[k];
  }
  return (uint32_t)b->vertices++;
}

static void add_triangle(builder *b, uint32_t i0, uint32_t i1, uint32_t i2) {
  if (b->triangles == b->triangle_cap) {
    b->triangle_cap = b->triangle_cap ? 2 * b->triangle_cap : 256;
    b->indices = checked_realloc(b->indices, 3 * b->triangle_cap * sizeof(uint32_t));
  }
  uint32_t *t = b->indices + 3 * b->triangles++;
  t[0] = i0, t[1] = i1, t[2] = i2;
}

static void sub3(const double a[3], const double b[3], double out[3]) {
  for (int k = 0; k < 3; k++)
    out[k] = a[k] - b[k];
}

/* A flat polygon (convex, corners in order) with one normal, pointing away
 * from `inside` and wound counter-clockwise seen from that side. */
static void add_flat(builder *b, const double (*corner)[3], int count, const double inside[3]) {
  double e1[3], e2[3], n[3], away[3];
  sub3(corner[1], corner[0], e1);
  sub3(corner[2], corner[0], e2);
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  sub3(corner[0], inside, away);
  int flip = n[0] * away[0] + n[1] * away[1] + n[2] * away[2] < 0.0;
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; k++)
    n[k] = (flip ? -n[k] : n[k]) / len;
  uint32_t first = (uint32_t)b->vertices;
  for (int i = 0; i < count; i++)
    add_vertex(b, corner[i], n);
  for (int i = 1; i + 1 < count; i++)
    if (flip)
      add_triangle(b, first, first + (uint32_t)i + 1, first + (uint32_t)i);
    else
      add_triangle(b, first, first + (uint32_t)i, first + (uint32_t)i + 1);
}

/* ------------------------------------------------------------------ parts */

/* A point at (x, z) of the panel, `height` in front of the base (-Y). */
static void at(double x, double z, double height, double p[3]) {
  p[0] = x, p[1] = -height, p[2] = z;
}

/* A prism standing on the base: a ring of `sides` shoulder corners at
 * `shoulder` height, vertical walls down to the base, bevels up to the top
 * face at `top` (its corners `inset` closer to the centre). Rectangles are
 * rings of 4 with per-side offsets, hexagons rings of 6. */
static void add_bevelled_prism(builder *b, const double (*shoulder_xz)[2],
                               const double (*top_xz)[2], int sides, double shoulder,
                               double top) {
  double centre[3] = {0.0, -top / 2.0, 0.0};
  for (int i = 0; i < sides; i++) {
    centre[0] += shoulder_xz[i][0] / sides;
    centre[2] += shoulder_xz[i][1] / sides;
  }
  double top_face[8][3];
  for (int i = 0; i < sides; i++)
    at(top_xz[i][0], top_xz[i][1], top, top_face[i]);
  add_flat(b, (const double(*)[3])top_face, sides, centre);
  for (int i = 0; i < sides; i++) {
    int j = (i + 1) % sides;
    double bevel[4][3], wall[4][3];
    at(top_xz[i][0], top_xz[i][1], top, bevel[0]);
    at(top_xz[j][0], top_xz[j][1], top, bevel[1]);
    at(shoulder_xz[j][0], shoulder_xz[j][1], shoulder, bevel[2]);
    at(shoulder_xz[i][0], shoulder_xz[i][1], shoulder, bevel[3]);
    add_flat(b, (const double(*)[3])bevel, 4, centre);
    at(shoulder_xz[i][0], shoulder_xz[i][1], shoulder, wall[0]);
    at(shoulder_xz[j][0], shoulder_xz[j][1], shoulder, wall[1]);
    at(shoulder_xz[j][0], shoulder_xz[j][1], 0.0, wall[2]);
    at(shoulder_xz[i][0], shoulder_xz[i][1], 0.0, wall[3]);
    add_flat(b, (const double(*)[3])wall, 4, centre);
  }
}

/* A dome (half sphere) of radius r centred at (x, z) on a surface at
 * `height`, with smooth normals: `around` segments, `rings` rings. */
static void add_dome(builder *b, double x, double z, double height, double r, int around,
                     int rings) {
  double centre[3];
  at(x, z, height, centre);
  double pole_n[3] = {0.0, -1.0, 0.0}, pole[3] = {centre[0], centre[1] - r, centre[2]};
  uint32_t apex = add_vertex(b, pole, pole_n);
  uint32_t first = (uint32_t)b->vertices;
  for (int ring = 1; ring <= rings; ring++) {
    double theta = 0.5 * PI * ring / rings;
    for (int s = 0; s < around; s++) {
      double phi = 2.0 * PI * s / around;
      double n[3] = {sin(theta) * cos(phi), -cos(theta), sin(theta) * sin(phi)};
      double p[3] = {centre[0] + r * n[0], centre[1] + r * n[1], centre[2] + r * n[2]};
      add_vertex(b, p, n);
    }
  }
  for (int s = 0; s < around; s++) {
    uint32_t a = first + (uint32_t)s, c = first + (uint32_t)((s + 1) % around);
    add_triangle(b, apex, c, a);
  }
  for (int ring = 1; ring < rings; ring++)
    for (int s = 0; s < around; s++) {
      uint32_t a = first + (uint32_t)((ring - 1) * around + s);
      uint32_t c = first + (uint32_t)((ring - 1) * around + (s + 1) % around);
      uint32_t a2 = a + (uint32_t)around, c2 = c + (uint32_t)around;
      add_triangle(b, a, c, c2);
      add_triangle(b, a, c2, a2);
    }
}

/* A bevelled plate over [x0, x1] x [z0, z1] with a rivet near each corner. */
static void add_plate(builder *b, double x0, double z0, double x1, double z1) {
  const double s[4][2] = {{x0, z0}, {x1, z0}, {x1, z1}, {x0, z1}};
  const double e = PLATE_BEVEL;
  const double t[4][2] = {{x0 + e, z0 + e}, {x1 - e, z0 + e}, {x1 - e, z1 - e}, {x0 + e, z1 - e}};
  add_bevelled_prism(b, s, t, 4, PLATE_THICKNESS - e, PLATE_THICKNESS);
  const double in = RIVET_INSET;
  const double rivets[4][2] = {
      {x0 + in, z0 + in}, {x1 - in, z0 + in}, {x1 - in, z1 - in}, {x0 + in, z1 - in}};
  for (int i = 0; i < 4; i++)
    add_dome(b, rivets[i][0], rivets[i][1], PLATE_THICKNESS, RIVET_RADIUS, 16, 6);
}

/* A smooth tube lying on the base along X from x0 to x1 (open ends: they
 * face sideways and are never seen from the front). */
static void add_pipe(builder *b, double x0, double x1, double z, double r, int around) {
  uint32_t first = (uint32_t)b->vertices;
  for (int s = 0; s < around; s++) {
    double a = 2.0 * PI * s / around;
    double n[3] = {0.0, cos(a), sin(a)};
    for (int end = 0; end < 2; end++) {
      double p[3] = {end ? x1 : x0, -r + r * n[1], z + r * n[2]};
      add_vertex(b, p, n);
    }
  }
  for (int s = 0; s < around; s++) {
    uint32_t a0 = first + 2 * (uint32_t)s, a1 = a0 + 1;
    uint32_t c0 = first + 2 * (uint32_t)((s + 1) % around), c1 = c0 + 1;
    add_triangle(b, a0, c0, c1);
    add_triangle(b, a0, c1, a1);
  }
}

/* A hexagonal bolt head centred at (x, z). */
static void add_bolt(builder *b, double x, double z) {
  double shoulder[6][2], top[6][2];
  for (int i = 0; i < 6; i++) {
    double a = PI / 6.0 + PI / 3.0 * i;
    shoulder[i][0] = x + BOLT_RADIUS * cos(a), shoulder[i][1] = z + BOLT_RADIUS * sin(a);
    double r = BOLT_RADIUS - BOLT_BEVEL;
    top[i][0] = x + r * cos(a), top[i][1] = z + r * sin(a);
  }
  add_bevelled_prism(b, (const double(*)[2])shoulder, (const double(*)[2])top, 6,
                     BOLT_HEIGHT - BOLT_BEVEL, BOLT_HEIGHT);
}

static void build_panel(builder *b) {
  const double base[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  const double behind[3] = {0.5, 1.0, 0.5};
  add_flat(b, base, 4, behind);
  add_plate(b, 0.02, 0.54, 0.48, 0.96); /* upper row */
  add_plate(b, 0.52, 0.54, 0.98, 0.96);
  add_plate(b, 0.27, 0.04, 0.73, 0.46); /* lower row, offset half a plate */
  add_plate(b, 0.77, 0.04, 1.23, 0.46); /* crosses the right edge */
  add_pipe(b, -0.1, 1.1, PIPE_Z, PIPE_RADIUS, 24);
  add_bolt(b, 0.0, 0.0); /* on the corner: a quarter in each corner */
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: gensculpt OUT.obj|OUT.ply|OUT.stl|OUT.glb\n");
    return 2;
  }
  builder b;
  memset(&b, 0, sizeof b);
  build_panel(&b);
  bb_mesh m = {b.vertices, b.triangles, b.positions, b.normals, b.indices};
  bb_error err = {{0}};
  bb_status st = bb__mesh_write(argv[1], &m, &err);
  free(b.positions);
  free(b.normals);
  free(b.indices);
  if (st != BB_OK) {
    fprintf(stderr, "gensculpt: %s\n", err.message);
    return 1;
  }
  printf("gensculpt: wrote %s (%zu vertices, %zu triangles)\n", argv[1], b.vertices,
         b.triangles);
  return 0;
}
