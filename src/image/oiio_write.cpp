// oiio_write.cpp: the OpenImageIO calls of writing one image, and the staged
// write (oiio_proxy.h) every writer goes through. What may be written where
// is decided in C (formats.c), the codes in quantise.c, the TGA comment in
// description.c; the public writes are image_write.c.
#include "core/internal.h"
#include "image/description.h"
#include "image/exr_pool.h"
#include "image/formats.h"
#include "image/oiio_calls.h"
#include "image/oiio_guard.h"
#include "image/oiio_setup.h"
#include "image/oiio_proxy.h"
#include "image/quantise.h"

#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <new>

using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace bb {

bb_status write_staged(const char *path, const encoder_fn &encode, bb_staged_file *f,
                       bb_error *err) {
  bb_status st = bb__safe_open(f, path, err);
  if (st != BB_OK) return st;
  std::string why;
  {
    StagedOutput proxy(f, f->temp_path);
    why = encode(f->temp_path, &proxy);
  }
  // An encoder that ignored the proxy would have written past the checks.
  if (why.empty() && bb__safe_size(f) == 0)
    why = "internal error: the encoder did not write through the checked output";
  // The encoder is done, so no other thread touches f. When a write failed,
  // finish reports the system's reason, which says more than the codec's.
  if (!why.empty() && !f->error) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  return bb__safe_finish(f, err);
}

TypeDesc file_type_of(bb_depth depth) {
  return depth == BB_DEPTH_8      ? TypeDesc::UINT8
         : depth == BB_DEPTH_16   ? TypeDesc::UINT16
         : depth == BB_DEPTH_HALF ? TypeDesc::HALF
                                  : TypeDesc::FLOAT;
}

// DateTime is set empty, which makes OpenImageIO leave the write time out
// of TIFF and EXR headers: the same input and options then give the same
// bytes, which is what a golden or a build cache compares. An image of
// more channels than RGBA (a basis map) has them named B0, B1, ... and
// none is alpha.
void set_common_attributes(ImageSpec &spec) {
  char name[8];
  if (bb__basis_channel_name(0, spec.nchannels, name)) {
    for (int c = 0; c < spec.nchannels; c++)
      spec.channelnames[(size_t)c] = bb__basis_channel_name(c, spec.nchannels, name);
    spec.alpha_channel = -1;
  }
  spec.attribute("oiio:UnassociatedAlpha", 1);
  spec.attribute("Software", "bumpbake " BB_VERSION_STRING);
  spec.attribute("DateTime", "");
}

} // namespace bb

namespace {

struct free_deleter {
  void operator()(void *p) const { std::free(p); }
};
template <typename T> using malloced = std::unique_ptr<T, free_deleter>;

// The codes of img at depth (8 or 16 bits); throws std::bad_alloc when
// there is no memory for them.
template <typename T> malloced<T> codes_of(const bb_image *img, bb_range range) {
  T *codes;
  if constexpr (sizeof(T) == 1)
    codes = bb__quantise_8(img, range);
  else
    codes = bb__quantise_16(img, range);
  if (!codes) throw std::bad_alloc();
  return malloced<T>(codes);
}

// Encodes img into file_name (a temporary name whose extension picks the
// format) through proxy. Returns "" on success, else OIIO's reason.
std::string encode_image(const std::string &file_name, OIIO::Filesystem::IOProxy *proxy,
                         const bb_image *img, bb_depth depth, bb_range range,
                         const char *description, int threads, const char *exr_compression) {
  ImageSpec spec(img->width, img->height, img->channels, bb::file_type_of(depth));
  bb::set_common_attributes(spec);
  if (description) {
    malloced<char> stored(bb__description_to_store(file_name.c_str(), description));
    if (!stored) throw std::bad_alloc();
    spec.attribute("ImageDescription", stored.get());
    malloced<char> overflow(bb__description_overflow(file_name.c_str(), description));
    if (!overflow)
      throw std::bad_alloc();
    if (overflow.get()[0])
      spec.attribute("targa:ImageID", overflow.get());
  }
  if (depth == BB_DEPTH_HALF || depth == BB_DEPTH_FLOAT) spec.attribute("compression", "zip");

  // OpenEXR compresses chunks from open() to close(), and out is destroyed
  // (closed, should an error leave it open) before this scope ends.
  std::optional<bb::ExrWriteThreads> exr_threads;
  if (bb__path_has_extension(file_name.c_str(), "exr")) exr_threads.emplace(threads);
  auto out = ImageOutput::create(file_name, proxy);
  if (!out) return bb::one_line(OIIO::geterror());
  if (!out->supports("ioproxy"))
    return std::string("internal error: the ") + out->format_name() +
           " writer cannot write through a checked output";
  if (std::strcmp(out->format_name(), "png") == 0) {
    // Bakes are iterated on far more often than shipped, so PNG favours speed.
    // libpng's default tries all five row filters on every row and keeps one
    // (Paeth on nearly all rows of a baked map); asking for Paeth alone skips
    // the other four. zlib's RLE strategy (matches at distance 1 only, which
    // is what Paeth residuals of noisy maps offer) then replaces the level-1
    // LZ77 search. On rock06's five 8-bit maps this halves the encoding CPU
    // and makes the files 15% smaller; on 16-bit maps the CPU drops by 54%.
    // zlib ignores the level under RLE; level 1 stays for the default strategy.
    spec.attribute("png:compressionLevel", 1);
    spec.attribute("png:filter", 128); // PNG_FILTER_PAETH
    spec.attribute("compression", "rle");
  } else if (std::strcmp(out->format_name(), "openexr") == 0) {
    spec.attribute("compression",
                   exr_compression ? exr_compression : bb__exr_compression(depth));
  } else if (std::strcmp(out->format_name(), "tiff") == 0) {
    // TIFF is deflated too (OIIO's default "zip"); level 1 instead of 6 takes
    // 73% less CPU for 6% more bytes on rock06's 8-bit maps (16-bit: -25%,
    // +1%; float: -29%, +3%).
    spec.attribute("tiff:zipquality", 1);
  }
  if (!out->open(file_name, spec)) return bb::one_line(out->geterror());

  bool ok;
  if (depth == BB_DEPTH_8)
    ok = out->write_image(TypeDesc::UINT8, codes_of<std::uint8_t>(img, range).get());
  else if (depth == BB_DEPTH_16)
    ok = out->write_image(TypeDesc::UINT16, codes_of<std::uint16_t>(img, range).get());
  else
    ok = out->write_image(TypeDesc::FLOAT, img->pixels);
  // close() flushes, so its failure (a full disk) matters as much as the write's.
  ok = out->close() && ok;
  // Trust the return values, not the error queue: OIIO 2.4's TIFF writer
  // queues "failed TIFFWriteCustomDirectory() of the Exif data" on every
  // successful write. Reading the queue also clears it.
  std::string why = out->geterror();
  if (!ok) return bb::one_line(why);
  return std::string();
}

} // namespace

extern "C" bb_status bb__oiio_write_image(const char *path, const bb_image *img, bb_depth depth,
                                          bb_range range, const char *description,
                                          int threads, const char *exr_compression,
                                          bb_staged_file *f, bb_error *err) {
  return bb::guard(err, path, bb::WRITING, [&] {
    bb::oiio_setup();
    return bb::write_staged(
        path,
        [&](const std::string &name, OIIO::Filesystem::IOProxy *proxy) {
          return encode_image(name, proxy, img, depth, range, description, threads,
                              exr_compression);
        },
        f, err);
  });
}
