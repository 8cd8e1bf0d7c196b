/* normal.c: tangent-space normals (+Y down) of the surface z = height_scale * h.
 *
 * Each estimator reads a fixed neighbourhood of the texel through the
 * addressing mode and sums it in a fixed order, so a periodic shift of the
 * input shifts the output bit for bit and the thread count does not matter.
 */
#include "internal.h"

#include <math.h>
#include <string.h>

int bb_normal_filter_parse(const char *name, bb_normal_filter *out) {
  static const struct {
    const char *name;
    bb_normal_filter filter;
  } names[] = {{"valve", BB_NORMAL_VALVE},
               {"central", BB_NORMAL_CENTRAL},
               {"sobel", BB_NORMAL_SOBEL}};
  if (!name || !out)
    return -1;
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (strcmp(name, names[i].name) == 0) {
      *out = names[i].filter;
      return 0;
    }
  return -1;
}

const char *bb_normal_filter_name(bb_normal_filter f) {
  switch (f) {
  case BB_NORMAL_VALVE:
    return "valve";
  case BB_NORMAL_CENTRAL:
    return "central";
  case BB_NORMAL_SOBEL:
    return "sobel";
  }
  return "unknown";
}

typedef struct normal_job {
  const bb_image *height;
  double scale;
  bb_normal_filter filter;
  bb_addressing addressing;
  bb_image *out;
} normal_job;

/* z = scale * h at texel (x, y), addressed. */
static double z_at(const normal_job *job, int x, int y) {
  int ax = bb__address(x, job->height->width, job->addressing);
  int ay = bb__address(y, job->height->height, job->addressing);
  return job->scale * (double)*bb_image_texel(job->height, ax, ay);
}

static void add_unit(double sum[3], double nx, double ny, double nz) {
  double len = sqrt(nx * nx + ny * ny + nz * nz);
  sum[0] += nx / len;
  sum[1] += ny / len;
  sum[2] += nz / len;
}

/* Valve's estimator: the 18 unit normals of the two triangles of the 9 cells
 * (x0, y0), x0 in x-1..x+1, y0 in y-1..y+1. Cell (x0, y0) spans the corners
 * (x0, y0)..(x0+1, y0+1) and is split along its (x0+1, y0)-(x0, y0+1)
 * diagonal. The 9 cells cover x-1..x+2, so the estimate is centred at
 * (x + 0.5, y + 0.5), as Valve's is. */
static void normal_valve(const normal_job *job, int x, int y, double n[3]) {
  double z[4][4]; /* z[j][i] = z(x - 1 + i, y - 1 + j) */
  for (int j = 0; j < 4; j++)
    for (int i = 0; i < 4; i++)
      z[j][i] = z_at(job, x - 1 + i, y - 1 + j);
  n[0] = n[1] = n[2] = 0.0;
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 3; i++) {
      double z00 = z[j][i], z10 = z[j][i + 1], z01 = z[j + 1][i], z11 = z[j + 1][i + 1];
      add_unit(n, -(z10 - z00), -(z01 - z00), 1.0); /* (v00, v10, v01) */
      add_unit(n, z01 - z11, z10 - z11, 1.0);       /* (v10, v11, v01) */
    }
}

/* Central differences: N ~ (-dz/dx, -dz/dy, 1) centred on the texel. */
static void normal_central(const normal_job *job, int x, int y, double n[3]) {
  n[0] = -(z_at(job, x + 1, y) - z_at(job, x - 1, y)) / 2.0;
  n[1] = -(z_at(job, x, y + 1) - z_at(job, x, y - 1)) / 2.0;
  n[2] = 1.0;
}

/* 3x3 Sobel gradient divided by 8 (its weights sum to 8 over a unit slope). */
static void normal_sobel(const normal_job *job, int x, int y, double n[3]) {
  double z[3][3]; /* z[j][i] = z(x - 1 + i, y - 1 + j) */
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 3; i++)
      z[j][i] = z_at(job, x - 1 + i, y - 1 + j);
  double gx =
      ((z[0][2] + 2.0 * z[1][2] + z[2][2]) - (z[0][0] + 2.0 * z[1][0] + z[2][0])) / 8.0;
  double gy =
      ((z[2][0] + 2.0 * z[2][1] + z[2][2]) - (z[0][0] + 2.0 * z[0][1] + z[0][2])) / 8.0;
  n[0] = -gx;
  n[1] = -gy;
  n[2] = 1.0;
}

static void normal_row(void *user, int y) {
  const normal_job *job = user;
  for (int x = 0; x < job->height->width; x++) {
    double n[3] = {0.0, 0.0, 1.0}; /* filter was validated; this quiets -Wuninitialized */
    switch (job->filter) {
    case BB_NORMAL_VALVE:
      normal_valve(job, x, y, n);
      break;
    case BB_NORMAL_CENTRAL:
      normal_central(job, x, y, n);
      break;
    case BB_NORMAL_SOBEL:
      normal_sobel(job, x, y, n);
      break;
    }
    /* n.z > 0 in every estimator, so the length is never zero. */
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    float *p = bb_image_texel(job->out, x, y);
    for (int c = 0; c < 3; c++)
      p[c] = (float)(n[c] / len);
  }
}

static bb_status check_arguments(const bb_image *height, float height_scale,
                                 bb_normal_filter filter, bb_addressing addressing,
                                 const bb_image *out, bb_error *err) {
  if (!height || !out || !height->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: missing image");
  if (out == height)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: the output must be a separate image");
  if (height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: height has %d channels, not 1",
                    height->channels);
  if (!isfinite(height_scale))
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: height scale is not finite");
  if (filter != BB_NORMAL_VALVE && filter != BB_NORMAL_CENTRAL &&
      filter != BB_NORMAL_SOBEL)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: unknown filter %d", (int)filter);
  if (addressing != BB_ADDRESS_PERIODIC && addressing != BB_ADDRESS_CLAMP)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: unknown addressing mode %d",
                    (int)addressing);
  for (int y = 0; y < height->height; y++)
    for (int x = 0; x < height->width; x++)
      if (!isfinite(*bb_image_texel(height, x, y)))
        return bb__fail(err, BB_ERR_VALUE, "normals: height at (%d, %d) is not finite", x,
                        y);
  return BB_OK;
}

bb_status bb_normals_compute(const bb_image *height, float height_scale,
                             bb_normal_filter filter, bb_addressing addressing,
                             bb_image *out, bb_error *err) {
  bb_status st = check_arguments(height, height_scale, filter, addressing, out, err);
  if (st != BB_OK)
    return st;
  st = bb_image_alloc(out, height->width, height->height, 3, err);
  if (st != BB_OK)
    return st;
  normal_job job = {height, (double)height_scale, filter, addressing, out};
  st = bb__parallel_for(height->height, 0, normal_row, &job, NULL, NULL, err);
  if (st != BB_OK)
    bb_image_free(out);
  return st;
}
