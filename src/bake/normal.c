/* normal.c: tangent-space normals (+Y down) of the surface z = height_scale * h.
 *
 * Each estimator reads a fixed neighbourhood of the texel through the
 * addressing mode and sums it in a fixed order, so a periodic shift of the
 * input shifts the output bit for bit and the thread count does not matter.
 */

#include "bake/bake_internal.h"
#include "core/internal.h"
#include <math.h>
#include <string.h>

bb_status bb__normal_filter_parse(const char *name, bb_normal_filter *out, bb_error *err) {
  /* In the order of --help (the default first), then mapped to the enum. */
  static const char *const names[] = {"vertex", "valve", "central", "sobel"};
  static const bb_normal_filter filters[] = {BB_NORMAL_VERTEX, BB_NORMAL_VALVE,
                                             BB_NORMAL_CENTRAL, BB_NORMAL_SOBEL};
  int i;
  bb_status st = bb__parse_name("normal filter", name, names, 4, 0, &i, err);
  if (st == BB_OK)
    *out = filters[i];
  return st;
}

const char *bb__normal_filter_name(bb_normal_filter f) {
  switch (f) {
  case BB_NORMAL_VERTEX:
    return "vertex";
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
  bb_image *out; /* rows row0 .. row0 + out->height - 1 of the normals */
  int row0;
} normal_job;

/* Texel rows per parallel work item: the cell rows above and below a band are
 * computed twice, so a band amortises them over its rows. */
#define BAND_ROWS 16

/* Texel columns per pass over a band: keeps the three cell rows in L1. */
#define SPAN 128

/* bb__address for an index at most two texels outside 0 .. n-1 (all the
 * estimators read), without the division of bb__wrap. */
static int address_near(int i, int n, bb_addressing a) {
  return a == BB_ADDRESS_PERIODIC ? bb__wrap_near(i, n) : bb__clampi(i, 0, n - 1);
}

/* z = scale * h at texel (x, y), addressed. */
static double z_at(const normal_job *job, int x, int y) {
  const bb_image *h = job->height;
  int ax = address_near(x, h->width, job->addressing);
  int ay = address_near(y, h->height, job->addressing);
  return job->scale * (double)h->pixels[(size_t)ay * (size_t)h->width + (size_t)ax];
}

/* The unit normals of the two triangles of one cell, as Valve's estimator
 * adds them: (v00, v10, v01) first, then (v10, v11, v01). */
typedef struct cell_normals {
  double a[3], b[3];
} cell_normals;

static void unit_normal(double nx, double ny, double nz, double out[3]) {
  double len = sqrt(nx * nx + ny * ny + nz * nz);
  out[0] = nx / len;
  out[1] = ny / len;
  out[2] = nz / len;
}

/* Cells (x0, y0) for x0 = first .. first+count-1 into cells[0 .. count-1].
 * Cell (x0, y0) spans the corners (x0, y0)..(x0+1, y0+1) and is split along
 * its (x0+1, y0)-(x0, y0+1) diagonal. */
static void cell_row(const normal_job *job, int y0, int first, int count,
                     cell_normals *cells) {
  double z00 = z_at(job, first, y0), z01 = z_at(job, first, y0 + 1);
  for (int i = 0; i < count; i++) {
    double z10 = z_at(job, first + 1 + i, y0), z11 = z_at(job, first + 1 + i, y0 + 1);
    unit_normal(-(z10 - z00), -(z01 - z00), 1.0, cells[i].a);
    unit_normal(z01 - z11, z10 - z11, 1.0, cells[i].b);
    z00 = z10;
    z01 = z11;
  }
}

/* Writes n / |n| at (x, y). n.z > 0 in every estimator, so |n| is never 0. */
static void write_unit(const normal_job *job, int x, int y, const double n[3]) {
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  float *p = job->out->pixels + 3 * ((size_t)(y - job->row0) * (size_t)job->out->width + (size_t)x);
  for (int c = 0; c < 3; c++)
    p[c] = (float)(n[c] / len);
}

/* Valve's estimator: the mean direction of the 18 unit normals of the two
 * triangles of the 9 cells (x0, y0), x0 in x-1..x+1, y0 in y-1..y+1. The 9
 * cells cover x-1..x+2, so the estimate is centred at (x + 0.5, y + 0.5), as
 * Valve's is.
 *
 * Each cell is shared by 9 texels, so its two unit normals (2 square roots,
 * 6 divisions) are computed once per band and span, in a ring of the three
 * cell rows y-1, y, y+1. Every texel still adds them in the order of the
 * direct per-texel sum: cell row j, then cell column i, triangle a before b,
 * each componentwise, so the floating-point result is bit for bit the same. */
static void valve_band(const normal_job *job, int y_start, int y_end) {
  cell_normals ring[3][SPAN + 2]; /* cell row y0 lives in ring[(y0 + 1) % 3] */
  const int width = job->height->width;
  for (int x_start = 0; x_start < width; x_start += SPAN) {
    const int x_end = x_start + SPAN < width ? x_start + SPAN : width;
    const int count = x_end - x_start + 2; /* cells x_start-1 .. x_end */
    for (int y0 = y_start - 1; y0 <= y_start; y0++)
      cell_row(job, y0, x_start - 1, count, ring[(y0 + 1) % 3]);
    for (int y = y_start; y < y_end; y++) {
      cell_row(job, y + 1, x_start - 1, count, ring[(y + 2) % 3]);
      for (int x = x_start; x < x_end; x++) {
        double n[3] = {0.0, 0.0, 0.0};
        for (int j = 0; j < 3; j++) {
          const cell_normals *cells = ring[(y + j) % 3] + (x - x_start);
          for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++) {
              n[c] += cells[i].a[c];
              n[c] += cells[i].b[c];
            }
        }
        write_unit(job, x, y, n);
      }
    }
  }
}

/* (1, 2, 2, 1) weights of the four cells centred 1.5 and 0.5 texels either
 * side of a vertex, summed in mirror pairs: (first + last) + 2 (middle two).
 * Adding mirror partners first makes the sum exactly antisymmetric when its
 * inputs are, which is what gives a symmetric bump's peak N = (0, 0, 1). */
static void tent4(const double *v0, const double *v1, const double *v2, const double *v3,
                  double out[3]) {
  for (int c = 0; c < 3; c++)
    out[c] = (v0[c] + v3[c]) + 2.0 * (v1[c] + v2[c]);
}

/* The vertex-centred estimator: the normalised sum of the unit normals of the
 * two triangles of each of the 16 cells around the vertex (x0 in x-2..x+1,
 * y0 in y-2..y+1), cells weighted (1, 2, 2, 1) x (1, 2, 2, 1): the sum of
 * Valve's 9-cell sums at the four cell centres around the vertex. Its
 * footprint is Valve's widened by one cell and its centre is the vertex the
 * rays leave from. A half-turn about the vertex maps every cell's triangle a
 * onto the opposite cell's triangle b with exactly negated x and y, and the
 * sums pair those cells first, so a point-symmetric bump gives exactly
 * (0, 0, 1) at its centre.
 *
 * Per cell, c = a + b; each cell row is filtered along x once (rows[]), then
 * each texel filters four filtered rows along y. */
static void vertex_band(const normal_job *job, int y_start, int y_end) {
  double rows[4][SPAN][3]; /* x-filtered cell row y0 lives in rows[(y0 + 4) % 4] */
  cell_normals cells[SPAN + 3];
  const int width = job->height->width;
  for (int x_start = 0; x_start < width; x_start += SPAN) {
    const int x_end = x_start + SPAN < width ? x_start + SPAN : width;
    const int count = x_end - x_start + 3; /* cells x_start-2 .. x_end */
    for (int y0 = y_start - 2; y0 <= y_end; y0++) {
      cell_row(job, y0, x_start - 2, count, cells);
      double sum[SPAN + 3][3];
      for (int i = 0; i < count; i++)
        for (int c = 0; c < 3; c++)
          sum[i][c] = cells[i].a[c] + cells[i].b[c];
      double(*row)[3] = rows[(y0 + 4) % 4];
      for (int x = x_start; x < x_end; x++) {
        const int i = x - x_start; /* cells x-2 .. x+1 are sum[i .. i+3] */
        tent4(sum[i], sum[i + 1], sum[i + 2], sum[i + 3], row[i]);
      }
      const int y = y0 - 1; /* cell rows y-2 .. y+1 are ready */
      if (y < y_start)
        continue;
      for (int x = x_start; x < x_end; x++) {
        const int i = x - x_start;
        double n[3];
        tent4(rows[(y + 2) % 4][i], rows[(y + 3) % 4][i], rows[(y + 4) % 4][i],
              rows[(y + 5) % 4][i], n);
        write_unit(job, x, y, n);
      }
    }
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

static void normal_rows(const normal_job *job, int y_start, int y_end);

/* One work item: texel rows band*BAND_ROWS .. +BAND_ROWS-1. */
static void normal_band(void *user, int band) {
  const normal_job *job = user;
  const int y_start = band * BAND_ROWS;
  const int y_end = y_start + BAND_ROWS < job->height->height ? y_start + BAND_ROWS
                                                              : job->height->height;
  normal_rows(job, y_start, y_end);
}

void bb__normals_rows(const bb_image *height, float height_scale, bb_normal_filter filter,
                      bb_addressing addressing, int y0, int y1, float *rows) {
  bb_image band = {height->width, y1 - y0, 3, rows};
  const normal_job job = {height, (double)height_scale, filter, addressing, &band, y0};
  normal_rows(&job, y0, y1);
}

/* Rows y_start .. y_end - 1 of the normals, each texel as every band
 * computes it (each estimator's per-texel sum does not depend on where a
 * band starts). */
static void normal_rows(const normal_job *job, int y_start, int y_end) {
  if (job->filter == BB_NORMAL_VALVE) {
    valve_band(job, y_start, y_end);
    return;
  }
  if (job->filter == BB_NORMAL_VERTEX) {
    vertex_band(job, y_start, y_end);
    return;
  }
  for (int y = y_start; y < y_end; y++)
    for (int x = 0; x < job->height->width; x++) {
      double n[3];
      if (job->filter == BB_NORMAL_SOBEL)
        normal_sobel(job, x, y, n);
      else
        normal_central(job, x, y, n);
      write_unit(job, x, y, n);
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
  if (filter != BB_NORMAL_VERTEX && filter != BB_NORMAL_VALVE &&
      filter != BB_NORMAL_CENTRAL && filter != BB_NORMAL_SOBEL)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: unknown filter %d", (int)filter);
  if (addressing != BB_ADDRESS_PERIODIC && addressing != BB_ADDRESS_CLAMP)
    return bb__fail(err, BB_ERR_ARGUMENT, "normals: unknown addressing mode %d",
                    (int)addressing);
  if (bb__image_all_finite(height))
    return BB_OK;
  for (int y = 0; y < height->height; y++)
    for (int x = 0; x < height->width; x++)
      if (!isfinite(*bb_image_texel(height, x, y)))
        return bb__fail(err, BB_ERR_VALUE, "normals: height at (%d, %d) is not finite", x,
                        y);
  return BB_OK;
}

bb_status bb__normals_compute_all_cores(const bb_image *height, float height_scale,
                             bb_normal_filter filter, bb_addressing addressing,
                             bb_image *out, bb_error *err) {
  return bb__normals_compute(height, height_scale, filter, addressing, 0, NULL, out, err);
}

bb_status bb__normals_compute(const bb_image *height, float height_scale,
                              bb_normal_filter filter, bb_addressing addressing, int threads,
                              const bb__checkpoint *checkpoint, bb_image *out, bb_error *err) {
  bb_status st = check_arguments(height, height_scale, filter, addressing, out, err);
  if (st != BB_OK)
    return st;
  st = bb_image_alloc(out, height->width, height->height, 3, err);
  if (st != BB_OK)
    return st;
  normal_job job = {height, (double)height_scale, filter, addressing, out, 0};
  const int bands = height->height / BAND_ROWS + (height->height % BAND_ROWS != 0);
  st = bb__parallel_for_checked(bands, threads, normal_band, &job, checkpoint, err);
  if (st != BB_OK)
    bb_image_free(out);
  return st;
}
