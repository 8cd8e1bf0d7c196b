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
// CompressMasked per block instead, on bb__parallel_for's threads, one job
// for all the levels of a texture. A block depends only on its 16 texels, so
// the bytes are the same on any count.
//
// Fit: a colour level (BC1, BC3's colour) is fitted by cluster fit and by
// range fit, and keeps range fit's blocks only where that level's squared
// error is under 90% of cluster fit's (blocks.h). Per level, with a margin,
// because per block the ranking is the decoder's rounding: choosing each
// block by libsquish's decoder moved an exact decoder's PSNR by -0.05 to
// +0.10 dB per level on rock06 and a 4096 x 16 strip; two decoders' ratios
// of the two fits' errors differed by up to 0.2 dB (4.7%), so a 10% margin
// keeps the choice a gain under either. On every level of those maps cluster
// fit wins by 0.8 to 3.5 dB, so their bytes are what cluster fit alone made
// (docs/textures.md). The range fit and the two decodes cost about 2% of the
// cluster fit's instructions.

#include "core/internal.h"
#include "texture/blocks.h"

#include <squish.h>

#include <atomic>
#include <climits>
#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <vector>

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

int squish_flags(bb__block_format format, int fit) {
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

// Squared error, in 8-bit codes, of R, G, B of the texels in mask between
// texels and block as the codec decodes it.
int64_t colour_error(const unsigned char texels[64], int mask, const unsigned char *block,
                     int flags) {
  unsigned char decoded[64];
  squish::Decompress(decoded, block, flags);
  int64_t sum = 0;
  for (int i = 0; i < 16; i++)
    if (mask & (1 << i))
      for (int c = 0; c < 3; c++) {
        const int d = (int)decoded[4 * i + c] - (int)texels[4 * i + c];
        sum += d * d;
      }
  return sum;
}

struct Job {
  const bb__block_image *images;
  std::vector<int> first_row; // block row where each image starts; one more at the end
  int flags;                  // the codec's flags for the fit asked for
  size_t block_bytes;
  // BB__FIT_BEST on colour blocks: range fit's blocks of every image (at
  // the same offsets as the images' own), and each row's squared error
  // under either fit.
  bool both;
  int range_flags;
  std::vector<unsigned char> range;
  std::vector<size_t> range_at; // where each image's range blocks start
  std::vector<int64_t> cluster_error, range_error;
  std::atomic<int> failed{0};
};

// One row of blocks of one image: gathers each block's texels (those inside
// the image set in the mask) and compresses it. The catch only keeps an
// exception from leaving a worker thread.
void compress_row(void *user, int item) {
  Job *job = static_cast<Job *>(user);
  try {
    size_t k = 0;
    while (item >= job->first_row[k + 1])
      k++;
    const bb__block_image &img = job->images[k];
    const int block_row = item - job->first_row[k];
    const int blocks_wide = (img.width + 3) / 4;
    const int y0 = block_row * 4, h = img.height - y0 < 4 ? img.height - y0 : 4;
    const size_t row_at = (size_t)block_row * (size_t)blocks_wide * job->block_bytes;
    float rgba[64];
    unsigned char texels[64];
    int64_t cluster_error = 0, range_error = 0;
    for (int bx = 0; bx < blocks_wide; bx++) {
      const int x0 = bx * 4, w = img.width - x0 < 4 ? img.width - x0 : 4;
      img.texels(img.source, x0, y0, w, h, rgba);
      std::memset(texels, 0, sizeof texels);
      int mask = 0;
      for (int py = 0; py < h; py++)
        for (int px = 0; px < w; px++) {
          const int i = py * 4 + px;
          for (int c = 0; c < 4; c++)
            texels[4 * i + c] = to_byte(rgba[4 * i + c]);
          mask |= 1 << i;
        }
      const size_t at = row_at + (size_t)bx * job->block_bytes;
      unsigned char *block = img.out + at;
      squish::CompressMasked(texels, mask, block, job->flags);
      if (job->both) {
        unsigned char *range = job->range.data() + job->range_at[k] + at;
        squish::CompressMasked(texels, mask, range, job->range_flags);
        cluster_error += colour_error(texels, mask, block, job->flags);
        range_error += colour_error(texels, mask, range, job->flags);
      }
    }
    if (job->both) {
      job->cluster_error[(size_t)item] = cluster_error;
      job->range_error[(size_t)item] = range_error;
    }
  } catch (...) {
    job->failed.store(1);
  }
}

// bb__blocks_compress's source: rows of 4 floats a texel.
struct FloatImage {
  const float *rgba;
  int width;
};

void float_texels(const void *source, int x0, int y0, int w, int h, float rgba[64]) {
  const FloatImage *f = static_cast<const FloatImage *>(source);
  for (int y = 0; y < h; y++)
    std::memcpy(rgba + 16 * y, f->rgba + ((size_t)(y0 + y) * (size_t)f->width + (size_t)x0) * 4,
                (size_t)w * 4 * sizeof(float));
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

extern "C" bb_status bb__blocks_compress_images(const bb__block_image *images, int count,
                                                bb__block_format format, bb__block_fit fit,
                                                int threads, bb_error *err) {
  if (format < BB__BLOCK_BC1 || format > BB__BLOCK_BC5)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: unknown block format %d",
                    (int)format);
  if (fit < BB__FIT_BEST || fit > BB__FIT_CLUSTER)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: unknown fit %d", (int)fit);
  if (count < 0 || (count > 0 && !images))
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no images");
  for (int k = 0; k < count; k++)
    if (!images[k].texels || !images[k].out || images[k].width <= 0 || images[k].height <= 0)
      return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no image (%d x %d)",
                      images[k].width, images[k].height);
  return guarded(err, [&]() -> bb_status {
    Job job;
    job.images = images;
    job.first_row.push_back(0);
    job.block_bytes = bb__block_bytes(format);
    size_t bytes = 0;
    for (int k = 0; k < count; k++) {
      const int rows = (images[k].height + 3) / 4;
      if (job.first_row.back() > INT_MAX - rows)
        return bb__fail(err, BB_ERR_SIZE, "block compression: too many rows of blocks");
      job.first_row.push_back(job.first_row.back() + rows);
      job.range_at.push_back(bytes);
      bytes += bb__blocks_size(format, images[k].width, images[k].height);
    }
    const bool colour = format == BB__BLOCK_BC1 || format == BB__BLOCK_BC3;
    job.flags = squish_flags(format, fit == BB__FIT_RANGE ? squish::kColourRangeFit
                                                          : squish::kColourClusterFit);
    job.both = colour && fit == BB__FIT_BEST;
    job.range_flags = squish_flags(format, squish::kColourRangeFit);
    const int rows = job.first_row.back();
    if (job.both) {
      job.range.resize(bytes);
      job.cluster_error.resize((size_t)rows);
      job.range_error.resize((size_t)rows);
    }
    bb_status st = bb__parallel_for(rows, threads, compress_row, &job, nullptr, nullptr, err);
    if (st == BB_OK && job.failed.load())
      st = bb__fail(err, BB_ERR_FORMAT, "block compression: the codec failed");
    // Each level's errors added in row order, in integers: the choice is
    // the same on any thread count.
    for (int k = 0; st == BB_OK && job.both && k < count; k++) {
      int64_t cluster = 0, range = 0;
      for (int r = job.first_row[(size_t)k]; r < job.first_row[(size_t)k + 1]; r++)
        cluster += job.cluster_error[(size_t)r], range += job.range_error[(size_t)r];
      if (10 * range < 9 * cluster)
        std::memcpy(images[k].out, job.range.data() + job.range_at[(size_t)k],
                    bb__blocks_size(format, images[k].width, images[k].height));
    }
    return st;
  });
}

extern "C" bb_status bb__blocks_compress(const float *rgba, int width, int height,
                                         bb__block_format format, bb__block_fit fit,
                                         int threads, unsigned char *out, bb_error *err) {
  if (!rgba)
    return bb__fail(err, BB_ERR_ARGUMENT, "block compression: no image (%d x %d)", width,
                    height);
  const FloatImage source = {rgba, width};
  const bb__block_image image = {width, height, float_texels, &source, out};
  return bb__blocks_compress_images(&image, 1, format, fit, threads, err);
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
