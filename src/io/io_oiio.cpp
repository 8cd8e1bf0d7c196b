// io_oiio.cpp: reading and writing image files through OpenImageIO (the only C++ file).
//
// This file is a firewall: OpenImageIO is included nowhere else, and every
// extern "C" function catches all exceptions and turns them, like OIIO's own
// error strings, into a bb_status with a one-line message that names the file.
//
// Alpha is never premultiplied or divided out: bumpbake's channels are data
// (heights, ssbump, ao), so both directions ask for unassociated alpha.
#include "core/input_file.h"
#include "core/internal.h"
#include "io/oiio.h"
#include "io/provenance.h"
#include "io/safe_file.h"
#include "io/text.h"
#include "core/sanitizer_options.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <fcntl.h>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

#ifdef BB_ASAN_BUILD
#include <sanitizer/lsan_interface.h>
#endif

using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

// OIIO error strings may hold several lines; bb_error holds one.
std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  std::string out;
  for (char c : s) {
    if (c == '\n')
      out += "; ";
    else if (c != '\r')
      out += c;
  }
  return out.empty() ? std::string("unknown OpenImageIO error") : out;
}

// ------------------------------------------------------------- TGA comments
//
// TGA keeps ImageDescription in its extension area's comment field: 4 rows
// of 80 characters, each NUL-terminated (324 bytes). OpenImageIO 2.4 writes
// the text flat into those bytes and reads each 81-byte row back as one line,
// so a provenance text longer than a row came back cut inside values
// ("input=roc" / "k.tga"). Provenance is therefore fitted to the rows with
// whole key=value lines (bb__provenance_pack), each row padded to its 81
// bytes with newlines, and the blank lines the padding leaves are dropped
// when it is read. Other text is left to OpenImageIO.

constexpr int TGA_COMMENT_ROWS = 4, TGA_COMMENT_CHARS = 80;

bool is_targa(const char *format_name) { return std::strcmp(format_name, "targa") == 0; }

// The ImageDescription to give OpenImageIO for a file (targa: a .tga file).
std::string description_to_store(bool targa, const char *description) {
  // A text that fits the first row comes back as it is.
  if (!targa || std::strlen(description) <= (size_t)TGA_COMMENT_CHARS ||
      bb_provenance_classify(description) == BB_PROVENANCE_NONE)
    return description;
  char rows[TGA_COMMENT_ROWS][TGA_COMMENT_CHARS + 1];
  bb__provenance_pack(description, TGA_COMMENT_ROWS, TGA_COMMENT_CHARS, &rows[0][0]);
  std::string flat;
  for (int r = 0; r < TGA_COMMENT_ROWS && rows[r][0]; r++) {
    flat.resize((size_t)r * (TGA_COMMENT_CHARS + 1), '\n'); // pad the previous row
    flat += rows[r];
  }
  return flat;
}

// The description as read: a TGA's provenance without the blank lines its
// row padding leaves (the rows' lines, in row order).
std::string description_as_read(const char *format_name, std::string desc) {
  // Padded rows always leave an empty line; a text stored as it was has none.
  if (!is_targa(format_name) || desc.find("\n\n") == std::string::npos ||
      bb_provenance_classify(desc.c_str()) == BB_PROVENANCE_NONE)
    return desc;
  std::string tidy;
  for (char c : desc)
    if (c != '\n' || (!tidy.empty() && tidy.back() != '\n')) tidy += c;
  while (!tidy.empty() && tidy.back() == '\n') tidy.pop_back();
  return tidy;
}

// ------------------------------------------------------------------ reading

void clear_info(bb_image_info *info) {
  if (!info) return;
  std::memset(info, 0, sizeof *info);
  info->alpha_channel = -1;
}

// Distinguishes "missing" and "unreadable" from "not an image" before OIIO
// sees the file, since OIIO reports all three as a failed open.
// Missing files, directories, FIFOs and devices are refused before
// OpenImageIO opens the name (it would block on a FIFO and spin on
// /dev/zero).
bb_status check_readable(const char *path, bb_error *err) { return bb__input_check(path, err); }

constexpr long MiB = 1L << 20;

// OpenImageIO's own guards against headers that declare absurd sizes: some
// readers check them in open(), before bumpbake sees the header. They are
// process-wide, so they are only ever lowered, never raised.
void lower_oiio_limits() {
  static std::once_flag once;
  std::call_once(once, [] {
    int mb = 0, channels = 0;
    const int our_mb = (int)((double)BB_MAX_PIXELS * BB_MAX_READ_BYTES_PER_TEXEL / MiB);
    if (!OIIO::getattribute("limits:imagesize_MB", mb) || mb <= 0 || mb > our_mb)
      OIIO::attribute("limits:imagesize_MB", our_mb);
    if (!OIIO::getattribute("limits:channels", channels) || channels <= 0 || channels > 64)
      OIIO::attribute("limits:channels", 64);
  });
}

// OIIO's refusal under its limits spans two lines and tells the reader to
// raise an OIIO attribute, which a bumpbake user cannot: keep the first line.
bool is_limit_refusal(const std::string &why) {
  return why.find("limits:imagesize_MB") != std::string::npos ||
         why.find("limits:channels") != std::string::npos;
}

std::string first_line(const std::string &s) {
  return s.substr(0, s.find('\n'));
}

// In sanitizer builds, allocations made while OpenImageIO's PNG reader
// opens or decodes a file (in this thread) are not leaks to LeakSanitizer:
// its one known leak is not ours (see sanitizer_options.h). Whether the
// file is a PNG is asked of OpenImageIO's PNG reader (its signature check),
// since OpenImageIO picks readers by content too. Release builds skip all
// of this.
class OiioPngLeakScope {
public:
  explicit OiioPngLeakScope(bool png) : active_(png) {
#ifdef BB_ASAN_BUILD
    if (active_) __lsan_disable();
#endif
  }
  ~OiioPngLeakScope() {
#ifdef BB_ASAN_BUILD
    if (active_) __lsan_enable();
#endif
  }
  OiioPngLeakScope(const OiioPngLeakScope &) = delete;
  OiioPngLeakScope &operator=(const OiioPngLeakScope &) = delete;

  static bool applies_to(const char *path) {
#ifdef BB_ASAN_BUILD
    auto png = ImageInput::create("png");
    return png && png->valid_file(path);
#else
    (void)path;
    return false;
#endif
  }

private:
  bool active_;
};

// An opened input and whether it is read by OpenImageIO's PNG reader.
struct opened_input {
  std::unique_ptr<ImageInput> in;
  bool png = false;
};

opened_input open_input(const char *path, bb_status *st, bb_error *err) {
  opened_input opened;
  *st = check_readable(path, err);
  if (*st != BB_OK) return opened;
  lower_oiio_limits();
  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  opened.png = OiioPngLeakScope::applies_to(path);
  {
    OiioPngLeakScope png_leak(opened.png);
    opened.in = ImageInput::open(path, &config);
  }
  if (!opened.in) {
    std::string why = OIIO::geterror();
    if (is_limit_refusal(why))
      *st = bb__fail(err, BB_ERR_SIZE,
                     "%s: too large to read: %s (bumpbake reads at most %ld MiB of samples)",
                     path, first_line(why).c_str(), BB_MAX_READ_BYTES / MiB);
    else
      *st = bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                     one_line(why).c_str());
  }
  return opened;
}

bb_status check_spec_shape(const char *path, const ImageSpec &spec, bb_error *err) {
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    return bb__fail(err, BB_ERR_SIZE, "%s: zero or negative image size %dx%d, %d channels",
                    path, spec.width, spec.height, spec.nchannels);
  if (spec.depth > 1)
    return bb__fail(err, BB_ERR_FORMAT, "%s: volume images (depth %d) are not supported",
                    path, spec.depth);
  if (spec.deep)
    return bb__fail(err, BB_ERR_FORMAT, "%s: deep images are not supported", path);
  return BB_OK;
}

// Everything a read would allocate, checked against the header before any
// allocation: the texel count, the channel count, the bytes of the file's
// own samples (some readers decode the whole image natively first) and the
// bytes of the floats handed back.
bb_status check_spec_size(const char *path, const ImageSpec &spec, int channels_read,
                          bb_error *err) {
  bb_status st = check_spec_shape(path, spec, err);
  if (st != BB_OK) return st;
  if (spec.nchannels > 64)
    return bb__fail(err, BB_ERR_FORMAT, "%s: %d channels (at most 64 are supported)", path,
                    spec.nchannels);
  const double texels = (double)spec.width * (double)spec.height;
  if (spec.width > BB_MAX_DIMENSION || spec.height > BB_MAX_DIMENSION ||
      texels > (double)BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: image %dx%d is over the maximum (%d per side, %ld texels)", path,
                    spec.width, spec.height, BB_MAX_DIMENSION, (long)BB_MAX_PIXELS);
  const double file_bytes = (double)spec.image_bytes(true);
  const double float_bytes = texels * channels_read * (double)sizeof(float);
  const double bytes = file_bytes > float_bytes ? file_bytes : float_bytes;
  const double limit = std::max((double)BB_MAX_READ_BYTES, texels * BB_MAX_READ_BYTES_PER_TEXEL);
  if (bytes > limit)
    return bb__fail(err, BB_ERR_SIZE,
                    "%s: %dx%d with %d channels of %s needs %.0f MiB, over the limit of "
                    "%.0f MiB",
                    path, spec.width, spec.height, spec.nchannels,
                    spec.format.c_str(), bytes / (double)MiB, limit / (double)MiB);
  // The floats, and at most the file's own samples decoded beside them.
  char what[600];
  snprintf(what, sizeof what, "%s: reading %dx%d with %d channels of %s", path, spec.width,
           spec.height, spec.nchannels, spec.format.c_str());
  return bb__memory_check(float_bytes + file_bytes, what, err);
}

bb_status fill_info(const ImageInput &in, const ImageSpec &spec, bb_image_info *info,
                    const char *path, bb_error *err) {
  if (!info) return BB_OK;
  info->alpha_channel = spec.alpha_channel;
  info->is_float = spec.format.is_floating_point() ? 1 : 0;
  // oiio:BitsPerSample tells 1-, 2-, 4-, 10- or 12-bit files from their carrier type.
  info->bits_per_sample =
      spec.get_int_attribute("oiio:BitsPerSample", (int)spec.format.size() * 8);
  std::snprintf(info->format_name, sizeof info->format_name, "%s", in.format_name());
  std::string desc =
      description_as_read(in.format_name(), spec.get_string_attribute("ImageDescription"));
  if (!desc.empty()) {
    info->description = static_cast<char *>(std::malloc(desc.size() + 1));
    if (!info->description)
      return bb__fail(err, BB_ERR_MEMORY, "%s: cannot allocate the description", path);
    std::memcpy(info->description, desc.c_str(), desc.size() + 1);
  }
  return BB_OK;
}

// Rows decoded per call: whole tile rows for tiled files, else about 4 MiB
// of floats. Reading in bands lets a file whose data stops early (a header
// promising 8192 rows over 52 bytes) fail at its first band instead of
// decoding, and touching, the whole image.
int rows_per_band(const ImageSpec &spec, int channels) {
  if (spec.tile_width > 0 && spec.tile_height > 0) return spec.tile_height;
  long row_bytes = (long)spec.width * channels * (long)sizeof(float);
  long rows = (4 * MiB) / (row_bytes > 0 ? row_bytes : 1);
  return rows < 1 ? 1 : (rows > spec.height ? spec.height : (int)rows);
}

// Decodes channels [first, first + out->channels) into out, band by band.
// A truncated file must fail, not come back as zeros: both the return value
// and the error queue are checked, since some readers only record a warning.
std::string read_bands(ImageInput &in, bool png, int miplevel, const ImageSpec &spec,
                       int first, bb_image *out) {
  const int band = rows_per_band(spec, out->channels);
  const size_t row_floats = (size_t)spec.width * (size_t)out->channels;
  for (int y = 0; y < spec.height; y += band) {
    const int rows = spec.height - y < band ? spec.height - y : band;
    float *dst = out->pixels + (size_t)y * row_floats;
    const int y0 = spec.y + y, y1 = spec.y + y + rows;
    OiioPngLeakScope png_leak(png);
    bool ok = spec.tile_width > 0
                  ? in.read_tiles(0, miplevel, spec.x, spec.x + spec.width, y0, y1, spec.z,
                                  spec.z + 1, first, first + out->channels, TypeDesc::FLOAT,
                                  dst)
                  : in.read_scanlines(0, miplevel, y0, y1, spec.z, first,
                                      first + out->channels, TypeDesc::FLOAT, dst);
    if (!ok || in.has_error()) {
      std::string why = in.geterror();
      return why.empty() ? std::string("read failed") : why;
    }
  }
  return std::string();
}

// Reads channels [first, first + count) (count < 0: all of them).
bb_status read_channels(const char *path, int first, int count, bb_image *out,
                        bb_image_info *info, bb_error *err) {
  bb_status st;
  opened_input opened = open_input(path, &st, err);
  if (!opened.in) return st;
  ImageInput *in = opened.in.get();
  const ImageSpec spec = in->spec();
  if (count < 0) {
    first = 0;
    count = spec.nchannels;
  }
  st = check_spec_size(path, spec, count, err);
  if (st != BB_OK) return st;
  if (first < 0 || count < 1 || first + count > spec.nchannels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: channels %d..%d asked of a %d-channel image",
                    path, first, first + count - 1, spec.nchannels);

  bb_error alloc_err;
  st = bb_image_alloc(out, spec.width, spec.height, count, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);

  std::string why = read_bands(*in, opened.png, 0, spec, first, out);
  if (!why.empty()) {
    bb_image_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: corrupt or truncated image: %s", path,
                    one_line(first_line(why)).c_str());
  }
  st = fill_info(*in, spec, info, path, err);
  if (st != BB_OK) {
    bb_image_free(out);
    bb_image_info_free(info);
  }
  return st;
}

bb_status read_header(const char *path, int *width, int *height, int *channels,
                      bb_image_info *info, bb_error *err) {
  bb_status st;
  opened_input opened = open_input(path, &st, err);
  if (!opened.in) return st;
  ImageInput *in = opened.in.get();
  const ImageSpec &spec = in->spec();
  st = check_spec_shape(path, spec, err);
  if (st != BB_OK) return st;
  if (width) *width = spec.width;
  if (height) *height = spec.height;
  if (channels) *channels = spec.nchannels;
  return fill_info(*in, spec, info, path, err);
}

// Runs a read, turning exceptions into statuses and cleaning up after any
// failure: the firewall every extern "C" read goes through.
template <typename Fn>
bb_status guarded_read(const char *path, bb_image *out, bb_image_info *info, bb_error *err,
                       Fn &&read) {
  bb_status st;
  try {
    st = read();
  } catch (const std::bad_alloc &) {
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while reading", path);
  } catch (const std::exception &e) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    st = bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
  if (st != BB_OK) {
    bb_image_free(out);
    bb_image_info_free(info);
  }
  return st;
}

// ------------------------------------------------------------------ writing

struct format_rule {
  const char *ext;      // lower case, with the dot
  bb_depth default_depth;
  unsigned allowed;     // bit (1 << bb_depth) per allowed depth
  int max_channels;
};

constexpr unsigned bit(bb_depth d) { return 1u << d; }

const format_rule FORMATS[] = {
    {".png", BB_DEPTH_8, bit(BB_DEPTH_8) | bit(BB_DEPTH_16), 4},
    {".tga", BB_DEPTH_8, bit(BB_DEPTH_8), 4},
    {".tif", BB_DEPTH_8, bit(BB_DEPTH_8) | bit(BB_DEPTH_16) | bit(BB_DEPTH_FLOAT), 64},
    {".tiff", BB_DEPTH_8, bit(BB_DEPTH_8) | bit(BB_DEPTH_16) | bit(BB_DEPTH_FLOAT), 64},
    {".exr", BB_DEPTH_FLOAT, bit(BB_DEPTH_HALF) | bit(BB_DEPTH_FLOAT), 64},
};

const char *depth_name(bb_depth d) {
  switch (d) {
  case BB_DEPTH_DEFAULT: return "default";
  case BB_DEPTH_8: return "8-bit";
  case BB_DEPTH_16: return "16-bit";
  case BB_DEPTH_HALF: return "half float";
  case BB_DEPTH_FLOAT: return "float";
  }
  return "unknown";
}

// Lower-case extension of the last path component, with the dot, or "".
std::string extension_of(const char *path) {
  const char *slash = std::strrchr(path, '/');
  const char *base = slash ? slash + 1 : path;
  const char *dot = std::strrchr(base, '.');
  if (!dot) return std::string();
  std::string ext(dot);
  for (char &c : ext) c = (char)std::tolower((unsigned char)c);
  return ext;
}

const format_rule *find_format(const std::string &ext) {
  for (const format_rule &f : FORMATS)
    if (ext == f.ext) return &f;
  return nullptr;
}

// ------------------------------------------------------- the safe write path

// An OpenImageIO output proxy over a bb_staged_file: every byte an encoder
// produces goes through bumpbake's checked, buffered writes (internal.h),
// whatever the encoder itself does with a failed write.
class SafeProxy final : public OIIO::Filesystem::IOProxy {
public:
  SafeProxy(bb_staged_file *file, const std::string &name)
      : IOProxy(name, Write), file_(file) {}
  const char *proxytype() const override { return "bumpbake-safe"; }
  void close() override {} // bb__safe_finish closes, checked
  int64_t tell() override { return bb__safe_tell(file_); }
  bool seek(int64_t offset) override { return bb__safe_seek(file_, offset) == 0; }
  size_t read(void *buf, size_t size) override { return bb__safe_read(file_, buf, size); }
  size_t write(const void *buf, size_t size) override {
    return bb__safe_write(file_, buf, size);
  }
  size_t pread(void *buf, size_t size, int64_t offset) override {
    return bb__safe_pread(file_, buf, size, offset);
  }
  size_t pwrite(const void *buf, size_t size, int64_t offset) override {
    return bb__safe_pwrite(file_, buf, size, offset);
  }
  size_t size() const override { return (size_t)bb__safe_size(file_); }
  void flush() const override {} // bb__safe_finish flushes and fsyncs

private:
  bb_staged_file *file_;
};

// What an encoder does: create an ImageOutput for name (its extension picks
// the format) that writes through proxy (ImageOutput::create(name, proxy)),
// open, write and close it, and return "" or OpenImageIO's reason.
using encoder_fn =
    std::function<std::string(const std::string &name, OIIO::Filesystem::IOProxy *proxy)>;

// THE way an OpenImageIO writer puts a file on disk; every writer in this
// file (and any new one: mip-mapped, multi-image...) calls it. It opens a
// bb_staged_file for path, runs encode through a SafeProxy, and then either
// finishes the file (flushed, fsynced, closed: complete under its temporary
// name, for the caller to bb__safe_commit or bb__safe_discard) or removes
// it and returns BB_ERR_IO. A failed write is reported with the system's
// reason ("No space left on device") even when the encoder claimed success.
bb_status write_safely(const char *path, const encoder_fn &encode, bb_staged_file *f,
                       bb_error *err) {
  bb_status st = bb__safe_open(f, path, err);
  if (st != BB_OK) return st;
  std::string why;
  try {
    SafeProxy proxy(f, f->temp_path);
    why = encode(f->temp_path, &proxy);
    // An encoder that ignored the proxy would have written past the checks.
    if (why.empty() && bb__safe_size(f) == 0)
      why = "internal error: the encoder did not write through the checked output";
  } catch (...) {
    bb__safe_discard(f);
    throw;
  }
  // The encoder is done, so no other thread touches f. When a write failed,
  // finish reports the system's reason, which says more than the codec's.
  if (!why.empty() && !f->error) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  return bb__safe_finish(f, err);
}

// Reads a finished file back; "" when it is whole, else why not.
using verify_fn = std::function<std::string(const std::string &name)>;

// write_safely for an encoder OpenImageIO cannot run through a proxy, which
// gets proxy == nullptr and writes to the temporary by name: OpenImageIO
// 2.4's TIFF writer re-opens its proxy in "w" mode for every directory it
// appends, so through a proxy a file of several directories keeps only the
// last. Its own writes are then not checked one by one, so the temporary is
// fsynced (a full disk can show only there) and verify must read the whole
// file back. Same contract as write_safely otherwise.
bb_status write_safely_by_name(const char *path, const encoder_fn &encode,
                               const verify_fn &verify, bb_staged_file *f, bb_error *err) {
  bb_status st = bb__safe_open(f, path, err);
  if (st != BB_OK) return st;
  std::string why;
  try {
    why = encode(f->temp_path, nullptr);
  } catch (...) {
    bb__safe_discard(f);
    throw;
  }
  if (why.empty()) {
    st = bb__safe_finish(f, err);
    if (st != BB_OK) return st;
    try {
      why = verify(f->temp_path);
    } catch (...) {
      bb__safe_discard(f);
      throw;
    }
  }
  if (!why.empty()) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  return BB_OK;
}

// Names the channels of an image with more than RGBA holds (a basis map of
// more than 4 directions) B0, B1, ... instead of OpenImageIO's R, G, B, A,
// channel4, ...: zero-padded to one width, since OpenEXR keeps channels
// sorted by name and reads them back in that order, and none is alpha.
void name_basis_channels(ImageSpec &spec) {
  if (spec.nchannels <= 4) return;
  const int width = (int)std::to_string(spec.nchannels - 1).size();
  for (int c = 0; c < spec.nchannels; c++) {
    std::string digits = std::to_string(c);
    spec.channelnames[(size_t)c] = "B" + std::string((size_t)width - digits.size(), '0') + digits;
  }
  spec.alpha_channel = -1;
}

// Round-half-up quantisation of v (after the range mapping) to 0..max_code.
// NaN becomes 0 so that it cannot reach an undefined float-to-int cast.
// u * max_code + 0.5 lies in [0.5, max_code + 0.5], so truncation is the
// floor: the same codes as std::floor, without a libm call per sample.
template <bb_range range> inline std::int32_t quantise(float v, double max_code) {
  double u = range == BB_RANGE_SIGNED ? 0.5 + 0.5 * (double)v : (double)v;
  u = u > 0.0 ? u : 0.0;
  u = u < 1.0 ? u : 1.0;
  return (std::int32_t)(u * max_code + 0.5);
}

template <typename T, bb_range range>
void quantise_all(const float *v, size_t n, T *codes) {
  const double max_code = (double)(T)~(T)0;
  for (size_t i = 0; i < n; i++) codes[i] = (T)quantise<range>(v[i], max_code);
}

template <typename T>
std::vector<T> quantise_image(const bb_image *img, bb_range range) {
  size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  std::vector<T> codes(n);
  if (range == BB_RANGE_SIGNED)
    quantise_all<T, BB_RANGE_SIGNED>(img->pixels, n, codes.data());
  else
    quantise_all<T, BB_RANGE_UNIT>(img->pixels, n, codes.data());
  return codes;
}

// Encodes img into file_name (a temporary name whose extension picks the
// format) through proxy. Returns "" on success, else OIIO's reason.
// What every file bumpbake writes carries besides its pixels. DateTime is
// set empty, which makes OpenImageIO leave the write time out of TIFF and
// EXR headers: the same input and options then give the same bytes, which
// is what a golden or a build cache compares.
void set_common_attributes(ImageSpec &spec) {
  spec.attribute("oiio:UnassociatedAlpha", 1);
  spec.attribute("Software", "bumpbake " BB_VERSION_STRING);
  spec.attribute("DateTime", "");
}

std::string encode_image(const std::string &file_name, OIIO::Filesystem::IOProxy *proxy,
                         const bb_image *img, bb_depth depth, bb_range range,
                         const char *description) {
  TypeDesc file_type = depth == BB_DEPTH_8      ? TypeDesc::UINT8
                       : depth == BB_DEPTH_16   ? TypeDesc::UINT16
                       : depth == BB_DEPTH_HALF ? TypeDesc::HALF
                                                : TypeDesc::FLOAT;
  ImageSpec spec(img->width, img->height, img->channels, file_type);
  name_basis_channels(spec);
  set_common_attributes(spec);
  if (description)
    spec.attribute("ImageDescription",
                   description_to_store(extension_of(file_name.c_str()) == ".tga", description));
  if (depth == BB_DEPTH_HALF || depth == BB_DEPTH_FLOAT) spec.attribute("compression", "zip");

  auto out = ImageOutput::create(file_name, proxy);
  if (!out) return one_line(OIIO::geterror());
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
  } else if (std::strcmp(out->format_name(), "tiff") == 0) {
    // TIFF is deflated too (OIIO's default "zip"); level 1 instead of 6 takes
    // 73% less CPU for 6% more bytes on rock06's 8-bit maps (16-bit: -25%,
    // +1%; float: -29%, +3%).
    spec.attribute("tiff:zipquality", 1);
  }
  if (!out->open(file_name, spec)) return one_line(out->geterror());

  bool ok;
  if (depth == BB_DEPTH_8) {
    std::vector<std::uint8_t> codes = quantise_image<std::uint8_t>(img, range);
    ok = out->write_image(TypeDesc::UINT8, codes.data());
  } else if (depth == BB_DEPTH_16) {
    std::vector<std::uint16_t> codes = quantise_image<std::uint16_t>(img, range);
    ok = out->write_image(TypeDesc::UINT16, codes.data());
  } else {
    ok = out->write_image(TypeDesc::FLOAT, img->pixels);
  }
  // close() flushes, so its failure (a full disk) matters as much as the write's.
  ok = out->close() && ok;
  // Trust the return values, not the error queue: OIIO 2.4's TIFF writer
  // queues "failed TIFFWriteCustomDirectory() of the Exif data" on every
  // successful write. Reading the queue also clears it.
  std::string why = out->geterror();
  if (!ok) return one_line(why);
  return std::string();
}

bb_status check_image_arg(const char *path, const bb_image *img, bb_error *err) {
  if (!img || !img->pixels || img->width <= 0 || img->height <= 0 || img->channels <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: nothing to write (empty image)", path);
  return BB_OK;
}

// C callers may store any int in an enum field, and loading an out-of-range
// enum is undefined in C++: read the field as the int it is.
template <typename E> int raw_enum(const E &field) {
  static_assert(sizeof(E) == sizeof(int), "C enums are int-sized here");
  int value;
  std::memcpy(&value, &field, sizeof value);
  return value;
}

bb_status check_options(const char *path, const bb_write_options &o, bb_error *err) {
  int depth = raw_enum(o.depth), range = raw_enum(o.range);
  if (depth < BB_DEPTH_DEFAULT || depth > BB_DEPTH_FLOAT)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: unknown sample depth %d", path, depth);
  if (range != BB_RANGE_UNIT && range != BB_RANGE_SIGNED)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: unknown value range %d", path, range);
  return BB_OK;
}

bb_status resolve_depth(const char *path, const format_rule &f, const bb_write_options &o,
                        int channels, bb_depth *depth, bb_error *err) {
  *depth = o.depth == BB_DEPTH_DEFAULT ? f.default_depth : o.depth;
  if (!(f.allowed & bit(*depth)))
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s samples are not supported by %s files", path,
                    depth_name(*depth), f.ext);
  if (channels > f.max_channels)
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s files hold at most %d channels, not %d", path,
                    f.ext, f.max_channels, channels);
  return BB_OK;
}

// Everything bb_image_write checks before writing a byte; *depth receives
// the depth to write.
bb_status check_write(const char *path, const bb_image *img, const bb_write_options &o,
                      bb_depth *depth, bb_error *err) {
  bb_status st = check_image_arg(path, img, err);
  if (st != BB_OK) return st;
  st = check_options(path, o, err);
  if (st != BB_OK) return st;
  std::string ext = extension_of(path);
  const format_rule *f = find_format(ext);
  if (!f)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: unknown output format '%s' (use .png, .tga, .tif, .tiff or .exr)", path,
                    ext.c_str());
  return resolve_depth(path, *f, o, img->channels, depth, err);
}

// Writes img to a finished (complete, synced) temporary for path: f is then
// committed or discarded by the caller.
bb_status write_image_staged(const char *path, const bb_image *img,
                             const bb_write_options *options, bb_staged_file *f,
                             bb_error *err) {
  const bb_write_options defaults = {BB_DEPTH_DEFAULT, BB_RANGE_UNIT, nullptr};
  const bb_write_options &o = options ? *options : defaults;
  bb_depth depth;
  bb_status st = check_write(path, img, o, &depth, err);
  if (st != BB_OK) return st;
  return write_safely(
      path,
      [&](const std::string &name, OIIO::Filesystem::IOProxy *proxy) {
        return encode_image(name, proxy, img, depth, o.range, o.description);
      },
      f, err);
}

// The firewall of every extern "C" write: exceptions become statuses, and
// whatever was staged is removed.
template <typename Fn>
bb_status guarded_write(const char *path, bb_staged_file *f, bb_error *err, Fn &&write) {
  try {
    return write();
  } catch (const std::bad_alloc &) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while writing", path);
  } catch (const std::exception &e) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    bb__safe_discard(f);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", path);
  }
}

// --------------------------------------------------------------------- text

// OIIO records a failed font lookup in its global error queue; read it so a
// later, unrelated OIIO error message does not carry it along.
void drop_global_error() { (void)OIIO::geterror(); }

bool text_size_of(const char *text, int size_px, const char *font, OIIO::ROI *roi) {
  *roi = OIIO::ImageBufAlgo::text_size(text, size_px, font);
  if (roi->defined()) return true;
  drop_global_error();
  return false;
}

// ---------------------------------------------------------------- animation

bb_status check_gif_path(const char *path, bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "animation: path is NULL");
  if (extension_of(path) != ".gif")
    return bb__fail(err, BB_ERR_FORMAT, "%s: animations are written as .gif files", path);
  return BB_OK;
}

bb_status count_frames(const char *path, int *frames, bb_error *err) {
  bb_status st = check_readable(path, err);
  if (st != BB_OK) return st;
  auto in = ImageInput::open(path);
  if (!in)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                    one_line(OIIO::geterror()).c_str());
  int n = 0;
  while (n < 1000000 && in->seek_subimage(n, 0)) n++;
  (void)in->geterror(); // seeking past the last subimage records an error
  *frames = n;
  return BB_OK;
}

} // namespace

// The GIF being written: OIIO's writer writes the frames through a
// SafeProxy into a staged temporary (the safe write path of internal.h); the
// final name appears only once bb_animation_close has checked the file.
struct bb_animation {
  std::string path;
  bb_staged_file file; // the temporary; discarded unless committed
  std::unique_ptr<OIIO::Filesystem::IOProxy> proxy; // outlives out
  std::unique_ptr<ImageOutput> out;
  ImageSpec spec;
  int frames = 0;
};

namespace {

// Closes and frees a; a temporary still staged is removed (after a commit
// there is none).
void animation_destroy(bb_animation *a) {
  if (!a) return;
  try {
    if (a->out) a->out->close();
  } catch (...) {
  }
  a->out.reset();
  bb__safe_discard(&a->file);
  delete a;
}

bb_status animation_open(const char *path, int width, int height, double fps,
                         bb_animation **out, bb_error *err) {
  bb_status st = check_gif_path(path, err);
  if (st != BB_OK) return st;
  if (width <= 0 || height <= 0 || width > 65535 || height > 65535)
    return bb__fail(err, BB_ERR_SIZE, "%s: a GIF frame cannot be %dx%d", path, width, height);
  if (!(fps >= 1.0 && fps <= 100.0))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: frames per second must be in 1..100 (got %g)",
                    path, fps);
  bb_animation *a = new bb_animation;
  a->path = path;
  st = bb__safe_open(&a->file, path, err);
  if (st != BB_OK) {
    delete a; // nothing was staged
    return st;
  }
  a->proxy.reset(new SafeProxy(&a->file, a->file.temp_path));
  a->out = ImageOutput::create(a->file.temp_path, a->proxy.get());
  if (!a->out || !a->out->supports("ioproxy")) {
    std::string why = a->out ? std::string("the GIF writer cannot write through a checked output")
                             : one_line(OIIO::geterror());
    animation_destroy(a);
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  a->spec = ImageSpec(width, height, 3, TypeDesc::UINT8);
  // GIF delays are in 1/100 s: a rational of 100 / delay is what OIIO reads.
  int per_second[2] = {100, (int)std::lround(100.0 / fps)};
  a->spec.attribute("FramesPerSecond", OIIO::TypeRational, per_second);
  a->spec.attribute("gif:LoopCount", 0); // loop forever
  *out = a;
  return BB_OK;
}

bb_status animation_add(bb_animation *a, const bb_image *frame, bb_error *err) {
  const char *path = a->path.c_str();
  if (!frame || !frame->pixels || frame->channels != 3 || frame->width != a->spec.width ||
      frame->height != a->spec.height)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: frames must be 3-channel %dx%d images", path,
                    a->spec.width, a->spec.height);
  ImageOutput::OpenMode mode = a->frames == 0 ? ImageOutput::Create : ImageOutput::AppendSubimage;
  std::vector<std::uint8_t> codes = quantise_image<std::uint8_t>(frame, BB_RANGE_UNIT);
  if (!a->out->open(a->file.temp_path, a->spec, mode) ||
      !a->out->write_image(TypeDesc::UINT8, codes.data()))
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path,
                    one_line(a->out->geterror()).c_str());
  a->frames++;
  return BB_OK;
}

// OIIO 2.4's GIF writer does not report a failed fwrite; the checked output
// does (bb__safe_finish), and the finished temporary is read back as well:
// a short file has fewer frames or none.
bb_status animation_close(bb_animation *a, bb_error *err) {
  const char *path = a->path.c_str();
  if (a->frames == 0) return bb__fail(err, BB_ERR_ARGUMENT, "%s: no frames to write", path);
  bool closed = a->out->close();
  std::string why = a->out->geterror();
  a->out.reset();
  if (!closed && !a->file.error)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, one_line(why).c_str());
  bb_status st = bb__safe_finish(&a->file, err);
  if (st != BB_OK) return st;
  int frames = 0;
  bb_error read_err;
  if (count_frames(a->file.temp_path, &frames, &read_err) != BB_OK || frames != a->frames)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: the file holds %d of %d frames", path,
                    frames, a->frames);
  return bb__safe_commit(&a->file, err);
}

// ------------------------------------------------------------ mip chains

// Tile size of mip-mapped files: OpenEXR stores mip levels only in tiled
// files, and TIFF readers expect a tiled pyramid too.
constexpr int MIP_TILE = 64;

bool format_holds_mips(const std::string &ext) {
  return ext == ".tif" || ext == ".tiff" || ext == ".exr";
}

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

// Encodes the chain into file_name (a temporary name whose extension picks
// TIFF or OpenEXR), level 0 first, each further level appended as a MIP
// level. proxy may be null. Returns "" or OpenImageIO's reason.
std::string encode_mips(const std::string &file_name, OIIO::Filesystem::IOProxy *proxy,
                        const bb_image *levels, int count, bb_depth depth, bb_range range,
                        const char *description) {
  TypeDesc file_type = depth == BB_DEPTH_8      ? TypeDesc::UINT8
                       : depth == BB_DEPTH_16   ? TypeDesc::UINT16
                       : depth == BB_DEPTH_HALF ? TypeDesc::HALF
                                                : TypeDesc::FLOAT;
  auto out = ImageOutput::create(file_name, proxy);
  if (!out) return one_line(OIIO::geterror());
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
    ImageSpec spec(img->width, img->height, img->channels, file_type);
    name_basis_channels(spec);
    spec.tile_width = MIP_TILE;
    spec.tile_height = MIP_TILE;
    spec.attribute("textureformat", "Plain Texture");
    set_common_attributes(spec);
    if (description) spec.attribute("ImageDescription", description);
    spec.attribute("compression", "zip");
    if (!out->open(file_name, spec, k == 0 ? ImageOutput::Create : append))
      return one_line(out->geterror());
    bool ok;
    if (depth == BB_DEPTH_8) {
      std::vector<std::uint8_t> codes = quantise_image<std::uint8_t>(img, range);
      ok = write_padded_tiles(*out, *img, TypeDesc::UINT8, codes.data());
    } else if (depth == BB_DEPTH_16) {
      std::vector<std::uint16_t> codes = quantise_image<std::uint16_t>(img, range);
      ok = write_padded_tiles(*out, *img, TypeDesc::UINT16, codes.data());
    } else {
      ok = write_padded_tiles(*out, *img, TypeDesc::FLOAT, img->pixels);
    }
    if (!ok) return one_line(out->geterror());
  }
  bool closed = out->close();
  std::string why = out->geterror(); // read (and cleared) whatever the outcome
  return closed ? std::string() : one_line(why);
}

// Every level must be half the one before (floored, at least 1), with the
// same channels, as bb_mip_chain makes them and as OpenEXR's round-down
// mode expects.
bb_status check_chain(const char *path, const bb_image *levels, int count, bb_error *err) {
  if (!levels || count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: nothing to write (no mip levels)", path);
  for (int k = 0; k < count; k++) {
    bb_status st = check_image_arg(path, &levels[k], err);
    if (st != BB_OK) return st;
    if (k == 0) continue;
    const bb_image &a = levels[k - 1], &b = levels[k];
    int w = a.width / 2 > 1 ? a.width / 2 : 1, h = a.height / 2 > 1 ? a.height / 2 : 1;
    if (b.width != w || b.height != h || b.channels != a.channels)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: mip level %d is %dx%dx%d, not %dx%dx%d (half of the level before)",
                      path, k, b.width, b.height, b.channels, w, h, a.channels);
  }
  return BB_OK;
}

// Writes the chain to a finished (complete, synced) temporary for path:
// staged is then committed or discarded by the caller.
bb_status read_mip(const char *path, int level, bb_image *out, bb_image_info *info,
                   int *level_count, bb_error *err);

bb_status write_mips(const char *path, const bb_image *levels, int count,
                     const bb_write_options *options, bb_staged_file *staged,
                     bb_error *err) {
  bb_status st = check_chain(path, levels, count, err);
  if (st != BB_OK) return st;
  const bb_write_options defaults = {BB_DEPTH_DEFAULT, BB_RANGE_UNIT, nullptr};
  const bb_write_options &o = options ? *options : defaults;
  st = check_options(path, o, err);
  if (st != BB_OK) return st;
  std::string ext = extension_of(path);
  const format_rule *f = find_format(ext);
  if (!f || !format_holds_mips(ext))
    return bb__fail(err, BB_ERR_FORMAT, "%s: mip maps need a .tif, .tiff or .exr file", path);
  bb_depth depth;
  st = resolve_depth(path, *f, o, levels[0].channels, &depth, err);
  if (st != BB_OK) return st;

  auto encode = [&](const std::string &name, OIIO::Filesystem::IOProxy *proxy) {
    return encode_mips(name, proxy, levels, count, depth, o.range, o.description);
  };
  // A TIFF of several directories cannot go through a proxy (see
  // write_safely_by_name); it is read back level by level instead.
  if (ext == ".exr" || count == 1) return write_safely(path, encode, staged, err);
  auto verify = [&](const std::string &name) -> std::string {
    for (int k = 0; k < count; k++) {
      bb_image level;
      bb_error why;
      int file_levels = 0;
      if (read_mip(name.c_str(), k, &level, nullptr, &file_levels, &why) != BB_OK)
        return std::string("read back: ") + why.message;
      bool same = level.width == levels[k].width && level.height == levels[k].height &&
                  file_levels == count;
      bb_image_free(&level);
      if (!same) return "read back: the file does not hold the levels written";
    }
    return std::string();
  };
  return write_safely_by_name(path, encode, verify, staged, err);
}

// Level `level` of a mip-mapped file, read with the same bounds and bands
// as bb_image_read.
bb_status read_mip(const char *path, int level, bb_image *out, bb_image_info *info,
                   int *level_count, bb_error *err) {
  bb_status st;
  opened_input opened = open_input(path, &st, err);
  if (!opened.in) return st;
  ImageInput *in = opened.in.get();
  int levels = 0;
  while (in->seek_subimage(0, levels)) levels++;
  (void)in->geterror(); // the failed seek past the last level queued a message
  if (level_count) *level_count = levels;
  if (level < 0 || level >= levels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no mip level %d (the file has %d)", path,
                    level, levels);
  if (!in->seek_subimage(0, level))
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(in->geterror()).c_str());
  const ImageSpec spec = in->spec();
  st = check_spec_size(path, spec, spec.nchannels, err);
  if (st != BB_OK) return st;
  bb_error alloc_err;
  st = bb_image_alloc(out, spec.width, spec.height, spec.nchannels, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);
  std::string why = read_bands(*in, opened.png, level, spec, 0, out);
  if (!why.empty()) {
    bb_image_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: corrupt or truncated image: %s", path,
                    one_line(first_line(why)).c_str());
  }
  st = fill_info(*in, spec, info, path, err);
  if (st != BB_OK) bb_image_free(out);
  return st;
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
    return bb__fail(err, BB_ERR_ARGUMENT, "mip level: %s", one_line(why).c_str());
  }
  return BB_OK;
}

} // namespace

extern "C" {

bb_status bb__image_resize_box(const bb_image *in, int width, int height, bb_image *out,
                               bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "resize: out is NULL");
  std::memset(out, 0, sizeof *out);
  if (!in || !in->pixels || in->width <= 0 || in->height <= 0 || in->channels <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "resize: empty image");
  try {
    return resize_box(in, width, height, out, err);
  } catch (const std::bad_alloc &) {
    bb_image_free(out);
    return bb__fail(err, BB_ERR_MEMORY, "resize: out of memory");
  } catch (...) {
    bb_image_free(out);
    return bb__fail(err, BB_ERR_ARGUMENT, "resize: OpenImageIO failed");
  }
}

int bb_path_supports_mips(const char *path) {
  if (!path) return 0;
  try {
    return format_holds_mips(extension_of(path)) ? 1 : 0;
  } catch (...) {
    return 0;
  }
}

bb_status bb_image_write_mips(const char *path, const bb_image *levels, int count,
                              const bb_write_options *options, bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write_mips: path is NULL");
  bb_staged_file f;
  std::memset(&f, 0, sizeof f);
  f.fd = -1;
  f.slot = -1;
  return guarded_write(path, &f, err, [&] {
    bb_status st = write_mips(path, levels, count, options, &f, err);
    return st == BB_OK ? bb__safe_commit(&f, err) : st;
  });
}

bb_status bb_image_write_mips_staged(const char *path, const bb_image *levels, int count,
                                     const bb_write_options *options,
                                     bb_staged_file **staged, bb_error *err) {
  if (!staged)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write_mips_staged: staged is NULL");
  *staged = nullptr;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write_mips_staged: path is NULL");
  bb_staged_file *f = bb__staged_new();
  if (!f) return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  bb_status st = guarded_write(
      path, f, err, [&] { return write_mips(path, levels, count, options, f, err); });
  if (st != BB_OK) {
    std::free(f);
    return st;
  }
  *staged = f;
  return BB_OK;
}

bb_status bb_image_read_mip(const char *path, int level, bb_image *out, bb_image_info *info,
                            int *level_count, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_mip: out is NULL");
  std::memset(out, 0, sizeof *out);
  clear_info(info);
  if (level_count) *level_count = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_mip: path is NULL");
  try {
    bb_status st = read_mip(path, level, out, info, level_count, err);
    if (st != BB_OK) bb_image_info_free(info);
    return st;
  } catch (const std::bad_alloc &) {
    bb_image_free(out);
    bb_image_info_free(info);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while reading", path);
  } catch (const std::exception &e) {
    bb_image_free(out);
    bb_image_info_free(info);
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    bb_image_free(out);
    bb_image_info_free(info);
    return bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
}


void bb_image_info_free(bb_image_info *info) {
  if (!info) return;
  std::free(info->description);
  info->description = nullptr;
}

bb_status bb_image_read(const char *path, bb_image *out, bb_image_info *info, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read: out is NULL");
  std::memset(out, 0, sizeof *out);
  clear_info(info);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read: path is NULL");
  return guarded_read(path, out, info, err,
                      [&] { return read_channels(path, 0, -1, out, info, err); });
}

bb_status bb__image_read_channels(const char *path, int first_channel, int channel_count,
                                  bb_image *out, bb_image_info *info, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_channels: out is NULL");
  std::memset(out, 0, sizeof *out);
  clear_info(info);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_read_channels: path is NULL");
  if (channel_count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no channel to read", path);
  return guarded_read(path, out, info, err, [&] {
    return read_channels(path, first_channel, channel_count, out, info, err);
  });
}

bb_status bb_image_read_info(const char *path, int *width, int *height, int *channels,
                             bb_image_info *info, bb_error *err) {
  clear_info(info);
  if (width) *width = 0;
  if (height) *height = 0;
  if (channels) *channels = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_info: path is NULL");
  return guarded_read(path, nullptr, info, err,
                      [&] { return read_header(path, width, height, channels, info, err); });
}

bb_status bb_image_write(const char *path, const bb_image *img, const bb_write_options *options,
                         bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write: path is NULL");
  bb_staged_file f;
  std::memset(&f, 0, sizeof f);
  f.fd = -1;
  f.slot = -1;
  return guarded_write(path, &f, err, [&] {
    bb_status st = write_image_staged(path, img, options, &f, err);
    return st == BB_OK ? bb__safe_commit(&f, err) : st;
  });
}

bb_status bb_image_write_staged(const char *path, const bb_image *img,
                                const bb_write_options *options, bb_staged_file **staged,
                                bb_error *err) {
  if (!staged) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write_staged: staged is NULL");
  *staged = nullptr;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write_staged: path is NULL");
  bb_staged_file *f = bb__staged_new();
  if (!f) return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  bb_status st = guarded_write(path, f, err,
                               [&] { return write_image_staged(path, img, options, f, err); });
  if (st != BB_OK) {
    std::free(f);
    return st;
  }
  *staged = f;
  return BB_OK;
}

int bb_path_supports_depth(const char *path, bb_depth depth) {
  if (!path) return 0;
  try {
    const format_rule *f = find_format(extension_of(path));
    return f && (depth == BB_DEPTH_DEFAULT || (f->allowed & bit(depth)) != 0);
  } catch (...) {
    return 0;
  }
}

int bb_path_max_channels(const char *path) {
  if (!path) return 0;
  try {
    const format_rule *f = find_format(extension_of(path));
    return f ? f->max_channels : 0;
  } catch (...) {
    return 0;
  }
}

int bb__path_resolved_depth(const char *path, bb_depth depth) {
  if (!path) return -1;
  try {
    const format_rule *f = find_format(extension_of(path));
    if (!f) return -1;
    return depth == BB_DEPTH_DEFAULT ? f->default_depth : depth;
  } catch (...) {
    return -1;
  }
}

// Headers only: each level's spec, never its pixels.
bb_status bb__image_level_count(const char *path, int *levels, bb_error *err) {
  *levels = 0;
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__image_level_count: path is NULL");
  try {
    bb_status st;
    opened_input opened = open_input(path, &st, err);
    if (!opened.in) return st;
    while (opened.in->seek_subimage(0, *levels)) ++*levels;
    (void)opened.in->geterror(); // the failed seek past the last level queued a message
    return BB_OK;
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while reading", path);
  } catch (const std::exception &e) {
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    return bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
}

int bb_path_is_readable_format(const char *path) {
  if (!path) return 0;
  try {
    std::string ext = extension_of(path);
    if (ext.size() < 2) return 0;
    ext.erase(0, 1);
    // "tiff:tif,tiff;png:png;...": a format, then its extensions.
    const std::string list = OIIO::get_string_attribute("extension_list");
    size_t pos = 0;
    while (pos < list.size()) {
      size_t end = list.find(';', pos);
      if (end == std::string::npos) end = list.size();
      size_t colon = list.find(':', pos);
      size_t at = colon != std::string::npos && colon < end ? colon + 1 : pos;
      while (at < end) {
        size_t comma = list.find(',', at);
        if (comma == std::string::npos || comma > end) comma = end;
        if (list.compare(at, comma - at, ext) == 0) return 1;
        at = comma + 1;
      }
      pos = end + 1;
    }
    return 0;
  } catch (...) {
    return 0;
  }
}

int bb_path_is_writable_format(const char *path) {
  if (!path) return 0;
  try {
    return find_format(extension_of(path)) != nullptr;
  } catch (...) {
    return 0;
  }
}

int bb__font_usable(const char *font) {
  if (!font || !font[0]) return 0;
  try {
    OIIO::ROI roi;
    return text_size_of("Ag", 16, font, &roi) ? 1 : 0;
  } catch (...) {
    return 0;
  }
}

int bb__text_width(const char *text, int size_px, const char *font) {
  if (!text || !font) return -1;
  try {
    OIIO::ROI roi;
    return text_size_of(text, size_px, font, &roi) ? roi.width() : -1;
  } catch (...) {
    return -1;
  }
}

bb_status bb__text_draw(bb_image *img, int center_x, int baseline_y, const char *text,
                        int size_px, const float color[3], const char *font, bb_error *err) {
  if (!img || !img->pixels || img->channels != 3 || !text || !font || !color)
    return bb__fail(err, BB_ERR_ARGUMENT, "text: bad arguments");
  try {
    // The ImageBuf wraps img's own pixels: OIIO draws straight into them.
    ImageSpec spec(img->width, img->height, 3, TypeDesc::FLOAT);
    OIIO::ImageBuf buf(spec, img->pixels);
    bool ok = OIIO::ImageBufAlgo::render_text(
        buf, center_x, baseline_y, text, size_px, font, OIIO::cspan<float>(color, 3),
        OIIO::ImageBufAlgo::TextAlignX::Center, OIIO::ImageBufAlgo::TextAlignY::Baseline, 0,
        OIIO::ROI(), 1);
    if (!ok) {
      std::string why = buf.geterror();
      drop_global_error();
      return bb__fail(err, BB_ERR_FORMAT, "text: cannot draw '%s' with font %s: %s", text,
                      font, one_line(why).c_str());
    }
    return BB_OK;
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "text: out of memory");
  } catch (...) {
    return bb__fail(err, BB_ERR_FORMAT, "text: cannot draw '%s'", text);
  }
}

bb_status bb_animation_open(const char *path, int width, int height, double frames_per_second,
                            bb_animation **out, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_animation_open: out is NULL");
  *out = nullptr;
  try {
    return animation_open(path, width, height, frames_per_second, out, err);
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path ? path : "animation");
  } catch (...) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", path ? path : "animation");
  }
}

bb_status bb_animation_add_frame(bb_animation *a, const bb_image *frame, bb_error *err) {
  if (!a || !a->out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_animation_add_frame: not open");
  try {
    return animation_add(a, frame, err);
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", a->path.c_str());
  } catch (...) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", a->path.c_str());
  }
}

bb_status bb_animation_close(bb_animation *a, bb_error *err) {
  if (!a) return bb__fail(err, BB_ERR_ARGUMENT, "bb_animation_close: NULL animation");
  bb_status st;
  try {
    st = animation_close(a, err);
  } catch (...) {
    st = bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", a->path.c_str());
  }
  animation_destroy(a);
  return st;
}

void bb_animation_abort(bb_animation *a) { animation_destroy(a); }

bb_status bb_image_frame_count(const char *path, int *frames, bb_error *err) {
  if (!path || !frames) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_frame_count: NULL argument");
  *frames = 0;
  try {
    return count_frames(path, frames, err);
  } catch (...) {
    return bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
}


} // extern "C"
