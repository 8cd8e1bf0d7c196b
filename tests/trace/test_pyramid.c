/* test_pyramid.c: every node bounds exactly the cells it covers, for odd,
 * non-square sizes and both addressing modes. */
#include "trace/testing.h"
#include <criterion/criterion.h>

#include <float.h>
#include <stdlib.h>

#include "bumpbake.h"
#include "trace/pyramid.h"

static bb_addressing modes[] = {BB_ADDRESS_PERIODIC, BB_ADDRESS_CLAMP};

static int addressed(int i, int n, bb_addressing a) {
  if (a == BB_ADDRESS_PERIODIC) return ((i % n) + n) % n;
  return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

/* Brute force: max of the corners of the cells [x0, x0+span) x [y0, y0+span). */
static float covered_max(const bb_image *z, int x0, int y0, int span, bb_addressing a) {
  float m = -FLT_MAX;
  for (int y = y0; y < y0 + span; y++)
    for (int x = x0; x < x0 + span; x++)
      for (int c = 0; c < 4; c++) {
        int vx = addressed(addressed(x, z->width, a) + (c & 1), z->width, a);
        int vy = addressed(addressed(y, z->height, a) + (c >> 1), z->height, a);
        float v = z->pixels[vy * z->width + vx];
        if (v > m) m = v;
      }
  return m;
}

Test(pyramid, nodes_equal_max_of_covered_cells) {
  const int sizes[][2] = {{1, 1}, {1, 5}, {3, 2}, {13, 7}, {16, 16}, {33, 17}};
  srand(5);
  for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
    for (int m = 0; m < 2; m++) {
      bb_image z;
      cr_assert_eq(bb_image_alloc(&z, sizes[s][0], sizes[s][1], 1, NULL), BB_OK);
      for (int i = 0; i < z.width * z.height; i++) z.pixels[i] = (float)(rand() % 1000) / 10.0f;
      bb_pyramid *p = NULL;
      cr_assert_eq(bb__pyramid_build_all_cores(&z, modes[m], &p, NULL), BB_OK);
      int levels = bb__pyramid_levels(p);
      cr_assert_eq(1 << (levels - 1) >= z.width && 1 << (levels - 1) >= z.height, 1);
      for (int k = 0; k < levels; k++) {
        int span = 1 << k;
        int lw = (z.width + span - 1) / span, lh = (z.height + span - 1) / span;
        for (int j = 0; j < lh; j++)
          for (int i = 0; i < lw; i++)
            cr_assert_eq(bb__pyramid_node_max(p, k, i, j),
                         covered_max(&z, i * span, j * span, span, modes[m]),
                         "%dx%d mode %d level %d node (%d, %d)", z.width, z.height, m, k, i, j);
      }
      bb_pyramid_free(p);
      bb_image_free(&z);
    }
}

Test(pyramid, rejects_non_finite_heights) {
  bb_image z;
  cr_assert_eq(bb_image_alloc(&z, 4, 4, 1, NULL), BB_OK);
  z.pixels[5] = 1.0f / 0.0f;
  bb_pyramid *p = (bb_pyramid *)1;
  bb_error err;
  cr_assert_eq(bb__pyramid_build_all_cores(&z, BB_ADDRESS_PERIODIC, &p, &err), BB_ERR_VALUE);
  cr_assert_null(p);
  bb_image_free(&z);
}
