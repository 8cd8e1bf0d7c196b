// squish.cpp: BC1/BC3/BC4/BC5 blocks through libsquish, the only file that
// includes it (blocks.h is its C face).
//
// A firewall like io_oiio.cpp: guarded() turns every exception into a
// bb_status with a message; nothing thrown crosses into C.
//
// Why libsquish 1.15 and not NVIDIA Texture Tools 2.0.8 (both Debian 12, both
// MIT): on rock06's 1024 x 1024 maps (tools/bench_blocks.sh) squish's cluster
// fit is 4.3 dB better on BC1 normal and 4.1 to 4.7 dB on BC1 ssbump (BC4, BC5
// are a tie); nvtt 2.0.8 turns some opaque texels of BC1 blocks into black
// (3-colour mode's fourth entry: errors of 255 codes), and its BC1 output
// differs from run to run on the same input; and nvtt takes only
// 8-bit input through its own pipeline with its own mip maps, where the
// project has its own (bb_mip_chain). nvtt also carries a private copy of
// squish whose symbols clash with libsquish's: the two cannot share a process
// (a crash in squish::ColourFit::Compress), so the benchmark runs nvtt as its
// own program (nvcompress).
//
// Threads: squish::CompressImage runs an OpenMP loop (libsquish links
// libgomp) whose thread count the caller does not choose; this file calls
// CompressMasked per block instead, on bb__parallel_for's threads. A block
// depends only on its 16 texels, so the bytes are the same on any count.

#include "core/internal.h"
#include "texture/blocks.h"

#include <squish.h>

#include <atomic>
#include <cstring>
#include <exception>
#include <new>

namespace {

// Runs fn, turning any exception into a status and a message in err.
template <typename Fn> bb_status guarded(bb_error *err, Fn &&fn) {
  try {
    return fn();
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "block compression: out of memory");
  } catch (const std::exception &e) {
    return bb__fail(err, BB_ERR_FORMAT, "block compression: %s", e.what());
  } catch (...) {
    return bb__fail(err, BB_ERR_FORMAT, "block compression: unknown error");
  }
}

int squish_flags(bb__block_format format, int fast) {
  const int fit = fast ? squish::kColourRangeFit : squish::kColourClusterFit;
  switch (format) {
  case BB__BLOCK_BC1: return squish::kDxt1 | fit;
  case BB__BLOCK_BC3: return squish::kDxt5 | fit;
  case BB__BLOCK_BC4: return squish::kBc4;
  case BB__BLOCK_BC5: return squish::kBc5;
  case BB__BLOCK_BC2: return squish::kDxt3; // decoded only: bb__blocks_compress refuses it
  }
  return 0;
}

// Round half up to 0..255, NaN to 0 (as io_oiio.cpp quantises 8-bit files).
inline unsigned char to_byte(float v) {
  double u = v > 0.0f ? (double)v : 0.0;
  u = u < 1.0 ? u : 1.0;
  return (unsigned char)(u * 255.0 + 0.5);
}

struct Job {
  const float *rgba;
  int width, height, blocks_wide;
  int flags;
  size_t block_bytes;
  unsigned char *out;
  std::atomic<int> failed{0};
};

// One row of blocks: gathers each block's 16 texels (those inside the image
// set in the mask) and compresses it. Nothing here allocates or throws; the
// catch only keeps an exception from leaving a worker thread.
void compress_row(void *user, int block_row) {
  Job *job = static_cast<Job *>(user);
  try {
    unsigned char texels[16 * 4];
    for (int bx = 0; bx < job->blocks_wide; bx++) {
      int mask = 0;
      std::memset(texels, 0, sizeof texels);
      for (int py = 0; py < 4; py++) {
        const int y = block_row * 4 + py;
        if (y >= job->height)
          break;
        for (int px = 0; px < 4; px++) {
          const int x = bx * 4 + px;
          if (x >= job->width)
            break;
          const float *t = job->rgba + ((size_t)y * (size_t)job->width + (size_t)x) * 4;
          unsigned char *d = texels + (py * 4 + px) * 4;
          for (int c = 0; c < 4; c++)
            d[c] = to_byte(t[c]);
          mask |= 1 << (py * 4 + px);
        }
      }
      unsigned char *block =
          job->out + ((size_t)block_row * (size_t)job->blocks_wide + (size_t)bx) * job->block_bytes;
      squish::CompressMasked(texels, mask, block, job->flags);
    }
  } catch (...) {
    job->failed.store(1);
  }
}

} // namespace

extern "C" size_t bb__block_bytes(bb__block_format format) {
  return format == BB__BLOCK_BC1 || format == BB__BLOCK_BC4 ? 8 : 16;
}

extern "C" size_t bb__blocks_size(bb__block_format format, int width, int height) {
  if (width <= 0 || height <= 0)
    return 0;
  return (size_t)((width + 3) / 4) * (size_t)((height + 3) / 4) * bb__block_bytes(format);
}

extern "C" bb_status bb__blocks_compress(const float *rgba, int width, int height,
                                         bb__block_format format, int fast, int threads,
                                         unsigned char *out, bb_error *err) {
  if (format < BB__BLOCK_BC1 || format > BB__BLOCK_BC5)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: unknown block format %d",
                    (int)format);
  if (!rgba || !out || width <= 0 || height <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no image (%d x %d)", width,
                    height);
  return guarded(err, [&]() -> bb_status {
    Job job;
    job.rgba = rgba;
    job.width = width;
    job.height = height;
    job.blocks_wide = (width + 3) / 4;
    job.flags = squish_flags(format, fast);
    job.block_bytes = bb__block_bytes(format);
    job.out = out;
    bb_status st = bb__parallel_for((height + 3) / 4, threads, compress_row, &job, nullptr,
                                    nullptr, err);
    if (st == BB_OK && job.failed.load())
      st = bb__fail(err, BB_ERR_FORMAT, "block compression: the codec failed");
    return st;
  });
}

// ------------------------------------------------------------- decoding
//
// The reading side (VTF and DDS inputs), apart from the compression above.
// libsquish 1.15 decodes BC1, BC2 and BC3 blocks, but its Decompress takes a
// BC4 or BC5 block as a BC1 colour block (FixFlags keeps the flag, but only
// BC1/2/3 have a decoder). A BC4 block is, byte for byte, the alpha half of
// a BC3 block (two 8-bit end points, 3-bit indices, the same two modes), so
// a BC4 block is decoded as the alpha of a BC3 block made of it and an
// empty colour block, by libsquish's own BC3 alpha decoder; BC5 is two BC4
// blocks, R then G.

namespace {

// BC4 block b into channel c of 16 RGBA texels.
void decode_bc4(const unsigned char *b, unsigned char *texels, int c) {
  unsigned char bc3[16] = {0};
  unsigned char decoded[16 * 4];
  std::memcpy(bc3, b, 8);
  squish::Decompress(decoded, bc3, squish::kDxt5);
  for (int i = 0; i < 16; i++)
    texels[4 * i + c] = decoded[4 * i + 3];
}

void decode_block(const unsigned char *b, bb__block_format format, unsigned char *texels) {
  switch (format) {
  case BB__BLOCK_BC1: squish::Decompress(texels, b, squish::kDxt1); return;
  case BB__BLOCK_BC2: squish::Decompress(texels, b, squish::kDxt3); return;
  case BB__BLOCK_BC3: squish::Decompress(texels, b, squish::kDxt5); return;
  case BB__BLOCK_BC4:
  case BB__BLOCK_BC5:
    for (int i = 0; i < 16; i++) {
      texels[4 * i + 0] = texels[4 * i + 1] = texels[4 * i + 2] = 0;
      texels[4 * i + 3] = 255;
    }
    decode_bc4(b, texels, 0);
    if (format == BB__BLOCK_BC5)
      decode_bc4(b + 8, texels, 1);
    return;
  }
}

} // namespace

extern "C" bb_status bb__blocks_decompress(const unsigned char *blocks, int width, int height,
                                           bb__block_format format, unsigned char *rgba,
                                           bb_error *err) {
  if (format < BB__BLOCK_BC1 || format > BB__BLOCK_BC2)
    return bb__fail(err, BB_ERR_ARGUMENT, "block decoding: unknown block format %d",
                    (int)format);
  if (!blocks || !rgba || width <= 0 || height <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "block decoding: no image (%d x %d)", width, height);
  return guarded(err, [&]() -> bb_status {
    const size_t block_bytes = bb__block_bytes(format);
    const int blocks_wide = (width + 3) / 4;
    unsigned char texels[16 * 4];
    for (int by = 0; by < (height + 3) / 4; by++)
      for (int bx = 0; bx < blocks_wide; bx++) {
        decode_block(blocks + ((size_t)by * (size_t)blocks_wide + (size_t)bx) * block_bytes,
                     format, texels);
        for (int py = 0; py < 4 && by * 4 + py < height; py++)
          for (int px = 0; px < 4 && bx * 4 + px < width; px++)
            std::memcpy(rgba + ((size_t)(by * 4 + py) * (size_t)width + (size_t)(bx * 4 + px)) * 4,
                        texels + (py * 4 + px) * 4, 4);
      }
    return BB_OK;
  });
}
