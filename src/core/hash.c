/* hash.c: the 64-bit FNV-1a hashes provenance records (of images, meshes,
 * bases): the same value on any host. */

#include "core/internal.h"

#include <string.h>

#define FNV64_PRIME 0x100000001b3ULL

uint64_t bb__fnv1a_u32(uint64_t h, uint32_t v) {
  /* Little-endian byte order whatever the host, so a hash recorded on one
   * machine can be checked on another. */
  for (int i = 0; i < 4; i++) {
    h ^= (v >> (8 * i)) & 0xffu;
    h *= FNV64_PRIME;
  }
  return h;
}

uint64_t bb__fnv1a_floats(uint64_t h, const float *v, size_t n) {
  for (size_t i = 0; i < n; i++) {
    uint32_t bits;
    memcpy(&bits, &v[i], sizeof bits);
    h = bb__fnv1a_u32(h, bits);
  }
  return h;
}

uint64_t bb__image_hash(const bb_image *img) {
  uint64_t h = BB__FNV64_OFFSET;
  if (!img)
    return h;
  h = bb__fnv1a_u32(h, (uint32_t)img->width);
  h = bb__fnv1a_u32(h, (uint32_t)img->height);
  h = bb__fnv1a_u32(h, (uint32_t)img->channels);
  if (!img->pixels || img->width <= 0 || img->height <= 0 || img->channels <= 0)
    return h;
  size_t count = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  return bb__fnv1a_floats(h, img->pixels, count);
}
