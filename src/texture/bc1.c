/* bc1.c: BC1 colour blocks (BC1, and BC3's colour half), encoded and
 * decoded (bc.h has the decoding rules).
 *
 * The encoder fits a block's texels by published methods, each candidate
 * scored by what the decoder will make of it: the squared error, in codes,
 * of the texels (unrounded) against the palette's colours, each texel at
 * its nearest colour. In 4-colour mode:
 * - the principal axis of the texels' colours (power iteration on their
 *   covariance), and end points at the texels' extremes along it;
 * - least squares: the end points that fit the indices the texels take,
 *   each channel's pair rounded to the 5:6:5 grid by trying the grid
 *   points either side, scored from the index classes' counts and sums
 *   (given the indices, one channel's error does not depend on the
 *   others'), as stb_dxt's refinement and rgbcx do;
 * - a second start from cluster fit (Simon Brown's, as libsquish's): the
 *   texels sorted along the axis and split into the four indices' runs,
 *   each split scored by its least-squares end points rounded to the grid
 *   (prefix sums make a split a few operations), over the splits near the
 *   extremes' own, where the first fit leaves enough error;
 * - a local search moving each channel's end points by a grid step, which
 *   finds what rounding the channels one by one misses.
 * 3-colour mode (BC1 only) gets the least-squares fit from the extremes,
 * and is kept where it is better. Blocks of one colour get, in each mode,
 * the pair whose in-between colour is nearest.
 *
 * Errors are floats summed in a fixed order, so a block's bytes depend on
 * its texels alone: the same on any thread count, and with or without
 * SSE2 (v4 below). */
#include "texture/bc.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Four floats, one per channel (the fourth unused) or per texel: SSE2
 * where the compiler has it, else plain C doing each lane's operation in
 * the same order (IEEE single precision either way: the same bits). */
#if defined(__SSE2__) && !defined(BB_BC1_PLAIN)
#include <emmintrin.h>
typedef __m128 v4;
static inline v4 v4_set(float a, float b, float c, float d) {
  return _mm_setr_ps(a, b, c, d);
}
static inline v4 v4_all(float a) {
  return _mm_set1_ps(a);
}
static inline v4 v4_load(const float *p) {
  return _mm_loadu_ps(p);
}
static inline v4 v4_add(v4 a, v4 b) {
  return _mm_add_ps(a, b);
}
static inline v4 v4_sub(v4 a, v4 b) {
  return _mm_sub_ps(a, b);
}
static inline v4 v4_mul(v4 a, v4 b) {
  return _mm_mul_ps(a, b);
}
/* a < b ? a : b, a > b ? a : b, lane by lane (minps, maxps) */
static inline v4 v4_min(v4 a, v4 b) {
  return _mm_min_ps(a, b);
}
static inline v4 v4_max(v4 a, v4 b) {
  return _mm_max_ps(a, b);
}
/* (float)(int)a, truncating toward zero, for lanes well inside int's range */
static inline v4 v4_trunc(v4 a) {
  return _mm_cvtepi32_ps(_mm_cvttps_epi32(a));
}
static inline float v4_lane(v4 a, int l) {
  float f[4];
  _mm_storeu_ps(f, a);
  return f[l];
}
static inline v4 v4_div(v4 a, v4 b) {
  return _mm_div_ps(a, b);
}
static inline void v4_store(float *p, v4 a) {
  _mm_storeu_ps(p, a);
}
/* round_up (below) of each lane into i[0..3]: floor(x + 0.5) */
static inline void v4_store_round_up(v4 a, int i[4]) {
  const __m128 y = _mm_add_ps(a, _mm_set1_ps(0.5f));
  const __m128i t = _mm_cvttps_epi32(y);
  /* (float)t > y: one less (all ones in a mask is -1) */
  const __m128i over = _mm_castps_si128(_mm_cmpgt_ps(_mm_cvtepi32_ps(t), y));
  _mm_storeu_si128((__m128i *)(void *)i, _mm_add_epi32(t, over));
}
/* a < b ? x : y, lane by lane */
static inline v4 v4_select_lt(v4 a, v4 b, v4 x, v4 y) {
  const __m128 m = _mm_cmplt_ps(a, b);
  return _mm_or_ps(_mm_and_ps(m, x), _mm_andnot_ps(m, y));
}
/* the lanes (small whole numbers) as ints into i[0..3] */
static inline void v4_store_int(v4 a, int i[4]) {
  _mm_storeu_si128((__m128i *)(void *)i, _mm_cvttps_epi32(a));
}
#else
typedef struct {
  float f[4];
} v4;
static inline v4 v4_set(float a, float b, float c, float d) {
  return (v4){{a, b, c, d}};
}
static inline v4 v4_all(float a) {
  return (v4){{a, a, a, a}};
}
static inline v4 v4_load(const float *p) {
  return (v4){{p[0], p[1], p[2], p[3]}};
}
#define V4_LANES(expr)                                                                   \
  v4 r;                                                                                  \
  for (int l = 0; l < 4; l++)                                                            \
    r.f[l] = (expr);                                                                     \
  return r
static inline v4 v4_add(v4 a, v4 b) {
  V4_LANES(a.f[l] + b.f[l]);
}
static inline v4 v4_sub(v4 a, v4 b) {
  V4_LANES(a.f[l] - b.f[l]);
}
static inline v4 v4_mul(v4 a, v4 b) {
  V4_LANES(a.f[l] * b.f[l]);
}
static inline v4 v4_min(v4 a, v4 b) {
  V4_LANES(a.f[l] < b.f[l] ? a.f[l] : b.f[l]);
}
static inline v4 v4_max(v4 a, v4 b) {
  V4_LANES(a.f[l] > b.f[l] ? a.f[l] : b.f[l]);
}
static inline v4 v4_trunc(v4 a) {
  V4_LANES((float)(int)a.f[l]);
}
#undef V4_LANES
static inline float v4_lane(v4 a, int l) {
  return a.f[l];
}
static inline void v4_store(float *p, v4 a) {
  for (int l = 0; l < 4; l++)
    p[l] = a.f[l];
}
static inline v4 v4_div(v4 a, v4 b) {
  v4 r;
  for (int l = 0; l < 4; l++)
    r.f[l] = a.f[l] / b.f[l];
  return r;
}
static inline void v4_store_round_up(v4 a, int i[4]) {
  for (int l = 0; l < 4; l++) {
    const float y = a.f[l] + 0.5f;
    const int t = (int)y;
    i[l] = (float)t > y ? t - 1 : t;
  }
}
static inline v4 v4_select_lt(v4 a, v4 b, v4 x, v4 y) {
  v4 r;
  for (int l = 0; l < 4; l++)
    r.f[l] = a.f[l] < b.f[l] ? x.f[l] : y.f[l];
  return r;
}
static inline void v4_store_int(v4 a, int i[4]) {
  for (int l = 0; l < 4; l++)
    i[l] = (int)a.f[l];
}
#endif

/* The sum of the lanes as bb__sum16 ends: (0 + 1) + (2 + 3). With a lane
 * per texel of a row of four, each lane summed down the rows first, a
 * block's sum comes out in bb__sum16's order. */
static inline float v4_sum(v4 a) {
  return (v4_lane(a, 0) + v4_lane(a, 1)) + (v4_lane(a, 2) + v4_lane(a, 3));
}

/* Grid levels of the 5:6:5 channels. */
static const int levels[3] = {31, 63, 31};

/* End point v of a channel with `top` levels, as 8 bits: round(255 v / top). */
static int expand(int v, int top) {
  return (510 * v + top) / (2 * top);
}

/* round(255 s / (3 top)), s = 2 a + b: colour 2 (a, b) or colour 3 (b, a)
 * of a 4-colour block. */
static int third(int s, int top) {
  return (510 * s + 3 * top) / (6 * top);
}

/* round(255 s / (2 top)), s = a + b, halves up: colour 2 of a 3-colour
 * block. */
static int half(int s, int top) {
  return (510 * s + 2 * top) / (4 * top);
}

/* The decoder's values of a 5-bit ([0]) and a 6-bit ([1]) channel, by the
 * functions above, made once: the fit looks them up millions of times. */
static struct { float expand[64], third[190], half[127]; } channel_values[2];
static pthread_once_t channel_values_once = PTHREAD_ONCE_INIT;

static void channel_values_make(void) {
  for (int k = 0; k < 2; k++) {
    const int top = k ? 63 : 31;
    for (int v = 0; v <= top; v++)
      channel_values[k].expand[v] = (float)expand(v, top);
    for (int s = 0; s <= 3 * top; s++)
      channel_values[k].third[s] = (float)third(s, top);
    for (int s = 0; s <= 2 * top; s++)
      channel_values[k].half[s] = (float)half(s, top);
  }
}

/* Channel c's four colours of end points a, b; three: 3-colour mode,
 * whose colour 3 (black) is left out by repeating colour 2. */
static void channel_colours(int c, int a, int b, int three, float v[4]) {
  const int k = c == 1;
  v[0] = channel_values[k].expand[a];
  v[1] = channel_values[k].expand[b];
  v[2] = three ? channel_values[k].half[a + b] : channel_values[k].third[2 * a + b];
  v[3] = three ? v[2] : channel_values[k].third[a + 2 * b];
}

/* The four colours of end points a, b (5:6:5 codes) as the decoder makes
 * them, p[j][c]. */
static void palette(const int a[3], const int b[3], int three, float p[4][3]) {
  for (int c = 0; c < 3; c++) {
    float v[4];
    channel_colours(c, a[c], b[c], three, v);
    for (int j = 0; j < 4; j++)
      p[j][c] = v[j];
  }
}

/* floor(x + 0.5), without a call (x well inside int's range). */
static int round_up(float x) {
  const float y = x + 0.5f;
  const int i = (int)y;
  return (float)i > y ? i - 1 : i;
}

static unsigned pack(const int q[3]) {
  return (unsigned)(q[0] << 11 | q[1] << 5 | q[2]);
}

static void unpack(unsigned v, int q[3]) {
  q[0] = (int)(v >> 11) & 31;
  q[1] = (int)(v >> 5) & 63;
  q[2] = (int)v & 31;
}

void bb__bc1_decode(const unsigned char block[8], int four, unsigned char rgba[64]) {
  const unsigned c0 = (unsigned)block[0] | (unsigned)block[1] << 8;
  const unsigned c1 = (unsigned)block[2] | (unsigned)block[3] << 8;
  int a[3], b[3];
  unpack(c0, a);
  unpack(c1, b);
  const int three = !four && c0 <= c1;
  pthread_once(&channel_values_once, channel_values_make);
  float p[4][3];
  palette(a, b, three, p);
  const uint32_t bits = (uint32_t)block[4] | (uint32_t)block[5] << 8 |
                        (uint32_t)block[6] << 16 | (uint32_t)block[7] << 24;
  for (int i = 0; i < 16; i++) {
    const int k = (int)(bits >> (2 * i)) & 3;
    const int black = three && k == 3;
    for (int c = 0; c < 3; c++)
      rgba[4 * i + c] = black ? 0 : (unsigned char)p[k][c];
    rgba[4 * i + 3] = black ? 0 : 255;
  }
}

/* ------------------------------------------------------------- encoding */

/* A block's texels in codes (0..255, not rounded), channel by channel;
 * w[i] is 1 for a texel of the image and 0 for one past its edge (which
 * holds a copy of a texel of the image, so it moves no extreme). */
typedef struct block {
  float x[3][16];
  float w[16];
  float rgb1[16][4]; /* texel i's R, G, B and 1, for sums over the channels at once */
  float n; /* texels of the image */
} block;

/* End points (5:6:5 codes, in either order), the mode, and once assessed
 * the error and each texel's nearest colour. */
typedef struct fit {
  int q[2][3];
  int three;
  float error;
  int index[16];
} fit;

/* f's palette as the decoder will read it: end points that pack to the
 * same 16 bits make a 3-colour block whatever the mode asked, all its
 * colours (but black) the one colour. */
static void palette_of(const fit *f, float p[4][3]) {
  palette(f->q[0], f->q[1], f->three, p);
  if (!f->three && pack(f->q[0]) == pack(f->q[1]))
    for (int j = 1; j < 4; j++)
      memcpy(p[j], p[0], sizeof p[0]);
}

/* f's error, each texel at its nearest colour (the first of equals),
 * and those colours' indices: four texels at a time, a lane each (each
 * lane's operations those of one texel, so the same bits as one by one). */
static void assess(const block *b, fit *f) {
  float p[4][3];
  palette_of(f, p);
  v4 colour[4][3];
  for (int j = 0; j < 4; j++)
    for (int c = 0; c < 3; c++)
      colour[j][c] = v4_all(p[j][c]);
  const v4 zero = v4_all(0), one = v4_all(1), two = v4_all(2), three = v4_all(3);
  v4 sum = zero;
  for (int g = 0; g < 16; g += 4) {
    const v4 x0 = v4_load(b->x[0] + g), x1 = v4_load(b->x[1] + g),
             x2 = v4_load(b->x[2] + g);
    v4 d[4];
    for (int j = 0; j < 4; j++) {
      const v4 e0 = v4_sub(x0, colour[j][0]), e1 = v4_sub(x1, colour[j][1]),
               e2 = v4_sub(x2, colour[j][2]);
      d[j] = v4_add(v4_add(v4_mul(e0, e0), v4_mul(e1, e1)), v4_mul(e2, e2));
    }
    /* nearest of 0 and 1, of 2 and 3, then of the two (ties: the first) */
    const v4 m01 = v4_min(d[1], d[0]), m23 = v4_min(d[3], d[2]);
    const v4 i01 = v4_select_lt(d[1], d[0], one, zero);
    const v4 i23 = v4_select_lt(d[3], d[2], three, two);
    v4_store_int(v4_select_lt(m23, m01, i23, i01), f->index + g);
    const v4 e = v4_mul(v4_load(b->w + g), v4_min(m23, m01));
    sum = g ? v4_add(sum, e) : e;
  }
  f->error = v4_sum(sum);
}

static void keep_better(fit *best, const fit *f) {
  if (f->error < best->error)
    *best = *f;
}

/* End point 0's weight, in sixths, of each index: 1, 0, 2/3, 1/3 in
 * 4-colour mode; 1, 0, 1/2 (and colour 2 again) in 3-colour mode. */
static const int weight6[2][4] = {{6, 0, 4, 2}, {6, 0, 3, 3}};

/* The end points that fit the texels best when each keeps its index:
 * least squares for each channel, then the four grid pairs around them (a
 * channel's error, given the indices, is the classes' counts, sums and the
 * pair's colours alone). 0 when the indices leave the end points free (one
 * class, or only the two equal-weighted ones). */
static int fit_indices(const block *b, const int index[16], int three, fit *out) {
  /* each class's sums of R, G, B and its count, a lane each (each lane
   * summed in the texels' order, as one channel at a time would be) */
  v4 sum[4];
  for (int j = 0; j < 4; j++)
    sum[j] = v4_all(0);
  for (int i = 0; i < 16; i++) {
    const int j = index[i];
    sum[j] = v4_add(sum[j], v4_mul(v4_all(b->w[i]), v4_load(b->rgb1[i])));
  }
  float count[4], aa = 0, bb = 0, ab = 0, wa[4];
  for (int j = 0; j < 4; j++) {
    count[j] = v4_lane(sum[j], 3);
    wa[j] = (float)weight6[three][j] / 6.0f;
    aa += count[j] * wa[j] * wa[j];
    bb += count[j] * (1.0f - wa[j]) * (1.0f - wa[j]);
    ab += count[j] * wa[j] * (1.0f - wa[j]);
  }
  const float det = aa * bb - ab * ab;
  if (!(det > 1e-3f))
    return 0;
  out->three = three;
  /* the three channels side by side, a lane each */
  v4 ax = v4_all(0), bx = v4_all(0);
  for (int j = 0; j < 4; j++) {
    ax = v4_add(ax, v4_mul(v4_all(wa[j]), sum[j]));
    bx = v4_add(bx, v4_mul(v4_all(1.0f - wa[j]), sum[j]));
  }
  const v4 scale = v4_set(31.0f / 255.0f, 63.0f / 255.0f, 31.0f / 255.0f, 0.0f);
  const v4 vdet = v4_all(det), vaa = v4_all(aa), vbb = v4_all(bb), vab = v4_all(ab);
  /* the grid points either side of each least-squares end (the nearest
   * pair when it lies off the grid) */
  int fa[4], fb[4];
  v4_store_round_up(
      v4_sub(v4_mul(v4_div(v4_sub(v4_mul(ax, vbb), v4_mul(bx, vab)), vdet), scale),
             v4_all(0.5f)),
      fa);
  v4_store_round_up(
      v4_sub(v4_mul(v4_div(v4_sub(v4_mul(bx, vaa), v4_mul(ax, vab)), vdet), scale),
             v4_all(0.5f)),
      fb);
  for (int c = 0; c < 3; c++) {
    const int top = levels[c];
    fa[c] = fa[c] < 0 ? 0 : fa[c] > top - 1 ? top - 1 : fa[c];
    fb[c] = fb[c] < 0 ? 0 : fb[c] > top - 1 ? top - 1 : fb[c];
  }
  const v4 twice[4] = {v4_mul(v4_all(2.0f), sum[0]), v4_mul(v4_all(2.0f), sum[1]),
                       v4_mul(v4_all(2.0f), sum[2]), v4_mul(v4_all(2.0f), sum[3])};
  float best[3] = {0, 0, 0};
  for (int m = 0; m < 4; m++) {
    float v[3][4];
    for (int c = 0; c < 3; c++)
      channel_colours(c, fa[c] + (m & 1), fb[c] + (m >> 1), three, v[c]);
    /* sum over the classes of v (count v - 2 sum), each channel a lane */
    v4 e = v4_all(0);
    for (int j = 0; j < 4; j++) {
      const v4 vj = v4_set(v[0][j], v[1][j], v[2][j], 0.0f);
      e = v4_add(e, v4_mul(vj, v4_sub(v4_mul(v4_all(count[j]), vj), twice[j])));
    }
    for (int c = 0; c < 3; c++) {
      const float ec = v4_lane(e, c);
      if (m == 0 || ec < best[c])
        best[c] = ec, out->q[0][c] = fa[c] + (m & 1), out->q[1][c] = fb[c] + (m >> 1);
    }
  }
  return 1;
}

/* Least squares on f's own indices (f assessed), while the error falls. */
static void refine(const block *b, fit *f, int rounds) {
  for (int r = 0; r < rounds; r++) {
    fit g;
    if (!fit_indices(b, f->index, f->three, &g))
      return;
    /* the same end points (in the same mode) score the same: no gain */
    if (g.three == f->three && memcmp(g.q, f->q, sizeof g.q) == 0)
      return;
    assess(b, &g);
    if (!(g.error < f->error))
      return;
    *f = g;
  }
}

/* Moves one channel's end points at a time: one end by a grid step, or
 * both apart or together (both one way hardly ever gains), keeping the
 * best move of each channel, for up to `passes` passes while the error
 * falls. A move of channel c changes only that channel's distances: the
 * others' are summed once. f is assessed, and is again at the end. */
static void local_search(const block *b, fit *f, int passes) {
  static const int move[6][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}, {1, -1}, {-1, 1}};
  int moved = 0;
  /* channels tried since the last move: at 3, every channel has been tried
   * on f as it stands and found no gain, and would find none again */
  int unmoved = 0;
  for (int pass = 0; pass < passes && f->error > 0 && unmoved < 3; pass++) {
    const float before = f->error;
    for (int c = 0; c < 3 && unmoved < 3; c++) {
      /* the other channels' part of each texel's distance to each colour,
       * four texels a lane each (as assess) */
      float p[4][3];
      palette_of(f, p);
      const int c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      v4 rest[4][4];
      for (int j = 0; j < 4; j++)
        for (int g = 0; g < 4; g++) {
          const v4 d1 = v4_sub(v4_load(b->x[c1] + 4 * g), v4_all(p[j][c1]));
          const v4 d2 = v4_sub(v4_load(b->x[c2] + 4 * g), v4_all(p[j][c2]));
          rest[j][g] = v4_add(v4_mul(d1, d1), v4_mul(d2, d2));
        }
      const int top = levels[c], qa = f->q[0][c], qb = f->q[1][c];
      /* a move making both end points one colour needs the others equal */
      const int others_equal = f->q[0][c1] == f->q[1][c1] && f->q[0][c2] == f->q[1][c2];
      int best_a = qa, best_b = qb;
      float best = f->error;
      for (int m = 0; m < 6; m++) {
        const int a = qa + move[m][0], bq = qb + move[m][1];
        if (a < 0 || a > top || bq < 0 || bq > top)
          continue;
        if (!f->three && others_equal && a == bq) {
          /* a one-colour block: every channel's colours change */
          fit g = *f;
          g.q[0][c] = a, g.q[1][c] = bq;
          assess(b, &g);
          if (g.error < best)
            best = g.error, best_a = a, best_b = bq;
          continue;
        }
        float v[4];
        channel_colours(c, a, bq, f->three, v);
        const v4 v0 = v4_all(v[0]), v1 = v4_all(v[1]), v2 = v4_all(v[2]), v3 = v4_all(v[3]);
        v4 sum = v4_all(0);
        for (int g = 0; g < 4; g++) {
          const v4 x = v4_load(b->x[c] + 4 * g);
          const v4 d0 = v4_sub(x, v0), d1 = v4_sub(x, v1), d2 = v4_sub(x, v2),
                   d3 = v4_sub(x, v3);
          const v4 s0 = v4_add(rest[0][g], v4_mul(d0, d0));
          const v4 s1 = v4_add(rest[1][g], v4_mul(d1, d1));
          const v4 s2 = v4_add(rest[2][g], v4_mul(d2, d2));
          const v4 s3 = v4_add(rest[3][g], v4_mul(d3, d3));
          const v4 t = v4_mul(v4_load(b->w + 4 * g),
                              v4_min(v4_min(s3, s2), v4_min(s1, s0)));
          sum = g ? v4_add(sum, t) : t;
        }
        const float e = v4_sum(sum);
        if (e < best)
          best = e, best_a = a, best_b = bq;
      }
      if (best < f->error)
        f->q[0][c] = best_a, f->q[1][c] = best_b, f->error = best, moved = 1, unmoved = 0;
      else
        unmoved++;
    }
    if (!(f->error < before))
      break;
  }
  if (moved)
    assess(b, f);
}

/* End points from two colours in codes, rounded to the grid. */
static void round_ends(const float a[3], const float b[3], int three, fit *f) {
  for (int c = 0; c < 3; c++) {
    const float s = (float)levels[c] / 255.0f;
    const float u = a[c] < 0 ? 0 : a[c] > 255 ? 255 : a[c];
    const float v = b[c] < 0 ? 0 : b[c] > 255 ? 255 : b[c];
    f->q[0][c] = round_up(u * s);
    f->q[1][c] = round_up(v * s);
  }
  f->three = three;
}

/* The end point pair of one channel whose colour 2 (of either mode) is
 * nearest v, for a block of one colour. */
static void one_colour(float v, int top, int three, int *qa, int *qb) {
  const int centre = round_up(v * (float)top / 255.0f);
  float best = 0;
  int first = 1;
  for (int a = centre - 2; a <= centre + 2; a++)
    for (int bq = centre - 2; bq <= centre + 2; bq++) {
      if (a < 0 || a > top || bq < 0 || bq > top)
        continue;
      const float d = (float)(three ? half(a + bq, top) : third(2 * a + bq, top)) - v;
      if (first || d * d < best)
        best = d * d, *qa = a, *qb = bq, first = 0;
    }
}

/* A split's sums of the squared weights of end point 0 (aa) and 1 (bb)
 * and of their products (ab), end point 0's weights 0, 1/3, 2/3, 1 over
 * the runs of i, j - i, k - j and n - k texels, and 1 / (aa bb - ab^2)
 * (0 when that is too small to fit: the split is skipped). */
static void split_terms(int i, int j, int k, int n, float terms[4]) {
  const float n0 = (float)i, n1 = (float)(j - i), n2 = (float)(k - j), n3 = (float)(n - k);
  const float aa = (n1 + 4.0f * n2) * (1.0f / 9.0f) + n3;
  const float bb = n0 + (4.0f * n1 + n2) * (1.0f / 9.0f);
  const float ab = 2.0f * (n1 + n2) * (1.0f / 9.0f), det = aa * bb - ab * ab;
  terms[0] = aa, terms[1] = bb, terms[2] = ab;
  terms[3] = det > 1e-3f ? 1.0f / det : 0.0f;
}

/* split_terms of every split of a whole block (n = 16), made once (a
 * block tries up to 125 of them), split i, j, k's at split_row[k] +
 * split_row2[j] + i (0 <= i <= j <= k <= 16: 969 splits). */
static float split_terms_16[969][4];
static int split_row[17], split_row2[17];
/* The order of the offsets of the three boundaries, [di + 2][dj + 2][dk +
 * 2]: those within one step first (the 27 of the narrow window), then the
 * rest of the 57 of the wide one (two steps at most, three in all), then
 * the rest of the 125, which are not tried (on the ssbumps and normal maps
 * of rock06, lava01, a noise map and the rivet panel they gained 0.002 dB
 * at most, for 6% of the instructions). */
static unsigned char offset_rank[5][5][5];

static void offsets_make(void) {
  for (int k = 0; k <= 16; k++) {
    split_row[k] = k * (k + 1) * (k + 2) / 6;
    split_row2[k] = k * (k + 1) / 2;
  }
  for (int k = 0; k <= 16; k++)
    for (int j = 0; j <= k; j++)
      for (int i = 0; i <= j; i++)
        split_terms(i, j, k, 16, split_terms_16[split_row[k] + split_row2[j] + i]);
  int m = 0;
  for (int ring = 0; ring < 3; ring++)
    for (int di = -2; di <= 2; di++)
      for (int dj = -2; dj <= 2; dj++)
        for (int dk = -2; dk <= 2; dk++) {
          const int near = abs(di) <= 1 && abs(dj) <= 1 && abs(dk) <= 1;
          const int wide = !near && abs(di) + abs(dj) + abs(dk) <= 3;
          if (ring != (near ? 0 : wide ? 1 : 2))
            continue;
          offset_rank[di + 2][dj + 2][dk + 2] = (unsigned char)m;
          m++;
        }
}

/* The texels of the image (w > 0) in order of t, equals in the order of
 * their places (an insertion sort), their count in *n. */
static void sort_texels(const block *b, const float t[16], int order[16], int *n) {
  int m = 0;
  for (int i = 0; i < 16; i++)
    if (b->w[i] > 0) {
      int k = m++;
      for (; k > 0 && t[order[k - 1]] > t[i]; k--)
        order[k] = order[k - 1];
      order[k] = i;
    }
  *n = m;
}

/* The cluster-fit start: the texels sorted along the axis, split into the
 * four indices' runs (i texels at end point 1, then j - i at colour 3, k -
 * j at colour 2, the rest at end point 0: squish's total orderings), for
 * the splits within a texel of where the extremes' palette splits them
 * (wide: two texels, three moves in all);
 * each scored by squish's measure (least-squares end points for the split,
 * rounded to the grid, their error given the split). The best split's
 * indices are fitted as any others. 0 when none fits. */
static int cluster_start(const block *b, const float t[16], int wide, fit *out) {
  int order[16], n;
  sort_texels(b, t, order, &n);
  /* prefix sums of the sorted texels, R, G, B and 0 */
  float sum[17][4];
  memset(sum[0], 0, sizeof sum[0]);
  for (int k = 0; k < n; k++) {
    for (int c = 0; c < 3; c++)
      sum[k + 1][c] = sum[k][c] + b->x[c][order[k]];
    sum[k + 1][3] = 0;
  }
  /* Where the extremes' palette splits the sorted texels: a third of the
   * way and two thirds, halfway between the colours. */
  const float lo = t[order[0]], span = t[order[n - 1]] - lo;
  int split[3] = {0, 0, 0};
  for (int k = 0; k < n; k++) {
    const float u = (t[order[k]] - lo) * 3.0f;
    for (int s = 0; s < 3; s++)
      if (u < ((float)s + 0.5f) * span)
        split[s] = k + 1;
  }
  const v4 to_grid = v4_set(31.0f / 255.0f, 63.0f / 255.0f, 31.0f / 255.0f, 0.0f);
  const v4 from_grid = v4_set(255.0f / 31.0f, 255.0f / 63.0f, 255.0f / 31.0f, 0.0f);
  const v4 zero = v4_all(0.0f), top = v4_all(255.0f), third_of = v4_all(1.0f / 3.0f);
  const v4 total = v4_load(sum[n]);
  float best = 0;
  int found = 0, best_rank = 0, bi = 0, bj = 0, bk = 0;
  /* The splits to try: each boundary moved by up to one texel (narrow:
   * 27 offsets), or (wide) by up to two with at most three moves in all
   * (57), those that are splits; of equals the first in the offsets'
   * order (their rank). */
  static pthread_once_t offsets_once = PTHREAD_ONCE_INIT;
  pthread_once(&offsets_once, offsets_make);
  const int r = wide ? 2 : 1, tries = wide ? 57 : 27;
  const int i1 = split[0] + r < n ? split[0] + r : n, k0 = split[2] - r > 0 ? split[2] - r : 0;
  for (int i = split[0] - r > 0 ? split[0] - r : 0; i <= i1; i++)
    for (int j = split[1] - r > i ? split[1] - r : i; j <= split[1] + r && j <= n; j++)
      for (int k = k0 > j ? k0 : j; k <= split[2] + r && k <= n; k++) {
        const int rank = offset_rank[i - split[0] + 2][j - split[1] + 2][k - split[2] + 2];
        if (rank >= tries)
          continue;
        float terms[4];
        if (n == 16)
          memcpy(terms, split_terms_16[split_row[k] + split_row2[j] + i], sizeof terms);
        else
          split_terms(i, j, k, n, terms);
        const float aa = terms[0], bb = terms[1], ab = terms[2], inv = terms[3];
        if (!(inv > 0))
          continue;
        const v4 bx = v4_mul(
            v4_add(v4_add(v4_load(sum[i]), v4_load(sum[j])), v4_load(sum[k])), third_of);
        const v4 ax = v4_sub(total, bx);
        const v4 vaa = v4_all(aa), vbb = v4_all(bb), vab = v4_all(ab);
        v4 a = v4_mul(v4_sub(v4_mul(ax, vbb), v4_mul(bx, vab)), v4_all(inv));
        v4 v = v4_mul(v4_sub(v4_mul(bx, vaa), v4_mul(ax, vab)), v4_all(inv));
        a = v4_min(v4_max(a, zero), top);
        v = v4_min(v4_max(v, zero), top);
        a = v4_mul(v4_trunc(v4_add(v4_mul(a, to_grid), v4_all(0.5f))), from_grid);
        v = v4_mul(v4_trunc(v4_add(v4_mul(v, to_grid), v4_all(0.5f))), from_grid);
        /* aa a^2 + bb v^2 + 2 ab a v - 2 (a ax + v bx), per channel */
        const v4 e4 =
            v4_sub(v4_add(v4_add(v4_mul(vaa, v4_mul(a, a)), v4_mul(vbb, v4_mul(v, v))),
                          v4_mul(v4_all(2.0f * ab), v4_mul(a, v))),
                   v4_mul(v4_all(2.0f), v4_add(v4_mul(a, ax), v4_mul(v, bx))));
        const float e = (v4_lane(e4, 0) + v4_lane(e4, 1)) + v4_lane(e4, 2);
        if (!found || e < best || (e == best && rank < best_rank))
          best = e, best_rank = rank, bi = i, bj = j, bk = k, found = 1;
      }
  if (!found)
    return 0;
  int index[16];
  for (int i = 0; i < 16; i++)
    index[i] = 0;
  for (int k = 0; k < n; k++)
    index[order[k]] = k < bi ? 1 : k < bj ? 3 : k < bk ? 2 : 0;
  return fit_indices(b, index, 0, out);
}

/* Writes f (assessed) as the decoder must read it: 4-colour mode with c0
 * > c1 (end points swapped if need be; equal ones make a one-colour
 * block), 3-colour mode with c0 <= c1. */
static void write_block(const fit *f, unsigned char out[8]) {
  unsigned c0 = pack(f->q[0]), c1 = pack(f->q[1]);
  /* swapping the end points swaps colours 2 and 3 of a 4-colour block;
   * colour 2 of a 3-colour block is halfway, either way */
  static const unsigned char swapped[2][4] = {{1, 0, 3, 2}, {1, 0, 2, 2}};
  const int swap = f->three ? c0 > c1 : c0 < c1;
  if (swap) {
    const unsigned t = c0;
    c0 = c1, c1 = t;
  }
  uint32_t bits = 0;
  for (int i = 0; i < 16; i++) {
    int k = f->index[i];
    if (f->three && k == 3)
      k = 2; /* colour 2 repeated: never black */
    if (!f->three && c0 == c1)
      k = 0;
    else if (swap)
      k = swapped[f->three][k];
    bits |= (uint32_t)k << (2 * i);
  }
  out[0] = (unsigned char)(c0 & 255), out[1] = (unsigned char)(c0 >> 8);
  out[2] = (unsigned char)(c1 & 255), out[3] = (unsigned char)(c1 >> 8);
  for (int k = 0; k < 4; k++)
    out[4 + k] = (unsigned char)(bits >> (8 * k));
}

/* Error thresholds, in squared codes summed over the block's texels and
 * channels (16 texels 1 code off in each channel: 48). A block the
 * least-squares fit leaves above `cluster_over` gets the cluster-fit start
 * too: below it the start seldom wins (on rock06's ssbump at 1024 x 1024,
 * skipping it below 256 cost 0.002 dB and saved 18% of the instructions;
 * from 256 to 400, with the wide window cut to 57 splits, 0.002 to 0.007
 * dB on the ssbumps and 0.04 at most on any map, each still above
 * libsquish's cluster fit, for 13% fewer instructions). The
 * wide window of splits is for blocks also above `wide_over` whose texels
 * spread over more than `wide_spread` (squared distances from their
 * mean): +0.01 dB on lava01's rough ssbump, for 7% more instructions on
 * it and 3% on rock06. The local search's second pass is for blocks the
 * least-squares fit leaves above `second_over`: below it the pass cost
 * 2.6% of the instructions for 0.0005 dB on the ssbumps and 0.001 to 0.013
 * on the normal maps. */
enum { cluster_over = 400, wide_over = 1000, wide_spread = 3000, second_over = 128 };

/* The fits of 4-colour mode (quick: least squares and one pass of the
 * local search alone), the best kept in *best. */
static void fit_four(const block *b, const float ends[2][3], const float t[16],
                     float spread, int quick, fit *best) {
  fit f;
  round_ends(ends[0], ends[1], 0, &f);
  assess(b, &f);
  refine(b, &f, 1);
  const float first = f.error;
  if (!quick && first > cluster_over) {
    fit g;
    if (cluster_start(b, t, first > wide_over && spread > wide_spread, &g)) {
      assess(b, &g);
      refine(b, &g, 1);
      keep_better(&f, &g);
    }
  }
  local_search(b, &f, quick || first <= second_over ? 1 : 2);
  keep_better(best, &f);
}

/* 3-colour mode: least squares from the extremes. It wins on about 1% of
 * the blocks of a smooth map, by little: the local search, which would
 * cost as much again, gained it nothing measurable there. */
static void fit_three(const block *b, const float ends[2][3], fit *best) {
  fit f;
  round_ends(ends[0], ends[1], 1, &f);
  assess(b, &f);
  refine(b, &f, 1);
  keep_better(best, &f);
}

void bb__bc1_encode(const float texels[64], int mask, int three, int quick,
                    unsigned char out[8]) {
  pthread_once(&channel_values_once, channel_values_make);
  block b;
  int first = 0;
  while (first < 15 && !(mask >> first & 1))
    first++;
  /* each texel's channels a lane each (the fourth, alpha, unused) */
  const v4 zero = v4_all(0.0f), one = v4_all(1.0f), code = v4_all(255.0f);
  v4 lo4 = code, hi4 = zero, sum4 = zero;
  b.n = 0;
  for (int i = 0; i < 16; i++) {
    const int in = mask >> i & 1, s = in ? i : first;
    b.w[i] = in ? 1.0f : 0.0f;
    const v4 v = v4_load(texels + 4 * s);
    /* v > 0 ? (v < 1 ? 255 v : 255) : 0 (NaN: 0) */
    const v4 x = v4_select_lt(zero, v, v4_select_lt(v, one, v4_mul(v, code), code), zero);
    v4_store(b.rgb1[i], x);
    b.rgb1[i][3] = 1.0f;
    for (int c = 0; c < 3; c++)
      b.x[c][i] = b.rgb1[i][c];
    lo4 = v4_min(x, lo4);
    hi4 = v4_max(x, hi4);
    sum4 = v4_add(sum4, v4_mul(v4_all(b.w[i]), x));
    b.n += b.w[i];
  }
  float lo[3], hi[3], mean[3];
  for (int c = 0; c < 3; c++) {
    lo[c] = v4_lane(lo4, c), hi[c] = v4_lane(hi4, c);
    mean[c] = v4_lane(sum4, c) / b.n;
  }
  fit best;
  best.error = INFINITY;
  /* One colour (to the 8-bit code): the pair whose in-between colour is
   * nearest, in each mode. */
  if (round_up(lo[0]) == round_up(hi[0]) && round_up(lo[1]) == round_up(hi[1]) &&
      round_up(lo[2]) == round_up(hi[2])) {
    for (int mode = 0; mode <= three; mode++) {
      fit f;
      f.three = mode;
      for (int c = 0; c < 3; c++)
        one_colour(mean[c], levels[c], mode, &f.q[0][c], &f.q[1][c]);
      assess(&b, &f);
      keep_better(&best, &f);
    }
    write_block(&best, out);
    return;
  }
  float cov[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < 16; i++) {
    const float d0 = b.x[0][i] - mean[0], d1 = b.x[1][i] - mean[1],
                d2 = b.x[2][i] - mean[2];
    cov[0] += b.w[i] * d0 * d0, cov[1] += b.w[i] * d0 * d1, cov[2] += b.w[i] * d0 * d2;
    cov[3] += b.w[i] * d1 * d1, cov[4] += b.w[i] * d1 * d2, cov[5] += b.w[i] * d2 * d2;
  }
  /* Power iteration from the bounding box's diagonal, each side signed as
   * its channel leans against the channel that varies most (a start
   * orthogonal to the axis would never turn to it). */
  const int at[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}}; /* cov of (c, d) */
  const int ref = cov[0] >= cov[3] && cov[0] >= cov[5] ? 0 : cov[3] >= cov[5] ? 1 : 2;
  float axis[3];
  for (int c = 0; c < 3; c++)
    axis[c] = cov[at[ref][c]] < 0 ? lo[c] - hi[c] : hi[c] - lo[c];
  for (int it = 0; it < 6; it++) {
    const float v0 = cov[0] * axis[0] + cov[1] * axis[1] + cov[2] * axis[2];
    const float v1 = cov[1] * axis[0] + cov[3] * axis[1] + cov[4] * axis[2];
    const float v2 = cov[2] * axis[0] + cov[4] * axis[1] + cov[5] * axis[2];
    /* the largest magnitude (no NaN here: the texels are clamped) */
    const float a0 = fabsf(v0), a1 = fabsf(v1), a2 = fabsf(v2);
    const float m12 = a1 > a2 ? a1 : a2, m = a0 > m12 ? a0 : m12;
    if (!(m > 0))
      break;
    axis[0] = v0 / m, axis[1] = v1 / m, axis[2] = v2 / m;
  }
  float len2 = axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2];
  if (!(len2 > 0)) /* no spread left: the box's diagonal */
    for (int c = 0; c < 3; c++)
      axis[c] = hi[c] - lo[c], len2 += axis[c] * axis[c];
  /* each texel's place along the axis, four texels a lane each; the
   * extremes from 0 (a minimum or maximum of the same values in any
   * order: the same bits) */
  float t[16];
  v4 tmin4 = zero, tmax4 = zero;
  for (int g = 0; g < 16; g += 4) {
    const v4 tg = v4_add(
        v4_add(v4_mul(v4_sub(v4_load(b.x[0] + g), v4_all(mean[0])), v4_all(axis[0])),
               v4_mul(v4_sub(v4_load(b.x[1] + g), v4_all(mean[1])), v4_all(axis[1]))),
        v4_mul(v4_sub(v4_load(b.x[2] + g), v4_all(mean[2])), v4_all(axis[2])));
    v4_store(t + g, tg);
    tmin4 = v4_min(tg, tmin4);
    tmax4 = v4_max(tg, tmax4);
  }
  float tmin = 0, tmax = 0;
  for (int l = 0; l < 4; l++) {
    const float lmin = v4_lane(tmin4, l), lmax = v4_lane(tmax4, l);
    tmin = lmin < tmin ? lmin : tmin;
    tmax = lmax > tmax ? lmax : tmax;
  }
  float ends[2][3];
  for (int c = 0; c < 3; c++) {
    ends[0][c] = mean[c] + tmax / len2 * axis[c];
    ends[1][c] = mean[c] + tmin / len2 * axis[c];
  }
  fit_four(&b, ends, t, cov[0] + cov[3] + cov[5], quick, &best);
  if (three && !quick)
    fit_three(&b, ends, &best);
  write_block(&best, out);
}
