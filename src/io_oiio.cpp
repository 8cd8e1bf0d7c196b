// io_oiio.cpp: reading and writing image files through OpenImageIO (the only C++ file).
//
// This file is a firewall: OpenImageIO is included nowhere else, and every
// extern "C" function catches all exceptions and turns them, like OIIO's own
// error strings, into a bb_status with a one-line message that names the file.
//
// Alpha is never premultiplied or divided out: bumpbake's channels are data
// (heights, ssbump, ao), so both directions ask for unassociated alpha.
#include "internal.h"
#include "maps_internal.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

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
bb_status check_readable(const char *path, bb_error *err) {
  struct stat st;
  if (stat(path, &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR)
      return bb__fail(err, BB_ERR_IO, "%s: no such file", path);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, std::strerror(errno));
  }
  if (S_ISDIR(st.st_mode)) return bb__fail(err, BB_ERR_IO, "%s: is a directory", path);
  int fd = open(path, O_RDONLY);
  if (fd < 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, std::strerror(errno));
  close(fd);
  return BB_OK;
}

bb_status check_spec_size(const char *path, const ImageSpec &spec, bb_error *err) {
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    return bb__fail(err, BB_ERR_SIZE, "%s: zero or negative image size %dx%d, %d channels",
                    path, spec.width, spec.height, spec.nchannels);
  if (spec.depth > 1)
    return bb__fail(err, BB_ERR_FORMAT, "%s: volume images (depth %d) are not supported",
                    path, spec.depth);
  if (spec.nchannels > 64)
    return bb__fail(err, BB_ERR_FORMAT, "%s: %d channels (at most 64 are supported)", path,
                    spec.nchannels);
  return BB_OK;
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

bb_status read_image(const char *path, bb_image *out, bb_image_info *info, bb_error *err) {
  bb_status st = check_readable(path, err);
  if (st != BB_OK) return st;

  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = ImageInput::open(path, &config);
  if (!in)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                    one_line(OIIO::geterror()).c_str());
  const ImageSpec spec = in->spec();
  st = check_spec_size(path, spec, err);
  if (st != BB_OK) return st;

  bb_error alloc_err;
  st = bb_image_alloc(out, spec.width, spec.height, spec.nchannels, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);

  // A truncated file must fail, not come back as zeros: check both the return
  // value and the error queue, since some readers only record a warning.
  bool ok = in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, out->pixels);
  if (!ok || in->has_error()) {
    std::string why = in->geterror();
    bb_image_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: corrupt or truncated image: %s", path,
                    one_line(why).c_str());
  }
  st = fill_info(*in, spec, info, path, err);
  if (st != BB_OK) {
    bb_image_free(out);
    bb_image_info_free(info);
  }
  return st;
}

// Opens path and reads its header only: no pixel is decoded, so a file of
// any size costs only its header (and a truncated file is not noticed).
bb_status read_header(const char *path, int *width, int *height, int *channels,
                      bb_image_info *info, bb_error *err) {
  bb_status st = check_readable(path, err);
  if (st != BB_OK) return st;
  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = ImageInput::open(path, &config);
  if (!in)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                    one_line(OIIO::geterror()).c_str());
  const ImageSpec spec = in->spec();
  st = check_spec_size(path, spec, err);
  if (st != BB_OK) return st;
  if (width) *width = spec.width;
  if (height) *height = spec.height;
  if (channels) *channels = spec.nchannels;
  return fill_info(*in, spec, info, path, err);
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

std::string directory_of(const char *path) {
  const char *slash = std::strrchr(path, '/');
  if (!slash) return ".";
  if (slash == path) return "/";
  return std::string(path, (size_t)(slash - path));
}

// Creates an empty temporary file "DIR/.bb-tmp-XXXXXX.ext" with mode 0666 less
// the umask (mkstemps would make it 0600, and the rename keeps the mode).
// Returns its name, or "" with errno set.
std::string create_temp_file(const std::string &dir, const std::string &ext) {
  static const char ALNUM[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  static std::uint64_t counter = 0;
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  std::uint64_t seed = (std::uint64_t)ts.tv_nsec ^ ((std::uint64_t)ts.tv_sec << 30) ^
                       ((std::uint64_t)getpid() << 16);
  for (int attempt = 0; attempt < 100; attempt++) {
    // splitmix64 step: a fresh, well mixed value per attempt and per call.
    std::uint64_t z = (seed += 0x9E3779B97F4A7C15ull + __atomic_fetch_add(&counter, 1, __ATOMIC_RELAXED));
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    std::string name = dir + "/.bb-tmp-";
    for (int i = 0; i < 6; i++, z /= 62) name += ALNUM[z % 62];
    name += ext;
    int fd = open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      close(fd);
      return name;
    }
    if (errno != EEXIST) return std::string();
  }
  errno = EEXIST;
  return std::string();
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

// Writes img to file_name (a temporary name whose extension picks the format).
// Returns "" on success, else OIIO's reason.
std::string write_with_oiio(const std::string &file_name, const bb_image *img, bb_depth depth,
                            bb_range range, const char *description) {
  TypeDesc file_type = depth == BB_DEPTH_8      ? TypeDesc::UINT8
                       : depth == BB_DEPTH_16   ? TypeDesc::UINT16
                       : depth == BB_DEPTH_HALF ? TypeDesc::HALF
                                                : TypeDesc::FLOAT;
  ImageSpec spec(img->width, img->height, img->channels, file_type);
  name_basis_channels(spec);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  spec.attribute("Software", "bumpbake " BB_VERSION_STRING);
  if (description)
    spec.attribute("ImageDescription",
                   description_to_store(extension_of(file_name.c_str()) == ".tga", description));
  if (depth == BB_DEPTH_HALF || depth == BB_DEPTH_FLOAT) spec.attribute("compression", "zip");

  auto out = ImageOutput::create(file_name);
  if (!out) return one_line(OIIO::geterror());
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

bb_status write_image(const char *path, const bb_image *img, const bb_write_options *options,
                      bb_error *err) {
  bb_status st = check_image_arg(path, img, err);
  if (st != BB_OK) return st;
  const bb_write_options defaults = {BB_DEPTH_DEFAULT, BB_RANGE_UNIT, nullptr};
  const bb_write_options &o = options ? *options : defaults;

  st = check_options(path, o, err);
  if (st != BB_OK) return st;

  std::string ext = extension_of(path);
  const format_rule *f = find_format(ext);
  if (!f)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: unknown output format '%s' (use .png, .tga, .tif, .tiff or .exr)", path,
                    ext.c_str());
  bb_depth depth;
  st = resolve_depth(path, *f, o, img->channels, &depth, err);
  if (st != BB_OK) return st;

  std::string tmp = create_temp_file(directory_of(path), ext);
  if (tmp.empty())
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, std::strerror(errno));
  std::string why;
  try {
    why = write_with_oiio(tmp, img, depth, o.range, o.description);
  } catch (...) {
    unlink(tmp.c_str());
    throw;
  }
  if (why.empty() && std::rename(tmp.c_str(), path) != 0)
    why = std::strerror(errno);
  if (!why.empty()) {
    unlink(tmp.c_str());
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  return BB_OK;
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

// The GIF being written: OIIO's writer holds the temporary file open; the
// final name appears only once bb_animation_close has checked the file.
struct bb_animation {
  std::string path, tmp;
  std::unique_ptr<ImageOutput> out;
  ImageSpec spec;
  int frames = 0;
};

namespace {

void animation_destroy(bb_animation *a, bool remove_tmp) {
  if (!a) return;
  try {
    if (a->out) a->out->close();
  } catch (...) {
  }
  if (remove_tmp && !a->tmp.empty()) unlink(a->tmp.c_str());
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
  std::unique_ptr<bb_animation> a(new bb_animation);
  a->path = path;
  a->tmp = create_temp_file(directory_of(path), ".gif");
  if (a->tmp.empty())
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, std::strerror(errno));
  a->out = ImageOutput::create(a->tmp);
  if (!a->out) {
    std::string why = one_line(OIIO::geterror());
    unlink(a->tmp.c_str());
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  a->spec = ImageSpec(width, height, 3, TypeDesc::UINT8);
  // GIF delays are in 1/100 s: a rational of 100 / delay is what OIIO reads.
  int per_second[2] = {100, (int)std::lround(100.0 / fps)};
  a->spec.attribute("FramesPerSecond", OIIO::TypeRational, per_second);
  a->spec.attribute("gif:LoopCount", 0); // loop forever
  *out = a.release();
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
  if (!a->out->open(a->tmp, a->spec, mode) || !a->out->write_image(TypeDesc::UINT8, codes.data()))
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path,
                    one_line(a->out->geterror()).c_str());
  a->frames++;
  return BB_OK;
}

// OIIO 2.4's GIF writer does not report a failed fwrite, so the finished
// temporary file is read back: a short file has fewer frames or none.
bb_status animation_close(bb_animation *a, bb_error *err) {
  const char *path = a->path.c_str();
  if (a->frames == 0) return bb__fail(err, BB_ERR_ARGUMENT, "%s: no frames to write", path);
  bool closed = a->out->close();
  std::string why = a->out->geterror();
  a->out.reset();
  if (!closed) return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, one_line(why).c_str());
  int frames = 0;
  bb_error read_err;
  if (count_frames(a->tmp.c_str(), &frames, &read_err) != BB_OK || frames != a->frames)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: the file holds %d of %d frames", path,
                    frames, a->frames);
  if (std::rename(a->tmp.c_str(), path) != 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, std::strerror(errno));
  a->tmp.clear(); // renamed: nothing to remove
  return BB_OK;
}

// ------------------------------------------------------------ mip chains

// Tile size of mip-mapped files: OpenEXR stores mip levels only in tiled
// files, and TIFF readers expect a tiled pyramid too.
constexpr int MIP_TILE = 64;

bool format_holds_mips(const std::string &ext) {
  return ext == ".tif" || ext == ".tiff" || ext == ".exr";
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
    spec.attribute("oiio:UnassociatedAlpha", 1);
    spec.attribute("Software", "bumpbake " BB_VERSION_STRING);
    if (description) spec.attribute("ImageDescription", description);
    spec.attribute("compression", "zip");
    if (!out->open(file_name, spec, k == 0 ? ImageOutput::Create : append))
      return one_line(out->geterror());
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

bb_status write_mips(const char *path, const bb_image *levels, int count,
                     const bb_write_options *options, bb_error *err) {
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

  std::string tmp = create_temp_file(directory_of(path), ext);
  if (tmp.empty())
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, std::strerror(errno));
  std::string why;
  try {
    why = encode_mips(tmp, nullptr, levels, count, depth, o.range, o.description);
  } catch (...) {
    unlink(tmp.c_str());
    throw;
  }
  if (why.empty() && std::rename(tmp.c_str(), path) != 0) why = std::strerror(errno);
  if (!why.empty()) {
    unlink(tmp.c_str());
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  return BB_OK;
}

bb_status read_mip(const char *path, int level, bb_image *out, bb_image_info *info,
                   int *level_count, bb_error *err) {
  bb_status st = check_readable(path, err);
  if (st != BB_OK) return st;
  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = ImageInput::open(path, &config);
  if (!in)
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                    one_line(OIIO::geterror()).c_str());
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
  st = check_spec_size(path, spec, err);
  if (st != BB_OK) return st;
  bb_error alloc_err;
  st = bb_image_alloc(out, spec.width, spec.height, spec.nchannels, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);
  bool ok = in->read_image(0, level, 0, spec.nchannels, TypeDesc::FLOAT, out->pixels);
  if (!ok || in->has_error()) {
    std::string why = in->geterror();
    bb_image_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: corrupt or truncated image: %s", path,
                    one_line(why).c_str());
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
  try {
    return write_mips(path, levels, count, options, err);
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while writing", path);
  } catch (const std::exception &e) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", path);
  }
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
  try {
    return read_image(path, out, info, err);
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

bb_status bb_image_read_info(const char *path, int *width, int *height, int *channels,
                             bb_image_info *info, bb_error *err) {
  clear_info(info);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_read_info: path is NULL");
  try {
    bb_status st = read_header(path, width, height, channels, info, err);
    if (st != BB_OK) bb_image_info_free(info);
    return st;
  } catch (const std::bad_alloc &) {
    bb_image_info_free(info);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while reading", path);
  } catch (const std::exception &e) {
    bb_image_info_free(info);
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    bb_image_info_free(info);
    return bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
}

bb_status bb_image_write(const char *path, const bb_image *img, const bb_write_options *options,
                         bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_image_write: path is NULL");
  try {
    return write_image(path, img, options, err);
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while writing", path);
  } catch (const std::exception &e) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", path);
  }
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
  animation_destroy(a, true);
  return st;
}

void bb_animation_abort(bb_animation *a) { animation_destroy(a, true); }

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
