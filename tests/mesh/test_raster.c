/* test_raster.c: the rasteriser's row runs against a scan of each
 * triangle's whole box (what it did before), sample for sample, the box
 * itself against every sample centre, and the bound on what a flat render
 * bump may draw. */
#include "bumpbake.h"
#include "mesh/rasterize.h"
#include "mesh/mesh_internal.h"

#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The box scan, as bb__band_draw did it before: every sample of the
 * triangle's box, through the rasteriser's own row terms and sample test.
 * Only the row runs (bb__band_draw's clipping) are left to compare. */
static void box_scan_draw(bb__sample_band *band, const bb__raster_setup *s, int32_t id) {
  int i0, i1, j0, j1;
  bb__raster_box(band, s, &i0, &i1, &j0, &j1);
  for (int j = j0; j <= j1; j++) {
    const bb__raster_row r = bb__raster_row_at(band, s, j);
    for (int i = i0; i <= i1; i++)
      bb__raster_sample(s, &r, i, band->per_texel, id);
  }
}

static uint64_t state = 0x9e3779b97f4a7c15ULL;
static double uniform(void) {
  state ^= state << 13, state ^= state >> 7, state ^= state << 17;
  return (double)(state >> 11) / 9007199254740992.0;
}

/* A triangle of one of several kinds over a W x H texel image: anywhere,
 * a sliver along a diagonal, nearly horizontal or vertical edges, tiny,
 * far larger than the image, vertices on sample centres. */
static void random_triangle(int kind, int W, int H, int n, bb__raster_tri *t) {
  for (int k = 0; k < 3; k++) {
    t->u[k] = (uniform() * 1.4 - 0.2) * W;
    t->v[k] = (uniform() * 1.4 - 0.2) * H;
    t->d[k] = uniform();
  }
  switch (kind) {
  case 1: /* a sliver from corner to corner */
    t->u[0] = 0, t->v[0] = 0, t->u[1] = W, t->v[1] = H;
    t->u[2] = W * (0.5 + 1e-3 * uniform()), t->v[2] = H * 0.5;
    break;
  case 2: /* a nearly horizontal edge */
    t->v[1] = t->v[0] + 1e-9 * uniform();
    break;
  case 3: /* a nearly vertical edge */
    t->u[1] = t->u[0] + 1e-12 * uniform();
    break;
  case 4: /* tiny */
    for (int k = 1; k < 3; k++)
      t->u[k] = t->u[0] + 0.3 * uniform(), t->v[k] = t->v[0] + 0.3 * uniform();
    break;
  case 5: /* much larger than the image */
    for (int k = 0; k < 3; k++)
      t->u[k] = (uniform() * 2e6 - 1e6), t->v[k] = (uniform() * 2e6 - 1e6);
    break;
  case 6: /* vertices on sample centres: edges through samples */
    for (int k = 0; k < 3; k++)
      t->u[k] = (floor(uniform() * W * n) + 0.5) / n,
      t->v[k] = (floor(uniform() * H * n) + 0.5) / n;
    break;
  default:
    break;
  }
}

/* Triangle id of the sequence above (its kind id % 7), set up; 0 when it
 * has no area. */
static int random_setup(int32_t id, int W, int H, int n, bb__raster_setup *s) {
  bb__raster_tri t;
  random_triangle(id % 7, W, H, n, &t);
  return bb__raster_setup_make(&t, s);
}

/* Thousands of triangles of every kind, drawn in order into bands of
 * every sampling: each sample's winner and depth equal the box scan's. */
Test(raster, row_runs_draw_exactly_what_the_box_scan_draws) {
  const int W = 37, H = 23;
  for (int n = 1; n <= 16; n += (n < 4 ? 1 : 5)) {
    for (int first = 0; first < H * n; first += H * n / 2) {
      bb__sample_band a = {W * n, H * n - first, first, n, NULL, NULL}, b = a;
      size_t count = (size_t)a.columns * (size_t)a.rows;
      a.depth = malloc(count * sizeof(double)), b.depth = malloc(count * sizeof(double));
      a.winner = malloc(count * sizeof(int32_t)),
      b.winner = malloc(count * sizeof(int32_t));
      cr_assert(a.depth && b.depth && a.winner && b.winner);
      for (size_t k = 0; k < count; k++)
        a.winner[k] = b.winner[k] = -1, a.depth[k] = b.depth[k] = 0.0;
      for (int32_t id = 0; id < 3500; id++) {
        bb__raster_setup s;
        if (!random_setup(id, W, H, n, &s))
          continue;
        bb__band_draw(&a, &s, id);
        box_scan_draw(&b, &s, id);
      }
      cr_expect_eq(memcmp(a.winner, b.winner, count * sizeof(int32_t)), 0,
                   "winners differ, %d samples per texel, band from row %d", n, first);
      cr_expect_eq(memcmp(a.depth, b.depth, count * sizeof(double)), 0,
                   "depths differ, %d samples per texel, band from row %d", n, first);
      free(a.depth), free(b.depth), free(a.winner), free(b.winner);
    }
  }
}

/* The first and last of count sample centres (i + 0.5) / n in [lo, hi],
 * found by looking at each one; last < first when there is none. */
static void centres_within(double lo, double hi, int n, int from, int count, int *first,
                           int *last) {
  *first = count, *last = -1;
  for (int i = from; i < count; i++) {
    const double centre = (i + 0.5) / n;
    if (centre >= lo && centre <= hi) {
      if (*first == count)
        *first = i;
      *last = i;
    }
  }
}

/* The box's columns and rows are the sample centres it holds, within the
 * band, for triangles of every kind (edges on centres, far outside). */
Test(raster, the_box_holds_exactly_the_sample_centres_inside_it) {
  const int W = 37, H = 23;
  for (int n = 1; n <= 16; n += (n < 4 ? 1 : 5)) {
    for (int first = 0; first < H * n; first += H * n / 3) {
      const bb__sample_band band = {W * n, H * n - first, first, n, NULL, NULL};
      for (int id = 0; id < 2000; id++) {
        bb__raster_setup s;
        if (!random_setup(id, W, H, n, &s))
          continue;
        int i0, i1, j0, j1, want_i0, want_i1, want_j0, want_j1;
        bb__raster_box(&band, &s, &i0, &i1, &j0, &j1);
        centres_within(s.box[0], s.box[2], n, 0, band.columns, &want_i0, &want_i1);
        centres_within(s.box[1], s.box[3], n, first, first + band.rows, &want_j0,
                       &want_j1);
        if (want_i1 < want_i0 || want_j1 < want_j0) {
          cr_assert(i1 < i0 || j1 < j0, "triangle %d (n %d, from row %d): box not empty",
                    id, n, first);
          continue;
        }
        cr_assert(i0 == want_i0 && i1 == want_i1 && j0 == want_j0 && j1 == want_j1,
                  "triangle %d (n %d, from row %d): box %d..%d x %d..%d, centres %d..%d "
                  "x %d..%d",
                  id, n, first, i0, i1, j0, j1, want_i0, want_i1, want_j0, want_j1);
      }
    }
  }
}

/* A right angle on a sample centre, its legs along the row and the column
 * (so both its edges are exactly 0 there): the sample is inside, and
 * drawn, at the box's first corner and at its last, at every centre of
 * every sampling. */
Test(raster, a_right_angle_on_a_sample_centre_draws_that_sample) {
  const int W = 6, H = 5;
  for (int n = 1; n <= 16; n++) {
    bb__sample_band band = {W * n, H * n, 0, n, NULL, NULL};
    const size_t count = (size_t)band.columns * (size_t)band.rows;
    band.depth = calloc(count, sizeof(double)),
    band.winner = malloc(count * sizeof(int32_t));
    cr_assert(band.depth && band.winner);
    for (size_t k = 0; k < count; k++)
      band.winner[k] = -1;
    int32_t id = 0;
    for (int j = 0; j < band.rows; j++)
      for (int i = 0; i < band.columns; i++)
        for (int leg = -2; leg <= 2; leg += 4, id++) {
          const double u = (i + 0.5) / n, v = (j + 0.5) / n;
          /* nearer than everything drawn before, so the sample is its own */
          bb__raster_tri t = {{u, u + leg, u}, {v, v, v + leg}, {id, id, id}};
          bb__raster_setup s;
          cr_assert(bb__raster_setup_make(&t, &s));
          bb__band_draw(&band, &s, id);
          cr_assert_eq(
              band.winner[(size_t)j * (size_t)band.columns + (size_t)i], id,
              "%d samples per texel: the corner on sample (%d, %d), legs %+d, not drawn",
              n, i, j, leg);
        }
    free(band.depth), free(band.winner);
  }
}

/* One triangle drawn many times over the same pixels is refused before
 * anything is drawn; the same number of triangles side by side is not. */
Test(raster, a_pile_of_triangles_is_refused_and_a_spread_is_not) {
  enum { COPIES = 200000 };
  bb_mesh pile, spread;
  cr_assert_eq(bb__mesh_alloc(&pile, 3, COPIES, 0, NULL), BB_OK);
  const float tri[9] = {0, 0, 0, 1, 0, 0, 1, 0, 1};
  memcpy(pile.positions, tri, sizeof tri);
  for (size_t t = 0; t < COPIES; t++)
    pile.indices[3 * t] = 0, pile.indices[3 * t + 1] = 1, pile.indices[3 * t + 2] = 2;
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = 64;
  bb_renderbump_result r;
  bb_error err = {{0}};
  cr_expect_eq(bb__renderbump_flat(&pile, &o, &r, &err), BB_ERR_SIZE);
  cr_expect(strstr(err.message, "over the 256 layers a render may draw"), "%s",
            err.message);
  cr_expect_null(r.normal.pixels);
  bb__mesh_free(&pile);

  /* a 400 x 250 grid of cells, two triangles each, over the same image */
  enum { NX = 400, NZ = 250 };
  cr_assert_eq(bb__mesh_alloc(&spread, (NX + 1) * (NZ + 1), 2 * NX * NZ, 0, NULL), BB_OK);
  for (int k = 0; k <= NZ; k++)
    for (int i = 0; i <= NX; i++) {
      float *p = spread.positions + 3 * (k * (NX + 1) + i);
      p[0] = (float)i / NX, p[1] = 0.01f * (float)sin(i + k), p[2] = (float)k / NZ;
    }
  uint32_t *idx = spread.indices;
  for (int k = 0; k < NZ; k++)
    for (int i = 0; i < NX; i++) {
      uint32_t a = (uint32_t)(k * (NX + 1) + i), b = a + 1, c = a + NX + 1, d = c + 1;
      const uint32_t two[6] = {a, b, c, b, d, c};
      memcpy(idx, two, sizeof two);
      idx += 6;
    }
  cr_expect_eq(bb__renderbump_flat(&spread, &o, &r, &err), BB_OK, "%s", err.message);
  cr_expect_eq(r.triangles_drawn, (size_t)(2 * NX * NZ));
  bb_renderbump_result_free(&r);
  bb__mesh_free(&spread);
}
