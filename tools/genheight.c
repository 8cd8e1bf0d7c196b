/* genheight.c: writes deterministic synthetic height maps that tile, for fixtures.
 *
 *   genheight noise|bricks|pit|cones WIDTH HEIGHT OUT [--seed K]
 *
 * Every map is a periodic function of the texel position with period
 * (WIDTH, HEIGHT) exactly, for any size (non-power-of-two, non-square), so
 * the wrap-around edge is like any other texel step and periodic bakes of
 * the fixtures have no seams. Values are in [0, 1]; OUT's extension picks
 * the format (16-bit for .png/.tif so slopes do not terrace).
 */
#include "bumpbake.h"
#include "image/image_write.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SIDE 4096

/* --------------------------------------------------------------- hashing */

/* A 32-bit integer mix (Chris Wellons' "lowbias32"): a few multiplies give
 * well-spread lattice values with no table, identical on every platform. */
static uint32_t mix32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

/* Uniform value in [0, 1) for lattice point (ix, iy) of one octave. */
static double lattice_value(uint32_t seed, int octave, int ix, int iy) {
  uint32_t h =
      mix32(seed ^ mix32((uint32_t)octave * 0x9e3779b9U ^
                         mix32((uint32_t)ix ^ mix32((uint32_t)iy + 0x632be5abU))));
  return (double)(h >> 8) / 16777216.0;
}

/* ----------------------------------------------------------------- noise */

static double quintic(double t) {
  return t * t * t * (t * (t * 6 - 15) + 10);
}

static int positive_mod(int i, int n) {
  int r = i % n;
  return r < 0 ? r + n : r;
}

/* Value noise with cells_x x cells_y lattice cells over the whole image:
 * lattice indices wrap modulo the cell counts, so the noise repeats exactly
 * once per image, whatever its size in texels. */
static double periodic_value_noise(double u, double v, int cells_x, int cells_y,
                                   uint32_t seed, int octave) {
  /* Quintic interpolation is flat at lattice lines; shifting each octave by
   * its own fraction of a cell keeps those lines of all octaves from lining
   * up (at the image border, say) into a visible grid. */
  double fx = u * cells_x + lattice_value(seed, octave, -1, 0);
  double fy = v * cells_y + lattice_value(seed, octave, 0, -1);
  int x0 = (int)floor(fx), y0 = (int)floor(fy);
  double tx = quintic(fx - x0), ty = quintic(fy - y0);
  int xa = positive_mod(x0, cells_x), xb = positive_mod(x0 + 1, cells_x);
  int ya = positive_mod(y0, cells_y), yb = positive_mod(y0 + 1, cells_y);
  double top = lattice_value(seed, octave, xa, ya) * (1 - tx) +
               lattice_value(seed, octave, xb, ya) * tx;
  double bottom = lattice_value(seed, octave, xa, yb) * (1 - tx) +
                  lattice_value(seed, octave, xb, yb) * tx;
  return top * (1 - ty) + bottom * ty;
}

/* fBm: 5 octaves, each twice the cells and half the amplitude. The coarsest
 * octave has about 4 cells across the shorter side, keeping cells square. */
static double noise_height(int x, int y, int width, int height, uint32_t seed) {
  int shorter = width < height ? width : height;
  double u = (x + 0.5) / width, v = (y + 0.5) / height;
  double sum = 0, amplitude = 1;
  for (int octave = 0; octave < 5; octave++) {
    double per_texel = 4.0 * (1 << octave) / shorter;
    int cells_x = (int)lround(per_texel * width),
        cells_y = (int)lround(per_texel * height);
    if (cells_x < 1)
      cells_x = 1;
    if (cells_y < 1)
      cells_y = 1;
    sum += amplitude * periodic_value_noise(u, v, cells_x, cells_y, seed, octave);
    amplitude *= 0.5;
  }
  return sum;
}

/* ---------------------------------------------------------------- bricks */

#define MORTAR_HALF_TEXELS 1.0
#define BEVEL_TEXELS 2.5
#define MORTAR_HEIGHT 0.1

/* Running bond: rows of bricks, every other row shifted by half a brick.
 * The brick and row counts divide the image exactly and the row count is
 * even, so both the shift pattern and the bricks repeat once per image. */
static double bricks_height(int x, int y, int width, int height, uint32_t seed) {
  int columns = (int)lround(width / 32.0), rows = 2 * (int)lround(height / 32.0);
  if (columns < 1)
    columns = 1;
  if (rows < 2)
    rows = 2;
  double brick_w = (double)width / columns, brick_h = (double)height / rows;
  double px = x + 0.5, py = y + 0.5;
  int row = (int)floor(py / brick_h);
  double shifted = px + (row % 2 ? brick_w / 2 : 0);
  int column = (int)floor(shifted / brick_w);
  double u = shifted - column * brick_w, v = py - row * brick_h;
  /* Distance to the nearest brick edge decides mortar, bevel or face. */
  double edge = fmin(fmin(u, brick_w - u), fmin(v, brick_h - v));
  /* Each brick face sits at its own height, so bricks are told apart. */
  double face = 0.85 + 0.15 * lattice_value(seed, 99, positive_mod(column, columns), row);
  if (edge <= MORTAR_HALF_TEXELS)
    return MORTAR_HEIGHT;
  double t = (edge - MORTAR_HALF_TEXELS) / BEVEL_TEXELS;
  if (t >= 1)
    return face;
  /* Rounded bevel: quarter circle profile from mortar up to the face. */
  return MORTAR_HEIGHT + (face - MORTAR_HEIGHT) * sqrt(1 - (1 - t) * (1 - t));
}

/* ------------------------------------------------------------------- pit */

/* Flat 1 with a round pit of 0 in the middle (radius 0.3 of the shorter
 * side); the border is flat, so it tiles trivially. A known shape for AO. */
static double pit_height(int x, int y, int width, int height, uint32_t seed) {
  (void)seed;
  double cx = width / 2.0, cy = height / 2.0;
  double r = 0.3 * (width < height ? width : height);
  double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
  return dx * dx + dy * dy <= r * r ? 0.0 : 1.0;
}

/* ----------------------------------------------------------------- cones */

/* Flat 0 with three small, sharp cones of height 1 (radius 1.5 to 3 texels)
 * at fixed fractions of the size, distances taken periodically so the map
 * tiles: where a bake's few azimuth slices show as wedges around each cone
 * (docs/accuracy.md, "Azimuth wedges"). */
static double cones_height(int x, int y, int width, int height, uint32_t seed) {
  (void)seed;
  static const double cones[3][3] = {{0.31, 0.31, 2.0}, {0.70, 0.55, 1.5}, {0.47, 0.78, 3.0}};
  double h = 0.0;
  for (int i = 0; i < 3; i++) {
    double dx = fabs(x - floor(cones[i][0] * width + 0.5));
    double dy = fabs(y - floor(cones[i][1] * height + 0.5));
    dx = fmin(dx, width - dx);
    dy = fmin(dy, height - dy);
    const double v = 1.0 - sqrt(dx * dx + dy * dy) / cones[i][2];
    h = v > h ? v : h;
  }
  return h;
}

/* ------------------------------------------------------------------ main */

typedef double (*height_fn)(int x, int y, int width, int height, uint32_t seed);

static height_fn generator_named(const char *kind) {
  if (strcmp(kind, "noise") == 0)
    return noise_height;
  if (strcmp(kind, "bricks") == 0)
    return bricks_height;
  if (strcmp(kind, "pit") == 0)
    return pit_height;
  if (strcmp(kind, "cones") == 0)
    return cones_height;
  return NULL;
}

/* Stretches the map to fill [0, 1] so every fixture uses the whole code range. */
static void normalise(bb_image *img) {
  size_t n = (size_t)img->width * (size_t)img->height;
  float lo = img->pixels[0], hi = img->pixels[0];
  for (size_t i = 1; i < n; i++) {
    lo = fminf(lo, img->pixels[i]);
    hi = fmaxf(hi, img->pixels[i]);
  }
  if (hi <= lo)
    return;
  for (size_t i = 0; i < n; i++)
    img->pixels[i] = (img->pixels[i] - lo) / (hi - lo);
}

static int parse_side(const char *s, int *out) {
  char *end;
  long v = strtol(s, &end, 10);
  if (end == s || *end || v < 1 || v > MAX_SIDE)
    return 1;
  *out = (int)v;
  return 0;
}

static int has_extension(const char *path, const char *ext) {
  size_t n = strlen(path), m = strlen(ext);
  return n >= m && strcmp(path + n - m, ext) == 0;
}

/* 8 bits would terrace gentle slopes into steps that every bake then shows;
 * the formats that can hold 16 bits get them. */
static int wants_16_bits(const char *path) {
  return has_extension(path, ".png") || has_extension(path, ".tif") ||
         has_extension(path, ".tiff");
}

static int usage(const char *reason) {
  fprintf(stderr,
          "genheight: %s\n"
          "usage: genheight noise|bricks|pit|cones WIDTH HEIGHT OUT [--seed K]\n",
          reason);
  return 2;
}

int main(int argc, char **argv) {
  if (argc != 5 && argc != 7)
    return usage("wrong number of arguments");
  height_fn fn = generator_named(argv[1]);
  if (!fn)
    return usage("unknown kind (noise, bricks, pit, cones)");
  int width, height;
  if (parse_side(argv[2], &width) || parse_side(argv[3], &height))
    return usage("WIDTH and HEIGHT must be 1..4096");
  unsigned long seed = 1;
  if (argc == 7) {
    char *end;
    seed = strtoul(argv[6], &end, 10);
    if (strcmp(argv[5], "--seed") != 0 || end == argv[6] || *end)
      return usage("expected --seed K");
  }
  const char *out = argv[4];

  bb_image img;
  bb_error err = {{0}};
  if (bb_image_alloc(&img, width, height, 1, &err) != BB_OK) {
    fprintf(stderr, "genheight: %s: %s\n", out, err.message);
    return 1;
  }
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
      *bb_image_texel(&img, x, y) = (float)fn(x, y, width, height, (uint32_t)seed);
  normalise(&img);

  char description[160];
  snprintf(description, sizeof description, "genheight %s %d %d --seed %lu", argv[1],
           width, height, seed);
  bb_write_options wo = {
      .depth = BB_DEPTH_DEFAULT, .range = BB_RANGE_UNIT, .description = description};
  if (wants_16_bits(out))
    wo.depth = BB_DEPTH_16;
  bb_status st = bb__image_write(out, &img, &wo, &err);
  bb_image_free(&img);
  if (st != BB_OK) {
    fprintf(stderr, "genheight: %s\n", err.message);
    return 1;
  }
  return 0;
}
