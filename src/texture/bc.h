/* bc.h: one 4 x 4 block of BC1 colour (bc1.c) or BC4 (bc4.c), encoded
 * and decoded; blocks.c makes images of them.
 *
 * The decoders follow the Direct3D rules exactly, each value rounded once
 * at the end, and the encoders fit what those decoders give: BC1 end
 * points of 5:6:5 bits as round(255 v / 31) and round(255 v / 63), colour
 * 2 = round(255 (2 e0 + e1) / 3) and colour 3 = round(255 (e0 + 2 e1) / 3)
 * (e the end points in [0, 1]) when c0 > c1 as 16-bit numbers (4-colour
 * mode; always in BC3, whose colour block has no other), else colour 2 =
 * round(255 (e0 + e1) / 2) and colour 3 black (3-colour mode); BC4 values
 * a0, a1 and 6 between, round(((7 - i) a0 + i a1) / 7), when a0 > a1, else
 * 4 between, round(((5 - i) a0 + i a1) / 5), then 0 and 255. Halves round
 * up. Decoders in use round on the way (truncating, or adding one before
 * dividing) and land within one code of these. */
#ifndef BB_TEXTURE_BC_H
#define BB_TEXTURE_BC_H

#ifdef __cplusplus
extern "C" {
#endif

/* Sixteen terms, one a texel, summed as four lanes of four and then the
 * lanes: the order a 4-wide vector sum takes, fixed whatever the compiler
 * makes of it, so an error depends on the texels alone. */
static inline float bb__sum16(const float e[16]) {
  float lane[4];
  for (int l = 0; l < 4; l++)
    lane[l] = ((e[l] + e[4 + l]) + e[8 + l]) + e[12 + l];
  return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}

/* Encodes channels 0, 1, 2 of the texels of texels[4 * i + c] (i = 4 y +
 * x; values in [0, 1], clamped; NaN counts as 0) whose bit i is set in
 * mask (at least one) into an 8-byte BC1 colour block. three: 3-colour
 * mode may be used (BC1); 0: never (BC3's colour block). Colour 3 of a
 * 3-colour block (black, transparent in BC1 with alpha) is never used.
 * quick: the least-squares fit and one pass of the local search alone
 * (bc1.c), about half the work. */
void bb__bc1_encode(const float texels[64], int mask, int three, int quick,
                    unsigned char out[8]);

/* Decodes an 8-byte BC1 colour block into rgba[4 * i + c] for its 16
 * texels: R, G, B and A (255, or 0 for colour 3 of a 3-colour block).
 * four: a BC3 colour block, always 4-colour. */
void bb__bc1_decode(const unsigned char block[8], int four, unsigned char rgba[64]);

/* Encodes channel c of texels (as bb__bc1_encode reads them) into an
 * 8-byte BC4 block (also BC3's alpha block and each half of BC5). */
void bb__bc4_encode(const float texels[64], int c, int mask, unsigned char out[8]);

/* Decodes an 8-byte BC4 block into out[stride * i] for its 16 texels. */
void bb__bc4_decode(const unsigned char block[8], unsigned char *out, int stride);

#ifdef __cplusplus
}
#endif

#endif /* BB_TEXTURE_BC_H */
