/* test_bc1_plain.c: bc1.c built a second time with its four-float lanes
 * in plain C (BB_BC1_PLAIN), against the library's (SSE2 on x86-64): the
 * same bytes, so a build for a machine without SSE2 writes the same
 * textures. */
#include <criterion/criterion.h>

#include <stdint.h>
#include <string.h>

#define BB_BC1_PLAIN 1
#define bb__bc1_encode plain_bc1_encode
#define bb__bc1_decode plain_bc1_decode
#include "texture/bc1.c"
#undef bb__bc1_encode
#undef bb__bc1_decode

/* The library's (texture/bc.h, under its own name). */
void bb__bc1_encode(const float texels[64], int mask, int three, int quick,
                    unsigned char out[8]);

Test(blocks, plain_c_lanes_give_the_same_bytes) {
  uint32_t s = 2024;
  for (int n = 0; n < 20000; n++) {
    float rgba[64];
    const float spread = (float)(n % 5) * 0.1f + 0.02f;
    for (int i = 0; i < 64; i++) {
      s ^= s << 13, s ^= s >> 17, s ^= s << 5;
      const float noise = (float)(s % 10000u) / 10000.0f;
      rgba[i] = 0.3f + spread * (noise + (float)(i / 4 % 4 + i / 16) * 0.1f);
    }
    const int mask = n % 7 ? 0xffff : 0x0f0f;
    for (int mode = 0; mode < 4; mode++) {
      unsigned char a[8], b[8];
      bb__bc1_encode(rgba, mask, mode & 1, mode >> 1, a);
      plain_bc1_encode(rgba, mask, mode & 1, mode >> 1, b);
      cr_assert_eq(memcmp(a, b, 8), 0, "block %d, mode %d", n, mode);
    }
  }
}
