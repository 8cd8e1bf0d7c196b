// oiio_mips.cpp: the OpenImageIO calls of mip chains: the box filter that
// makes each level (bb__image_resize_box, for mips.c) and the tiled,
// mip-mapped TIFF or OpenEXR file that holds them. The chain's checks are
// C (formats.c); the public writes are image_write.c.
#include "core/internal.h"
#include "image/oiio.h"
#include "image/exr_pool.h"
#include "image/formats.h"
#include "image/oiio_calls.h"
#include "image/oiio_guard.h"
#include "image/oiio_setup.h"
#include "image/oiio_proxy.h"
#include "image/quantise.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <new>
#include <vector>

using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

// Tile size of mip-mapped files: OpenEXR stores mip levels only in tiled
// files, and TIFF readers expect a tiled pyramid too.
constexpr int MIP_TILE = 64;

// Writes one level tile by tile, each from a full MIP_TILE x MIP_TILE buffer
// whose part past the image edge is zero. OpenImageIO 2.4's write_image
// leaves that part of edge tiles uninitialised (valgrind: uninitialised
// bytes reach deflate), so mip-mapped TIFFs came out different on every run
// (171557 to 198825 bytes for one 96 x 64 chain) and could carry stray
// memory. samples: the level's width x height x channels values of type.
template <typename T>
bool write_padded_tiles(ImageOutput &out, const bb_image &img, TypeDesc type,
                        const T *samples) {
  const size_t channels = (size_t)img.channels, tile = (size_t)MIP_TILE;
  std::vector<T> buffer(tile * tile * channels);
  for (int y0 = 0; y0 < img.height; y0 += MIP_TILE)
    for (int x0 = 0; x0 < img.width; x0 += MIP_TILE) {
      std::fill(buffer.begin(), buffer.end(), T(0));
      const int rows = std::min(MIP_TILE, img.height - y0), cols = std::min(MIP_TILE, img.width - x0);
      for (int r = 0; r < rows; r++)
        std::memcpy(&buffer[(size_t)r * tile * channels],
                    samples + ((size_t)(y0 + r) * (size_t)img.width + (size_t)x0) * channels,
                    (size_t)cols * channels * sizeof(T));
      if (!out.write_tile(x0, y0, 0, type, buffer.data())) return false;
    }
  return true;
}

// The codes of one level, as write_padded_tiles wants them.
template <typename T> bool write_level_codes(ImageOutput &out, const bb_image &img, bb_range range) {
  T *codes;
  if constexpr (sizeof(T) == 1)
    codes = bb__quantise_8(&img, range);
  else
    codes = bb__quantise_16(&img, range);
  if (!codes) throw std::bad_alloc();
  std::unique_ptr<T, void (*)(void *)> owned(codes, std::free);
  return write_padded_tiles(out, img, sizeof(T) == 1 ? TypeDesc::UINT8 : TypeDesc::UINT16,
                            codes);
}

// Encodes the chain into file_name (a temporary name whose extension picks
// TIFF or OpenEXR), level 0 first, each further level appended as a MIP
// level. proxy may be null. Returns "" or OpenImageIO's reason.
std::string encode_mips(const std::string &file_name, OIIO::Filesystem::IOProxy *proxy,
                        const bb_image *levels, int count, bb_depth depth, bb_range range,
                        const char *description, int threads) {
  // OpenEXR compresses tiles from the first open() to close(), and out is
  // destroyed before this scope ends.
  std::optional<bb::ExrWriteThreads> exr_threads;
  if (bb__path_has_extension(file_name.c_str(), "exr")) exr_threads.emplace(threads);
  auto out = ImageOutput::create(file_name, proxy);
  if (!out) return bb::one_line(OIIO::geterror());
  // OpenEXR stores MIP levels; OpenImageIO's TIFF writer does not, but it
  // reads a "Plain Texture" TIFF's further directories as MIP levels (as
  // maketx writes them), so TIFF levels are appended as subimages.
  const bool mip_levels = out->supports("mipmap");
  if (!out->supports("tiles") || (!mip_levels && !out->supports("multiimage")))
    return std::string(out->format_name()) + " files cannot hold mip levels";
  const ImageOutput::OpenMode append =
      mip_levels ? ImageOutput::AppendMIPLevel : ImageOutput::AppendSubimage;
  for (int k = 0; k < count; k++) {
    const bb_image *img = &levels[k];
    ImageSpec spec(img->width, img->height, img->channels, bb::file_type_of(depth));
    spec.tile_width = MIP_TILE;
    spec.tile_height = MIP_TILE;
    spec.attribute("textureformat", "Plain Texture");
    bb::set_common_attributes(spec);
    if (description) spec.attribute("ImageDescription", description);
    spec.attribute("compression", std::strcmp(out->format_name(), "openexr") == 0
                                      ? bb__exr_compression(depth)
                                      : "zip");
    if (!out->open(file_name, spec, k == 0 ? ImageOutput::Create : append))
      return bb::one_line(out->geterror());
    bool ok;
    if (depth == BB_DEPTH_8)
      ok = write_level_codes<std::uint8_t>(*out, *img, range);
    else if (depth == BB_DEPTH_16)
      ok = write_level_codes<std::uint16_t>(*out, *img, range);
    else
      ok = write_padded_tiles(*out, *img, TypeDesc::FLOAT, img->pixels);
    if (!ok) return bb::one_line(out->geterror());
  }
  bool closed = out->close();
  std::string why = out->geterror(); // read (and cleared) whatever the outcome
  return closed ? std::string() : bb::one_line(why);
}

// Reads a finished file back; "" when it holds the chain, else why not.
// The file is one of OpenImageIO's formats (never a VTF or DDS): read by
// this module's own read, as the library's read of a mip level would pass it on.
std::string verify_chain(const std::string &name, const bb_image *levels, int count) {
  for (int k = 0; k < count; k++) {
    bb_image level{};
    bb_error why;
    int file_levels = 0;
    if (bb__oiio_read(name.c_str(), 0, -1, k, &level, nullptr, &file_levels, &why) != BB_OK) {
      bb_image_free(&level);
      // The reason, without the temporary's name the read gave it.
      std::string reason = why.message;
      if (reason.compare(0, name.size() + 2, name + ": ") == 0) reason.erase(0, name.size() + 2);
      return "read back: " + reason;
    }
    bool same = level.width == levels[k].width && level.height == levels[k].height &&
                file_levels == count;
    bb_image_free(&level);
    if (!same) return "read back: the file does not hold the levels written";
  }
  return std::string();
}

// bb::write_staged for a TIFF of several directories, which OpenImageIO
// cannot write through a proxy: OpenImageIO 2.4's TIFF writer appends a
// directory by opening its output again in "a" mode, and its proxy
// callbacks cannot read (writer_readproc returns 0), so through a proxy a
// file of several directories keeps only the last. The encoder therefore
// opens a name, and reopens it for every level: the name is in a private
// directory reached through its descriptor (bb__safe_open_private), never
// one in the destination's directory, where a link planted between two
// opens would be written through. Its writes are not checked one
// by one, so the file is fsynced (a full disk can show only there) and
// read back whole.
bb_status write_staged_by_name(const char *path, const bb::encoder_fn &encode,
                               const bb_image *levels, int count, bb_staged_file *f,
                               bb_error *err) {
  bb_status st = bb__safe_open_private(f, path, err);
  if (st != BB_OK) return st;
  // The encoder makes the file: a signal's cleanup waits for it (ended
  // however encode ends, an exception included).
  struct creation {
    sigset_t held;
    bool begun;
    ~creation() {
      if (begun) bb__safe_creation_end(&held);
    }
  } making;
  making.begun = bb__safe_creation_begin(&making.held) == 0;
  if (!making.begun) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: the process is ending", path);
  }
  std::string why = encode(f->temp_path, nullptr);
  bb__safe_creation_end(&making.held);
  making.begun = false;
  if (why.empty()) {
    st = bb__safe_adopt(f, err);
    if (st != BB_OK) return st;
    why = verify_chain(f->temp_path, levels, count);
  }
  if (!why.empty()) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  return BB_OK;
}

bb_status resize_box(const bb_image *in, int width, int height, bb_image *out, bb_error *err) {
  bb_status st = bb_image_alloc(out, width, height, in->channels, err);
  if (st != BB_OK) return st;
  // Both buffers are wrapped, not copied: ImageBuf reads and writes the
  // bb_images' own float pixels.
  OIIO::ImageBuf src(ImageSpec(in->width, in->height, in->channels, TypeDesc::FLOAT), in->pixels);
  OIIO::ImageBuf dst(ImageSpec(width, height, in->channels, TypeDesc::FLOAT), out->pixels);
  if (!OIIO::ImageBufAlgo::resize(dst, src, "box")) {
    std::string why = dst.geterror();
    bb_image_free(out);
    return bb__fail(err, BB_ERR_ARGUMENT, "mip level: %s", bb::one_line(why).c_str());
  }
  return BB_OK;
}

} // namespace

extern "C" {

bb_status bb__oiio_write_mips(const char *path, const bb_image *levels, int count,
                              bb_depth depth, bb_range range, const char *description,
                              int threads, bb_staged_file *f, bb_error *err) {
  return bb::guard(err, path, bb::WRITING, [&] {
    bb::oiio_setup();
    auto encode = [&](const std::string &name, OIIO::Filesystem::IOProxy *proxy) {
      return encode_mips(name, proxy, levels, count, depth, range, description, threads);
    };
    if (bb__path_has_extension(path, "exr") || count == 1)
      return bb::write_staged(path, encode, f, err);
    return write_staged_by_name(path, encode, levels, count, f, err);
  });
}

bb_status bb__image_resize_box(const bb_image *in, int width, int height, bb_image *out,
                               bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "resize: out is NULL");
  std::memset(out, 0, sizeof *out);
  if (!in || !in->pixels || in->width <= 0 || in->height <= 0 || in->channels <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "resize: empty image");
  bb_status st = bb::guard(err, "resize", bb::RESIZING,
                           [&] { return resize_box(in, width, height, out, err); });
  if (st != BB_OK) bb_image_free(out);
  return st;
}

} // extern "C"
